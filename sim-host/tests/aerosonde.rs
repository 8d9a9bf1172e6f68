//! The Aerosonde of Beard and McLain's *Small Unmanned Aircraft*, a second aircraft file:
//! its trim, its reduced models and its tricycle gear, against the book's simulator `mavsim`,
//! the book's closed-form expressions and statics.

use common::math::atmosphere::standard_atmosphere;
use sim_host::aircraft::{Aircraft, GearLayout};
use sim_host::analysis::linearize::linearize;
use sim_host::analysis::reduced::{closed_form, from_linearization, ReducedCoefficients};
use sim_host::analysis::trim::{trim_with, TrimResult, TrimTarget};
use sim_host::plant::gear::{MAIN_LEFT, MAIN_RIGHT, NOSE};
use sim_host::plant::{ground, Controls, Environment, ModelParams, Plant};
use std::path::PathBuf;

fn file() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("aircraft/aerosonde.toml")
}

fn aerosonde() -> Aircraft {
    Aircraft::from_file(&file()).expect("aerosonde.toml loads")
}

/// mavsim's air density (aerosonde_parameters.py `rho`), kg/m^3.
const MAVSIM_RHO: f64 = 1.2682;

/// The altitude whose US1976 density is mavsim's, m (bisection: density falls with height).
fn mavsim_density_altitude_m() -> f64 {
    let (mut lo, mut hi) = (-500.0, 500.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if standard_atmosphere(mid).density > MAVSIM_RHO {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The aircraft with its home 100 m below `alt_msl_m` (the ground plane is home's altitude,
/// and mavsim's density lies below sea level).
fn with_home_below(a: &Aircraft, alt_msl_m: f64) -> Aircraft {
    let mut a = a.clone();
    a.environment.home_alt_msl_m = alt_msl_m - 100.0;
    a
}

/// The level trim of `a` at `va` and `alt_msl_m`.
fn level_at(a: &Aircraft, va: f64, alt_msl_m: f64) -> TrimResult {
    let target = TrimTarget {
        alt_msl_m,
        ..TrimTarget::level().at_airspeed(va)
    };
    trim_with(&ModelParams::new(a), &target)
}

fn rel(ours: f64, reference: f64) -> f64 {
    (ours - reference).abs() / reference.abs()
}

#[test]
fn every_value_of_the_aerosonde_file_names_its_source_or_says_it_is_an_estimate() {
    let text = std::fs::read_to_string(file()).unwrap();
    for (i, line) in text.lines().enumerate() {
        let code = line.split('#').next().unwrap_or("").trim();
        // A value line: `key = value`; an array opened on it carries its sources per element.
        if code.contains('=') && !code.ends_with('[') {
            let comment = line.split_once('#').map_or("", |(_, c)| c);
            assert!(
                comment.contains("MAVSIM") || comment.contains("estimate"),
                "line {}: `{line}` names no source",
                i + 1
            );
        }
    }
    let a = aerosonde();
    assert_eq!(a.cruise_airspeed_mps(), 25.0);
    assert_eq!(a.mass.mass_kg, 11.0);
    assert_eq!(
        a.ground.third_wheel().map(|w| w.layout),
        Some(GearLayout::Tricycle)
    );
}

#[test]
fn at_mavsims_air_density_the_aerosonde_trims_at_25_mps_as_mavsim_does() {
    let alt = mavsim_density_altitude_m();
    let a = with_home_below(&aerosonde(), alt);
    let t = level_at(&a, 25.0, alt);
    assert!(t.converged, "residual {}", t.residual_norm);
    // mavsim_python/launch_files/chap05/chap5_check.py (randybeard/mavsim_public @ a514cf1):
    // the trim at Va 25 m/s, straight and level: u 24.968743, w 1.249755 (alpha 0.050011),
    // elevator -0.124778, throttle 0.676752, aileron 0.001836 and rudder -0.000303 in the
    // book's aileron sense (positive rolls right: -0.001836 here).
    let alpha_book = (1.249755_f64).atan2(24.968743);
    println!(
        "trim: alpha {:.6} elevator {:.6} throttle {:.6} aileron {:.6} rudder {:.6} theta {:.6} Omega {:.2}",
        t.alpha, t.elevator, t.throttle, t.aileron, t.rudder, t.theta, t.engine_speed
    );
    assert!(rel(t.alpha, alpha_book) < 0.01, "alpha {}", t.alpha);
    assert!((t.theta - t.alpha).abs() < 1e-9, "level: theta = alpha");
    assert!(rel(t.elevator, -0.124778) < 0.01, "elevator {}", t.elevator);
    assert!(rel(t.throttle, 0.676752) < 0.01, "throttle {}", t.throttle);
    // The lateral trim balances the propeller's torque: small, and in the book's direction.
    assert!(rel(t.aileron, -0.001836) < 0.05, "aileron {}", t.aileron);
    assert!(rel(t.rudder, -0.000303) < 0.10, "rudder {}", t.rudder);
}

#[test]
fn at_its_cruise_airspeed_and_the_default_altitude_the_aerosonde_trims_with_a_sensible_angle_of_attack(
) {
    let a = aerosonde();
    let t = trim_with(
        &ModelParams::new(&a),
        &TrimTarget::level().at_airspeed(a.cruise_airspeed_mps()),
    );
    assert!(t.converged, "residual {}", t.residual_norm);
    // Lift equals weight: CL = m g / (qbar S) at 100 m's density, on the linear lift curve with
    // the elevator's share (the pitch rate is zero).
    let rho = standard_atmosphere(100.0).density;
    let cl = 11.0 * 9.81 / (0.5 * rho * 25.0 * 25.0 * 0.55);
    let alpha = (cl - 0.23 - 0.13 * t.elevator) / 5.61;
    assert!((t.alpha - alpha).abs() < 0.002, "{} vs {alpha}", t.alpha);
    assert!((0.02..0.07).contains(&t.alpha), "alpha {}", t.alpha);
    assert!(
        (-0.2..-0.05).contains(&t.elevator),
        "elevator {}",
        t.elevator
    );
    assert!((0.5..0.9).contains(&t.throttle), "throttle {}", t.throttle);
}

fn reduced_at(a: &Aircraft, alt: f64) -> (ReducedCoefficients, ReducedCoefficients) {
    let t = level_at(a, 25.0, alt);
    assert!(t.converged);
    let lin = linearize(&ModelParams::new(a), &t);
    (from_linearization(&lin, &t), closed_form(a, &t))
}

#[test]
fn the_linearised_aerosondes_reduced_models_are_the_books_closed_forms_within_one_percent() {
    let a = aerosonde();
    let (lin, closed) = reduced_at(&a, 100.0 + a.environment.home_alt_msl_m);
    for ((name, l), (_, c)) in lin.named().into_iter().zip(closed.named()) {
        println!("{name}: linear {l:.5}, closed form {c:.5}");
        // Within 1 %: what the reduced models leave out (the drag's side force with sideslip,
        // 0.4 % of a_beta1; the thrust's cos alpha, 0.1 % of a_V1 and a_V2) is smaller.
        assert!(rel(l, c) < 0.01, "{name}: linear {l}, closed form {c}");
    }
}

#[test]
fn at_mavsims_air_density_the_reduced_models_are_mavsims() {
    let alt = mavsim_density_altitude_m();
    let (lin, _) = reduced_at(&with_home_below(&aerosonde(), alt), alt);
    // chap5_check.py's printed compute_tf_model, and its A_lat, B_lat for the sideslip rows
    // (a_beta1 = -A_lat[0][0], a_beta2 = B_lat[0][1] / Va). a_phi2 changes sign with the
    // aileron sense. mavsim's a_V1 = 0.2817 takes its linear drag C_D_0 + C_D_alpha alpha
    // (0.043 + 0.03 alpha), which its own nonlinear model does not fly (C_D_p = 0): not
    // compared; its thrust slope dT/dVa = -2.3522 N s/m is, through a_V1 less the drag term.
    let book = [
        ("a_phi1", lin.a_phi1, 22.62885),
        ("a_phi2", lin.a_phi2, -130.88368),
        ("a_theta1", lin.a_theta1, 5.294738),
        ("a_theta2", lin.a_theta2, 99.947424),
        ("a_theta3", lin.a_theta3, -36.112390),
        ("a_V2", lin.a_v2, 8.207221),
        ("a_V3", lin.a_v3, 9.81),
        ("a_beta1", lin.a_beta1, 0.776773),
        ("a_beta2", lin.a_beta2, 3.764969 / 25.0),
    ];
    for (name, ours, theirs) in book {
        println!("{name}: ours {ours:.6}, mavsim {theirs:.6}");
        assert!(
            rel(ours, theirs) < 0.01,
            "{name}: ours {ours}, mavsim {theirs}"
        );
    }
}

#[test]
fn the_aerosondes_tricycle_gear_holds_it_about_level_with_the_nose_wheel_carrying_its_lever_share()
{
    let a = aerosonde();
    let plant = Plant::at_rest_on_ground(&a, 0.0, 0.0, 0.3);
    let p = plant.params().clone();
    let (_, residual) = ground::rest_state(&p, 0.0, 0.0, 0.3);
    assert!(residual < 1e-9, "equilibrium residual {residual}");
    let weight = p.mass * p.g;
    let gc = plant.ground_contact();
    assert!(plant.weight_on_wheels() && gc.belly_load_n == 0.0);
    assert!((gc.normal_total_n() - weight).abs() < 1e-6 * weight);
    // Moments about the CG: the nose wheel carries W x_main / (x_main - x_nose), horizontal
    // distances along the ground (the file's 0.10 m and 0.45 m: 18 %).
    let e = plant.euler();
    let horiz = |i: usize| {
        let r = p.ground.points[i].pos_body;
        r.x * e.theta.cos() + r.z * e.theta.sin()
    };
    let (xm, xn) = (horiz(MAIN_LEFT), horiz(NOSE));
    let nose_expected = weight * xm / (xm - xn);
    let nose = gc.normal_n[NOSE];
    println!(
        "at rest: theta {:.3} deg, nose {nose:.2} N ({:.1} %), mains {:.2} N each",
        e.theta.to_degrees(),
        100.0 * nose / weight,
        gc.normal_n[MAIN_LEFT]
    );
    assert!(
        rel(nose, nose_expected) < 1e-3,
        "nose {nose} vs {nose_expected}"
    );
    assert!((nose / weight - 0.10 / 0.55).abs() < 0.005);
    assert!((gc.normal_n[MAIN_LEFT] - gc.normal_n[MAIN_RIGHT]).abs() < 1e-9);
    // Level-ish: the file's legs compress alike (2 cm each), so within a degree of level.
    assert!(e.theta.abs() < 1.0_f64.to_radians(), "theta {}", e.theta);
    assert!(e.phi.abs() < 1e-9);
}

/// Rolls the aircraft from rest-on-its-wheels at 8 m/s along heading 0.3 rad for 4 s, engine
/// off: (distance along, drift across, heading change, speed at the end).
fn roll_out(a: &Aircraft) -> (f64, f64, f64, f64) {
    let heading = 0.3_f64;
    let mut plant = Plant::at_rest_on_ground(a, 0.0, 0.0, heading);
    let mut s = plant.state();
    s.vel_body.x = 8.0;
    plant.set_state(s);
    let env = Environment::default();
    let idle = Controls::new(0.0, 0.0, 0.0, 0.0);
    let dt = 0.005;
    for _ in 0..800 {
        plant.step(&idle, &env, dt);
    }
    assert!(plant.on_ground() && plant.weight_on_wheels());
    let pos = plant.position_ned();
    (
        pos.x * heading.cos() + pos.y * heading.sin(),
        -pos.x * heading.sin() + pos.y * heading.cos(),
        plant.euler().psi - heading,
        plant.velocity_ned().norm(),
    )
}

#[test]
fn the_aerosonde_rolls_straight_on_its_tricycle_gear_but_for_its_windmilling_propellers_torque() {
    let a = aerosonde();
    let (along, across, turn, v) = roll_out(&a);
    // The same aircraft with its propeller turning the other way: every torque of the
    // propeller mirrored, nothing else.
    let mut mirrored = a.clone();
    mirrored.propulsion.spin = sim_host::aircraft::PropSpin::Minnesota;
    let (along_m, across_m, turn_m, _) = roll_out(&mirrored);
    println!(
        "4 s: {along:.2} m along, {across:.4} m across, heading {:.4} deg, speed {v:.2} m/s; \
         mirrored propeller: {across_m:.4} m across, heading {:.4} deg",
        turn.to_degrees(),
        turn_m.to_degrees()
    );
    // The gear itself rolls straight: what drift there is changes sign with the propeller's
    // spin (the windmilling propeller's torque loads one main wheel more than the other).
    assert!((along - along_m).abs() < 1e-6 * along);
    assert!(
        (across + across_m).abs() < 1e-6 * along,
        "{across} vs {across_m}"
    );
    assert!((turn + turn_m).abs() < 1e-9, "{turn} vs {turn_m}");
    // And it is small: under 0.2 % of the distance rolled, a fifth of a degree of heading.
    assert!(
        across.abs() < 2e-3 * along,
        "drifted {across} m in {along} m"
    );
    assert!(turn.abs() < 0.2_f64.to_radians(), "turned {turn} rad");
    // The wheels' rolling friction alone would take mu g t = 1.96 m/s off in 4 s; the
    // windmilling propeller and the air take more, and nothing adds speed.
    assert!(v < 8.0 - 0.05 * 9.81 * 4.0 && v > 0.0, "speed {v}");
}
