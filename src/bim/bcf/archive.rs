//! The `.bcfzip`: `bcf.version`, (3.0) `extensions.xml`, and per topic a folder named by
//! its GUID with `markup.bcf`, `viewpoint.bcfv` and `snapshot.png` (when it has one). Entries are stored (XML is small) with
//! the zip format's fixed 1980-01-01 date, so the same topics give the same bytes.

use super::topics::IssueTopic;
use super::{BcfHeader, BcfVersion, xml};
use std::collections::BTreeSet;
use std::io::{Cursor, Write};
use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, DateTime, ZipWriter};

#[derive(Debug, thiserror::Error)]
pub enum BcfError {
    #[error("cannot write the BCF archive: {0}")]
    Zip(#[from] zip::result::ZipError),
    #[error("cannot write the BCF archive: {0}")]
    Io(#[from] std::io::Error),
}

/// The archive's bytes.
pub fn write_bcfzip(
    version: BcfVersion,
    header: &BcfHeader,
    topics: &[IssueTopic],
) -> Result<Vec<u8>, BcfError> {
    let options = SimpleFileOptions::default()
        .compression_method(CompressionMethod::Stored)
        .last_modified_time(DateTime::DEFAULT)
        .unix_permissions(0o644);
    let mut zip = ZipWriter::new(Cursor::new(Vec::new()));
    zip.start_file("bcf.version", options)?;
    zip.write_all(&xml::version(version)?)?;
    if version == BcfVersion::V3_0 {
        let mut labels: BTreeSet<String> = ["framing", "nailing"].map(String::from).into();
        labels.extend(topics.iter().flat_map(|t| t.labels.iter().cloned()));
        let labels: Vec<String> = labels.into_iter().collect();
        zip.start_file("extensions.xml", options)?;
        zip.write_all(&xml::extensions(&labels)?)?;
    }
    for t in topics {
        zip.start_file(format!("{}/markup.bcf", t.guid), options)?;
        zip.write_all(&xml::markup(version, header, t)?)?;
        zip.start_file(format!("{}/viewpoint.bcfv", t.guid), options)?;
        zip.write_all(&xml::viewpoint(version, t)?)?;
        if let Some(snapshot) = &t.snapshot {
            zip.start_file(format!("{}/{}", t.guid, xml::SNAPSHOT_FILE), options)?;
            zip.write_all(&snapshot.0)?;
        }
    }
    Ok(zip.finish()?.into_inner())
}
