//! The command line: JSON output carries the same numbers the tables print.

use std::process::Command;

fn run(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_sim-host"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn trim_json() {
    let (ok, out, err) = run(&["trim", "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let level = &v[0]["result"];
    assert_eq!(level["target"]["name"], "level");
    assert!((level["throttle"].as_f64().unwrap() - 0.56947).abs() < 1e-3);
    assert_eq!(v.as_array().unwrap().len(), 5);
}

#[test]
fn linearize_json_and_unknown_trim() {
    let (ok, out, err) = run(&["linearize", "--trim", "turn", "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["lon"]["states"][0], "u");
    assert!(v["lat_modes"]["roll"]["re"].as_f64().unwrap() < -10.0);
    let (ok, _, err) = run(&["linearize", "--trim", "loop"]);
    assert!(!ok);
    assert!(err.contains("unknown trim `loop`"), "{err}");
}

/// A parameter the autopilot does not have, or a value outside its bounds, is refused before
/// anything flies, with the name, the value and the bounds (`NAV_LND_SLP_DEG`: 1 to 20 deg).
#[test]
fn fly_refuses_a_parameter_the_autopilot_would_refuse() {
    let (ok, _, err) = run(&["fly", "--mission", "default", "--param", "NAV_FOO=1"]);
    assert!(!ok);
    assert!(err.contains("no parameter `NAV_FOO`"), "{err}");
    let (ok, _, err) = run(&[
        "fly",
        "--mission",
        "default",
        "--param",
        "NAV_LND_SLP_DEG=60",
    ]);
    assert!(!ok);
    assert!(
        err.contains("NAV_LND_SLP_DEG refuses 60") && err.contains("bounds 1 to 20 deg"),
        "{err}"
    );
    let (ok, _, err) = run(&["fly", "--param", "NAV_LND_SLP_DEG=steep"]);
    assert!(!ok);
    assert!(err.contains("value `steep`"), "{err}");
}
