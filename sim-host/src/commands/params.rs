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
use serde_json::{json, Value};

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
                let mut description = d.description.to_string();
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
                    d.unit.to_string(),
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

/// Decimal places that show a value as declared (1 to 6).
fn decimal_places(d: &ParamDef) -> usize {
    [d.default, d.min, d.max]
        .iter()
        .map(|x| {
            let s = format!("{x}");
            match s.split_once('.') {
                Some((_, frac)) if !s.contains('e') => frac.len(),
                _ if s.contains('e') => 6,
                _ => 0,
            }
        })
        .max()
        .unwrap_or(0)
        .clamp(1, 6)
}

/// The parameter metadata in the format QGroundControl reads (component metadata, type
/// PARAMETER, `version` 1).
pub fn metadata_json(registry: Registry) -> Value {
    let mut params = Vec::new();
    for (stage, defs) in stages(registry) {
        for d in defs {
            let integer = d.kind.is_integer();
            // f32 to f64 through its shortest decimal, so 0.1 reads 0.1 and not 0.100000001.
            let exact = |x: f32| number(x).parse::<f64>().unwrap_or(f64::from(x));
            let mut p = json!({
                "name": d.name,
                "type": if integer { "Int32" } else { "Float" },
                "shortDesc": d.description,
                "default": if integer { json!(d.default as i64) } else { json!(exact(d.default)) },
                "min": if integer { json!(d.min as i64) } else { json!(exact(d.min)) },
                "max": if integer { json!(d.max as i64) } else { json!(exact(d.max)) },
                "group": stage,
                "category": "Standard",
            });
            if !d.unit.is_empty() {
                p["units"] = json!(d.unit);
            }
            if !integer {
                p["decimalPlaces"] = json!(decimal_places(d));
            }
            let l = labels(d);
            if !l.is_empty() {
                p["values"] = l
                    .iter()
                    .map(|(v, n)| json!({ "value": v, "description": n }))
                    .collect();
            }
            params.push(p);
        }
    }
    json!({ "version": 1, "parameters": params })
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
        assert_eq!(set["values"][3]["description"], "minnesota");
        assert_eq!(set["max"], 4);
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
    fn decimal_places_show_the_declared_values() {
        // The lower bound 1e-5 needs five places.
        let d = ParamDef::real("X", 0.0015, 1e-5, 0.1, "", "");
        assert_eq!(decimal_places(&d), 5);
        let d = ParamDef::real("Y", 17.0, 8.0, 30.0, "m/s", "");
        assert_eq!(decimal_places(&d), 1);
        let d = ParamDef::real("Z", 0.25, 0.0, 1.0, "", "");
        assert_eq!(decimal_places(&d), 2);
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
