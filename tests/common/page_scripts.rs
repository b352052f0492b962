//! The scripts a report page may hold: the 3D view's scenes (base64 only) and the viewer's own
//! code; nothing from the model.

use regex::Regex;

/// Counts a page's scripts, (scenes, viewer scripts), asserting that every script element (as
/// written, or in the DOM a browser built) is one of the two.
pub fn viewer_scripts(page: &str) -> (usize, usize) {
    let script = Regex::new(r"(?s)<script([^>]*)>(.*?)</script>").unwrap();
    let (mut scenes, mut viewers) = (0, 0);
    for c in script.captures_iter(page) {
        if &c[1] == r#" type="application/octet-stream" class="viewer-scene""# {
            assert!(
                c[2].bytes()
                    .all(|b| b.is_ascii_alphanumeric() || b"+/=".contains(&b)),
                "a scene that is not base64"
            );
            scenes += 1;
        } else {
            assert!(
                c[1].is_empty() && c[2] == *framewright::report::viewer::SCRIPT,
                "markup from the model reached the page as a script: {}",
                &c[0][..c[0].len().min(200)]
            );
            viewers += 1;
        }
    }
    assert_eq!(page.matches("<script").count(), scenes + viewers);
    (scenes, viewers)
}
