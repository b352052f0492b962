//! Reading a written BCF archive back: every entry, and its XML documents as text.
#![allow(dead_code)]

use std::io::Read;
use std::path::Path;

/// Every entry of a BCF archive in archive order: its name and bytes.
pub fn entries(bcfzip: &Path) -> Vec<(String, Vec<u8>)> {
    let file = std::fs::File::open(bcfzip)
        .unwrap_or_else(|e| panic!("{}: cannot open: {e}", bcfzip.display()));
    let mut archive = zip::ZipArchive::new(file)
        .unwrap_or_else(|e| panic!("{} is not a zip archive: {e}", bcfzip.display()));
    (0..archive.len())
        .map(|i| {
            let mut f = archive.by_index(i).unwrap();
            let name = f.name().unwrap().to_string();
            let mut bytes = Vec::new();
            f.read_to_end(&mut bytes).unwrap();
            (name, bytes)
        })
        .collect()
}

/// Whether an entry is a snapshot image rather than an XML document.
pub fn is_image(name: &str) -> bool {
    name.ends_with(".png")
}

/// The XML documents of a BCF archive (every entry but the snapshot images) as UTF-8 text.
pub fn xml_documents(bcfzip: &Path) -> Vec<(String, String)> {
    entries(bcfzip)
        .into_iter()
        .filter(|(name, _)| !is_image(name))
        .map(|(name, bytes)| {
            let text =
                String::from_utf8(bytes).unwrap_or_else(|e| panic!("{name} is not UTF-8: {e}"));
            (name, text)
        })
        .collect()
}
