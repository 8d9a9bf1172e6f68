//! `sim-host params`: the autopilot's parameter registry as tables, as the Markdown of
//! `docs/PARAMETERS.md`, or as the parameter metadata file QGroundControl reads.
//!
//! Everything comes from the registry the firmware flies with
//! (`common::vehicle::params::REGISTRY`): each stage's declarations, nothing written twice.
//! The JSON follows the component-metadata parameter format (`version` 1, one object per
//! parameter with `name`, `type`, `shortDesc`, `units`, `default`, `min`, `max`,
//! `decimalPlaces`, `group` and, for switches and choices, `values`), which is what
//! QGroundControl parses.

use crate::report::table::Table;
use common::params::{ParamDef, ParamKind, Registry};
use serde_json::Value;

/// One stage of the registry and its definitions.
pub fn stages(registry: Registry) -> Vec<(&'static str, Vec<&'static ParamDef>)> {
    registry
        .iter()
        .map(|s| (s.name(), (0..s.len()).filter_map(|i| s.def(i)).collect()))
        .collect()
}

/// A number as the shortest decimal that reads back as the same `f32`.
fn number(x: f32) -> String {
    format!("{x}")
}

/// The labels of a switch or a choice, as `value: label` pairs.
fn labels(d: &ParamDef) -> Vec<(i32, &'static str)> {
    match d.kind {
        ParamKind::Bool => vec![(0, "off"), (1, "on")],
        ParamKind::Enum(names) => names
            .get()
            .iter()
            .enumerate()
            .map(|(i, n)| (i as i32, *n))
            .collect(),
        ParamKind::Real | ParamKind::Int => Vec::new(),
    }
}

fn kind_name(k: ParamKind) -> &'static str {
    match k {
        ParamKind::Real => "real",
        ParamKind::Int => "integer",
        ParamKind::Bool => "switch",
        ParamKind::Enum(_) => "choice",
    }
}

/// The registry as one table per stage.
pub fn tables(registry: Registry) -> Vec<Table> {
    stages(registry)
        .into_iter()
        .map(|(stage, defs)| {
            let mut t = Table::new(
                stage,
                &[
                    "name",
                    "default",
                    "min",
                    "max",
                    "unit",
                    "kind",
                    "description",
                ],
            );
            for d in defs {
                let mut description = d.description.get().to_string();
                let l = labels(d);
                if !l.is_empty() {
                    let values: Vec<String> = l.iter().map(|(v, n)| format!("{v} {n}")).collect();
                    description.push_str(&format!(" ({})", values.join(", ")));
                }
                t.row([
                    d.name.to_string(),
                    number(d.default),
                    number(d.min),
                    number(d.max),
                    d.unit.get().to_string(),
                    kind_name(d.kind).to_string(),
                    description,
                ]);
            }
            t
        })
        .collect()
}

/// `docs/PARAMETERS.md`: the stages' tables with numbers right-aligned and words left.
pub fn markdown(registry: Registry) -> String {
    let count: usize = registry.iter().map(|s| s.len()).sum();
    let mut md = include_str!("params_intro.md").replace("{count}", &count.to_string());
    for t in tables(registry) {
        md.push_str(&format!("\n## {}\n\n", t.title));
        md.push_str(&format!("| {} |\n", t.headers.join(" | ")));
        md.push_str("|---|---:|---:|---:|---|---|---|\n");
        for r in &t.rows {
            md.push_str(&format!("| {} |\n", r.join(" | ")));
        }
    }
    md
}

/// The parameter metadata in the format QGroundControl reads (component metadata, type
/// PARAMETER, `version` 1): `common::params::metadata` writes it, the same bytes the firmware
/// serves over MAVLink FTP.
pub fn metadata_json(registry: Registry) -> Value {
    let mut text = String::new();
    // Writing into a String cannot fail.
    let _ = common::params::metadata::write_json(registry, &mut text);
    serde_json::from_str(&text).unwrap_or(Value::Null)
}

#[cfg(test)]
mod tests {
    use super::*;
    use common::vehicle::params::REGISTRY;

    #[test]
    fn every_parameter_of_the_registry_is_listed_once_with_its_declaration() {
        let json = metadata_json(REGISTRY);
        let params = json["parameters"].as_array().unwrap();
        let count: usize = REGISTRY.iter().map(|s| s.len()).sum();
        assert_eq!(params.len(), count);
        assert_eq!(json["version"], 1);
        let find = |n: &str| params.iter().find(|p| p["name"] == n).unwrap();
        // A real with a unit, an integer, a switch and a choice.
        let slope = find("NAV_LND_SLP_DEG");
        assert_eq!(slope["type"], "Float");
        assert_eq!(slope["units"], "deg");
        assert!(slope["decimalPlaces"].as_u64().unwrap() >= 1);
        assert_eq!(find("EST_HOME_SATS")["type"], "Int32");
        let land = find("NAV_RTL_LAND");
        assert_eq!(land["values"][1]["description"], "on");
        let set = find("SYS_GAIN_SET");
        assert_eq!(set["values"][4]["description"], "minnesota");
        assert_eq!(set["max"], 5);
        // Every default lies within its bounds, as QGroundControl requires.
        for p in params {
            let (d, lo, hi) = (&p["default"], &p["min"], &p["max"]);
            assert!(
                lo.as_f64() <= d.as_f64() && d.as_f64() <= hi.as_f64(),
                "{}",
                p["name"]
            );
        }
    }

    #[test]
    fn docs_parameters_md_is_what_params_markdown_prints() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/PARAMETERS.md");
        let doc = std::fs::read_to_string(path).expect("docs/PARAMETERS.md");
        assert!(
            doc == markdown(REGISTRY),
            "docs/PARAMETERS.md is stale: cargo run --release -p sim-host -- params --markdown > docs/PARAMETERS.md"
        );
    }
}
