//! The reader takes products in parallel runs. Whatever run a product falls in, the model
//! reads as one pass would: pieces in file order, and each bad product skipped with one
//! warning naming it. Checked on a generated block model (several runs of products), with
//! products in different runs stripped of their geometry.
mod common;

use framewright::ifc::Model;

/// The attributes of a STEP instance's parameter list, split at top-level commas.
fn attributes(params: &str) -> Vec<&str> {
    let (mut depth, mut quoted, mut start) = (0usize, false, 0usize);
    let mut out = Vec::new();
    for (i, c) in params.char_indices() {
        match c {
            '\'' => quoted = !quoted,
            '(' if !quoted => depth += 1,
            ')' if !quoted => depth -= 1,
            ',' if !quoted && depth == 0 => {
                out.push(&params[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    out.push(&params[start..]);
    out
}

#[test]
fn products_in_every_run_read_as_one_pass_reads_them() {
    // Two blocks of four storeys of 1 x 2 units, members grouped in their walls.
    let dir = tempfile::tempdir().expect("temp dir");
    let path = common::synth_block(
        dir.path(),
        &[
            "--grouping",
            "wall",
            "--blocks",
            "2",
            "--storeys",
            "4",
            "--grid",
            "1x2",
        ],
    );
    let text = std::fs::read_to_string(&path).expect("read the generated model");
    let members: Vec<usize> = text
        .lines()
        .enumerate()
        .filter(|(_, l)| l.contains("=IFCMEMBER("))
        .map(|(k, _)| k)
        .collect();
    assert!(
        members.len() > 3 * 512,
        "the model must span several runs of products: {} members",
        members.len()
    );
    // The first member, the last, and some in between, in different runs.
    let n = members.len();
    let broken: Vec<usize> = [0, 511, 512, n / 2, n - 2, n - 1]
        .map(|k| members[k])
        .to_vec();
    let mut broken_ids = Vec::new();
    let mut broken_gids = Vec::new();
    let lines: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(k, line)| {
            if !broken.contains(&k) {
                return line.to_string();
            }
            let (head, rest) = line.split_once("=IFCMEMBER(").expect("member");
            let params = rest.strip_suffix(");").expect("one line per instance");
            let mut attrs = attributes(params);
            broken_ids.push(head.trim_start_matches('#').to_string());
            broken_gids.push(attrs[0].trim_matches('\'').to_string());
            attrs[6] = "$"; // Representation
            format!("{head}=IFCMEMBER({});", attrs.join(","))
        })
        .collect();
    let broken_text = lines.join("\n") + "\n";

    let whole = Model::from_bytes("whole.ifc", text.into_bytes(), &Default::default())
        .expect("read the whole model");
    let model = Model::from_bytes("broken.ifc", broken_text.into_bytes(), &Default::default())
        .expect("read the model with products stripped");
    // Pieces: the whole model's, in file order, less the stripped products.
    let expected: Vec<&str> = whole
        .pieces()
        .iter()
        .filter(|p| !broken_gids.contains(&p.global_id))
        .map(|p| p.id.as_str())
        .collect();
    let got: Vec<&str> = model.pieces().iter().map(|p| p.id.as_str()).collect();
    assert_eq!(got, expected);
    // Warnings: one per stripped product, naming it, sorted as the reader sorts them.
    let skipped: Vec<&str> = model
        .warnings
        .iter()
        .filter(|w| w.message.contains("has no representation"))
        .map(|w| w.message.as_str())
        .collect();
    assert_eq!(skipped.len(), broken_ids.len(), "{skipped:#?}");
    for id in &broken_ids {
        assert_eq!(
            skipped
                .iter()
                .filter(|m| m.contains(&format!("#{id} ")))
                .count(),
            1,
            "#{id} in {skipped:#?}"
        );
    }
    let mut sorted = model.warnings.clone();
    sorted.sort();
    assert_eq!(model.warnings, sorted);
    assert_eq!(
        whole.warnings.len() + broken_ids.len(),
        model.warnings.len()
    );
}
