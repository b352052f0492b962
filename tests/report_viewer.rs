//! The report's 3D view of each wall's run (`report::viewer`, `src/report/viewer.js`): the page
//! embeds each wall's scene byte for byte and the viewer's script once; in a real browser
//! (Debian's chromium, headless, WebGL on SwiftShader, from `file://`, no network) every view
//! draws, loads every piece of its scene, logs nothing, and a click on a failed piece shows
//! that piece's root cause beside the canvas. With more than 8 walls each wall's page holds
//! its view and the index none. Browser checks skip with a message when chromium is absent.

mod common;

use common::browser::{browse, chromium, console_errors};
use framewright::cell::Cell;
use framewright::ifc::Model;
use framewright::pipeline::simulate;
use framewright::report::html::{DEFAULT_MAX_REPORT_BYTES, ReportInput, write_report};
use framewright::report::simulate::SimReport;
use framewright::report::viewer::SCRIPT;
use framewright::sim::SimOptions;
use regex::Regex;
use std::io::Read;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Where the tests leave what a person may look at (screenshots).
fn output_dir() -> PathBuf {
    let dir = root().join("target/test-output/report");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Simulates `model` on the study cell and writes its report into `dir`.
fn report(model: &Path, dir: &Path) {
    let m = Model::open(model).expect("model");
    let cell = Cell::load("study-abb").unwrap();
    let sim = simulate(&m, &cell, &SimOptions::default()).expect("simulation runs");
    let report = SimReport::new(&sim, SimOptions::default().dt).expect("report");
    let name = model.file_name().unwrap().to_string_lossy().into_owned();
    let input = ReportInput {
        model: &m,
        model_name: &name,
        cell: &cell,
        sim: &sim,
        report: &report,
    };
    write_report(dir, &input, DEFAULT_MAX_REPORT_BYTES).expect("report written");
}

fn base64_decode(text: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => u32::from(c - b'A'),
        b'a'..=b'z' => u32::from(c - b'a') + 26,
        b'0'..=b'9' => u32::from(c - b'0') + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("{c} is not base64"),
    };
    let digits: Vec<u32> = text
        .bytes()
        .filter(|b| !b.is_ascii_whitespace() && *b != b'=')
        .map(value)
        .collect();
    digits
        .chunks(4)
        .flat_map(|c| {
            let n = c
                .iter()
                .enumerate()
                .fold(0, |n, (k, v)| n | (v << (18 - 6 * k)));
            [(n >> 16) as u8, (n >> 8) as u8, n as u8][..c.len() - 1].to_vec()
        })
        .collect()
}

/// The scenes a page embeds, in page order, as GLB bytes.
fn embedded_scenes(page: &str) -> Vec<Vec<u8>> {
    let scene = Regex::new(
        r#"<script type="application/octet-stream" class="viewer-scene">([A-Za-z0-9+/=]*)</script>"#,
    )
    .unwrap();
    scene
        .captures_iter(page)
        .map(|c| {
            let mut glb = Vec::new();
            flate2::read::ZlibDecoder::new(&base64_decode(&c[1])[..])
                .read_to_end(&mut glb)
                .expect("a zlib stream");
            glb
        })
        .collect()
}

/// Every script element of a page is a scene or the viewer's own script, and the viewer's
/// script is there once when there is a scene.
fn assert_only_the_viewers_scripts(page: &str) {
    let (scenes, viewers) = common::page_scripts::viewer_scripts(page);
    assert_eq!(
        viewers,
        usize::from(scenes > 0),
        "the viewer's script once a page"
    );
}

/// The number of `piece …` nodes in a GLB's JSON.
fn piece_nodes(glb: &[u8]) -> usize {
    let word = |i: usize| u32::from_le_bytes(glb[i..i + 4].try_into().unwrap()) as usize;
    let doc: serde_json::Value = serde_json::from_slice(&glb[20..20 + word(12)]).unwrap();
    doc["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|n| n["name"].as_str().is_some_and(|s| s.starts_with("piece ")))
        .count()
}

/// The attributes the viewer wrote on each `figure.viewer` of a rendered DOM.
fn figures(dom: &str) -> Vec<String> {
    Regex::new(r#"<figure class="viewer"[^>]*>"#)
        .unwrap()
        .find_iter(dom)
        .map(|m| m.as_str().to_string())
        .collect()
}

fn attribute(tag: &str, name: &str) -> Option<String> {
    Regex::new(&format!(r#" {name}="([^"]*)""#))
        .unwrap()
        .captures(tag)
        .map(|c| c[1].to_string())
}

#[test]
fn tm3_each_walls_view_embeds_its_scene_and_draws_it_in_a_browser() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("report");
    report(&root().join("examples/models/tm3.ifc"), &out);
    let page = std::fs::read_to_string(out.join("index.html")).unwrap();
    // One self-contained page: nothing loaded from elsewhere, the scene files still linked.
    assert!(!page.contains(" src=") && !page.contains("<link"));
    assert_eq!(page.matches("url(").count(), page.matches("url(#").count());
    assert_eq!(
        page.replace("http://www.w3.org/2000/svg", "")
            .matches("http")
            .count(),
        0
    );
    assert_only_the_viewers_scripts(&page);
    // The viewer's code cannot end its element early, nor open a comment that would.
    let code = SCRIPT.to_ascii_lowercase();
    assert!(!code.contains("</script") && !code.contains("<!--") && SCRIPT.is_ascii());
    // Each wall's scene, byte for byte (the base64 and zlib decoded here independently).
    let scenes = embedded_scenes(&page);
    assert_eq!(scenes.len(), 4, "a view per wall");
    for (i, glb) in scenes.iter().enumerate() {
        let file = format!("scene-{:03}.glb", i + 1);
        assert!(*glb == std::fs::read(out.join(&file)).unwrap(), "{file}");
        assert!(page.contains(&format!(r#"href="{file}""#)));
    }

    let Some(browser) = chromium() else { return };
    let shot = output_dir().join("tm3-viewer.png");
    let (dom, log) = browse(browser, &out.join("index.html"), &shot);
    assert!(console_errors(&log).is_empty(), "{log}");
    eprintln!("screenshot: {}", shot.display());
    let shown = figures(&dom);
    assert_eq!(shown.len(), 4);
    for (tag, glb) in shown.iter().zip(&scenes) {
        assert_eq!(attribute(tag, "data-error"), None, "{tag}");
        let pieces: usize = attribute(tag, "data-pieces").expect(tag).parse().unwrap();
        assert_eq!(pieces, piece_nodes(glb), "every piece of the scene loaded");
        // 640 × 360 at least: a good part of the canvas is the scene, not the background.
        let drawn: usize = attribute(tag, "data-drawn").unwrap().parse().unwrap();
        assert!(drawn > 640 * 360 / 4, "{drawn} pixels drawn");
    }
}

/// Clicks, through the page's own pointer events, at where the viewer draws each piece of the
/// first wall with root causes, and records what the panel beside the canvas then says.
const CLICK_EVERY_PIECE: &str = r#"<script>
(function () {
  function report(result) {
    const pre = document.createElement('pre');
    pre.id = 'clicks';
    pre.textContent = JSON.stringify(result);
    document.body.append(pre);
  }
  function click(figure, id) {
    const viewer = figure.viewer;
    const at = viewer.project(id);
    if (!at) return null;
    const box = viewer.canvas.getBoundingClientRect();
    const x = box.left + at[0] * box.width / viewer.canvas.width;
    const y = box.top + at[1] * box.height / viewer.canvas.height;
    for (const type of ['pointerdown', 'pointerup']) {
      viewer.canvas.dispatchEvent(new PointerEvent(type, { clientX: x, clientY: y, buttons: type === 'pointerdown' ? 1 : 0, bubbles: true }));
    }
    const info = figure.querySelector('.viewer-info');
    const strong = info.querySelector('strong');
    const picked = figure.closest('section').querySelector('.causes li.picked');
    return {
      id,
      shown: strong ? strong.textContent : null,
      text: info.textContent,
      why: Array.from(info.querySelectorAll('.why')).map((e) => e.textContent),
      picked: picked ? picked.getAttribute('data-id') : null,
    };
  }
  function run() {
    const figures = Array.from(document.querySelectorAll('figure.viewer'));
    if (!figures.every((f) => f.viewer || f.hasAttribute('data-error'))) { setTimeout(run, 50); return; }
    const result = [];
    for (const figure of figures) {
      if (!figure.viewer) continue;
      const section = figure.closest('section');
      const causes = Array.from(section.querySelectorAll('.causes li[data-id]')).map((li) => ({ id: li.getAttribute('data-id'), text: li.textContent }));
      for (const shape of section.querySelectorAll('svg.elevation g.piece')) {
        const id = shape.getAttribute('data-id');
        const clicked = click(figure, id);
        if (clicked) {
          clicked.wall = section.getAttribute('data-wall');
          clicked.verdict = shape.getAttribute('data-verdict');
          clicked.cause = (causes.find((c) => c.id === id) || {}).text || null;
          result.push(clicked);
        }
      }
    }
    report(result);
  }
  run();
})();
</script>"#;

/// The clicks' record from a page with [`CLICK_EVERY_PIECE`] appended, loaded in chromium.
fn click_every_piece(browser: &str, page: &Path, shot: &str) -> Vec<serde_json::Value> {
    let text = std::fs::read_to_string(page).unwrap();
    let test_page = page.with_file_name("click-test.html");
    std::fs::write(
        &test_page,
        text.replace("</body>", &format!("{CLICK_EVERY_PIECE}</body>")),
    )
    .unwrap();
    let shot = output_dir().join(shot);
    let (dom, log) = browse(browser, &test_page, &shot);
    assert!(console_errors(&log).is_empty(), "{log}");
    let record = Regex::new(r#"<pre id="clicks">([^<]*)</pre>"#)
        .unwrap()
        .captures(&dom)
        .expect("the clicks' record")[1]
        .replace("&quot;", "\"")
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&amp;", "&");
    serde_json::from_str::<serde_json::Value>(&record)
        .unwrap()
        .as_array()
        .unwrap()
        .clone()
}

#[test]
fn tm3_a_click_on_a_failed_piece_shows_its_root_cause_beside_the_view() {
    let Some(browser) = chromium() else { return };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("report");
    report(&root().join("examples/models/tm3.ifc"), &out);
    let clicks = click_every_piece(browser, &out.join("index.html"), "tm3-viewer-click.png");
    // A click at a piece's drawn centre hits that piece unless another is drawn in front of
    // it; most are hit.
    let hits: Vec<&serde_json::Value> = clicks.iter().filter(|c| c["shown"] == c["id"]).collect();
    assert!(
        hits.len() * 2 > clicks.len(),
        "{} of {}",
        hits.len(),
        clicks.len()
    );
    let mut causes_shown = 0;
    for c in &hits {
        let verdict = c["verdict"].as_str().unwrap().replace('-', " ");
        assert!(c["text"].as_str().unwrap().contains(&verdict), "{c}");
        match c["cause"].as_str() {
            // A root cause's entry is shown and highlighted.
            Some(cause) => {
                assert_eq!(c["why"][0].as_str(), Some(cause), "{c}");
                assert_eq!(c["picked"], c["id"], "{c}");
                causes_shown += 1;
            }
            None => assert_eq!(c["picked"], serde_json::Value::Null, "{c}"),
        }
    }
    assert!(causes_shown >= 4, "{causes_shown} root causes shown");
    assert!(
        hits.iter()
            .any(|c| c["verdict"] == "framed" || c["verdict"] == "nailing-failed"),
        "a piece that did not fail its framing"
    );
}

#[test]
fn hostile_ids_picked_in_the_view_show_as_text() {
    let Some(browser) = chromium() else { return };
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("hostile.ifc");
    std::fs::copy(
        root().join("tests/fixtures/report_hostile_names.ifc"),
        &model,
    )
    .unwrap();
    let out = dir.path().join("report");
    report(&model, &out);
    let clicks = click_every_piece(browser, &out.join("index.html"), "hostile-viewer-click.png");
    assert!(!clicks.is_empty());
    // The ids hold markup; the panel shows them as they are.
    assert!(clicks.iter().any(|c| {
        c["shown"] == c["id"]
            && c["id"]
                .as_str()
                .is_some_and(|id| id.contains('<') || id.contains('&') || id.contains('"'))
    }));
}

#[test]
fn with_more_than_eight_walls_each_wall_page_embeds_its_own_view_and_the_index_none() {
    let dir = tempfile::tempdir().unwrap();
    let model = common::synth_block(
        dir.path(),
        &["--blocks", "1", "--storeys", "3", "--grid", "1x1"],
    );
    let out = dir.path().join("report");
    report(&model, &out);
    let index = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(!index.contains("<script") && !index.contains("<figure class=\"viewer\""));
    let mut pages = 0;
    while out.join(format!("wall-{:03}.html", pages + 1)).exists() {
        pages += 1;
        let page = std::fs::read_to_string(out.join(format!("wall-{pages:03}.html"))).unwrap();
        assert_only_the_viewers_scripts(&page);
        let glb = std::fs::read(out.join(format!("scene-{pages:03}.glb"))).unwrap();
        assert!(
            embedded_scenes(&page) == [glb],
            "wall {pages}: its own scene only"
        );
    }
    assert!(pages > 8, "{pages} wall pages");

    let Some(browser) = chromium() else { return };
    let shot = output_dir().join("block-wall-001-viewer.png");
    let (dom, log) = browse(browser, &out.join("wall-001.html"), &shot);
    assert!(console_errors(&log).is_empty(), "{log}");
    let shown = figures(&dom);
    assert_eq!(shown.len(), 1);
    assert_eq!(attribute(&shown[0], "data-error"), None);
    let drawn: usize = attribute(&shown[0], "data-drawn").unwrap().parse().unwrap();
    assert!(drawn > 640 * 360 / 4, "{drawn} pixels drawn");
}
