//! Reporting pieces every command shares: aligned text and Markdown tables, JSON, CSV time
//! series and time-series plots.

pub mod csv_out;
pub mod plot;
pub mod table;

pub use plot::{Figure, Panel, Series};
pub use table::Table;

/// Pretty JSON of any serialisable value.
pub fn to_json<T: serde::Serialize>(value: &T) -> anyhow::Result<String> {
    Ok(serde_json::to_string_pretty(value)?)
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
}
