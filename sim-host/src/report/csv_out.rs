//! Time series written as CSV through the `csv` crate.

use anyhow::Context;
use std::path::Path;

/// Writes a header row and numeric rows to `path`.
pub fn write_csv(path: &Path, headers: &[String], rows: &[Vec<f64>]) -> anyhow::Result<()> {
    let mut w = csv::Writer::from_path(path)
        .with_context(|| format!("cannot create CSV file `{}`", path.display()))?;
    w.write_record(headers)?;
    for r in rows {
        w.write_record(r.iter().map(|x| format!("{x:.9}")))?;
    }
    w.flush()
        .with_context(|| format!("cannot write CSV file `{}`", path.display()))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("x.csv");
        write_csv(
            &p,
            &["t".into(), "y".into()],
            &[vec![0.0, 1.5], vec![0.1, -2.0]],
        )
        .unwrap();
        let mut r = csv::Reader::from_path(&p).unwrap();
        let rows: Vec<csv::StringRecord> = r.records().map(|x| x.unwrap()).collect();
        assert_eq!(rows.len(), 2);
        assert_eq!(rows[1][1].parse::<f64>().unwrap(), -2.0);
    }
}
