use super::identify::{Axis, AxisError, Identifier, IdentifyConfig, Sample};
use super::least_squares::LeastSquares;
use crate::math::{DEG, GRAVITY};
use nalgebra::SVector;

/// The 25e's roll and pitch coefficients at 17 m/s (`docs/GAIN-DESIGN.md`, from its aero
/// data) and a 20 ms servo (its file's 8 Hz bandwidth).
const A_PHI1: f32 = 16.094;
const A_PHI2: f32 = -156.47;
const A_THETA1: f32 = 15.68;
const A_THETA2: f32 = 180.0;
const A_THETA3: f32 = -120.0;
const SERVO_TAU: f32 = 0.0199;
const VA_REF: f32 = 17.0;

/// A 3-2-1-1 sequence of `amp` on steps of `unit` s, then rest: the excitation flight
/// testing uses for a broad band with few reversals.
fn three_two_one_one(t: f32, unit: f32, amp: f32) -> f32 {
    let k = t / unit;
    if k < 3.0 {
        amp
    } else if k < 5.0 {
        -amp
    } else if k < 6.0 {
        amp
    } else if k < 7.0 {
        -amp
    } else {
        0.0
    }
}

/// Flies the reduced roll and pitch models (and a slow airspeed swing that their `Va` and
/// `Va^2` scaling must follow) at 4 kHz with first-order servos (stepped exactly), and samples them at 50 Hz
/// with the surface commands held over each 20 ms, as the autopilot's loop holds them.
fn flown(servo_tau: f32, seconds: f32) -> [Sample; 1500] {
    let mut out = [Sample::default(); 1500];
    let (mut p, mut q, mut alpha, mut da_s, mut de_s, mut phi, mut theta) =
        (0.0f32, 0.0f32, 0.05f32, 0.0f32, 0.0f32, 0.0f32, 0.05f32);
    let h = 0.000_25f32;
    let mut cmd = (0.0, 0.0);
    let n = (seconds / 0.02) as usize;
    for (k, s) in out.iter_mut().enumerate().take(n) {
        let t = k as f32 * 0.02;
        let va = VA_REF + 2.0 * libm::sinf(0.3 * t);
        *s = Sample {
            p,
            q,
            r: 0.1 * libm::sinf(0.7 * t),
            ay: 0.3 * libm::sinf(1.1 * t),
            phi,
            theta,
            airspeed: va,
            alpha,
            aileron: cmd.0,
            elevator: cmd.1,
            throttle: 0.5,
            ground_speed: va,
            ..Sample::default()
        };
        // The commands of this period: doublets repeated every 4 s, the elevator's offset.
        let cyc = t % 4.0;
        cmd = (
            three_two_one_one(cyc, 0.15, 3.0 * DEG) - 0.02 * p,
            three_two_one_one((cyc + 2.0) % 4.0, 0.2, 2.0 * DEG) - 0.01,
        );
        s.aileron = cmd.0;
        s.elevator = cmd.1;
        for i in 0..80 {
            let tt = t + i as f32 * h;
            let v = (VA_REF + 2.0 * libm::sinf(0.3 * tt)) / VA_REF;
            let r = 0.1 * libm::sinf(0.7 * tt);
            let k = if servo_tau > 0.0 {
                1.0 - libm::expf(-h / servo_tau)
            } else {
                1.0
            };
            da_s += k * (cmd.0 - da_s);
            de_s += k * (cmd.1 - de_s);
            let ay = 0.3 * libm::sinf(1.1 * tt);
            let pd = -A_PHI1 * v * p + A_PHI2 * v * v * da_s + 0.4 * v * r + 2.0 * ay + 0.2 * v * v;
            let qd = -A_THETA1 * v * q - A_THETA2 * v * v * (alpha - 0.05)
                + A_THETA3 * v * v * (de_s + 0.01);
            let alphad = q - 6.0 * (alpha - 0.05);
            p += h * pd;
            q += h * qd;
            alpha += h * alphad;
            phi += h * p;
            theta += h * q;
        }
    }
    out
}

/// The models at the reference airspeed through a servo of time constant `servo_tau` (s), no
/// rate limit, no pre-filters: the data here are clean.
fn unfiltered(servo_tau: f32) -> IdentifyConfig {
    IdentifyConfig {
        airspeed_ref: VA_REF,
        servo_tau_s: servo_tau,
        servo_rate_radps: 0.0,
        airspeed_filter_tau_s: 0.0,
        attitude_filter_tau_s: 0.0,
    }
}

fn identified(samples: &[Sample], servo_tau: f32) -> Identifier {
    let mut id = Identifier::new(unfiltered(servo_tau));
    for s in samples {
        id.push(0.02, s);
    }
    id
}

fn within(x: f32, want: f32, rel: f32) -> bool {
    (x - want).abs() <= rel * want.abs()
}

#[test]
fn a_line_is_fitted_exactly_and_its_errors_vanish() {
    let mut ls = LeastSquares::<2>::new();
    for i in 0..50 {
        let x = i as f32 * 0.1;
        assert!(ls.push(&SVector::from([x, 1.0]), 3.0 * x - 2.0));
    }
    let f = ls.solve().expect("fit");
    assert!((f.coef[0] - 3.0).abs() < 1e-4 && (f.coef[1] + 2.0).abs() < 1e-4);
    assert!(f.std_err[0] < 1e-4 && f.r2 > 0.999_99 && f.rows == 50);
}

/// Noise of a known spread on a line: the standard error the fit gives is the textbook's
/// `sigma / sqrt(sum (x - mean)^2)` for the slope.
#[test]
fn the_slopes_standard_error_is_the_noises_spread_over_the_regressors_spread() {
    let mut ls = LeastSquares::<2>::new();
    let mut seed = 12345u32;
    let mut sxx = 0.0f32;
    for i in 0..400 {
        let x = (i % 40) as f32 * 0.05;
        sxx += (x - 0.975) * (x - 0.975);
        // A uniform noise of +-0.1 (sigma 0.0577), from a linear congruential generator.
        seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        let e = (seed >> 8) as f32 / 16_777_216.0 * 0.2 - 0.1;
        ls.push(&SVector::from([x, 1.0]), 2.0 * x + e);
    }
    let f = ls.solve().expect("fit");
    let want = 0.2 / libm::sqrtf(12.0) / libm::sqrtf(sxx);
    assert!(
        within(f.std_err[0], want, 0.15),
        "{} vs {want}",
        f.std_err[0]
    );
    assert!((f.coef[0] - 2.0).abs() < 4.0 * want);
}

#[test]
fn a_regressor_that_never_varies_alone_leaves_no_fit_and_a_bad_row_is_left_out() {
    let mut ls = LeastSquares::<2>::new();
    for i in 0..20 {
        let x = i as f32;
        ls.push(&SVector::from([x, 2.0 * x]), x);
    }
    assert!(ls.solve().is_none());
    let mut ls = LeastSquares::<2>::new();
    assert!(!ls.push(&SVector::from([f32::NAN, 1.0]), 1.0));
    assert!(!ls.push(&SVector::from([1.0, 1.0]), f32::INFINITY));
    assert_eq!(ls.rows(), 0);
}

/// The models flown with the 25e's coefficients give them back over a swing of +-2 m/s about
/// the reference airspeed, the servo accounted for: roll to 1 %, pitch to 3 % (its 13 rad/s
/// short period sampled at 50 Hz: the trapezoid's own error, 1-2.5 % here, is a bias no
/// amount of data removes; the bound against the aircraft is 15 %).
#[test]
fn the_reduced_roll_and_pitch_models_flown_with_a_servo_give_their_coefficients_back() {
    let data = flown(SERVO_TAU, 30.0);
    let id = identified(&data, SERVO_TAU);
    let roll = id.fit(Axis::Roll).expect("roll");
    assert!(
        within(roll.coef[0], A_PHI1, 0.01),
        "a_phi1 {}",
        roll.coef[0]
    );
    assert!(
        within(roll.coef[1], A_PHI2, 0.01),
        "a_phi2 {}",
        roll.coef[1]
    );
    assert!(roll.r2 > 0.99, "{roll:?}");
    let pitch = id.fit(Axis::Pitch).expect("pitch");
    assert!(
        within(pitch.coef[0], A_THETA1, 0.03),
        "a_theta1 {}",
        pitch.coef[0]
    );
    assert!(
        within(pitch.coef[1], A_THETA2, 0.03),
        "a_theta2 {}",
        pitch.coef[1]
    );
    assert!(
        within(pitch.coef[2], A_THETA3, 0.03),
        "a_theta3 {}",
        pitch.coef[2]
    );
}

/// Read as if the surfaces followed their commands at once, the same flight's 20 ms servo
/// lag makes the roll look less damped and its aileron weaker than they are (9.3 and -102
/// for 16.1 and -156: both a third or more short).
#[test]
fn leaving_the_servo_out_biases_the_roll_fit() {
    let data = flown(SERVO_TAU, 30.0);
    let id = identified(&data, 0.0);
    let roll = id.fit(Axis::Roll).expect("roll");
    assert!(roll.coef[0] < 0.7 * A_PHI1, "a_phi1 {}", roll.coef[0]);
    assert!(
        roll.coef[1].abs() < 0.7 * A_PHI2.abs(),
        "a_phi2 {}",
        roll.coef[1]
    );
}

#[test]
fn an_aileron_held_still_is_named_as_the_missing_excitation() {
    let mut data = flown(SERVO_TAU, 30.0);
    for s in data.iter_mut() {
        s.aileron = -0.01;
    }
    let id = identified(&data, SERVO_TAU);
    match id.fit(Axis::Roll) {
        Err(AxisError::NotExcited { input, sd, .. }) => {
            assert_eq!(input, "aileron");
            assert!(sd < 1e-6);
        }
        other => panic!("{other:?}"),
    }
}

/// Samples with a time step that is not a step (zero, negative, NaN, a gap of seconds) or a
/// value that is not finite are not turned into rates: the fit is the clean data's.
#[test]
fn bad_time_steps_and_values_start_a_new_stretch_and_leave_the_fit_as_it_was() {
    let data = flown(SERVO_TAU, 30.0);
    let clean = identified(&data, SERVO_TAU).fit(Axis::Roll).expect("roll");
    let mut id = Identifier::new(unfiltered(SERVO_TAU));
    for (k, s) in data.iter().enumerate() {
        match k {
            500 => id.push(f32::NAN, s),
            700 => id.push(-0.02, s),
            900 => id.push(3.0, s),
            1100 => {
                id.push(
                    0.02,
                    &Sample {
                        p: f32::INFINITY,
                        ..*s
                    },
                );
                id.push(0.02, s);
            }
            _ => id.push(0.02, s),
        }
    }
    let f = id.fit(Axis::Roll).expect("roll");
    assert!(f.rows < clean.rows && f.rows + 10 > clean.rows);
    assert!(within(f.coef[1], A_PHI2, 0.02) && f.coef.iter().all(|c| c.is_finite()));
}

/// The airspeed model from throttle, pitch, angle-of-attack and sideslip swings of different
/// periods.
#[test]
fn the_airspeed_model_gives_its_damping_throttle_gravity_and_sideslip_drag_terms_back() {
    // The sideslip's drag as the 25e's at 17 m/s: about 3 m/s^2 per rad^2.
    let (a1, a2, a3, ka, kb) = (0.6f32, 8.0f32, GRAVITY, 2.0f32, -3.0f32);
    let mut id = Identifier::new(unfiltered(SERVO_TAU));
    let mut va = VA_REF;
    for k in 0..3000 {
        let t = k as f32 * 0.02;
        let thr = 0.5 + 0.2 * three_two_one_one(t % 12.0, 1.0, 1.0);
        let theta = 0.05 * libm::sinf(0.4 * t);
        let alpha = 0.06 + 0.02 * libm::sinf(1.3 * t);
        let beta = |t: f32| 0.08 * libm::sinf(0.9 * t);
        id.push(
            0.02,
            &Sample {
                airspeed: va,
                throttle: thr,
                theta,
                alpha,
                beta: beta(t),
                ground_speed: va,
                ..Sample::default()
            },
        );
        // Integrated over the period at the period's mid-point values.
        let tm = t + 0.01;
        let (thm, alm) = (
            0.05 * libm::sinf(0.4 * tm),
            0.06 + 0.02 * libm::sinf(1.3 * tm),
        );
        let drag = kb * beta(tm) * beta(tm);
        for _ in 0..20 {
            let v = va / VA_REF;
            va += 0.001
                * (-a1 * (va - VA_REF) + a2 * (thr - 0.5) - a3 * thm + ka * alm - 0.1
                    + drag * v * v);
        }
    }
    let f = id.fit(Axis::Airspeed).expect("airspeed");
    assert!(within(f.coef[0], a1, 0.03), "{f:?}");
    assert!(within(f.coef[1], a2, 0.03), "{f:?}");
    assert!(within(f.coef[2], a3, 0.03), "{f:?}");
    assert!(within(f.coef[5], kb, 0.05), "{f:?}");
}

/// A coordinated turn's course rate is `g tan(phi) / Vg`: the kinematic gain comes out 1.
#[test]
fn the_course_kinematics_of_banked_turns_give_a_gain_of_one() {
    let mut id = Identifier::new(unfiltered(SERVO_TAU));
    let mut chi = 0.0f32;
    for k in 0..2000 {
        let t = k as f32 * 0.02;
        let phi = 30.0 * DEG * libm::sinf(0.25 * t);
        id.push(
            0.02,
            &Sample {
                phi,
                course: chi,
                ground_speed: 18.0,
                airspeed: 17.0,
                ..Sample::default()
            },
        );
        let phim = 30.0 * DEG * libm::sinf(0.25 * (t + 0.01));
        chi = crate::math::frames::wrap_pi(chi + 0.02 * GRAVITY * libm::tanf(phim) / 18.0);
    }
    let f = id.fit(Axis::Course).expect("course");
    assert!(within(f.coef[0], 1.0, 0.01), "{f:?}");
}

/// A 45 deg command on a 20 ms servo limited to 150 deg/s: 3 deg in the 20 ms interval, a
/// ramp's mean of 1.5 deg; a 0.1 deg command stays on the first-order curve
/// (`1 - e^(-1.005)` of it by the end).
#[test]
fn a_full_stick_command_moves_the_surface_at_the_rate_limit_and_a_small_one_on_its_lag() {
    let c = IdentifyConfig {
        servo_rate_radps: 150.0 * DEG,
        ..unfiltered(SERVO_TAU)
    };
    let (end, mean) = super::identify::servo(&c, 0.0, 45.0 * DEG, 0.02);
    assert!((end - 3.0 * DEG).abs() < 1e-5 && (mean - 1.5 * DEG).abs() < 1e-5);
    let (end, _) = super::identify::servo(&c, 0.0, 0.1 * DEG, 0.02);
    let want = 0.1 * DEG * (1.0 - libm::expf(-0.02 / SERVO_TAU));
    assert!((end - want).abs() < 1e-4 * want.abs() + 1e-9);
}

/// The lift that turns the flight path, flown with the 25e's heave damping at 17 m/s (`a_gamma`
/// 7.54 1/s, its linearisation's): `Va gamma' = v^2 cos(phi) (g + a_gamma Va_ref (alpha -
/// alpha_0)) - g cos(gamma)` with the angle of attack swung by pitch doublets, the airspeed by
/// +-2 m/s and the bank by +-20 deg; the fit gives `a_gamma` back to 1 % and the lift at
/// no angle of attack to 2 %.
#[test]
fn the_flight_path_s_lift_gives_the_heave_damping_back() {
    let a_gamma = 7.54f32;
    let mut id = Identifier::new(unfiltered(SERVO_TAU));
    let (alpha_0, h) = (0.05f32, 0.001f32);
    let at = |t: f32| {
        let va = VA_REF + 2.0 * libm::sinf(0.3 * t);
        let alpha = alpha_0 + three_two_one_one(t % 6.0, 0.3, 2.0 * DEG);
        let phi = 20.0 * DEG * libm::sinf(0.2 * t);
        (va, alpha, phi)
    };
    let mut gamma = 0.0f32;
    for k in 0..3000 {
        let t = k as f32 * 0.02;
        let (va, alpha, phi) = at(t);
        id.push(
            0.02,
            &Sample {
                airspeed: va,
                alpha,
                phi,
                theta: alpha + gamma,
                climb_rate: va * gamma,
                ground_speed: va,
                ..Sample::default()
            },
        );
        for i in 0..20 {
            let (va, alpha, phi) = at(t + (i as f32 + 0.5) * h);
            let v = va / VA_REF;
            let lift = v * v * libm::cosf(phi) * (GRAVITY + a_gamma * VA_REF * (alpha - alpha_0));
            gamma += h * (lift - GRAVITY * libm::cosf(gamma)) / va;
        }
    }
    let f = id.fit(Axis::FlightPath).expect("flight path");
    assert!(within(f.coef[0], a_gamma, 0.01), "{f:?}");
    // The lift at no angle of attack per v^2: g less the trim angle's share.
    assert!(
        within(f.coef[1], GRAVITY - a_gamma * VA_REF * alpha_0, 0.02),
        "{f:?}"
    );
    // The doublets' steps fall inside a sample's interval, where the trapezoid's mean angle
    // of attack is not the one the lift had: what the fit leaves is that, 2-3 %.
    assert!(f.r2 > 0.95, "{f:?}");
}

/// The side force of rudder 3-2-1-1s read by a noisy accelerometer (0.6 m/s^2, the 25e's): the
/// sideslip flown by a Dutch roll, the rudder through its servo, the airspeed swinging as the
/// `Va^2` scaling must follow. The book's coefficients at 17 m/s (`a_beta1` 0.796, `a_beta2`
/// 0.312, the 25e's aero data) come back within three of the standard errors the fit gives
/// (each under 5 % of its value: the noise's share) and the 1 % the trapezoid's means leave
/// (without the noise: 0.9 % and 0.8 % low), the noise left unexplained.
#[test]
fn the_sideslip_model_gives_the_side_forces_coefficients_back_through_the_accelerometers_noise() {
    const A_BETA1: f32 = 0.7963;
    const A_BETA2: f32 = 0.3116;
    let mut id = Identifier::new(unfiltered(SERVO_TAU));
    let (mut beta, mut r, mut dr_s) = (0.0f32, 0.0f32, 0.0f32);
    let mut seed = 777u32;
    let mut uniform = || {
        seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (seed >> 8) as f32 / (1u32 << 24) as f32 - 0.5
    };
    let h = 0.000_25f32;
    for k in 0..1500 {
        let t = k as f32 * 0.02;
        let va = VA_REF + 2.0 * libm::sinf(0.3 * t);
        let v = va / VA_REF;
        let p = 0.05 * libm::sinf(0.9 * t);
        let cmd = three_two_one_one(t % 5.0, 0.3, 6.0 * DEG);
        // A sum of twelve uniforms has unit variance: 0.6 m/s^2 of noise.
        let noise = 0.6 * (0..12).map(|_| uniform()).sum::<f32>();
        let force = VA_REF * v * v * (-A_BETA1 * beta + A_BETA2 * dr_s);
        id.push(
            0.02,
            &Sample {
                p,
                r,
                beta,
                accel_y: force + 0.3 * v * r + 0.05 * v * v + noise,
                rudder: cmd,
                airspeed: va,
                ground_speed: va,
                ..Sample::default()
            },
        );
        for _ in 0..80 {
            dr_s += (1.0 - libm::expf(-h / SERVO_TAU)) * (cmd - dr_s);
            let beta_dot = -A_BETA1 * v * beta + A_BETA2 * v * dr_s - r;
            let r_dot = 20.0 * v * v * beta - 2.0 * v * r - 5.0 * v * v * dr_s;
            beta += h * beta_dot;
            r += h * r_dot;
        }
    }
    let f = id.fit(Axis::Sideslip).expect("sideslip");
    for (i, want) in [A_BETA1, A_BETA2].into_iter().enumerate() {
        assert!(f.std_err[i] < 0.05 * want, "{f:?}");
        assert!(
            (f.coef[i] - want).abs() < 3.0 * f.std_err[i] + 0.01 * want,
            "{f:?}"
        );
    }
    assert!(f.r2 > 0.3 && f.r2 < 0.99, "{f:?}");
}

/// Rows given to the other models only leave the sideslip model without any (its rudder
/// unexcited), and rows given to it only leave the roll model without any: each fits on the
/// stages that are its own.
#[test]
fn a_model_whose_rows_are_off_takes_none_and_says_its_input_was_not_excited() {
    let data = flown(SERVO_TAU, 30.0);
    let mut others = Identifier::new(unfiltered(SERVO_TAU));
    let mut sideslip = Identifier::new(unfiltered(SERVO_TAU));
    others.take_rows(false, true);
    sideslip.take_rows(true, false);
    for s in &data[..1500] {
        let s = Sample {
            rudder: 0.05 * s.aileron.signum(),
            ..*s
        };
        others.push(0.02, &s);
        sideslip.push(0.02, &s);
    }
    assert!(others.fit(Axis::Roll).is_ok());
    assert!(matches!(
        others.fit(Axis::Sideslip),
        Err(AxisError::NotExcited { sd, .. }) if sd == 0.0
    ));
    assert!(matches!(
        sideslip.fit(Axis::Roll),
        Err(AxisError::NotExcited { sd, .. }) if sd == 0.0
    ));
}
