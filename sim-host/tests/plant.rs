//! Behaviour of the nonlinear plant from physics, independent of the references.

use nalgebra::Vector3;
use sim_host::aircraft::Aircraft;
use sim_host::analysis::linearize::{iu, ix, linearize};
use sim_host::analysis::trim::{trim, TrimTarget};
use sim_host::plant::{Environment, ModelParams, Plant, ServoBank};

#[test]
fn trimmed_flight_stays_trimmed() {
    let a = Aircraft::ultrastick25e().unwrap();
    for target in [TrimTarget::level(), TrimTarget::turn()] {
        let t = trim(&a, &target);
        let mut plant = Plant::new(&a, t.state);
        let env = Environment::default();
        for _ in 0..1000 {
            plant.step(&t.controls, &env, 0.01);
        }
        // 10 s later: same airspeed, angle of attack, bank, rates; the altitude changed by
        // gamma * V * t only (zero here).
        let air = plant.air_data();
        assert!(
            (air.va - 17.0).abs() < 1e-3,
            "{} Va {}",
            target.name,
            air.va
        );
        assert!((air.alpha - t.alpha).abs() < 1e-4);
        assert!((plant.euler().phi - t.phi).abs() < 1e-3);
        assert!(
            (plant.alt_msl_m() - 100.0).abs() < 0.05,
            "alt {}",
            plant.alt_msl_m()
        );
        assert!((plant.body_rates() - t.state.omega_body).norm() < 1e-4);
        assert!((plant.attitude().quaternion().norm() - 1.0).abs() < 1e-12);
        if target.name == "turn" {
            // 10 s at 20 deg/s: heading advanced by 200 deg (-160 deg after wrapping).
            let psi = plant.euler().psi.to_degrees();
            assert!((psi - (-160.0)).abs() < 0.1, "psi {psi}");
        }
    }
}

#[test]
fn specific_force_in_level_flight_is_minus_g_along_z() {
    let a = Aircraft::ultrastick25e().unwrap();
    let t = trim(&a, &TrimTarget::level());
    let mut plant = Plant::new(&a, t.state);
    plant.set_inputs(&t.controls, &Environment::default());
    let f = plant.specific_force_body();
    // Unaccelerated flight: the specific force is minus gravity in body axes.
    let g = a.environment.g_mps2;
    let theta = t.theta;
    assert!((f.x - g * theta.sin()).abs() < 1e-3, "{f}");
    assert!((f.z + g * theta.cos() * t.phi.cos()).abs() < 1e-3, "{f}");
    assert!((f.norm() - g).abs() < 1e-3);
}

#[test]
fn steady_wind_only_carries_the_aircraft_along() {
    // In a uniform wind the motion relative to the air mass is the calm-air motion; only the
    // ground track drifts by wind * t (Galilean invariance). Horizontal wind only: a vertical
    // one would move the aircraft through the density gradient and break the invariance.
    let a = Aircraft::ultrastick25e().unwrap();
    let t = trim(&a, &TrimTarget::turn());
    let wind = Vector3::new(3.0, -4.0, 0.0);
    let mut calm = Plant::new(&a, t.state);
    let mut windy_state = t.state;
    windy_state.vel_body += t.state.attitude.inverse_transform_vector(&wind);
    let mut windy = Plant::new(&a, windy_state);
    let env = Environment { wind_ned: wind };
    for _ in 0..500 {
        calm.step(&t.controls, &Environment::default(), 0.01);
        windy.step(&t.controls, &env, 0.01);
    }
    let drift = windy.position_ned() - calm.position_ned();
    assert!((drift - wind * 5.0).norm() < 1e-6, "drift {drift}");
    assert!((windy.air_data().va - calm.air_data().va).abs() < 1e-9);
    assert!(windy.attitude().angle_to(&calm.attitude()) < 1e-9);
    assert!((windy.velocity_ned() - calm.velocity_ned() - wind).norm() < 1e-9);
}

#[test]
fn throttle_step_spins_up_the_engine_with_the_linear_time_constant() {
    // The engine-speed pole at level trim is A(Omega, Omega) = -5.903 1/s (UMN): a small
    // throttle step settles 63 % of the way in about 1/5.9 s at fixed airspeed.
    let a = Aircraft::ultrastick25e().unwrap();
    let t = trim(&a, &TrimTarget::level());
    let mut plant = Plant::new(&a, t.state);
    let mut c = t.controls;
    c.throttle += 0.01;
    let omega0 = plant.engine_speed();
    // Expected final increase from the linear model: B/(-A) * 0.01 = 2503/5.903 * 0.01.
    let final_increase = 2503.3 / 5.903 * 0.01;
    let tau: f64 = 1.0 / 5.903;
    let dt = 1e-3;
    let n = (tau / dt).round() as usize;
    for _ in 0..n {
        plant.step(&c, &Environment::default(), dt);
    }
    let frac = (plant.engine_speed() - omega0) / final_increase;
    assert!((frac - 0.632).abs() < 0.03, "fraction after tau {frac}");
}

#[test]
fn geodetic_position_moves_north() {
    let a = Aircraft::ultrastick25e().unwrap();
    let t = trim(&a, &TrimTarget::level());
    let mut plant = Plant::new(&a, t.state);
    for _ in 0..100 {
        plant.step(&t.controls, &Environment::default(), 0.01);
    }
    // 1 s north at 17 m/s: about 17 / 111 km per degree of latitude.
    let p = plant.geodetic();
    let dlat = p.lat_deg() - a.environment.home_lat_deg;
    assert!((dlat - 17.0 / 111_130.0).abs() < 2e-6, "dlat {dlat}");
    assert!((plant.velocity_ned().x - 17.0).abs() < 1e-3);
}

#[test]
fn servo_bank_holds_trim_and_follows_a_command() {
    let a = Aircraft::ultrastick25e().unwrap();
    let t = trim(&a, &TrimTarget::level());
    let mut s = ServoBank::new(&a.actuators, &t.controls);
    let out = s.step(&t.controls, 0.02);
    assert!((out.elevator - t.controls.elevator).abs() < 1e-15);
    assert!((out.aileron() - t.controls.aileron()).abs() < 1e-15);
    let mut cmd = t.controls;
    cmd.throttle = 1.7;
    cmd.rudder = 1.0;
    let mut out = s.step(&cmd, 0.02);
    assert_eq!(out.throttle, 1.0);
    for _ in 0..100 {
        out = s.step(&cmd, 0.02);
    }
    assert!((out.rudder - 25f64.to_radians()).abs() < 1e-6);
}

#[test]
fn an_elevator_step_through_the_servos_pitches_by_the_servo_motion_inside_the_step() {
    // From trim, a 1 deg elevator step is held over one 5 ms step with the servos moving inside
    // it: delta(t) = A (1 - exp(-w t)). To second order in the step the linear model gives
    // dx = B I1 + A B I2, I1 and I2 the single and double integrals of delta over the step.
    // Surfaces held at their end-of-step position would give about twice the pitch rate.
    let a = Aircraft::ultrastick25e().unwrap();
    let t = trim(&a, &TrimTarget::level());
    let lin = linearize(&ModelParams::new(&a), &t);
    let (amp, dt) = (1f64.to_radians(), 0.005);
    let w = 2.0 * std::f64::consts::PI * a.actuators.bandwidth_Hz;
    let decay = (1.0 - (-w * dt).exp()) / w;
    let i1 = amp * (dt - decay);
    let i2 = amp * (dt * dt / 2.0 - dt / w + decay / w);
    let b = lin.b.column(iu::ELEVATOR).into_owned();
    let predicted = b * i1 + lin.a * b * i2;

    let mut plant = Plant::new(&a, t.state);
    let mut servos = ServoBank::new(&a.actuators, &t.controls);
    let mut cmd = t.controls;
    cmd.elevator += amp;
    let end = plant.step_servos(&mut servos, &cmd, &Environment::default(), dt);
    assert!((end.elevator - t.controls.elevator - amp * (1.0 - (-w * dt).exp())).abs() < 1e-15);
    let dq = plant.body_rates().y - t.state.omega_body.y;
    let want = predicted[ix::Q];
    assert!(
        ((dq - want) / want).abs() < 0.01,
        "pitch rate change {dq} against {want} rad/s"
    );
}
