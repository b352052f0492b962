//! The HEADER section: FILE_DESCRIPTION, FILE_NAME, FILE_SCHEMA.

use super::params::Param;

#[derive(Debug, Clone, Default, PartialEq)]
pub struct Header {
    pub description: Vec<String>,
    pub implementation_level: String,
    pub file_name: String,
    pub time_stamp: String,
    pub authors: Vec<String>,
    pub organizations: Vec<String>,
    pub preprocessor_version: String,
    pub originating_system: String,
    pub authorization: String,
    /// Schema identifiers as written, e.g. `IFC4` or `IFC2X3`.
    pub schemas: Vec<String>,
}

fn text(p: Option<&Param<'_>>) -> String {
    p.and_then(Param::text)
        .map(|(t, _)| t.into_owned())
        .unwrap_or_default()
}

fn texts(p: Option<&Param<'_>>) -> Vec<String> {
    match p {
        Some(Param::List(items)) => items.iter().map(|i| text(Some(i))).collect(),
        Some(other) => vec![text(Some(other))],
        None => Vec::new(),
    }
}

impl Header {
    /// Fills the fields from one header entity (unknown ones are ignored).
    pub(crate) fn absorb(&mut self, name: &str, params: &[Param<'_>]) {
        match name {
            "FILE_DESCRIPTION" => {
                self.description = texts(params.first());
                self.implementation_level = text(params.get(1));
            }
            "FILE_NAME" => {
                self.file_name = text(params.first());
                self.time_stamp = text(params.get(1));
                self.authors = texts(params.get(2));
                self.organizations = texts(params.get(3));
                self.preprocessor_version = text(params.get(4));
                self.originating_system = text(params.get(5));
                self.authorization = text(params.get(6));
            }
            "FILE_SCHEMA" => self.schemas = texts(params.first()),
            _ => {}
        }
    }
}
