//! Trim against the UMN committed trim and thesis Table 2.3.

use sim_host::aircraft::Aircraft;
use sim_host::analysis::references::{umn_trim, THESIS_TRIM};
use sim_host::analysis::trim::{trim, TrimTarget};

fn rel(ours: f64, reference: f64) -> f64 {
    ((ours - reference) / reference).abs()
}

#[test]
fn level_trim_matches_the_umn_committed_trim_within_0_1_percent() {
    let a = Aircraft::ultrastick25e().unwrap();
    let t = trim(&a, &TrimTarget::level());
    assert!(t.converged, "residual {}", t.residual_norm);
    assert!(
        rel(t.throttle, umn_trim::THROTTLE) < 1e-3,
        "throttle {}",
        t.throttle
    );
    assert!(
        rel(t.elevator, umn_trim::ELEVATOR) < 1e-3,
        "elevator {}",
        t.elevator
    );
    assert!(rel(t.alpha, umn_trim::ALPHA) < 1e-3, "alpha {}", t.alpha);
    assert!(
        rel(t.engine_speed, umn_trim::ENGINE_SPEED) < 1e-3,
        "Omega {}",
        t.engine_speed
    );
    // The lateral trim of the UMN file too (aileron balances the propeller torque).
    assert!(
        rel(t.aileron, umn_trim::AILERON) < 1e-3,
        "aileron {}",
        t.aileron
    );
    assert!(
        rel(t.rudder, umn_trim::RUDDER) < 1e-3,
        "rudder {}",
        t.rudder
    );
    assert!(rel(t.phi, umn_trim::PHI) < 1e-3, "phi {}", t.phi);
    // Accelerometer reading at trim: the UMN file's specific force.
    for i in 0..3 {
        assert!(
            (t.specific_force_body[i] - umn_trim::SPECIFIC_FORCE[i]).abs() < 1e-3,
            "specific force {:?}",
            t.specific_force_body
        );
    }
}

/// Thesis Table 2.3, rows II to IV: throttle, aileron, rudder, roll, q, r agree within two
/// units of the thesis's last printed digit. Alpha, elevator, theta and p do not (the thesis's
/// alpha is lower than the UMN model gives, see docs/VALIDATION.md); they are held to the
/// documented offsets instead.
#[test]
fn thesis_table_2_3() {
    let a = Aircraft::ultrastick25e().unwrap();
    let unit = |x: f64| -> f64 {
        // One unit of the last printed digit of a value printed with 3 significant digits.
        if x == 0.0 {
            1e-3
        } else {
            10f64.powf(x.abs().log10().floor() - 2.0)
        }
    };
    for th in THESIS_TRIM {
        let t = trim(&a, &TrimTarget::by_name(th.name).unwrap());
        assert!(t.converged, "{}: residual {}", th.name, t.residual_norm);
        for (name, ours, reference) in [
            ("throttle", t.throttle, th.throttle),
            ("aileron", t.aileron, th.aileron),
            ("rudder", t.rudder, th.rudder),
            ("phi", t.phi, th.phi),
            ("q", t.q, th.q),
            ("r", t.r, th.r),
        ] {
            let tol = 2.0 * unit(reference) + 1e-9;
            assert!(
                (ours - reference).abs() <= tol,
                "{} {name}: ours {ours} thesis {reference} (tol {tol})",
                th.name
            );
        }
        // Documented offsets: alpha 2-5 % above the thesis, elevator 1-2 % more negative.
        assert!(
            t.alpha > th.alpha && rel(t.alpha, th.alpha) < 0.05,
            "{} alpha {}",
            th.name,
            t.alpha
        );
        assert!(
            t.elevator < th.elevator && rel(t.elevator, th.elevator) < 0.02,
            "{} elevator {}",
            th.name,
            t.elevator
        );
        assert!(
            (t.theta - th.theta).abs() < 0.003,
            "{} theta {}",
            th.name,
            t.theta
        );
    }
}

#[test]
fn steady_heading_sideslip() {
    let a = Aircraft::ultrastick25e().unwrap();
    let t = trim(&a, &TrimTarget::sideslip());
    assert!(t.converged);
    assert!((t.beta - 5f64.to_radians()).abs() < 1e-12);
    // Positive sideslip (wind from the right) is held with rudder that yaws the nose right
    // into it... in UMN signs, positive rudder yaws the nose LEFT, and Cn_beta > 0 yaws the
    // nose right: the rudder must be positive. The side force is balanced by banking: phi > 0.
    assert!(t.rudder > 0.0 && t.phi > 0.0 && t.q.abs() < 1e-12);
}

#[test]
fn impossible_target_reports_instead_of_panicking() {
    let a = Aircraft::ultrastick25e().unwrap();
    let mut target = TrimTarget::climb();
    target.name = "steep".into();
    target.gamma_rad = 40f64.to_radians();
    let t = trim(&a, &target);
    assert!(!t.converged);
    assert!(t.residual_norm > 1e-6 && t.residual_norm.is_finite());
    assert_eq!(t.target.name, "steep");
}
