//! Reporting pieces every command shares: aligned text and Markdown tables, JSON, CSV time
//! series, time-series plots and prose templates.

pub mod csv_out;
pub mod plot;
pub mod table;
pub mod template;

pub use plot::{Figure, Panel, Series};
pub use table::Table;

/// Pretty JSON of any serialisable value.
pub fn to_json<T: serde::Serialize>(value: &T) -> anyhow::Result<String> {
    Ok(serde_json::to_string_pretty(value)?)
}

/// [`sig`] of a figure that may be missing, `-` when it is.
pub fn sig_or_dash(x: Option<f64>, digits: usize) -> String {
    x.map_or_else(|| "-".into(), |v| sig(v, digits))
}

/// Formats `x` with `digits` significant digits (plain notation for ordinary magnitudes).
pub fn sig(x: f64, digits: usize) -> String {
    if !x.is_finite() {
        return x.to_string();
    }
    if x == 0.0 {
        return "0".into();
    }
    let mag = x.abs().log10().floor() as i32;
    if !(-4..=6).contains(&mag) {
        return format!("{:.*e}", digits.saturating_sub(1), x);
    }
    let decimals = (digits as i32 - 1 - mag).max(0) as usize;
    format!("{:.*}", decimals, x)
}

/// Where the hand-written notes of a generated document begin: a command that rewrites the
/// document keeps everything from here on (`sim-host fly --report`, `navigation`, `campaign
/// --doc`).
pub const NOTES_MARKER: &str = "\n---\n";

/// The opening marker of a section `name` that a command writes into a document another
/// command owns (`docs/RESULTS.md` carries the missions of `sim-host navigation`).
fn section_markers(name: &str) -> (String, String) {
    (
        format!("<!-- begin {name} (generated; do not edit) -->"),
        format!("<!-- end {name} -->"),
    )
}

/// The section `name` of `doc`, markers included, if it has one.
pub fn section<'a>(doc: &'a str, name: &str) -> Option<&'a str> {
    let (begin, end) = section_markers(name);
    let i = doc.find(&begin)?;
    let j = doc[i..].find(&end)? + i + end.len();
    Some(&doc[i..j])
}

/// `doc` with its section `name` replaced by `body` (between the markers), or with the
/// section appended when it has none.
pub fn splice_section(doc: &str, name: &str, body: &str) -> String {
    let (begin, end) = section_markers(name);
    let block = format!("{begin}\n{}\n{end}", body.trim_end());
    match section(doc, name) {
        Some(old) => doc.replacen(old, &block, 1),
        None => append_block(doc, &block),
    }
}

/// `into` with the section `name` of `from` at its end (unchanged when `from` has none): a
/// command that rewrites a whole document keeps what another command wrote into it.
pub fn carry_section(from: &str, into: &str, name: &str) -> String {
    match section(from, name) {
        Some(block) => append_block(into, block),
        None => into.to_string(),
    }
}

fn append_block(doc: &str, block: &str) -> String {
    format!("{}\n\n{block}\n", doc.trim_end())
}

/// Relative difference `(ours - reference) / |reference|` in percent.
pub fn pct(ours: f64, reference: f64) -> f64 {
    100.0 * (ours - reference) / reference.abs()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn significant_digits() {
        assert_eq!(sig(0.0550621, 4), "0.05506");
        assert_eq!(sig(-133.6906, 4), "-133.7");
        assert_eq!(sig(826.677, 5), "826.68");
        assert_eq!(sig(1.2e-7, 3), "1.20e-7");
        assert!((pct(1.01, 1.0) - 1.0).abs() < 1e-9);
    }

    #[test]
    fn sections_are_replaced_in_place_or_appended() {
        let doc = "# Title\n\nText.\n";
        let one = splice_section(doc, "missions", "first\n");
        assert!(one.starts_with("# Title\n\nText.\n\n<!-- begin missions"));
        assert_eq!(
            section(&one, "missions").map(|s| s.contains("first")),
            Some(true)
        );
        let more = format!("{one}\nAfter.\n");
        let two = splice_section(&more, "missions", "second");
        assert!(!two.contains("first") && two.contains("second"));
        assert!(two.ends_with("<!-- end missions -->\n\nAfter.\n"), "{two}");
        assert_eq!(section(doc, "missions"), None);
    }
}
