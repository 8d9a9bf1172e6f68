//! Ground contact of the plant, checked against statics and simple mechanics.

use nalgebra::Vector3;
use sim_host::aircraft::Aircraft;
use sim_host::analysis::trim::{trim, TrimTarget};
use sim_host::plant::gear::{MAIN_LEFT, MAIN_RIGHT, TAIL};
use sim_host::plant::ground;
use sim_host::plant::{Controls, Environment, ModelParams, Plant, State};

fn aircraft() -> Aircraft {
    Aircraft::ultrastick25e().unwrap()
}

fn ground_speed(p: &Plant) -> f64 {
    let v = p.velocity_ned();
    v.x.hypot(v.y)
}

/// Full elevator travel in the model, rad (the servo limit of the aircraft file).
const ELEVATOR_FULL_UP: f64 = -0.4363323;

#[test]
fn at_rest_the_wheels_carry_the_weight_by_the_lever_rule_and_nothing_creeps() {
    let a = aircraft();
    let mut plant = Plant::at_rest_on_ground(&a, 10.0, -5.0, 0.7);
    let p = plant.params().clone();
    let weight = p.mass * p.g;
    let (_, residual) = ground::rest_state(&p, 10.0, -5.0, 0.7);
    assert!(residual < 1e-9, "equilibrium residual {residual}");
    let gc = plant.ground_contact();
    assert!(plant.on_ground() && plant.weight_on_wheels());
    // Vertical balance: the normal forces sum to the weight.
    assert!(
        (gc.normal_total_n() - weight).abs() < 0.01 * weight,
        "normal {} N, weight {weight} N",
        gc.normal_total_n()
    );
    assert_eq!(gc.belly_load_n, 0.0);
    // Lever rule about the CG along the ground: main and tail loads in the inverse ratio of
    // their horizontal distances from the CG.
    let e = plant.euler();
    let horiz = |i: usize| {
        let r = p.ground.points[i].pos_body;
        r.x * e.theta.cos() + r.z * e.theta.sin()
    };
    let (xm, xt) = (horiz(MAIN_LEFT), horiz(TAIL));
    let tail_expected = weight * xm / (xm - xt);
    let tail = gc.normal_n[TAIL];
    assert!(
        (tail - tail_expected).abs() < 0.01 * tail_expected,
        "tail {tail} N, lever rule {tail_expected} N"
    );
    assert!((gc.normal_n[MAIN_LEFT] - gc.normal_n[MAIN_RIGHT]).abs() < 1e-9);
    // The three-point attitude: the line through the compressed contacts is level, close to
    // the uncompressed geometry's atan(dz / dx).
    let (m, t) = (
        p.ground.points[MAIN_LEFT].pos_body,
        p.ground.points[TAIL].pos_body,
    );
    let geometric = ((m.z - t.z) / (m.x - t.x)).atan();
    assert!(
        (e.theta - geometric).abs() < 0.5_f64.to_radians(),
        "theta {} deg, geometry {} deg",
        e.theta.to_degrees(),
        geometric.to_degrees()
    );
    assert!(e.phi.abs() < 1e-9 && (e.psi - 0.7).abs() < 1e-9);
    // An accelerometer at rest reads minus gravity.
    assert!((plant.specific_force_body().norm() - p.g).abs() < 0.01 * p.g);
    println!(
        "at rest: theta {:.2} deg, mains {:.3} N each, tail {:.3} N, sum {:.4} N (weight {:.4} N), main deflection {:.1} mm",
        e.theta.to_degrees(),
        gc.normal_n[MAIN_LEFT],
        tail,
        gc.normal_total_n(),
        weight,
        gc.penetration_m[MAIN_LEFT] * 1e3
    );

    let start = plant.position_ned();
    let env = Environment::default();
    let idle = Controls::default();
    for _ in 0..2000 {
        plant.step(&idle, &env, 0.005);
    }
    let moved = plant.position_ned() - start;
    println!("at rest: moved {:.2e} m in 10 s", moved.norm());
    assert!(moved.norm() < 0.01, "moved {moved} m in 10 s");
    assert!(plant.on_ground() && plant.touchdown().is_none() && plant.liftoff_s().is_none());
}

#[test]
fn a_drop_from_thirty_centimetres_settles_on_the_wheels() {
    let a = aircraft();
    let p = ModelParams::new(&a);
    let (rest, _) = ground::rest_state(&p, 0.0, 0.0, 0.0);
    for dt in [0.005, 0.02] {
        let mut start = rest;
        start.pos_ned.z -= 0.3;
        let mut plant = Plant::from_params(p.clone(), start);
        assert!(!plant.on_ground());
        let (env, idle) = (Environment::default(), Controls::default());
        let mut deepest: f64 = 0.0;
        let mut belly: f64 = 0.0;
        let steps = (5.0 / dt) as usize;
        for _ in 0..steps {
            plant.step(&idle, &env, dt);
            assert!(plant.state_vector().iter().all(|v| v.is_finite()));
            let gc = plant.ground_contact();
            deepest = deepest.max(gc.penetration_m.iter().cloned().fold(0.0, f64::max));
            belly = belly.max(gc.belly_load_n);
        }
        // Stopped at the static equilibrium's height and attitude. It lands a little ahead of
        // where it was dropped: falling flat, the relative wind comes from below, and the
        // linear model's lift (perpendicular to it) pushes the airframe forward.
        let s = plant.state();
        assert!(
            (s.pos_ned.z - rest.pos_ned.z).abs() < 1e-3,
            "dt {dt}: {:?}",
            s.pos_ned
        );
        assert!(
            s.pos_ned.y.abs() < 5e-3 && s.pos_ned.x.abs() < 0.15,
            "dt {dt}: {:?}",
            s.pos_ned
        );
        assert!(s.attitude.angle_to(&rest.attitude) < 1e-3);
        assert!(s.vel_body.norm() < 1e-3 && s.omega_body.norm() < 1e-3);
        // The gear took the impact (2.4 m/s) within its travel: no point went deeper than
        // the 8 cm the belly clears the ground at rest, and the belly never touched.
        assert!(deepest < 0.08, "dt {dt}: deepest {deepest} m");
        assert_eq!(belly, 0.0, "dt {dt}");
        // Free fall from 0.3 m: sqrt(2 g h) = 2.43 m/s. The falling airframe's drag (relative
        // wind from below, far outside the linear model's range) can only slow it.
        let td = plant.touchdown().expect("touchdown recorded");
        let free_fall = (2.0 * p.g * 0.3).sqrt();
        assert!(
            td.sink_rate_mps() <= free_fall && td.sink_rate_mps() > 0.8 * free_fall,
            "sink {} m/s, free fall {free_fall}",
            td.sink_rate_mps()
        );
        assert!(td.time_s > 0.2 && td.time_s < 0.3, "{}", td.time_s);
        assert!(
            td.distance_from_m(0.0, 0.0) < 0.15 && td.bounces == 0,
            "{td:?}"
        );
        println!(
            "drop dt {dt}: touchdown {:.3} s at {:.3} m/s (free fall {:.3}), deepest {:.1} mm, bounces {}, forward {:.3} m",
            td.time_s,
            td.sink_rate_mps(),
            free_fall,
            deepest * 1e3,
            td.bounces,
            s.pos_ned.x
        );
    }
}

#[test]
fn rolling_with_the_engine_off_decelerates_at_mu_roll_g() {
    let a = aircraft();
    let mut plant = Plant::at_rest_on_ground(&a, 0.0, 0.0, 0.0);
    let mut s = plant.state();
    let heading: f64 = 1.2;
    s.attitude = nalgebra::UnitQuaternion::from_euler_angles(0.0, plant.euler().theta, heading);
    let v0 = Vector3::new(1.5 * heading.cos(), 1.5 * heading.sin(), 0.0);
    s.vel_body = s.attitude.inverse_transform_vector(&v0);
    plant.set_state(s);
    let (env, idle) = (Environment::default(), Controls::default());
    let dt = 0.002;
    let (mut t_hi, mut t_lo) = (None, None);
    while t_lo.is_none() && plant.time_s() < 10.0 {
        plant.step(&idle, &env, dt);
        let v = ground_speed(&plant);
        if t_hi.is_none() && v < 1.2 {
            t_hi = Some(plant.time_s());
        }
        if v < 0.6 {
            t_lo = Some(plant.time_s());
        }
    }
    let decel = 0.6 / (t_lo.unwrap() - t_hi.unwrap());
    let expected = a.ground.mu_roll * a.environment.g_mps2;
    // Below 1.2 m/s the aerodynamic drag and lift change the deceleration by < 2 %, and the
    // friction's smoothing below the 0.1 m/s slip speed takes < 1.5 % off at 0.6 m/s.
    assert!(
        (decel - expected).abs() < 0.03 * expected,
        "deceleration {decel} m/s^2, mu_roll g = {expected}"
    );
    // It rolled straight along its heading.
    let course = plant.velocity_ned().y.atan2(plant.velocity_ned().x);
    assert!((course - heading).abs() < 1e-3, "course {course}");
    println!("rolling: deceleration {decel:.4} m/s^2, mu_roll g {expected:.4} m/s^2");
}

#[test]
fn full_throttle_with_the_stick_back_takes_off_at_the_lift_speed_of_the_three_point_attitude() {
    let a = aircraft();
    let mut plant = Plant::at_rest_on_ground(&a, 0.0, 0.0, 0.0);
    let p = plant.params().clone();
    let env = Environment::default();
    let controls = Controls::new(ELEVATOR_FULL_UP, 0.0, 0.0, 1.0);
    let dt = 0.002;
    let theta_rest = plant.euler().theta;
    let weight = p.mass * p.g;
    // (time, speed, thrust, density, pitch, tail load) when both main wheels first carry
    // nothing.
    let mut mains_off = None;
    while plant.liftoff_s().is_none() && plant.time_s() < 15.0 {
        plant.step(&controls, &env, dt);
        let gc = plant.ground_contact();
        if mains_off.is_none() && gc.normal_n[MAIN_LEFT] == 0.0 && gc.normal_n[MAIN_RIGHT] == 0.0 {
            let d = plant.derivatives();
            mains_off = Some((
                plant.time_s(),
                ground_speed(&plant),
                d.propulsion.thrust_n,
                d.rho,
                plant.euler().theta,
                gc.normal_n[TAIL],
            ));
        }
    }
    let t_lo = plant.liftoff_s().expect("lifted off");
    let v_lo = ground_speed(&plant);
    let (t_m, v_m, thrust, rho, theta, tail) = mains_off.expect("main wheels unloaded");
    assert!((theta - theta_rest).abs() < 1f64.to_radians());
    // The mains unload about where the lift of the three-point attitude (angle of attack =
    // pitch on the level run, elevator full up) and the thrust's vertical part carry the
    // weight: L(theta_rest) + T sin(theta_rest) = W. Within 5 %: the tail wheel still carries
    // a few per cent of the weight then (lowering the speed), and the attitude has grown by
    // ~0.6 deg as the gear extends (raising CL by ~6 %, lowering the speed by ~3 %).
    let cl =
        p.aero.lift.CL0 + p.aero.lift.CL_alpha * theta_rest + p.aero.lift.CL_de * ELEVATOR_FULL_UP;
    let v_3pt = (2.0 * (weight - thrust * theta_rest.sin()) / (rho * p.s * cl)).sqrt();
    assert!(
        (v_m - v_3pt).abs() < 0.05 * v_3pt,
        "mains off at {v_m} m/s, three-point balance {v_3pt} m/s (CL {cl}, T {thrust} N)"
    );
    // Then it rotates on the tail wheel and leaves the ground above that speed, between the
    // speed of CL = 1.2 (a typical maximum of this class of wing; the linear model has no stall)
    // and the 17 m/s cruise.
    let v_cl12 = (2.0 * weight / (rho * p.s * 1.2)).sqrt();
    assert!(
        v_lo > v_m && v_lo > v_cl12 && v_lo < 17.0,
        "lift-off {v_lo} m/s"
    );
    // Down the runway, no rudder held: the propeller's torque and gyroscopic moment swing the
    // nose left a few degrees, as they do on a real taildragger (a pilot holds right rudder).
    let pos = plant.position_ned();
    let psi = plant.euler().psi;
    println!("lateral {} m, heading {} deg", pos.y, psi.to_degrees());
    assert!(pos.y.abs() < 2.0, "lateral {} m", pos.y);
    assert!(
        psi.abs() < 10f64.to_radians(),
        "heading {} deg",
        psi.to_degrees()
    );
    println!(
        "take-off: mains off after {t_m:.2} s at {v_m:.2} m/s (balance {v_3pt:.2} m/s, CL {cl:.3}, thrust {thrust:.2} N, tail {tail:.2} N); lift-off after {t_lo:.2} s and {:.1} m at {v_lo:.2} m/s, theta {:.1} deg; CL=1.2 speed {v_cl12:.2} m/s",
        pos.x,
        plant.euler().theta.to_degrees()
    );
    // And it climbs away.
    let alt_lo = plant.alt_msl_m();
    for _ in 0..250 {
        plant.step(&controls, &env, dt);
        assert!(!plant.on_ground());
    }
    assert!(
        plant.alt_msl_m() > alt_lo + 0.3,
        "alt {}",
        plant.alt_msl_m()
    );
    assert!(plant.velocity_ned().z < -1.0, "{}", plant.velocity_ned());
}

#[test]
fn rudder_steers_the_tail_wheel_nose_left_for_positive_rudder() {
    let a = aircraft();
    let env = Environment::default();
    let run = |rudder: f64| {
        let mut plant = Plant::at_rest_on_ground(&a, 0.0, 0.0, 0.0);
        let mut s: State = plant.state();
        s.vel_body = s
            .attitude
            .inverse_transform_vector(&Vector3::new(3.0, 0.0, 0.0));
        plant.set_state(s);
        // Throttle to hold about 3 m/s against the rolling friction.
        let c = Controls::new(0.0, 0.0, rudder, 0.12);
        for _ in 0..1000 {
            plant.step(&c, &env, 0.002);
        }
        (
            plant.body_rates().z,
            ground_speed(&plant),
            plant.euler().psi,
        )
    };
    let (r_left, v, psi_left) = run(0.2);
    let (r_right, _, psi_right) = run(-0.2);
    let (r0, _, psi0) = run(0.0);
    // Without rudder it runs straight but for the propeller's torque, which loads one main
    // wheel more than the other.
    assert!(psi0.abs() < 0.01 * psi_left.abs() && r0.abs() < 0.01 * r_left.abs());
    // Positive rudder (trailing edge left) yaws the nose left: negative yaw rate.
    assert!(r_left < 0.0 && psi_left < 0.0, "r {r_left}, psi {psi_left}");
    assert!(
        (r_left + r_right).abs() < 0.05 * r_left.abs(),
        "{r_left} {r_right}"
    );
    assert!(psi_right > 0.0);
    // A steered tail wheel with the mains as the pivot: r = -V sin(steer) / wheelbase, less
    // the tyres' slip.
    let tail = a.ground.third_wheel().expect("a taildragger's tail wheel");
    let wb = a.ground.main_wheel_left_m[0] - tail.pos_m[0];
    let kinematic = -v * (0.2 * tail.steer_per_rudder).sin() / wb;
    assert!(
        r_left / kinematic > 0.7 && r_left / kinematic < 1.1,
        "yaw rate {r_left}, kinematic {kinematic} at {v} m/s"
    );
    println!("steering: yaw rate {r_left:.3} rad/s at {v:.2} m/s, kinematic {kinematic:.3}");
}

#[test]
fn contact_is_exactly_zero_in_flight_and_trim_is_unchanged() {
    let a = aircraft();
    let t = trim(&a, &TrimTarget::level());
    let mut plant = Plant::new(&a, t.state);
    plant.set_inputs(&t.controls, &Environment::default());
    let d = plant.derivatives();
    assert_eq!(d.ground, ground::GroundContact::default());
    assert!(!plant.on_ground() && !plant.weight_on_wheels());
    // Just clear of the ground, the full evaluation gives zero too (not only the early-out).
    let p = plant.params().clone();
    let (mut s, _) = ground::rest_state(&p, 0.0, 0.0, 0.0);
    let x = s.to_vector();
    s.pos_ned.z -= ground::clearance_m(&p, &x).abs() + 1e-3;
    let gc = ground::contact(&p, &s.to_vector(), &Controls::default());
    assert_eq!(gc, ground::GroundContact::default());
    assert!(!p.ground.clear_of_ground(s.pos_ned.z));
}

#[test]
fn a_glide_onto_the_runway_records_its_touchdown() {
    // The trimmed 17 m/s level flight, 3 m above the runway, engine off: it sinks onto the
    // wheels. The record is the state when the lowest point reached the ground plane.
    let a = aircraft();
    let t = trim(&a, &TrimTarget::level());
    let mut s = t.state;
    s.pos_ned = Vector3::new(0.0, 0.0, -3.0);
    let mut plant = Plant::new(&a, s);
    let env = Environment::default();
    let glide = Controls {
        throttle: 0.0,
        ..t.controls
    };
    let dt = 0.005;
    let mut last_air = plant.clone();
    while plant.touchdown().is_none() && plant.time_s() < 20.0 {
        last_air = plant.clone();
        plant.step(&glide, &env, dt);
    }
    let td = *plant.touchdown().expect("touched down");
    // Between the last airborne state and the one after it.
    assert!(td.time_s > last_air.time_s() && td.time_s <= plant.time_s());
    let v_before = last_air.velocity_ned();
    assert!(
        (td.vel_ned - v_before).norm() < 0.05,
        "{:?} vs {v_before}",
        td.vel_ned
    );
    assert!(td.sink_rate_mps() > 0.0 && td.vel_ned.x > 10.0);
    // Its position lies on the path flown in that step.
    let along = (td.pos_ned - last_air.position_ned()).norm();
    assert!(along <= (plant.position_ned() - last_air.position_ned()).norm() + 1e-9);
    println!(
        "glide landing: touchdown after {:.2} s, {:.1} m along, sink {:.2} m/s at {:.1} m/s",
        td.time_s,
        td.distance_from_m(0.0, 0.0),
        td.sink_rate_mps(),
        td.vel_ned.x
    );
    // It rolls out and stops on its wheels, right side up.
    let idle = Controls {
        throttle: 0.0,
        ..Controls::default()
    };
    for _ in 0..(60.0 / dt) as usize {
        plant.step(&idle, &env, dt);
    }
    assert!(plant.state_vector().iter().all(|v| v.is_finite()));
    assert!(ground_speed(&plant) < 0.05, "{}", ground_speed(&plant));
    assert!(plant.weight_on_wheels() && plant.euler().phi.abs() < 0.1);
}
