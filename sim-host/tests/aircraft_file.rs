//! The aircraft file: bad input is rejected with the file, the key and the value named.

use sim_host::aircraft::{Aircraft, AircraftError, DEFAULT_AIRCRAFT_TOML};
use std::path::Path;
use std::process::Command;

fn write(dir: &tempfile::TempDir, text: &str) -> std::path::PathBuf {
    let p = dir.path().join("plane.toml");
    std::fs::write(&p, text).unwrap();
    p
}

fn replace(key_line_start: &str, new_line: &str) -> String {
    replace_in(DEFAULT_AIRCRAFT_TOML, key_line_start, new_line)
}

/// `text` with the line starting `key_line_start` replaced by `new_line`.
fn replace_in(text: &str, key_line_start: &str, new_line: &str) -> String {
    text.lines()
        .map(|l| {
            if l.starts_with(key_line_start) {
                new_line.to_string()
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn missing_file() {
    let e = Aircraft::from_file(Path::new("/nonexistent/plane.toml")).unwrap_err();
    assert!(matches!(e, AircraftError::Read { .. }));
    assert!(e.to_string().contains("/nonexistent/plane.toml"), "{e}");
}

#[test]
fn malformed_toml() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(&dir, "[mass]\nmass_kg = = 1.9\n");
    let e = Aircraft::from_file(&p).unwrap_err();
    assert!(matches!(e, AircraftError::Syntax { .. }), "{e}");
    let msg = e.to_string();
    assert!(
        msg.contains("plane.toml") && msg.contains("line 2"),
        "{msg}"
    );
}

#[test]
fn unknown_key() {
    let dir = tempfile::tempdir().unwrap();
    let text = replace("CL_q = ", "CL_q = 6.1639\nCL_stall = 1.2");
    let e = Aircraft::from_file(&write(&dir, &text)).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, AircraftError::Shape { .. }), "{msg}");
    assert!(
        msg.contains("aero.lift") && msg.contains("CL_stall"),
        "{msg}"
    );
}

#[test]
fn missing_key() {
    let dir = tempfile::tempdir().unwrap();
    let text = replace("Cm_q = ", "");
    let msg = Aircraft::from_file(&write(&dir, &text))
        .unwrap_err()
        .to_string();
    assert!(msg.contains("aero.pitch") && msg.contains("Cm_q"), "{msg}");
}

#[test]
fn negative_mass() {
    let dir = tempfile::tempdir().unwrap();
    let text = replace("mass_kg = ", "mass_kg = -1.959");
    let e = Aircraft::from_file(&write(&dir, &text)).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, AircraftError::Value { .. }), "{msg}");
    assert!(
        msg.contains("plane.toml") && msg.contains("mass.mass_kg") && msg.contains("-1.959"),
        "{msg}"
    );
}

#[test]
fn non_finite_value() {
    let dir = tempfile::tempdir().unwrap();
    for (line, key) in [
        ("CL_alpha = nan", "aero.lift.CL_alpha"),
        ("Jy_kgm2 = inf", "mass.Jy_kgm2"),
    ] {
        let prefix = line.split(" = ").next().unwrap().to_string() + " = ";
        let text = replace(&prefix, line);
        let msg = Aircraft::from_file(&write(&dir, &text))
            .unwrap_err()
            .to_string();
        assert!(msg.contains(key) && msg.contains("finite"), "{msg}");
    }
    // Inside an array the index is named too.
    let text = replace(
        "CT_poly_J = ",
        "CT_poly_J = [-0.4314, 1.08, -inf, 0.1089, 0.0604]",
    );
    let msg = Aircraft::from_file(&write(&dir, &text))
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("propulsion.CT_poly_J[2]") && msg.contains("-inf"),
        "{msg}"
    );
}

#[test]
fn thesis_inertia_typo_is_rejected() {
    // The thesis prints Jxz = 0.14: Jx Jz - Jxz^2 = 0.011 - 0.0196 < 0.
    let dir = tempfile::tempdir().unwrap();
    let text = replace("Jxz_kgm2 = ", "Jxz_kgm2 = 0.14");
    let msg = Aircraft::from_file(&write(&dir, &text))
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("mass.Jxz_kgm2") && msg.contains("0.14"),
        "{msg}"
    );
}

#[test]
fn wrong_type_and_bad_limits() {
    let dir = tempfile::tempdir().unwrap();
    let text = replace("b_m = ", "b_m = \"wide\"");
    let msg = Aircraft::from_file(&write(&dir, &text))
        .unwrap_err()
        .to_string();
    assert!(msg.contains("geometry.b_m"), "{msg}");
    let text = replace("J_clamp = ", "J_clamp = [0.7, 0.0]");
    let msg = Aircraft::from_file(&write(&dir, &text))
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("propulsion.J_clamp") && msg.contains("0.7"),
        "{msg}"
    );
}

#[test]
fn shipped_file_equals_embedded_and_loads_from_disk() {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("aircraft/ultrastick25e.toml");
    assert_eq!(
        Aircraft::from_file(&p).unwrap(),
        Aircraft::ultrastick25e().unwrap()
    );
}

#[test]
fn cli_exits_non_zero_and_names_the_problem() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(&dir, &replace("mass_kg = ", "mass_kg = -2.5"));
    let out = Command::new(env!("CARGO_BIN_EXE_sim-host"))
        .args(["--aircraft", p.to_str().unwrap(), "trim"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("plane.toml") && err.contains("mass.mass_kg") && err.contains("-2.5"),
        "{err}"
    );
    let out = Command::new(env!("CARGO_BIN_EXE_sim-host"))
        .args(["--aircraft", "/nonexistent.toml", "linearize"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("/nonexistent.toml"));
}

#[test]
fn ground_table_is_required_and_checked() {
    let dir = tempfile::tempdir().unwrap();
    // Without the table.
    let cut = DEFAULT_AIRCRAFT_TOML
        .find("\n[ground]")
        .expect("the shipped file has a [ground] table");
    let msg = Aircraft::from_file(&write(&dir, &DEFAULT_AIRCRAFT_TOML[..cut]))
        .unwrap_err()
        .to_string();
    assert!(msg.contains("ground"), "{msg}");
    // An unknown key in it.
    let text = replace("mu_roll = ", "mu_roll = 0.05\nmu_brake = 0.5");
    let msg = Aircraft::from_file(&write(&dir, &text))
        .unwrap_err()
        .to_string();
    assert!(msg.contains("ground") && msg.contains("mu_brake"), "{msg}");
    // A spring that pulls.
    let text = replace("main_stiffness_Npm = ", "main_stiffness_Npm = -600.0");
    let msg = Aircraft::from_file(&write(&dir, &text))
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("ground.main_stiffness_Npm") && msg.contains("-600"),
        "{msg}"
    );
    // A tail wheel ahead of the CG is not a taildragger.
    let text = replace("tail_wheel_m = ", "tail_wheel_m = [0.78, 0.0, 0.03]");
    let msg = Aircraft::from_file(&write(&dir, &text))
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("ground.tail_wheel_m") && msg.contains("0.78"),
        "{msg}"
    );
    // A friction coefficient out of range.
    let text = replace("mu_side = ", "mu_side = 6.0");
    let msg = Aircraft::from_file(&write(&dir, &text))
        .unwrap_err()
        .to_string();
    assert!(msg.contains("ground.mu_side") && msg.contains('6'), "{msg}");
}

/// The Aerosonde's file with the line starting `key_line_start` replaced.
fn aerosonde_with(key_line_start: &str, new_line: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("aircraft/aerosonde.toml");
    replace_in(
        &std::fs::read_to_string(path).unwrap(),
        key_line_start,
        new_line,
    )
}

#[test]
fn the_aerosondes_bad_motor_value_missing_nose_key_and_mixed_gear_are_each_named() {
    let dir = tempfile::tempdir().unwrap();
    let load = |text: &str| {
        Aircraft::from_file(&write(&dir, text))
            .unwrap_err()
            .to_string()
    };
    let msg = load(&aerosonde_with(
        "resistance_ohm = ",
        "resistance_ohm = -0.042",
    ));
    assert!(
        msg.contains("plane.toml")
            && msg.contains("propulsion.dc_motor.resistance_ohm")
            && msg.contains("-0.042"),
        "{msg}"
    );
    let msg = load(&aerosonde_with("nose_stiffness_Npm = ", ""));
    assert!(
        msg.contains("plane.toml") && msg.contains("ground.nose_stiffness_Npm"),
        "{msg}"
    );
    let msg = load(&aerosonde_with(
        "nose_wheel_m = ",
        "nose_wheel_m = [0.45, 0.0, 0.32]\ntail_wheel_m = [-0.9, 0.0, 0.1]",
    ));
    assert!(
        msg.contains("nose_wheel_m") && msg.contains("not both"),
        "{msg}"
    );
    // Mains ahead of the CG with a nose wheel: no tricycle stands on that.
    let msg = load(&aerosonde_with(
        "main_wheel_left_m = ",
        "main_wheel_left_m = [0.10, -0.30, 0.32]",
    ));
    assert!(
        msg.contains("ground.main_wheel_left_m") && msg.contains("0.1"),
        "{msg}"
    );
    // Neither motor, and a torque polynomial given twice.
    let no_motor: String = aerosonde_with("[propulsion.dc_motor]", "")
        .lines()
        .filter(|l| {
            !["KV_rpm", "resistance_ohm", "no_load_current", "max_voltage"]
                .iter()
                .any(|k| l.starts_with(k))
        })
        .collect::<Vec<_>>()
        .join("\n");
    let msg = load(&no_motor);
    assert!(
        msg.contains("plane.toml") && msg.contains("propulsion.motor_power_poly_throttle_W"),
        "{msg}"
    );
    let msg = load(&aerosonde_with(
        "CQ_poly_J = ",
        "CQ_poly_J = [0.0, 0.0, -0.01664, 0.004970, 0.005230]\nCP_poly_J = [0.0, 0.0, 0.0, 0.0, 0.1]",
    ));
    assert!(
        msg.contains("propulsion.CQ_poly_J") && msg.contains("not both"),
        "{msg}"
    );
}

#[test]
fn an_airspeed_the_aerosonde_cannot_trim_at_is_a_clear_error_not_a_panic() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("aircraft/aerosonde.toml");
    for command in ["linearize", "design"] {
        let out = Command::new(env!("CARGO_BIN_EXE_sim-host"))
            .args([
                "--aircraft",
                file.to_str().unwrap(),
                command,
                "--airspeed",
                "90",
            ])
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1), "{command}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("cannot be trimmed")
                && err.contains("90 m/s")
                && !err.contains("panicked"),
            "{command}: {err}"
        );
    }
    let out = Command::new(env!("CARGO_BIN_EXE_sim-host"))
        .args([
            "--aircraft",
            file.to_str().unwrap(),
            "trim",
            "--airspeed",
            "-5",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("positive"), "{err}");
}
