//! `sim-host identify`: the reduced models fitted from a flight's simulator-link log, through
//! the real programs (`sim-host fly`, then `sim-host identify --json`), against the aircraft
//! file's linearisation at the same airspeed (an independent computation: the Jacobian of the
//! plant about its trim, `sim-host linearize`).

use std::path::Path;
use std::process::Command;

fn sim_host() -> Command {
    Command::new(env!("CARGO_BIN_EXE_sim-host"))
}

/// The thesis's scripted flight (Hold, +100 m climb, four 90 deg turns, +-10 m altitude
/// doublet) of the 25e with the computed gains, in still air.
fn flown(dir: &Path) {
    let out = sim_host()
        .args(["fly", "--out"])
        .arg(dir)
        .output()
        .expect("run sim-host fly");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn coefficient(report: &serde_json::Value, axis: &str, name: &str) -> (f64, f64) {
    let a = report["axes"]
        .as_array()
        .expect("axes")
        .iter()
        .find(|a| a["axis"] == axis)
        .expect("axis");
    let c = a["coefficients"]
        .as_array()
        .expect("coefficients")
        .iter()
        .find(|c| c["name"] == name)
        .expect("coefficient");
    (
        c["value"].as_f64().expect("value"),
        c["reference"].as_f64().expect("reference"),
    )
}

/// Roll damping and aileron power from the closed-loop turns and corrections of an ordinary
/// flight: within 15 % of the linearisation (measured: -6.3 % and -3.6 %), the fit explaining
/// over 95 % of the roll acceleration.
#[test]
fn the_roll_model_of_the_thesis_flight_is_the_aircraft_files_within_15_percent() {
    let dir = tempfile::tempdir().expect("tempdir");
    flown(dir.path());
    let out = sim_host()
        .args(["identify", "--json"])
        .arg(dir.path().join("simlink.tlog"))
        .output()
        .expect("run sim-host identify");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    assert!((report["airspeed_ref_mps"].as_f64().expect("va") - 17.0).abs() < 0.5);
    for name in ["a_phi1", "a_phi2"] {
        let (v, r) = coefficient(&report, "roll", name);
        assert!(((v - r) / r).abs() < 0.15, "{name}: {v} against {r}");
    }
    let roll = report["axes"]
        .as_array()
        .expect("axes")
        .iter()
        .find(|a| a["axis"] == "roll")
        .expect("roll");
    assert!(roll["r2"].as_f64().expect("r2") > 0.95, "{roll}");
}

/// The ground link's log has attitude at 15 Hz and no surfaces: no model, and the error says
/// what the log lacks.
#[test]
fn a_log_without_the_simulators_truth_is_refused_with_what_it_lacks() {
    let dir = tempfile::tempdir().expect("tempdir");
    let log = dir.path().join("ground.tlog");
    // One ATTITUDE frame of the ground link, time-stamped as a .tlog record.
    let mut bytes = 1_767_225_600_000_000u64.to_be_bytes().to_vec();
    bytes.extend_from_slice(&[
        0xFD, 28, 0, 0, 0, 1, 1, 30, 0, 0, //
        0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, //
        0, 0,
    ]);
    std::fs::write(&log, bytes).expect("write");
    let out = sim_host()
        .arg("identify")
        .arg(&log)
        .output()
        .expect("run sim-host identify");
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("ground.tlog") && e.contains("HIL_STATE_QUATERNION"),
        "{e}"
    );
}
