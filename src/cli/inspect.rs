//! `framewright inspect MODEL.ifc [--json]`: what the reader finds in a model.

use super::{CmdResult, print_stdout, write_stdout};
use framewright::ifc::Model;
use framewright::report::inspect::InspectReport;
use framewright::step::ReadOptions;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct InspectArgs {
    /// The IFC model (ISO 10303-21: IFC2X3, IFC4 or IFC4X3).
    pub model: PathBuf,
    /// Print JSON (members in metres, world frame) instead of a summary.
    #[arg(long)]
    pub json: bool,
    /// Refuse files larger than this many megabytes.
    #[arg(long, value_name = "MB", default_value_t = 4096)]
    pub max_size: u64,
}

pub fn run(args: InspectArgs) -> CmdResult {
    let options = ReadOptions {
        max_bytes: args.max_size.saturating_mul(1 << 20),
        ..super::limits::read_options().map_err(|e| framewright::ifc::IfcError {
            path: args.model.clone(),
            kind: e.into(),
        })?
    };
    let model = Model::open_with(&args.model, &options)?;
    let report = InspectReport::new(&model);
    if args.json {
        write_stdout(|out| report.write_json(&mut &mut *out))
    } else {
        print_stdout(&report.to_text())
    }
}
