//! `simulate … --bcf OUT.bcfzip [--bcf-version 3.0|2.1]`: the failing members as BCF topics.

use super::{Failure, write_atomically};
use framewright::bim::bcf::{topics_of, write_bcfzip};
use framewright::bim::{BcfHeader, BcfVersion, iso_date_time};
use framewright::ifc::Model;
use framewright::sim::Simulation;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct BcfArgs {
    /// Also write the failures as BCF topics (one per root cause per wall) to this file.
    #[arg(long, value_name = "OUT.bcfzip")]
    pub bcf: Option<PathBuf>,
    /// The BCF release to write.
    #[arg(long, value_enum, default_value = "3.0", requires = "bcf")]
    pub bcf_version: BcfVersion,
    /// The topics' creation date (ISO 8601); default: the model header's time stamp.
    #[arg(long, value_name = "DATE", requires = "bcf")]
    pub bcf_date: Option<String>,
}

impl BcfArgs {
    /// Writes the BCF file when asked to (whole or not at all).
    pub fn write(&self, model: &Model, sim: &Simulation) -> Result<(), Failure> {
        let Some(path) = &self.bcf else {
            return Ok(());
        };
        let date = match &self.bcf_date {
            Some(d) => iso_date_time(d).ok_or_else(|| {
                Failure::bad_input(format!(
                    "--bcf-date `{d}` is not an ISO 8601 date-time such as 2026-03-01T08:00:00"
                ))
            })?,
            None => iso_date_time(&model.header().time_stamp).ok_or_else(|| {
                Failure::bad_input(format!(
                    "{}: the header time stamp `{}` is not an ISO 8601 date-time; give the topics' date with --bcf-date",
                    model.path.display(),
                    model.header().time_stamp
                ))
            })?,
        };
        let file = model.step();
        let project = file
            .of_type("IFCPROJECT")
            .next()
            .and_then(|r| file.entity(r.id)?.ok())
            .and_then(|e| e.get(0).text().map(|(t, _)| t.into_owned()));
        let header = BcfHeader {
            model_file: model.path.file_name().map_or_else(
                || model.path.display().to_string(),
                |n| n.to_string_lossy().into_owned(),
            ),
            project_global_id: project,
            date: date.to_string(),
        };
        let topics = topics_of(model, sim, &header);
        let bytes = write_bcfzip(self.bcf_version, &header, &topics)?;
        write_atomically(path, &bytes)
            .map_err(|e| Failure::bad_input(format!("cannot write {}: {e}", path.display())))?;
        eprintln!(
            "{}: BCF {}, {} topic(s)",
            path.display(),
            self.bcf_version.id(),
            topics.len()
        );
        Ok(())
    }
}
