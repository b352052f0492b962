//! `simulate … --bcf OUT.bcfzip [--bcf-version 3.0|2.1]`: the failing members as BCF topics.

use super::{Failure, write_atomically};
use framewright::bim::bcf::Snapshot;
use framewright::bim::bcf::{topics_of, write_bcfzip};
use framewright::bim::{BcfHeader, BcfVersion, iso_date_time};
use framewright::ifc::Model;
use framewright::report::png::svg_to_png;
use framewright::report::simulate::SimReport;
use framewright::report::svg::elevation_svg;
use framewright::sim::Simulation;
use std::collections::BTreeMap;
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
    pub fn write(
        &self,
        model: &Model,
        sim: &Simulation,
        report: &SimReport,
    ) -> Result<(), Failure> {
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
        let mut topics = topics_of(sim.model(model), sim, &header);
        // Each topic shows its wall's elevation drawing, rendered once per wall.
        let mut snapshots: BTreeMap<String, Snapshot> = BTreeMap::new();
        for topic in &mut topics {
            if !snapshots.contains_key(&topic.wall_id) {
                let Some(svg) = elevation_svg(sim, report, &topic.wall_id) else {
                    continue;
                };
                let png = svg_to_png(&svg).map_err(|e| {
                    Failure::bad_input(format!(
                        "cannot draw the snapshot of wall {}: {e}",
                        topic.wall_id
                    ))
                })?;
                snapshots.insert(topic.wall_id.clone(), Snapshot(png));
            }
            topic.snapshot = snapshots.get(&topic.wall_id).cloned();
        }
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
