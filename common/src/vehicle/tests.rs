//! The commander and the vehicle without any link: requests in, modes, commands and notices
//! out. Expectations come from the modes' definitions (DESIGN.md, PX4's behaviour) and the
//! thesis's trims, not from this code.

extern crate std;

use super::commander::*;
use super::modes::FlightMode;
use super::requests::{AltitudeSetpoint, ArmRequest, VehicleRequests};
use super::*;
use crate::control::gains::DESIGNED;
use crate::control::lateral::RollMode;
use crate::control::longitudinal::LonMode;
use crate::estimator::Home;
use crate::failsafe::Reaction;
use crate::math::geodetic::GeoPoint;
use crate::navigation::navigator::Navigator;
use nalgebra::Vector3;

/// Flying level at 17 m/s, 60 m above a home at 300 m, course 90 deg, every sensor healthy.
fn flying() -> EstimatedState {
    let mut e = Estimator::default().state();
    e.home = Some(Home {
        point: GeoPoint {
            lat_e7: 449_000_000,
            lon_e7: -932_000_000,
        },
        alt_amsl_m: 300.0,
    });
    e.alt_amsl_m = 360.0;
    e.pos_ned = Vector3::new(0.0, 0.0, -60.0);
    e.airspeed = 17.0;
    e.course = core::f32::consts::FRAC_PI_2;
    e.ground_speed = 17.0;
    e.position_valid = true;
    e.converged = true;
    e.health.gps.healthy = true;
    e.health.pitot.healthy = true;
    e
}

fn on_ground() -> EstimatedState {
    let mut e = flying();
    e.alt_amsl_m = 300.0;
    e.pos_ned = Vector3::zeros();
    e.airspeed = 0.0;
    e
}

fn arm() -> VehicleRequests {
    VehicleRequests {
        arm: Some(ArmRequest {
            arm: true,
            forced: false,
        }),
        ..Default::default()
    }
}

fn mode(m: FlightMode) -> VehicleRequests {
    VehicleRequests {
        mode: Some(m),
        ..Default::default()
    }
}

fn texts(c: &mut Commander) -> std::vec::Vec<&'static str> {
    let mut v = std::vec::Vec::new();
    while let Some(n) = c.next_notice() {
        if let Notice::Text(_, t) = n {
            v.push(t);
        }
    }
    v
}

#[test]
fn arming_on_the_ground_sets_home_where_the_aircraft_stands_and_says_so() {
    let mut c = Commander::new();
    let mut n = Navigator::default();
    let mut e = on_ground();
    // The estimate moved 2 m north and 0.4 m up since the first fix set home.
    e.position = GeoPoint {
        lat_e7: 449_000_180,
        lon_e7: -932_000_000,
    };
    e.alt_amsl_m = 300.4;
    let home = c.apply(&arm(), &e, &mut n);
    assert_eq!(
        home,
        Some(Home {
            point: e.position,
            alt_amsl_m: 300.4
        })
    );
    assert!(c.armed());
    assert_eq!(texts(&mut c), ["Armed"]);
    // Arming again changes nothing and says nothing.
    assert_eq!(c.apply(&arm(), &e, &mut n), None);
    assert!(texts(&mut c).is_empty());
}

#[test]
fn arming_in_the_air_keeps_home() {
    let mut c = Commander::new();
    let mut n = Navigator::default();
    assert_eq!(c.apply(&arm(), &flying(), &mut n), None);
    assert!(c.armed());
}

#[test]
fn entering_hold_holds_the_present_course_and_altitude() {
    let mut c = Commander::new();
    let mut n = Navigator::default();
    let e = flying();
    detect(&mut c, &e, 0.1);
    c.apply(&mode(FlightMode::Hold), &e, &mut n);
    let sp = c.setpoints();
    assert_eq!((sp.course, sp.alt_amsl_m), (e.course, 360.0));
    // Hold flies the outer loops on those set points.
    let (d, _) = c.demand(0, 0.02, &e, &mut n, &MissionStore::default(), &DESIGNED);
    match d {
        Demand::Commands(cmd) => {
            assert_eq!(cmd.roll, RollMode::Course(e.course));
            assert_eq!(
                cmd.lon,
                LonMode::Altitude {
                    altitude: 360.0,
                    airspeed: sp.airspeed
                }
            );
        }
        Demand::Surfaces(_) => panic!("Hold flies the loops"),
    }
}

#[test]
fn an_altitude_above_home_needs_a_home() {
    let mut c = Commander::new();
    let mut n = Navigator::default();
    let mut e = flying();
    let up = VehicleRequests {
        altitude: Some(AltitudeSetpoint {
            alt_m: 80.0,
            relative_to_home: true,
        }),
        ..Default::default()
    };
    c.apply(&up, &e, &mut n);
    assert_eq!(c.setpoints().alt_amsl_m, 380.0);
    e.home = None;
    c.apply(&up, &e, &mut n);
    assert_eq!(texts(&mut c), ["Altitude above home refused: no home yet"]);
}

#[test]
fn manual_passes_the_sticks_and_falls_back_to_the_thesis_trim_without_them() {
    let mut c = Commander::new();
    let mut n = Navigator::default();
    let e = flying();
    // In the air (on the ground the motor idles without sticks).
    detect(&mut c, &e, 0.1);
    let (d, _) = c.demand(
        1_000_000,
        0.02,
        &e,
        &mut n,
        &MissionStore::default(),
        &DESIGNED,
    );
    let trim = Surfaces {
        elevator: -0.0963,
        aileron: 0.01,
        rudder: 0.00317,
        throttle: 0.569,
    };
    assert_eq!(d, Demand::Surfaces(trim));
    // Full right roll in PX4's sense is aileron -25 deg in the UMN sense.
    c.on_sticks(ManualInput {
        roll: 1.0,
        pitch: 0.0,
        yaw: 0.0,
        throttle: 0.5,
        time_us: 1_000_000,
    });
    let (d, _) = c.demand(
        1_100_000,
        0.02,
        &e,
        &mut n,
        &MissionStore::default(),
        &DESIGNED,
    );
    let Demand::Surfaces(s) = d else {
        panic!("Manual sets the surfaces")
    };
    assert!((s.aileron + 25f32.to_radians()).abs() < 1e-6, "{s:?}");
    assert_eq!(s.throttle, 0.5);
    // Sticks older than the timeout no longer count.
    let later = 1_000_000 + STICK_TIMEOUT_US + 1;
    let (d, _) = c.demand(later, 0.02, &e, &mut n, &MissionStore::default(), &DESIGNED);
    assert_eq!(d, Demand::Surfaces(trim));
}

#[test]
fn losing_the_ground_station_in_flight_returns_until_the_pilot_chooses_a_mode() {
    let mut c = Commander::new();
    let mut n = Navigator::default();
    let e = flying();
    c.apply(&arm(), &e, &mut n);
    c.apply(&mode(FlightMode::Hold), &e, &mut n);
    // The land detector has seen the flight.
    detect(&mut c, &e, 0.1);
    texts(&mut c);
    let watch = Watch::default();
    let plan = MissionStore::default();
    // Heard at 0 s; FS_GCS_TOUT_S is 5 s by default.
    c.check_failsafes(4_900_000, &e, &watch, &plan, (Some(0), None), &mut n);
    assert_eq!(c.flown_mode(), FlightMode::Hold);
    c.check_failsafes(5_100_000, &e, &watch, &plan, (Some(0), None), &mut n);
    assert_eq!(c.reaction(), Reaction::Return);
    assert_eq!(c.flown_mode(), FlightMode::Return);
    assert_eq!(c.chosen_mode(), FlightMode::Hold);
    assert!(!texts(&mut c).is_empty(), "the failsafe is reported");
    // Choosing a mode, even the same one, takes over from the return.
    c.apply(&mode(FlightMode::Hold), &e, &mut n);
    c.check_failsafes(
        5_200_000,
        &e,
        &watch,
        &plan,
        (Some(5_150_000), None),
        &mut n,
    );
    assert_eq!(c.flown_mode(), FlightMode::Hold);
}

#[test]
fn a_navigation_mode_without_home_holds_altitude_wings_level() {
    let mut c = Commander::new();
    let mut n = Navigator::default();
    let mut e = flying();
    e.home = None;
    c.apply(&mode(FlightMode::Loiter), &e, &mut n);
    let (d, _) = c.demand(0, 0.02, &e, &mut n, &MissionStore::default(), &DESIGNED);
    let Demand::Commands(cmd) = d else {
        panic!("Loiter flies the loops")
    };
    assert_eq!(cmd.roll, RollMode::Roll(0.0));
}

#[test]
fn the_vehicle_runs_its_control_tick_every_20_ms_of_sensor_time() {
    let mut v = Vehicle::new();
    let imu = crate::sensors::ImuSample {
        accel: Vector3::new(0.0, 0.0, -crate::math::GRAVITY),
        gyro: Vector3::zeros(),
    };
    let g = FromGround::default();
    // 100 Hz frames: the Manual trim, motor idle on the ground, is applied at the first
    // frame and held.
    for k in 0..10u64 {
        let f = SensorFrame {
            time_us: k * 10_000,
            imu: Some(imu),
            ..Default::default()
        };
        v.on_sensors(&f, &g);
    }
    let idle = Surfaces {
        throttle: 0.0,
        ..trim_surfaces(&DESIGNED)
    };
    assert_eq!(v.surfaces(), idle);
    assert_eq!(v.time_us(), Some(90_000));
    // A frame from the past is counted, and the clock does not go back.
    let old = SensorFrame {
        time_us: 50_000,
        imu: Some(imu),
        ..Default::default()
    };
    v.on_sensors(&old, &g);
    assert_eq!(v.stale_frames(), 1);
    assert_eq!(v.time_us(), Some(90_000));
}

#[test]
fn a_gain_set_chosen_by_parameter_is_flown_and_read_back() {
    let mut v = Vehicle::new();
    v.params_mut().set("SYS_GAIN_SET", 4.0).unwrap();
    let f = SensorFrame::default();
    v.on_sensors(&f, &FromGround::default());
    // The Minnesota set's roll gain (Table 3.10) is now in the store.
    assert_eq!(v.params().get("RLL_KP"), Some(-0.52));
}

/// Steps the land detector (default parameters, 1 g on the accelerometer) for `seconds`.
fn detect(c: &mut Commander, e: &EstimatedState, seconds: f32) {
    let p = land_detector::LandParams::default();
    for _ in 0..(seconds / 0.02).round() as usize {
        c.detect_landing(&p, e, Some(9.81), 0.02);
    }
}

#[test]
fn standing_still_on_the_ground_the_vehicle_reports_on_ground_armed_or_not() {
    use super::snapshot::LandedState;
    let mut c = Commander::new();
    let mut n = Navigator::default();
    let e = {
        let mut e = on_ground();
        e.ground_speed = 0.0;
        e
    };
    detect(&mut c, &e, 2.0);
    assert_eq!(c.landed_state(), LandedState::OnGround);
    c.apply(&arm(), &e, &mut n);
    c.apply(&mode(FlightMode::Hold), &e, &mut n);
    detect(&mut c, &e, 2.0);
    assert_eq!(c.landed_state(), LandedState::OnGround);
    assert!(!c.flying());
}

#[test]
fn a_take_off_reports_takeoff_from_the_roll_to_its_altitude_then_in_air() {
    use super::snapshot::LandedState;
    let mut c = Commander::new();
    let mut n = Navigator::default();
    let mut e = on_ground();
    e.ground_speed = 0.0;
    c.apply(&arm(), &e, &mut n);
    c.apply(&mode(FlightMode::Takeoff), &e, &mut n);
    let plan = MissionStore::default();
    let tick = |c: &mut Commander, n: &mut Navigator, e: &EstimatedState| {
        c.detect_landing(&land_detector::LandParams::default(), e, Some(9.81), 0.02);
        c.demand(0, 0.02, e, n, &plan, &DESIGNED);
    };
    tick(&mut c, &mut n, &e);
    assert_eq!(
        c.navigation().phase,
        crate::navigation::navigator::io::Phase::TakeoffRoll
    );
    assert_eq!(c.landed_state(), LandedState::Takeoff);
    // Rolling at 10 m/s: still the take-off, failsafes watching once it moves like flight.
    e.ground_speed = 10.0;
    e.airspeed = 10.0;
    e.vel_ned = Vector3::new(0.0, 10.0, 0.0);
    for _ in 0..50 {
        tick(&mut c, &mut n, &e);
    }
    assert_eq!(c.landed_state(), LandedState::Takeoff);
    // Airborne at 3 m, climbing: the take-off until its altitude.
    e.airspeed = 16.0;
    e.ground_speed = 16.0;
    e.vel_ned = Vector3::new(0.0, 16.0, -2.0);
    e.pos_ned.z = -3.0;
    e.alt_amsl_m = 303.0;
    for _ in 0..50 {
        tick(&mut c, &mut n, &e);
    }
    assert_eq!(
        c.navigation().phase,
        crate::navigation::navigator::io::Phase::TakeoffClimb
    );
    assert_eq!(c.landed_state(), LandedState::Takeoff);
    assert!(c.flying(), "airborne at 3 m: the failsafes watch");
    // At the take-off altitude it circles: in the air.
    let top = n.params().rtl_alt;
    e.pos_ned.z = -top;
    e.alt_amsl_m = 300.0 + top;
    e.vel_ned.z = 0.0;
    for _ in 0..50 {
        tick(&mut c, &mut n, &e);
    }
    assert_ne!(
        c.navigation().phase,
        crate::navigation::navigator::io::Phase::TakeoffClimb
    );
    assert_eq!(c.landed_state(), LandedState::InAir);
}

#[test]
fn at_4_5_m_over_home_sinking_at_approach_speed_it_is_flying_and_the_failsafes_watch() {
    use super::snapshot::LandedState;
    let mut c = Commander::new();
    let mut n = Navigator::default();
    // 4.5 m above home, 14 m/s, sinking 1.5 m/s.
    let mut e = flying();
    e.pos_ned = Vector3::new(-30.0, 0.0, -4.5);
    e.alt_amsl_m = 304.5;
    e.airspeed = 14.0;
    e.ground_speed = 14.0;
    e.vel_ned = Vector3::new(14.0, 0.0, 1.5);
    c.apply(&arm(), &e, &mut n);
    c.apply(&mode(FlightMode::Hold), &e, &mut n);
    detect(&mut c, &e, 3.0);
    // Below 5 m over home and still flying: not on the ground.
    assert_eq!(c.landed_state(), LandedState::InAir);
    assert!(c.flying());
    // The failsafes watch below 5 m too: a silent ground link returns.
    c.check_failsafes(
        10_000_000,
        &e,
        &Watch::default(),
        &MissionStore::default(),
        (Some(0), None),
        &mut n,
    );
    assert_eq!(c.reaction(), Reaction::Return);
}

#[test]
fn an_air_start_below_home_altitude_at_cruise_speed_is_in_air() {
    use super::snapshot::LandedState;
    let mut c = Commander::new();
    let mut n = Navigator::default();
    let mut e = flying();
    // 40 m below home, cruising.
    e.alt_amsl_m = 260.0;
    e.pos_ned = Vector3::new(0.0, 0.0, 40.0);
    e.vel_ned = Vector3::new(0.0, 17.0, 0.0);
    detect(&mut c, &e, 0.02);
    assert_eq!(c.landed_state(), LandedState::InAir);
    let _ = c.apply(&arm(), &e, &mut n);
    detect(&mut c, &e, 2.0);
    assert_eq!(c.landed_state(), LandedState::InAir);
    assert!(c.flying());
}

/// Armed on the ground with no pilot on the sticks, neither Manual's pass-through nor the
/// attitude and altitude holds run the motor at its trim (57 %) the moment the vehicle is
/// armed: it idles, surfaces at trim, until a take-off; in the air the same modes fly.
#[test]
fn armed_on_the_ground_without_sticks_the_motor_idles() {
    let mut e = on_ground();
    e.ground_speed = 0.0;
    for m in [
        FlightMode::Manual,
        FlightMode::Stabilized,
        FlightMode::Altitude,
        FlightMode::Hold,
    ] {
        let mut c = Commander::new();
        let mut n = Navigator::default();
        detect(&mut c, &e, 2.0);
        c.apply(&arm(), &e, &mut n);
        c.apply(&mode(m), &e, &mut n);
        detect(&mut c, &e, 0.1);
        let (d, _) = c.demand(0, 0.02, &e, &mut n, &MissionStore::default(), &DESIGNED);
        match d {
            Demand::Surfaces(s) => {
                assert_eq!(s.throttle, 0.0, "{m:?}");
                assert_eq!(s.elevator, DESIGNED.longitudinal.trim_elevator, "{m:?}");
            }
            Demand::Commands(c) => panic!("{m:?} on the ground flies {c:?}"),
        }
    }
    let mut c = Commander::new();
    let mut n = Navigator::default();
    c.apply(&arm(), &flying(), &mut n);
    c.apply(&mode(FlightMode::Stabilized), &flying(), &mut n);
    detect(&mut c, &flying(), 0.1);
    let (d, _) = c.demand(
        0,
        0.02,
        &flying(),
        &mut n,
        &MissionStore::default(),
        &DESIGNED,
    );
    assert!(matches!(d, Demand::Commands(_)), "in the air: {d:?}");
}

/// Each row of the table of mode facts names its own mode back: through its PX4 pair, through
/// the whole `custom_mode` word, and through its standard mode where the standard names it;
/// a non-standard mode is not reached by the standard's NON_STANDARD.
#[test]
fn every_mode_round_trips_through_its_px4_numbers_and_its_standard_mode() {
    use super::modes::MODES;
    use mavlink::dialects::common::{MavModeProperty, MavStandardMode};
    assert_eq!(MODES.len(), FlightMode::ALL.len());
    for (f, m) in MODES.iter().zip(FlightMode::ALL) {
        assert_eq!(f.mode, m);
        assert_eq!(m.facts().name, m.name());
        let (main, sub) = f.px4;
        assert_eq!(FlightMode::from_px4(main, sub), Some(m));
        assert_eq!(FlightMode::from_custom_mode(m.custom_mode()), Some(m));
        if f.standard == MavStandardMode::MAV_STANDARD_MODE_NON_STANDARD {
            assert_eq!(FlightMode::from_standard(f.standard), None);
        } else {
            assert_eq!(FlightMode::from_standard(f.standard), Some(m));
        }
        // The AUTO_MODE property and the heartbeat's AUTO flag are the navigator's modes.
        assert_eq!(
            f.properties
                .contains(MavModeProperty::MAV_MODE_PROPERTY_AUTO_MODE),
            m.needs_navigator()
        );
    }
}

// ------------------------------------------------ failsafes near the ground
//
// What PX4 and ArduPlane users expect: a failsafe on the take-off roll gives the take-off up
// (throttle closed, wings level; the plant has no brakes), one past the rotation climbs on
// wings level to the take-off's clearance height (`NAV_TKO_CLR_M`) before the reaction turns
// the aircraft, and one in the flare or roll-out lets the landing finish.

/// One control tick of the commander with the default settings; the ground station last
/// heard at 0 s (`FS_GCS_TOUT_S` is 5 s).
fn tick_at(
    c: &mut Commander,
    n: &mut Navigator,
    e: &EstimatedState,
    plan: &MissionStore,
    now_us: u64,
) -> CommanderOutput {
    c.step(CommanderInputs {
        now_us,
        dt: 0.02,
        estimate: e,
        navigator: n,
        plan,
        gains: &DESIGNED,
        watch: &Watch::default(),
        land: &land_detector::LandParams::default(),
        specific_force: Some(9.81),
        gcs_heard_us: Some(0),
        battery: None,
        oracle: None,
    })
}

/// On the runway at home heading east at `speed` m/s (air and ground), wheels down.
fn rolling(speed: f32) -> EstimatedState {
    let mut e = on_ground();
    e.euler.psi = core::f32::consts::FRAC_PI_2;
    e.airspeed = speed;
    e.ground_speed = speed;
    e.vel_ned = Vector3::new(0.0, speed, 0.0);
    e
}

/// Armed in Takeoff on the runway, rolled for a second at `speed` m/s with the ground station
/// heard: the take-off roll (or, past `NAV_TKO_VR`, its climb).
fn on_the_take_off(speed: f32) -> (Commander, Navigator, EstimatedState) {
    let mut c = Commander::new();
    let mut n = Navigator::default();
    let e = rolling(0.0);
    c.apply(&arm(), &e, &mut n);
    c.apply(&mode(FlightMode::Takeoff), &e, &mut n);
    let e = rolling(speed);
    for k in 0..50 {
        tick_at(&mut c, &mut n, &e, &MissionStore::default(), k * 20_000);
    }
    texts(&mut c);
    (c, n, e)
}

fn commands(o: &CommanderOutput) -> crate::control::autopilot::Commands {
    match o.demand {
        Demand::Commands(c) => c,
        Demand::Surfaces(s) => panic!("surfaces {s:?}"),
    }
}

#[test]
fn a_ground_link_loss_on_the_take_off_roll_aborts_the_take_off_instead_of_returning() {
    use super::snapshot::LandedState;
    use crate::navigation::navigator::io::Phase;
    let plan = MissionStore::default();
    // 10 m/s on the runway: the land detector has seen a flight, the rotation is at 13 m/s.
    let (mut c, mut n, e) = on_the_take_off(10.0);
    assert_eq!(c.navigation().phase, Phase::TakeoffRoll);
    assert!(c.flying());
    // Silent for more than FS_GCS_TOUT_S.
    let o = tick_at(&mut c, &mut n, &e, &plan, 5_100_000);
    assert_eq!(
        texts(&mut c),
        [crate::failsafe::Event::GcsLost.text(), TEXT_ABORTED]
    );
    assert_eq!(
        c.flown_mode(),
        FlightMode::Takeoff,
        "no return from the runway"
    );
    assert_eq!(c.navigation().phase, Phase::TakeoffAbort);
    let cmd = commands(&o);
    assert_eq!(cmd.roll, RollMode::Roll(0.0), "wings level");
    assert!(
        matches!(cmd.lon, LonMode::Pitch { throttle, .. } if throttle == 0.0),
        "throttle closed: {:?}",
        cmd.lon
    );
    assert_eq!(c.landed_state(), LandedState::Landing);
    // Rolling out: still no return, still closed.
    for k in 0..100 {
        let o = tick_at(&mut c, &mut n, &rolling(6.0), &plan, 5_120_000 + k * 20_000);
        assert_eq!(c.flown_mode(), FlightMode::Takeoff);
        assert!(matches!(commands(&o).lon, LonMode::Pitch { throttle, .. } if throttle == 0.0));
    }
    assert!(c.armed());
    // Slower than 3 m/s: disarmed, and on the ground once at rest.
    tick_at(&mut c, &mut n, &rolling(2.0), &plan, 8_000_000);
    assert!(!c.armed());
    assert_eq!(texts(&mut c), [TEXT_ABORT_DISARMED]);
    for k in 0..100 {
        tick_at(&mut c, &mut n, &rolling(0.0), &plan, 8_020_000 + k * 20_000);
    }
    assert_eq!(c.landed_state(), LandedState::OnGround);
    assert_eq!(c.flown_mode(), FlightMode::Takeoff);
}

/// Whatever raised it, a failsafe that changes the mode flown gives the take-off roll up: the
/// ground link silent, GPS lost, the battery critical or at its emergency level; one that
/// changes nothing (the airspeed sensor failed, the battery low: a warning) does not. At 3 m/s
/// the land detector still reads the aircraft as on the ground, but the roll is watched from
/// its first metre.
#[test]
fn every_failsafe_that_changes_the_mode_aborts_the_take_off_roll_and_no_other_does() {
    use crate::battery::Warning;
    use crate::navigation::navigator::io::Phase;
    type Fault = fn(&mut EstimatedState) -> (Option<u64>, Option<Warning>);
    let faults: [(&str, Fault, bool); 6] = [
        ("link", |_| (Some(0), None), true),
        (
            "gps",
            |e| {
                e.health.gps.healthy = false;
                (None, None)
            },
            true,
        ),
        (
            "battery critical",
            |_| (None, Some(Warning::Critical)),
            true,
        ),
        (
            "battery emergency",
            |_| (None, Some(Warning::Emergency)),
            true,
        ),
        (
            "airspeed",
            |e| {
                e.health.pitot.healthy = false;
                (None, None)
            },
            false,
        ),
        ("battery low", |_| (None, Some(Warning::Low)), false),
    ];
    for (what, fault, aborts) in faults {
        let (mut c, mut n, mut e) = on_the_take_off(3.0);
        assert!(!c.flying(), "the land detector has seen no flight yet");
        let (heard, battery) = fault(&mut e);
        let o = c.step(CommanderInputs {
            now_us: 5_100_000,
            dt: 0.02,
            estimate: &e,
            navigator: &mut n,
            plan: &MissionStore::default(),
            gains: &DESIGNED,
            watch: &Watch::default(),
            land: &land_detector::LandParams::default(),
            specific_force: Some(9.81),
            gcs_heard_us: heard,
            battery,
            oracle: None,
        });
        let said = texts(&mut c);
        let throttle = match commands(&o).lon {
            LonMode::Pitch { throttle, .. } => throttle,
            other => panic!("{what}: {other:?}"),
        };
        assert_eq!(c.flown_mode(), FlightMode::Takeoff, "{what}");
        if aborts {
            assert!(said.contains(&TEXT_ABORTED), "{what}: {said:?}");
            assert_eq!(c.navigation().phase, Phase::TakeoffAbort, "{what}");
            assert_eq!(throttle, 0.0, "{what}");
        } else {
            assert!(!said.contains(&TEXT_ABORTED), "{what}: {said:?}");
            assert_eq!(c.navigation().phase, Phase::TakeoffRoll, "{what}");
            assert!(throttle > 0.5, "{what}: the roll goes on at {throttle}");
        }
    }
}

#[test]
fn a_ground_link_loss_just_after_rotation_climbs_wings_level_to_nav_tko_clr_m_then_returns() {
    use crate::navigation::navigator::io::{GroundStage, Phase};
    let plan = MissionStore::default();
    // Rotated at 15 m/s, the wheels just off.
    let (mut c, mut n, mut e) = on_the_take_off(15.0);
    assert_eq!(c.navigation().phase, Phase::TakeoffClimb);
    let clear = n.params().takeoff_clear;
    let mut t = 5_100_000;
    for h in [0.2, 3.0, 6.0, clear - 0.5] {
        e.pos_ned.z = -h;
        e.alt_amsl_m = 300.0 + h;
        e.vel_ned.z = -2.0;
        let o = tick_at(&mut c, &mut n, &e, &plan, t);
        t += 20_000;
        assert_eq!(c.flown_mode(), FlightMode::Takeoff, "at {h} m");
        assert_eq!(c.held_at(), Some(GroundStage::ClimbOut));
        let cmd = commands(&o);
        assert_eq!(cmd.roll, RollMode::Roll(0.0), "wings level at {h} m");
        assert!(
            matches!(cmd.lon, LonMode::TakeOff { .. }),
            "still the take-off's climb at {h} m: {:?}",
            cmd.lon
        );
    }
    assert_eq!(
        texts(&mut c),
        [crate::failsafe::Event::GcsLost.text(), TEXT_CLIMB_FIRST]
    );
    // At the clearance height the return takes over and turns for home.
    e.pos_ned.z = -(clear + 0.5);
    e.alt_amsl_m = 300.0 + clear + 0.5;
    tick_at(&mut c, &mut n, &e, &plan, t);
    let o = tick_at(&mut c, &mut n, &e, &plan, t + 20_000);
    assert_eq!(c.held_at(), None);
    assert_eq!(c.flown_mode(), FlightMode::Return);
    assert_eq!(c.navigation().phase, Phase::Return);
    assert!(matches!(commands(&o).roll, RollMode::Course(_)));
}

/// A landing item at home, for the flare tests.
fn land_at_home() -> MissionStore {
    let h = flying().home.expect("home");
    let mut plan = MissionStore::default();
    let land = crate::navigation::plan::MissionItem {
        params: [0; 4],
        x: h.point.lat_e7,
        y: h.point.lon_e7,
        z: 0f32.to_bits(),
        command: crate::navigation::items::NAV_LAND,
        frame: 6,
        autocontinue: true,
    };
    plan.replace(crate::navigation::plan::PlanKind::Mission, &[land])
        .expect("room");
    plan
}

/// `h` m up, `short_m` m short of home on a northbound final at 13 m/s, sinking 0.5 m/s.
fn on_final(h: f32, short_m: f32) -> EstimatedState {
    let mut e = flying();
    e.pos_ned = Vector3::new(-short_m, 0.0, -h);
    e.alt_amsl_m = 300.0 + h;
    e.airspeed = 13.0;
    e.ground_speed = 13.0;
    e.course = 0.0;
    e.vel_ned = Vector3::new(13.0, 0.0, 0.5);
    e
}

/// Armed in Mission on the final of [`on_final`] at `h` m, `short_m` m out, its landing item at
/// home flown for one tick; then the ground link silent for more than `FS_GCS_TOUT_S`. Returns
/// the commander and the phase before the loss.
fn loss_on_final(h: f32, short_m: f32) -> (Commander, crate::navigation::navigator::io::Phase) {
    let plan = land_at_home();
    let mut c = Commander::new();
    let mut n = Navigator::default();
    let e = on_final(h, short_m);
    c.apply(&arm(), &e, &mut n);
    c.apply(&mode(FlightMode::Mission), &e, &mut n);
    tick_at(&mut c, &mut n, &e, &plan, 0);
    let before = c.navigation().phase;
    texts(&mut c);
    tick_at(&mut c, &mut n, &e, &plan, 5_100_000);
    (c, before)
}

#[test]
fn a_ground_link_loss_in_the_flare_lets_the_landing_finish_and_one_on_the_approach_returns() {
    use crate::navigation::navigator::io::Phase;
    let (mut c, before) = loss_on_final(1.0, 40.0);
    assert_eq!(before, Phase::Flare);
    assert_eq!(c.flown_mode(), FlightMode::Mission);
    assert_eq!(c.navigation().phase, Phase::Flare);
    assert_eq!(
        texts(&mut c),
        [crate::failsafe::Event::GcsLost.text(), TEXT_LANDING_FIRST]
    );
    // The same loss higher on the approach (300 m out, under its slope) returns.
    let (c, before) = loss_on_final(20.0, 300.0);
    assert_eq!(before, Phase::Approach);
    assert_eq!(c.flown_mode(), FlightMode::Return);
}

#[test]
fn every_text_of_the_failsafes_near_the_ground_fits_one_statustext() {
    for t in [
        TEXT_ABORTED,
        TEXT_CLIMB_FIRST,
        TEXT_LANDING_FIRST,
        TEXT_ABORT_DISARMED,
    ] {
        assert!(t.len() <= crate::gcs::STATUSTEXT_LEN, "{t}");
    }
}
