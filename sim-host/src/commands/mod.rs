//! The analysis commands as library functions: each returns its results (for `--json` and for
//! tests) and the tables it prints, so the CLI only chooses the output form.

pub mod campaign;
pub mod compare;
pub mod design;
pub mod design_model;
pub mod doublet;
pub mod fly;
pub mod flying;
pub mod identify;
pub mod laws;
pub mod linearize;
pub mod log;
pub mod mission_tables;
pub mod navigation;
pub mod params;
pub mod scenario;
pub mod sim;
pub mod trim;
pub mod validation;
pub mod wind_rose;

use crate::report::table::Table;

/// How a command prints its tables.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Aligned plain text.
    Text,
    /// Markdown.
    Markdown,
}

/// Renders tables one after another.
pub fn render(tables: &[Table], format: Format) -> String {
    tables
        .iter()
        .map(|t| match format {
            Format::Text => t.render_text(),
            Format::Markdown => t.render_markdown(),
        })
        .collect::<Vec<_>>()
        .join("\n")
}
