//! Errors of the BIM writers: each names the file and what to do.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum AnnotateError {
    #[error(
        "{path}: annotating an {schema} model is not supported: IFC2X3 lays out processes, \
         schedules and fasteners differently; upgrade the model to IFC4 or IFC4X3 in the \
         authoring tool (or with IfcOpenShell's ifcpatch Migrate) and annotate that"
    )]
    UnsupportedSchema { path: PathBuf, schema: String },
    #[error(
        "{path}: the HEADER has no FILE_NAME record, which ISO 10303-21 requires; \
         add one (FILE_NAME('name','date',(''),(''),'','','');) and run again"
    )]
    NoFileName { path: PathBuf },
    #[error(
        "{path}: the header time stamp `{found}` is not an ISO 8601 date-time \
         (YYYY-MM-DDThh:mm:ss); give the work schedule's date with --date"
    )]
    NoDate { path: PathBuf, found: String },
    #[error("--date `{0}` is not an ISO 8601 date-time such as 2026-03-01T08:00:00")]
    BadDate(String),
    #[error("{path}: the model holds no entities to annotate")]
    Empty { path: PathBuf },
    #[error("{path}: the model has no IfcProject to declare the work schedule in")]
    NoProject { path: PathBuf },
    #[error(
        "{path}: the model already holds a Framewright_Assembly property set; \
         annotate the original model instead (its GlobalIds would repeat)"
    )]
    AlreadyAnnotated { path: PathBuf },
    #[error("bad nail size: {0}")]
    BadNail(String),
}
