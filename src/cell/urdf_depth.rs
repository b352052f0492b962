//! The URDF parser takes time quadratic in how deeply elements nest (200,000 nested unknown
//! elements, 4 MB, take about a minute). A robot description nests about six levels
//! (robot, link, visual, geometry, mesh), so a file nesting past `MAX_DEPTH` is refused before
//! it is parsed.

use quick_xml::Reader;
use quick_xml::events::Event;

pub(crate) const MAX_DEPTH: usize = 64;

/// The 1-based line where the elements first nest deeper than `MAX_DEPTH`, if they do.
/// Malformed XML stops the scan: the URDF parser reports it with its own message.
pub(crate) fn too_deep(xml: &str) -> Option<usize> {
    let mut reader = Reader::from_str(xml);
    let mut depth = 0usize;
    loop {
        match reader.read_event() {
            Ok(Event::Start(_)) => {
                depth += 1;
                if depth > MAX_DEPTH {
                    let at = (reader.buffer_position() as usize).min(xml.len());
                    let line = 1 + xml.as_bytes()[..at].iter().filter(|&&b| b == b'\n').count();
                    return Some(line);
                }
            }
            Ok(Event::End(_)) => depth = depth.saturating_sub(1),
            Ok(Event::Eof) | Err(_) => return None,
            Ok(_) => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_nesting_not_siblings() {
        let deep = format!("<robot>\n{}{}</robot>", "<a>".repeat(70), "</a>".repeat(70));
        assert_eq!(too_deep(&deep), Some(2));
        let wide = format!("<robot>{}</robot>", "<a></a>".repeat(1000));
        assert_eq!(too_deep(&wide), None);
        let at_limit = format!("{}{}", "<a>".repeat(MAX_DEPTH), "</a>".repeat(MAX_DEPTH));
        assert_eq!(too_deep(&at_limit), None);
    }
}
