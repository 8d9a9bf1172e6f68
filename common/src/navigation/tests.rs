//! Mission flights of the navigator against the kinematic aircraft of [`super::sim`].

extern crate std;

use super::items::*;
use super::navigator::io::{GroundStage, HeightOracle};
use super::navigator::params::PARAMS as EXEC_PARAMS;
use super::path_manager::PARAMS as PATH_PARAMS;
use super::plan::MissionItem;
use super::sim::Kinematic;
use super::*;
use crate::control::autopilot::Commands;
use crate::control::lateral::RollMode;
use crate::control::longitudinal::LonMode;
use crate::estimator::Home;
use crate::guidance::Guidance;
use crate::guidance::PARAMS as GUIDANCE_PARAMS;
use crate::math::geodetic::{ned_offset, offset_point, GeoPoint};
use crate::math::wrap_pi;
use nalgebra::Vector3;
use std::vec::Vec;

const REL_ALT_INT: u8 = 6;
const DT: f32 = 0.05;

/// The home of the navigation tests.
pub(crate) fn home() -> Home {
    Home {
        point: GeoPoint::from_deg(44.7258357, -93.07501316),
        alt_amsl_m: 250.0,
    }
}

/// An item `n`, `e` m from [`home`], `h` m above it.
pub(crate) fn item(command: u16, params: [f32; 4], n: f32, e: f32, h: f32) -> MissionItem {
    let p = offset_point(home().point, n, e);
    MissionItem {
        params: params.map(f32::to_bits),
        x: p.lat_e7,
        y: p.lon_e7,
        z: h.to_bits(),
        command,
        frame: REL_ALT_INT,
        autocontinue: true,
    }
}

fn wp(n: f32, e: f32, h: f32) -> MissionItem {
    item(NAV_WAYPOINT, [0.0; 4], n, e, h)
}

fn do_item(command: u16, params: [f32; 4]) -> MissionItem {
    MissionItem {
        params: params.map(f32::to_bits),
        command,
        frame: 2, // MAV_FRAME_MISSION
        autocontinue: true,
        ..MissionItem::default()
    }
}

/// The kinematic aircraft driven by the autopilot commands, standing in for the closed loops:
/// course and altitude lags as in `sim`, airspeed lag 2 s, a runway at height 0.
struct Plane {
    k: Kinematic,
    climb: f32,
}

impl Plane {
    fn flying(n: f32, e: f32, h: f32, heading: f32) -> Self {
        Self {
            k: Kinematic::new(Vector3::new(n, e, -h), heading, 17.0),
            climb: 0.0,
        }
    }

    fn state(&self) -> NavState {
        let v = self.k.ground_velocity();
        NavState {
            pos_ned: self.k.pos,
            vel_ned: Vector3::new(v.x, v.y, -self.climb),
            heading: self.k.heading,
            roll: 0.0,
            airspeed: self.k.airspeed,
            yaw_rate: 0.0,
            wind_speed: self.k.wind.xy().norm(),
            range_hagl: None,
            oracle: None,
        }
    }

    fn height(&self) -> f32 {
        -self.k.pos.z
    }

    fn apply(&mut self, c: &Commands, dt: f32) {
        let h = self.height();
        let max_rate = crate::math::GRAVITY / self.k.airspeed.max(5.0);
        match c.roll {
            RollMode::Course(chi) | RollMode::CourseWithin { course: chi, .. } if h > 0.5 => {
                let rate =
                    (wrap_pi(chi - self.k.course()) / self.k.tau_course).clamp(-max_rate, max_rate);
                self.k.heading = wrap_pi(self.k.heading + rate * dt);
            }
            _ => {}
        }
        let va = self.k.airspeed;
        // The commands' altitudes are above mean sea level; the model flies heights above home.
        let (climb, aspd_cmd) = match c.lon.shifted(-home().alt_amsl_m) {
            LonMode::Altitude { altitude, airspeed } => (
                ((altitude - h) / self.k.tau_alt).clamp(-self.k.max_vz, self.k.max_vz),
                airspeed,
            ),
            // The feed-forward of the command's rate takes the first-order lag off the ramp.
            LonMode::Glide {
                altitude,
                airspeed,
                climb_rate,
            } => (
                (climb_rate + (altitude - h) / self.k.tau_alt).clamp(-self.k.max_vz, self.k.max_vz),
                airspeed,
            ),
            LonMode::TakeOff {
                altitude,
                airspeed,
                clear_altitude,
            } => {
                if h < clear_altitude {
                    (va * libm::sinf(10f32.to_radians()), airspeed)
                } else {
                    (
                        ((altitude - h) / self.k.tau_alt).clamp(-self.k.max_vz, self.k.max_vz),
                        airspeed,
                    )
                }
            }
            LonMode::Pitch { pitch, throttle } => {
                if throttle > 0.5 {
                    // Full throttle on the runway: 3 m/s^2.
                    (0.0, va + 3.0)
                } else {
                    // Gliding with the engine idle: 1.8 m/s of sink at zero pitch; the flight
                    // path follows the pitch with a 0.5 s lag.
                    let target = va * libm::sinf(pitch) - 1.8;
                    (
                        self.climb + (target - self.climb) * dt / 0.5,
                        (va - 0.3).max(0.0),
                    )
                }
            }
            _ => (0.0, va),
        };
        self.k.airspeed += (aspd_cmd - va).clamp(-0.3, 3.0) * dt;
        // On the runway: no sinking through it.
        self.climb = if h <= 0.0 && climb < 0.0 { 0.0 } else { climb };
        self.k.move_by(self.climb, dt);
        if self.k.pos.z > 0.0 {
            self.k.pos.z = 0.0;
        }
    }
}

#[derive(Default)]
struct Log {
    reached: Vec<u16>,
    warnings: Vec<NavWarning>,
    outs: Vec<(f32, NavOutput, Vector3<f32>)>,
}

fn fly(
    nav: &mut Navigator,
    plane: &mut Plane,
    items: &[MissionItem],
    seconds: f32,
    mut stop: impl FnMut(&NavOutput) -> bool,
) -> Log {
    let mut log = Log::default();
    let mut t = 0.0;
    while t < seconds {
        let out = nav.step(items, &home(), &plane.state(), DT);
        if let Some(r) = out.reached {
            log.reached.push(r);
        }
        log.warnings.extend(out.warnings.iter().copied());
        if let Some(c) = out.commands {
            plane.apply(&c, DT);
        }
        let done = stop(&out);
        log.outs.push((t, out, plane.k.pos));
        if done {
            break;
        }
        t += DT;
    }
    log
}

#[test]
fn navigation_parameters_are_well_formed_and_default_to_their_declarations() {
    use crate::params::{ParamStore, Registry};
    const NAV: Registry = &[
        &GUIDANCE_PARAMS,
        &PATH_PARAMS,
        &EXEC_PARAMS,
        &super::validate::PARAMS,
        &super::fence::PARAMS,
    ];
    assert_eq!(ParamStore::validate(NAV), Ok(()));
    let store = ParamStore::new(NAV);
    let p = store.load(&EXEC_PARAMS);
    assert_eq!(p, NavParams::default());
    for d in EXEC_PARAMS.defs() {
        let v = EXEC_PARAMS.get(&p, d.name).unwrap();
        assert!((v - d.default).abs() < 1e-5, "{}", d.name);
    }
    let mut q = p;
    assert_eq!(
        EXEC_PARAMS.set(&mut q, "NAV_ACC_RAD", 1e6),
        Err(crate::params::ParamError::OutOfBounds)
    );
    assert_eq!(
        EXEC_PARAMS.set(&mut q, "NO_SUCH", 1.0),
        Err(crate::params::ParamError::Unknown)
    );
}

#[test]
fn item_altitude_frames() {
    let h = home();
    let mut it = wp(100.0, -50.0, 80.0);
    let t = target_ned(&it, &h, &Vector3::zeros());
    assert!((t.x - 100.0).abs() < 0.05 && (t.y + 50.0).abs() < 0.05);
    assert_eq!(t.z, -80.0);
    // Absolute frame (GLOBAL_INT): 350 m AMSL is 100 m above a home at 250 m.
    it.frame = 5;
    it.z = 350f32.to_bits();
    assert_eq!(target_ned(&it, &h, &Vector3::zeros()).z, -100.0);
    // NaN altitude: keep the present one; 0/0: the present position.
    let mut here = item(NAV_LOITER_UNLIM, [0.0; 4], 0.0, 0.0, f32::NAN);
    here.x = 0;
    here.y = 0;
    let t = target_ned(&here, &h, &Vector3::new(5.0, 6.0, -70.0));
    assert_eq!(t, Vector3::new(5.0, 6.0, -70.0));
}

/// Three waypoints in a 5 m/s wind: reached in order, current item follows, then the aircraft
/// circles the last one.
#[test]
fn waypoints_reached_in_order_then_circle_the_last() {
    let items = [
        wp(400.0, 0.0, 80.0),
        wp(400.0, 400.0, 100.0),
        wp(0.0, 400.0, 100.0),
    ];
    let mut nav = navigator();
    let mut plane = Plane::flying(0.0, 0.0, 80.0, 0.0);
    plane.k.wind = Vector3::new(-3.0, 4.0, 0.0);
    nav.start_mission(0);
    let log = fly(&mut nav, &mut plane, &items, 300.0, |_| false);
    assert_eq!(log.reached, [0, 1, 2]);
    assert!(log.warnings.is_empty());
    let currents: Vec<u16> = log.outs.iter().filter_map(|o| o.1.current_seq).collect();
    assert!(currents.windows(2).all(|w| w[0] <= w[1]));
    let (_, last, pos) = log.outs.last().unwrap();
    assert_eq!(last.phase, Phase::Complete);
    let r = libm::hypotf(pos.x, pos.y - 400.0);
    assert!((r - 60.0).abs() < 5.0, "circle radius {r}");
    assert!((-pos.z - 100.0).abs() < 1.0);
}

/// The commands carry altitudes above mean sea level, the autopilot's datum: the guidance's
/// height above home plus the home's altitude; the guidance output and the target stay in the
/// navigator's frame from home.
#[test]
fn commands_are_above_mean_sea_level() {
    let items = [wp(400.0, 0.0, 80.0), wp(400.0, 400.0, 100.0)];
    let mut nav = navigator();
    let mut plane = Plane::flying(0.0, 0.0, 80.0, 0.0);
    nav.start_mission(0);
    let log = fly(&mut nav, &mut plane, &items, 120.0, |_| false);
    for (_, o, _) in &log.outs {
        let g = o.guidance.expect("guidance");
        let Some(LonMode::Altitude { altitude, .. }) = o.commands.map(|c| c.lon) else {
            panic!("a waypoint without an altitude command: {:?}", o.commands);
        };
        assert_eq!(altitude, g.altitude + home().alt_amsl_m);
    }
    let (_, last, _) = log.outs.last().unwrap();
    assert_eq!(last.target.map(|t| -t.z), Some(100.0));
}

/// DO_JUMP back to item 0 with repeat 2: the two waypoints are flown three times, then the
/// mission goes on to the last one (item 3).
#[test]
fn do_jump_repeats_exactly_n_times() {
    let items = [
        wp(300.0, 0.0, 80.0),
        wp(300.0, 300.0, 80.0),
        do_item(DO_JUMP, [0.0, 2.0, 0.0, 0.0]),
        wp(0.0, 300.0, 80.0),
    ];
    let mut nav = navigator();
    let mut plane = Plane::flying(0.0, 0.0, 80.0, 0.0);
    nav.start_mission(0);
    let log = fly(&mut nav, &mut plane, &items, 600.0, |o| {
        o.phase == Phase::Complete
    });
    assert_eq!(log.reached, [0, 1, 0, 1, 0, 1, 3]);
    // Starting again resets the count.
    nav.start_mission(0);
    let log = fly(&mut nav, &mut plane, &items, 600.0, |o| {
        o.phase == Phase::Complete
    });
    assert_eq!(log.reached, [0, 1, 0, 1, 0, 1, 3]);
}

#[test]
fn unknown_and_unsupported_items_are_skipped_with_a_warning() {
    let servo = MissionItem {
        command: 183, // MAV_CMD_DO_SET_SERVO: not executed here
        ..do_item(0, [1.0, 1500.0, 0.0, 0.0])
    };
    let items = [
        wp(300.0, 0.0, 80.0),
        servo,
        do_item(9999, [0.0; 4]),
        do_item(DO_CHANGE_SPEED, [2.0, 3.0, -1.0, 0.0]),
        wp(300.0, 300.0, 80.0),
    ];
    let mut nav = navigator();
    let mut plane = Plane::flying(0.0, 0.0, 80.0, 0.0);
    nav.start_mission(0);
    let log = fly(&mut nav, &mut plane, &items, 300.0, |o| {
        o.phase == Phase::Complete
    });
    assert_eq!(log.reached, [0, 4]);
    assert_eq!(
        log.warnings,
        [
            NavWarning::UnknownCommand {
                seq: 1,
                command: 183
            },
            NavWarning::UnknownCommand {
                seq: 2,
                command: 9999
            },
            NavWarning::UnsupportedSpeed { seq: 3 },
        ]
    );
}

#[test]
fn jump_loop_without_a_navigation_item_ends_the_mission() {
    let items = [
        do_item(DO_JUMP, [1.0, -1.0, 0.0, 0.0]),
        do_item(DO_JUMP, [0.0, -1.0, 0.0, 0.0]),
    ];
    let mut nav = navigator();
    nav.start_mission(0);
    let plane = Plane::flying(0.0, 0.0, 80.0, 0.0);
    let out = nav.step(&items, &home(), &plane.state(), DT);
    assert!(matches!(out.warnings[..], [NavWarning::JumpLoop { .. }]));
    assert_eq!(out.phase, Phase::Complete);
    // A jump to an item that does not exist is skipped.
    let items = [do_item(DO_JUMP, [7.0, 1.0, 0.0, 0.0]), wp(100.0, 0.0, 80.0)];
    nav.start_mission(0);
    let out = nav.step(&items, &home(), &plane.state(), DT);
    assert_eq!(out.warnings[..], [NavWarning::BadJump { seq: 0 }]);
    assert_eq!(out.current_seq, Some(1));
    // Nothing to fly.
    nav.start_mission(0);
    let out = nav.step(&[], &home(), &plane.state(), DT);
    assert_eq!(out.warnings[..], [NavWarning::NoMission]);
}

#[test]
fn change_speed_and_set_home() {
    let items = [
        do_item(DO_CHANGE_SPEED, [0.0, 21.0, -1.0, 0.0]),
        do_item(DO_SET_HOME, [1.0, 0.0, 0.0, 0.0]),
        wp(300.0, 0.0, 80.0),
        do_item(DO_CHANGE_SPEED, [0.0, 99.0, -1.0, 0.0]),
        wp(300.0, 300.0, 80.0),
    ];
    let mut nav = navigator();
    let mut plane = Plane::flying(0.0, 0.0, 80.0, 0.0);
    nav.start_mission(0);
    let out = nav.step(&items, &home(), &plane.state(), DT);
    assert_eq!(out.set_home, Some(HomeRequest::Here));
    assert_eq!(out.current_seq, Some(2));
    assert_eq!(out.guidance.unwrap().airspeed, 21.0);
    // 99 m/s is clamped to NAV_ASPD_MAX.
    let log = fly(&mut nav, &mut plane, &items, 100.0, |o| {
        o.current_seq == Some(4)
    });
    let last = &log.outs.last().unwrap().1;
    nav.step(&items, &home(), &plane.state(), DT);
    let o = nav.step(&items, &home(), &plane.state(), DT);
    assert_eq!(last.current_seq, Some(4));
    assert_eq!(o.guidance.unwrap().airspeed, nav.params().airspeed_max);
    // Crossed limits (a minimum above the maximum) are no reason to panic: the maximum wins.
    let mut nav = navigator();
    let mut p = *nav.params();
    p.airspeed_min = 30.0;
    p.airspeed_max = 20.0;
    nav.set_params(&p);
    nav.start_mission(0);
    let o = nav.step(&items, &home(), &plane.state(), DT);
    assert_eq!(o.guidance.unwrap().airspeed, 20.0);
}

/// LOITER_TURNS, 2 turns counter-clockwise (radius -80): the angle swept round the centre
/// between arriving on the circle and the item's end is two turns, in the negative sense.
#[test]
fn loiter_turns_counted() {
    let items = [
        item(NAV_LOITER_TURNS, [2.0, 0.0, -80.0, 0.0], 500.0, 0.0, 80.0),
        wp(500.0, 600.0, 80.0),
    ];
    let mut nav = navigator();
    let mut plane = Plane::flying(0.0, 0.0, 80.0, 0.0);
    plane.k.wind = Vector3::new(0.0, 4.0, 0.0);
    nav.start_mission(0);
    let log = fly(&mut nav, &mut plane, &items, 400.0, |o| {
        o.reached == Some(0)
    });
    assert_eq!(log.reached, [0]);
    let c = log.outs[0].1.target.unwrap();
    // Swept angle from the first step within 8 m of the circle.
    let mut swept = 0.0;
    let mut last: Option<f32> = None;
    for (_, _, p) in &log.outs {
        let d = libm::hypotf(p.x - c.x, p.y - c.y);
        if last.is_none() && (d - 80.0).abs() > 8.0 {
            continue;
        }
        let phi = libm::atan2f(p.y - c.y, p.x - c.x);
        if let Some(l) = last {
            swept += wrap_pi(phi - l);
        }
        last = Some(phi);
    }
    let turns = swept / core::f32::consts::TAU;
    assert!((turns + 2.0).abs() < 0.05, "turns {turns}");
}

/// A loiter narrower than the turn at `NAV_TURN_BNK_DEG` (35 deg) allows at the cruise
/// airspeed is flown on that turn's circle: 30 m asked at 17 m/s becomes
/// `17^2 / (g tan 35 deg)` = 42.1 m (ArduPlane's loiter radius at its bank limit), while a
/// wider one (80 m, above) is flown as asked.
#[test]
fn a_loiter_narrower_than_the_turn_bank_allows_is_widened_to_it() {
    let items = [
        item(NAV_LOITER_TURNS, [2.0, 0.0, 30.0, 0.0], 300.0, 0.0, 80.0),
        wp(500.0, 600.0, 80.0),
    ];
    let mut nav = navigator();
    let mut plane = Plane::flying(0.0, 0.0, 80.0, 0.0);
    nav.start_mission(0);
    let log = fly(&mut nav, &mut plane, &items, 400.0, |o| {
        o.reached == Some(0)
    });
    assert_eq!(log.reached, [0]);
    let c = log.outs[0].1.target.unwrap();
    let expected = 17.0 * 17.0 / (crate::math::GRAVITY * libm::tanf(35f32.to_radians()));
    assert!((expected - 42.1).abs() < 0.1, "{expected}");
    // The second turn, well on the circle.
    let half = log.outs.len() / 2;
    let radii: Vec<f32> = log.outs[half..]
        .iter()
        .map(|(_, _, p)| libm::hypotf(p.x - c.x, p.y - c.y))
        .collect();
    let mean = radii.iter().sum::<f32>() / radii.len() as f32;
    assert!((mean - expected).abs() < 2.0, "mean radius {mean} m");
}

#[test]
fn loiter_time_and_to_altitude() {
    let items = [
        item(NAV_LOITER_TIME, [30.0, 0.0, 70.0, 0.0], 300.0, 0.0, 80.0),
        item(NAV_LOITER_TO_ALT, [0.0, 70.0, 0.0, 0.0], 300.0, 0.0, 120.0),
        item(NAV_LOITER_UNLIM, [0.0, 0.0, 0.0, 0.0], 0.0, 0.0, 120.0),
    ];
    let mut nav = navigator();
    let mut plane = Plane::flying(0.0, 0.0, 80.0, 0.0);
    nav.start_mission(0);
    let log = fly(&mut nav, &mut plane, &items, 400.0, |_| false);
    assert_eq!(log.reached, [0, 1, 2]);
    let at = |seq| {
        log.outs
            .iter()
            .find(|o| o.1.reached == Some(seq))
            .map(|o| (o.0, o.2))
            .unwrap()
    };
    let arrived = log
        .outs
        .iter()
        .find(|o| {
            let d = libm::hypotf(o.2.x - 300.0, o.2.y);
            (d - 70.0).abs() <= 15.0
        })
        .unwrap()
        .0;
    let (t0, _) = at(0);
    assert!(
        (t0 - arrived - 30.0).abs() < 0.2,
        "loiter time {}",
        t0 - arrived
    );
    let (_, p1) = at(1);
    assert!((-p1.z - 120.0).abs() <= 5.0);
    // Unlimited: reached on arrival, never left.
    let (_, last, _) = log.outs.last().unwrap();
    assert_eq!((last.current_seq, last.phase), (Some(2), Phase::Loiter));
}

/// A runway take-off heading east (param4 = 90 deg), no wind: rolls wings level at pitch 0
/// below the rotation airspeed, the throttle opened from idle to full in `NAV_TKO_RAMP_S` (2 s:
/// 0.5 after one second of the roll), then the take-off regime; reached at the item's altitude
/// (less NAV_ALT_ACC), on the runway's line.
#[test]
fn runway_takeoff() {
    let items = [
        {
            let mut t = item(NAV_TAKEOFF, [0.0, 0.0, 0.0, 90.0], 0.0, 0.0, 40.0);
            t.x = 0;
            t.y = 0;
            t
        },
        wp(0.0, 1500.0, 60.0),
    ];
    let mut nav = navigator();
    let mut plane = at_rest_on_the_runway_east();
    nav.start_mission(0);
    let log = fly(&mut nav, &mut plane, &items, 120.0, |o| {
        o.reached == Some(0)
    });
    assert_eq!(log.reached, [0]);
    let vr = nav.params().takeoff_vr;
    let ramp = nav.params().takeoff_ramp;
    assert_eq!(ramp, 2.0);
    let mut rolled = 0;
    for (_, o, p) in &log.outs {
        let c = o.commands.unwrap();
        if o.phase == Phase::TakeoffRoll {
            rolled += 1;
            let opened = (rolled as f32 * DT / ramp).min(1.0);
            assert_eq!(c.roll, RollMode::Roll(0.0));
            match c.lon {
                LonMode::Pitch { pitch, throttle } => {
                    assert_eq!(pitch, 0.0);
                    assert!(
                        (throttle - opened).abs() < 1e-4,
                        "throttle {throttle} after {rolled} steps, expected {opened}"
                    );
                }
                other => panic!("take-off roll without a pitch command: {other:?}"),
            }
            assert_eq!(-p.z, 0.0);
        } else {
            assert_eq!(o.phase, Phase::TakeoffClimb);
            assert!(
                matches!(c.lon, LonMode::TakeOff { altitude, clear_altitude, .. }
                if altitude == 40.0 + home().alt_amsl_m
                    && clear_altitude == 10.0 + home().alt_amsl_m)
            );
        }
        assert!(p.x.abs() < 0.5, "off the runway line by {}", p.x);
    }
    assert!(
        rolled as f32 * DT > ramp,
        "rolled {rolled} steps, shorter than the ramp"
    );
    // Rotation at VR: the first climb step comes with the airspeed at or above it.
    let first_climb = log
        .outs
        .iter()
        .position(|o| o.1.phase == Phase::TakeoffClimb)
        .unwrap();
    assert!(first_climb > 0);
    let (_, _, end) = log.outs.last().unwrap();
    assert!(-end.z >= 35.0 && -end.z < 40.0 + 1.0);
    assert!(plane.k.airspeed >= vr);
}

/// A plane at home on the runway of [`takeoff_east`], nose east, with the flying plane's
/// airspeed.
fn on_the_runway_east() -> Plane {
    Plane::flying(0.0, 0.0, 0.0, 90f32.to_radians())
}

/// [`on_the_runway_east`] standing still: no air over it.
fn at_rest_on_the_runway_east() -> Plane {
    let mut plane = on_the_runway_east();
    plane.k.airspeed = 0.0;
    plane
}

/// The runway take-off of [`runway_takeoff`]: heading east from home, to 40 m.
fn takeoff_east() -> [MissionItem; 2] {
    let mut t = item(NAV_TAKEOFF, [0.0, 0.0, 0.0, 90.0], 0.0, 0.0, 40.0);
    t.x = 0;
    t.y = 0;
    [t, wp(0.0, 1500.0, 60.0)]
}

/// One step of the navigator and of the plane it flies; the output and what the navigator
/// then says of the ground.
fn step_plane(
    nav: &mut Navigator,
    plane: &mut Plane,
    items: &[MissionItem],
) -> (NavOutput, GroundStage) {
    let out = nav.step(items, &home(), &plane.state(), DT);
    if let Some(c) = out.commands {
        plane.apply(&c, DT);
    }
    (out, nav.ground_stage())
}

/// A take-off given up on its roll (a failsafe at 8 m/s, below `NAV_TKO_VR`): from the next
/// step the throttle is closed, the wings held level and the tail wheel steers along the
/// runway's line to a stop; the navigator says the aircraft may be disarmed once it rolls
/// slower than 3 m/s (`NAV_LND_DISARM_S`'s rule), not before. For a failsafe the roll is the
/// take-off roll, and the roll-out after the abort a touchdown to be finished.
#[test]
fn a_take_off_given_up_on_its_roll_rolls_out_wings_level_with_the_throttle_closed_to_a_stop() {
    let items = takeoff_east();
    let mut nav = navigator();
    let mut plane = at_rest_on_the_runway_east();
    nav.start_mission(0);
    while plane.k.airspeed < 8.0 {
        let (out, stage) = step_plane(&mut nav, &mut plane, &items);
        assert_eq!(
            (out.phase, stage),
            (Phase::TakeoffRoll, GroundStage::TakeoffRoll)
        );
    }
    assert!(plane.k.airspeed < nav.params().takeoff_vr);
    assert!(nav.abort_takeoff(), "a take-off on its roll is given up");
    assert!(!nav.abort_takeoff(), "once");
    let mut steps = 0;
    loop {
        let speed = plane.state().ground_speed();
        let (out, stage) = step_plane(&mut nav, &mut plane, &items);
        steps += 1;
        assert_given_up(&out, stage);
        assert!(
            plane.k.pos.x.abs() < 0.5 && plane.k.pos.z == 0.0,
            "on the runway's line: {:?}",
            plane.k.pos
        );
        assert_eq!(out.landed, speed < 3.0, "at {speed} m/s");
        if out.landed {
            break;
        }
        assert!(steps < 2000, "still rolling at {speed} m/s");
    }
    assert_eq!(out_reached_none(&mut nav, &mut plane, &items), None);
}

/// A ground loop on the roll: the heading swung off the runway's line. With `NAV_TKO_HDG_DEG`
/// set to 60 deg, up to 60 deg off the roll goes on (a tail-dragger weathervaning in a gust
/// steers back); past it the take-off is given up on that step, as a failsafe would give it
/// up: the station told why, the throttle closed, the wings level, rolled out to a stop. A
/// failsafe after it finds nothing left to give up.
#[test]
fn a_take_off_roll_swung_past_nav_tko_hdg_deg_off_its_line_is_given_up_with_the_throttle_closed() {
    let items = takeoff_east();
    let mut nav = navigator();
    let mut p = *nav.params();
    EXEC_PARAMS
        .set(&mut p, "NAV_TKO_HDG_DEG", 60.0)
        .expect("in range");
    nav.set_params(&p);
    let mut plane = at_rest_on_the_runway_east();
    nav.start_mission(0);
    for _ in 0..20 {
        assert_eq!(
            step_plane(&mut nav, &mut plane, &items).0.phase,
            Phase::TakeoffRoll
        );
    }
    for off_deg in [-59.0f32, 59.0] {
        plane.k.heading = (90.0 + off_deg).to_radians();
        let (out, _) = step_plane(&mut nav, &mut plane, &items);
        assert_eq!(out.phase, Phase::TakeoffRoll, "{off_deg} deg off");
        assert!(out.warnings.is_empty());
    }
    plane.k.heading = (90.0 - 61.0f32).to_radians();
    let (out, stage) = step_plane(&mut nav, &mut plane, &items);
    assert_given_up(&out, stage);
    assert_eq!(out.warnings.as_slice(), &[NavWarning::TakeoffOffLine]);
    assert!(!nav.abort_takeoff(), "already given up");
}

/// By default (`NAV_TKO_HDG_DEG` 0) a swing off the line does not give the take-off up: in the
/// campaign's tailwinds of up to 12 m/s the tail-dragger weathervanes 60 to 120 deg in the
/// roll's first seconds and then flies (docs/NAVIGATION.md).
#[test]
fn by_default_a_take_off_roll_swung_120_deg_off_its_line_rolls_on() {
    let items = takeoff_east();
    let mut nav = navigator();
    assert_eq!(nav.params().takeoff_heading_max, 0.0);
    let mut plane = at_rest_on_the_runway_east();
    nav.start_mission(0);
    step_plane(&mut nav, &mut plane, &items);
    plane.k.heading = (90.0 + 120.0f32).to_radians();
    let (out, _) = step_plane(&mut nav, &mut plane, &items);
    assert_eq!(out.phase, Phase::TakeoffRoll);
    assert!(out.warnings.is_empty());
}

/// A roll swung more than 135 deg off its line (beyond where it began) closes the throttle
/// until the heading is back within 135 deg, then opens it again over `NAV_TKO_RAMP_S` (2 s):
/// it is not given up for it (`NAV_TKO_HDG_DEG` is off by default). Swung 120 deg, it keeps
/// full throttle.
#[test]
fn a_take_off_roll_swung_past_135_deg_closes_the_throttle_until_it_is_back_then_opens_it_again() {
    let items = takeoff_east();
    let mut nav = navigator();
    let ramp = nav.params().takeoff_ramp;
    assert_eq!(ramp, 2.0);
    let mut plane = at_rest_on_the_runway_east();
    nav.start_mission(0);
    let throttle = |out: &NavOutput| match out.commands.map(|c| c.lon) {
        Some(LonMode::Pitch { throttle, .. }) => throttle,
        other => panic!("{other:?}"),
    };
    // Three seconds on the line: full throttle.
    let mut out = step_plane(&mut nav, &mut plane, &items).0;
    for _ in 0..60 {
        out = step_plane(&mut nav, &mut plane, &items).0;
    }
    assert_eq!(throttle(&out), 1.0);
    // Swung 120 deg off: still full throttle.
    plane.k.heading = (90.0 + 120.0f32).to_radians();
    out = step_plane(&mut nav, &mut plane, &items).0;
    assert_eq!(throttle(&out), 1.0);
    // Swung 150 deg off: closed at once, still rolling.
    plane.k.heading = (90.0 + 150.0f32).to_radians();
    out = step_plane(&mut nav, &mut plane, &items).0;
    assert_eq!(out.phase, Phase::TakeoffRoll);
    assert_eq!(throttle(&out), 0.0);
    assert!(out.warnings.is_empty());
    // Back within 130 deg: opened again from closed, 50 ms of the 2 s ramp a step.
    plane.k.heading = (90.0 + 130.0f32).to_radians();
    out = step_plane(&mut nav, &mut plane, &items).0;
    assert!(
        (throttle(&out) - DT / ramp).abs() < 1e-6,
        "{}",
        throttle(&out)
    );
    for _ in 0..40 {
        out = step_plane(&mut nav, &mut plane, &items).0;
    }
    assert_eq!(throttle(&out), 1.0);
}

/// A roll that never reaches the rotation airspeed (`NAV_TKO_VR`, here held at 5 m/s: a
/// brake binding, a headwind the engine cannot beat, a wrong propeller) is given up once it
/// has lasted `NAV_TKO_ROLL_S` (20 s), not before.
#[test]
fn a_take_off_roll_short_of_its_rotation_airspeed_for_20_s_is_given_up() {
    let items = takeoff_east();
    let mut nav = navigator();
    assert_eq!(nav.params().takeoff_roll_max, 20.0);
    let mut plane = on_the_runway_east();
    nav.start_mission(0);
    let mut t = 0.0;
    let out = loop {
        plane.k.airspeed = 5.0;
        let (out, _) = step_plane(&mut nav, &mut plane, &items);
        t += DT;
        if out.phase != Phase::TakeoffRoll {
            break out;
        }
        assert!(t < 21.0, "still rolling at {t} s");
    };
    assert!((t - 20.0).abs() <= 2.0 * DT, "given up at {t} s");
    assert_eq!(out.phase, Phase::TakeoffAbort);
    assert_eq!(out.warnings.as_slice(), &[NavWarning::TakeoffTooSlow]);
}

/// A step of a take-off given up: its roll-out, a touchdown for a failsafe, wings level, the
/// throttle closed.
fn assert_given_up(out: &NavOutput, stage: GroundStage) {
    assert_eq!(
        (out.phase, stage),
        (Phase::TakeoffAbort, GroundStage::Touchdown)
    );
    let c = out.commands.expect("commands");
    assert_eq!(c.roll, RollMode::Roll(0.0), "wings level");
    assert!(
        matches!(c.lon, LonMode::Pitch { throttle, .. } if throttle == 0.0),
        "throttle closed: {:?}",
        c.lon
    );
}

/// The aborted take-off reports no item reached, however long it stands: the mission was not
/// flown.
fn out_reached_none(nav: &mut Navigator, plane: &mut Plane, items: &[MissionItem]) -> Option<u16> {
    (0..100).find_map(|_| step_plane(nav, plane, items).0.reached)
}

/// Past the rotation airspeed the take-off is committed: it cannot be given up, and a
/// failsafe waits (the climb-out) until the aircraft is `NAV_TKO_CLR_M` (10 m) above where
/// the roll began; from there on it is clear.
#[test]
fn past_the_rotation_a_take_off_goes_on_and_is_clear_for_a_failsafe_from_nav_tko_clr_m() {
    let items = takeoff_east();
    let mut nav = navigator();
    let clear = nav.params().takeoff_clear;
    assert_eq!(clear, 10.0);
    let mut plane = at_rest_on_the_runway_east();
    nav.start_mission(0);
    let mut seen = Vec::new();
    for _ in 0..2000 {
        let before = plane.height();
        let (out, stage) = step_plane(&mut nav, &mut plane, &items);
        if out.phase == Phase::TakeoffClimb {
            assert!(!nav.abort_takeoff(), "given up past the rotation");
        }
        let expected = match out.phase {
            Phase::TakeoffRoll => GroundStage::TakeoffRoll,
            Phase::TakeoffClimb if before < clear => GroundStage::ClimbOut,
            _ => GroundStage::Clear,
        };
        assert_eq!(stage, expected, "{:?} at {before} m", out.phase);
        if seen.last() != Some(&stage) {
            seen.push(stage);
        }
        if out.reached.is_some() {
            break;
        }
    }
    assert_eq!(
        seen,
        [
            GroundStage::TakeoffRoll,
            GroundStage::ClimbOut,
            GroundStage::Clear
        ]
    );
}

/// The take-off regime's climb from the runway, the take-off's and the go-around's, holds its
/// course within a bank that widens from `NAV_GND_RLL_DEG` (5 deg) on the ground to 90 deg at
/// `NAV_TKO_CLR_M` (10 m), the regime's end: 22 deg at 2 m, where `NAV_GND_RLL_M` (3 m) alone
/// allowed 61.7 deg; the Ultra Stick's wing-tip clearance is the wider limit all the way up.
#[test]
fn a_climb_from_the_runway_banks_no_more_than_the_ground_allows_up_to_nav_tko_clr_m() {
    let expected = |h: f32| (5.0 + 85.0 * (h / 10.0).clamp(0.0, 1.0)).to_radians();
    let check = |out: &NavOutput, h: f32| match out.commands.map(|c| c.roll) {
        Some(RollMode::CourseWithin { roll_max, .. }) => assert!(
            (roll_max - expected(h)).abs() < 1e-4,
            "{:?} at {h} m: {} deg",
            out.phase,
            roll_max.to_degrees()
        ),
        other => panic!("{:?} at {h} m: {other:?}", out.phase),
    };
    // The take-off: every step of its climb up to 12 m.
    let items = takeoff_east();
    let mut nav = navigator();
    assert_eq!(nav.params().takeoff_clear, 10.0);
    assert_eq!(nav.params().ground_roll_height, 3.0);
    let mut plane = at_rest_on_the_runway_east();
    nav.start_mission(0);
    let mut heights = Vec::new();
    for _ in 0..4000 {
        let h = plane.height();
        let (out, _) = step_plane(&mut nav, &mut plane, &items);
        if out.phase == Phase::TakeoffClimb {
            check(&out, h);
            heights.push(h);
        }
        if h > 12.0 {
            break;
        }
    }
    assert!(
        heights.iter().any(|h| (1.0..3.0).contains(h)) && heights.iter().any(|&h| h > 10.0),
        "climb seen at {heights:?}"
    );
    // The go-around's climb, from 2 m over the land point.
    let items = [item(NAV_LAND, [0.0; 4], 0.0, 0.0, 0.0)];
    let mut nav = navigator();
    let mut plane = land_here_until(&mut nav, &items, Phase::Approach);
    assert!(nav.go_around());
    plane.k.pos.z = -2.0;
    let out = nav.step(&items, &home(), &plane.state(), DT);
    assert_eq!(out.phase, Phase::GoAround);
    check(&out, 2.0);
    assert!((expected(2.0).to_degrees() - 22.0).abs() < 1e-4);
}

/// A return begun on the runway (a failsafe's, before any height was gained) turns for home
/// within the bank the ground allows: `NAV_GND_RLL_DEG` (5 deg) on it, 47.5 deg at 1.5 m,
/// the roll limit alone from `NAV_GND_RLL_M` (3 m) up.
#[test]
fn a_return_begun_near_the_ground_banks_no_more_than_the_ground_allows() {
    for (h, limit_deg) in [
        (0.0, Some(5.0)),
        (1.5, Some(47.5)),
        (3.0, None),
        (60.0, None),
    ] {
        let mut nav = navigator();
        // 200 m north of home, heading north: home is behind.
        let plane = Plane::flying(200.0, 0.0, h, 0.0);
        nav.start_return(false);
        let out = nav.step(&[], &home(), &plane.state(), DT);
        assert_eq!(out.phase, Phase::Return);
        match (out.commands.map(|c| c.roll), limit_deg) {
            (Some(RollMode::CourseWithin { roll_max, .. }), Some(l)) => assert!(
                (roll_max.to_degrees() - l).abs() < 1e-3,
                "at {h} m: {} deg",
                roll_max.to_degrees()
            ),
            (Some(RollMode::Course(_)), None) => {}
            (other, _) => panic!("at {h} m: {other:?}"),
        }
    }
}

/// A landing's flare and roll-out are a touchdown for a failsafe (the landing is finished);
/// its approach is not.
#[test]
fn a_landing_s_flare_and_roll_out_are_a_touchdown_for_a_failsafe_and_its_approach_is_not() {
    let items = [item(NAV_LAND, [0.0; 4], 0.0, 0.0, 0.0)];
    let mut nav = navigator();
    let mut plane = Plane::flying(300.0, 0.0, 30.0, core::f32::consts::PI);
    nav.start_mission(0);
    let mut seen = Vec::new();
    for _ in 0..8000 {
        let (out, stage) = step_plane(&mut nav, &mut plane, &items);
        let expected = match out.phase {
            Phase::Flare | Phase::Landed => GroundStage::Touchdown,
            _ => GroundStage::Clear,
        };
        assert_eq!(stage, expected, "{:?}", out.phase);
        if seen.last() != Some(&out.phase) {
            seen.push(out.phase);
        }
        if out.landed {
            break;
        }
    }
    assert_eq!(seen, [Phase::Approach, Phase::Flare, Phase::Landed]);
}

/// A take-off item 60 deg off the heading the aircraft stands on (an item placed anywhere by a
/// ground station): the roll and the climb follow the runway the aircraft stands on, never
/// towards the item, until the item's altitude; with `NAV_TKO_TO_ITEM` the line runs to the
/// item instead.
#[test]
fn a_take_off_follows_the_heading_the_aircraft_stands_on_not_an_item_off_the_runway() {
    let bearing = 60f32.to_radians();
    let items = [item(
        NAV_TAKEOFF,
        [0.0; 4],
        600.0 * libm::cosf(bearing),
        600.0 * libm::sinf(bearing),
        40.0,
    )];
    for to_item in [false, true] {
        let mut nav = navigator();
        let mut p = *nav.params();
        EXEC_PARAMS
            .set(&mut p, "NAV_TKO_TO_ITEM", if to_item { 1.0 } else { 0.0 })
            .expect("in range");
        nav.set_params(&p);
        let mut plane = Plane::flying(0.0, 0.0, 0.0, 0.0);
        plane.k.airspeed = 0.0;
        nav.start_mission(0);
        let log = fly(&mut nav, &mut plane, &items, 120.0, |o| {
            o.reached == Some(0)
        });
        assert_eq!(log.reached, [0], "NAV_TKO_TO_ITEM {to_item}");
        let (_, first, _) = &log.outs[0];
        let far = first.target.expect("a take-off flies to a point");
        let runway = libm::atan2f(far.y, far.x);
        let expected = if to_item { bearing } else { 0.0 };
        assert!(
            (runway - expected).abs() < 0.01,
            "NAV_TKO_TO_ITEM {to_item}: runway {} deg",
            runway.to_degrees()
        );
        if !to_item {
            for (_, o, p) in &log.outs {
                assert!(
                    matches!(o.phase, Phase::TakeoffRoll | Phase::TakeoffClimb),
                    "{:?}",
                    o.phase
                );
                assert!(p.y.abs() < 0.5, "off the runway by {} m", p.y);
            }
        }
    }
}

/// Landing from a waypoint 900 m north of the land point at 60 m: level until the 6-degree
/// glide slope, down it, flare, touchdown near the land point, on the line, `landed`
/// reported after a second on the ground, with the item reached. On the slope the height is
/// the slope's, aimed short of the point by the flare's length (the model's altitude loop
/// has the climb-rate feed-forward, so no ramp lag), to within 1 m.
#[test]
fn landing_glide_path_reaches_the_land_point() {
    let items = [
        wp(900.0, 0.0, 60.0),
        item(NAV_LAND, [0.0; 4], 0.0, 0.0, 0.0),
    ];
    let mut nav = navigator();
    // Approaching the waypoint from the north-east, at its altitude.
    let mut plane = Plane::flying(1300.0, 300.0, 60.0, -2.5);
    plane.k.wind = Vector3::new(2.0, 1.0, 0.0);
    nav.start_mission(0);
    let log = fly(&mut nav, &mut plane, &items, 400.0, |o| {
        o.phase == Phase::Landed
    });
    assert_eq!(log.reached, [0, 1]);
    let tan_g = libm::tanf(6f32.to_radians());
    let flare = nav.params().flare_alt;
    let mut on_slope = 0;
    for (_, o, p) in &log.outs {
        if o.current_seq == Some(1) && o.phase == Phase::Approach {
            let to_go = p.x.max(0.0);
            let glide = tan_g * to_go;
            // From 10 s after the glide slope is met down to the flare.
            if glide < 55.0 - 10.0 * 1.5 && glide > flare + 2.0 {
                on_slope += 1;
                let vg = o.guidance.map_or(14.0, |_| plane_speed(&log, p));
                // The slope aims short of the point by the flare's overrun: an exponential
                // flare from h_f with the sink falling from s_a = vg tan(gamma) to s_t covers
                // vg tau ln(s_a / s_t), tau = h_f / (s_a - s_t), past where the slope met h_f.
                let (h_f, s_t) = (flare, nav.params().flare_sink);
                let s_a = vg * tan_g;
                let tau = h_f / (s_a - s_t);
                let overrun = vg * tau * libm::logf(s_a / s_t) - h_f / tan_g;
                let aimed = tan_g * (to_go - overrun);
                assert!(
                    (-p.z - aimed).abs() < 1.0,
                    "height {} vs the slope {aimed} at {to_go} m (overrun {overrun} m)",
                    -p.z
                );
                assert!(p.y.abs() < 2.0, "cross-track {}", p.y);
            }
        }
    }
    assert!(on_slope > 200);
    let flare_at = log.outs.iter().find(|o| o.1.phase == Phase::Flare).unwrap();
    let ground_at = log.outs.iter().find(|o| o.2.z >= 0.0).unwrap();
    // The flare begins as far out as it will carry the aircraft (its length at the
    // approach's ground speed, the expectation above with the overrun added back; within
    // 3 m, a fifth of a second), and the wheels meet the runway near the point: the
    // kinematic model's flare (a pitch-driven glide) is not the exponential one, within 15 m.
    let vg = plane_speed(&log, &flare_at.2);
    let (h_f, s_t) = (flare, nav.params().flare_sink);
    let s_a = vg * tan_g;
    let flare_len = vg * h_f / (s_a - s_t) * libm::logf(s_a / s_t);
    assert!(
        (flare_at.2.x - flare_len).abs() < 3.0,
        "flare at {} m, expected {flare_len} m out",
        flare_at.2.x
    );
    assert!(
        ground_at.2.x.abs() < 15.0,
        "wheels on the runway {} m past the land point",
        -ground_at.2.x
    );
    let (_, last, td) = log.outs.last().unwrap();
    assert_eq!(last.phase, Phase::Landed);
    // The kinematic model rolls on at its speed: on the ground, but not stopped, so not yet
    // to be disarmed (a taildragger rolling free swings round).
    assert!(!last.landed);
    assert!(
        td.x < 0.0 && td.x > -120.0,
        "touchdown {} m past the land point",
        -td.x
    );
    assert!(td.y.abs() < 3.0);
    assert!(matches!(
        last.commands.unwrap().lon,
        LonMode::Pitch { throttle, .. } if throttle == 0.0
    ));
}

/// Ground speed at the logged position `p` (from the next logged position).
fn plane_speed(log: &Log, p: &Vector3<f32>) -> f32 {
    let i = log.outs.iter().position(|o| o.2 == *p).unwrap();
    let q = log.outs.get(i + 1).map_or(*p, |o| o.2);
    libm::hypotf(q.x - p.x, q.y - p.y) / DT
}

/// Return mode without landing: home at NAV_RTL_ALT, circling at NAV_LOIT_RAD. With landing:
/// down the glide slope onto home.
#[test]
fn return_and_circle_or_land() {
    let mut nav = navigator();
    let mut plane = Plane::flying(600.0, -400.0, 120.0, 1.0);
    plane.k.wind = Vector3::new(0.0, -4.0, 0.0);
    nav.start_return(false);
    let log = fly(&mut nav, &mut plane, &[], 200.0, |_| false);
    let (_, last, p) = log.outs.last().unwrap();
    assert_eq!(last.phase, Phase::ReturnLoiter);
    assert_eq!(last.current_seq, None);
    let r = libm::hypotf(p.x, p.y);
    assert!((r - 60.0).abs() < 5.0, "radius {r}");
    assert!((-p.z - 60.0).abs() < 1.0);

    nav.start_return(true);
    let log = fly(&mut nav, &mut plane, &[], 600.0, |o| {
        o.phase == Phase::Landed
    });
    let (_, last, p) = log.outs.last().unwrap();
    assert_eq!(last.phase, Phase::Landed);
    assert!(libm::hypotf(p.x, p.y) < 120.0, "landed at {p:?}");
}

#[test]
fn loiter_here_circles_the_present_position() {
    let mut nav = navigator();
    let mut plane = Plane::flying(200.0, 100.0, 90.0, 0.0);
    nav.start_loiter(None);
    let log = fly(&mut nav, &mut plane, &[], 120.0, |_| false);
    let (_, last, p) = log.outs.last().unwrap();
    assert_eq!(last.phase, Phase::Hold);
    let c = last.target.unwrap();
    assert_eq!(c, Vector3::new(200.0, 100.0, -90.0));
    let r = libm::hypotf(p.x - c.x, p.y - c.y);
    assert!((r - 60.0).abs() < 3.0, "radius {r}");
    assert!((last.wp_dist_m - r).abs() < 1e-3);
}

/// The item positions come from `ned_offset` about home: a home moved by DO_SET_HOME moves
/// every target with it on the next step.
#[test]
fn a_new_home_moves_the_targets() {
    let items = [wp(300.0, 0.0, 80.0)];
    let mut nav = navigator();
    let plane = Plane::flying(0.0, 0.0, 80.0, 0.0);
    nav.start_mission(0);
    let a = nav
        .step(&items, &home(), &plane.state(), DT)
        .target
        .unwrap();
    let mut h2 = home();
    h2.point = offset_point(home().point, 100.0_f32, 0.0);
    h2.alt_amsl_m = 260.0;
    let b = nav.step(&items, &h2, &plane.state(), DT).target.unwrap();
    let (n, _): (f32, f32) = ned_offset(h2.point, offset_point(home().point, 300.0_f32, 0.0));
    assert!((a.x - 300.0).abs() < 0.05);
    assert!((b.x - n).abs() < 0.05 && (b.x - 200.0).abs() < 0.1);
}

/// A waypoint without autocontinue: reached, then held (circled) rather than left.
#[test]
fn no_autocontinue_holds_at_the_waypoint() {
    let mut first = wp(300.0, 0.0, 80.0);
    first.autocontinue = false;
    let items = [first, wp(300.0, 300.0, 80.0)];
    let mut nav = navigator();
    let mut plane = Plane::flying(0.0, 0.0, 80.0, 0.0);
    nav.start_mission(0);
    let log = fly(&mut nav, &mut plane, &items, 150.0, |_| false);
    assert_eq!(log.reached, [0]);
    let (_, last, p) = log.outs.last().unwrap();
    assert_eq!((last.phase, last.current_seq), (Phase::Hold, Some(0)));
    let r = libm::hypotf(p.x - 300.0, p.y);
    assert!((r - 60.0).abs() < 5.0, "radius {r}");
    // The firmware moves on with set_current.
    nav.set_current(1);
    let log = fly(&mut nav, &mut plane, &items, 100.0, |o| o.reached.is_some());
    assert_eq!(log.reached, [1]);
}

/// Items with garbage in every field (NaN and huge parameters, wild frames, jumps anywhere)
/// and a garbage state: the navigator never panics and never stalls in a step.
#[test]
fn garbage_items_and_state_do_not_panic() {
    let mut seed = 0x2545_f491_u32;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 17;
        seed ^= seed << 5;
        seed
    };
    let specials = [f32::NAN, f32::INFINITY, -1.0, 0.0, 1e30, -2.0, 3.0, 0.5];
    for _ in 0..200 {
        let mut items = [MissionItem::default(); 12];
        for it in items.iter_mut() {
            let cmds = [
                NAV_WAYPOINT,
                NAV_LOITER_UNLIM,
                NAV_LOITER_TURNS,
                NAV_LOITER_TIME,
                NAV_RETURN_TO_LAUNCH,
                NAV_LAND,
                NAV_TAKEOFF,
                NAV_LOITER_TO_ALT,
                DO_JUMP,
                DO_CHANGE_SPEED,
                DO_SET_HOME,
                0xffff,
            ];
            it.command = cmds[(next() % cmds.len() as u32) as usize];
            it.frame = (next() % 12) as u8;
            it.x = next() as i32;
            it.y = next() as i32;
            it.z = specials[(next() % 8) as usize].to_bits();
            it.params = core::array::from_fn(|_| {
                if next() % 2 == 0 {
                    specials[(next() % 8) as usize].to_bits()
                } else {
                    ((next() % 14) as f32).to_bits()
                }
            });
            it.autocontinue = next() % 4 != 0;
        }
        let mut nav = navigator();
        nav.start_mission((next() % 14) as u16);
        let mut plane = Plane::flying(0.0, 0.0, 50.0, 0.0);
        let _ = fly(&mut nav, &mut plane, &items, 10.0, |_| false);
        let bad = NavState {
            pos_ned: Vector3::new(f32::NAN, 1e30, f32::INFINITY),
            vel_ned: Vector3::new(f32::NAN, 0.0, 0.0),
            heading: f32::NAN,
            roll: f32::NAN,
            airspeed: f32::NAN,
            yaw_rate: f32::NAN,
            wind_speed: f32::NAN,
            range_hagl: Some(f32::NAN),
            oracle: Some(HeightOracle {
                height_m: f32::NAN,
                vel_down_mps: f32::INFINITY,
            }),
        };
        nav.set_current((next() % 14) as u16);
        let _ = nav.step(&items, &home(), &bad, f32::NAN);
        let _ = nav.step(&items, &home(), &bad, -1.0);
        let _ = super::validate::validate_mission(
            &items,
            Some(&home()),
            &MissionLimits::default(),
            &NavParams::default(),
        );
        let _ = super::fence::validate_fence(&items);
        let _ = breached(&items, &home(), &bad.pos_ned, &FenceParams::default());
    }
}

/// A finished loiter is left where the course points at the next waypoint, so the next leg
/// starts on its line: without that exit the aircraft turns round on the leg, up to two turn
/// radii off it.
#[test]
fn a_finished_loiter_is_left_heading_for_the_next_point() {
    let items = [
        item(NAV_LOITER_TURNS, [1.0, 0.0, 80.0, 0.0], 300.0, 0.0, 80.0),
        item(NAV_WAYPOINT, [0.0; 4], 300.0, 1200.0, 80.0),
    ];
    let mut nav = navigator();
    let mut plane = Plane::flying(0.0, 0.0, 80.0, 0.0);
    nav.start_mission(0);
    let log = fly(&mut nav, &mut plane, &items, 300.0, |o| {
        o.reached == Some(1)
    });
    assert_eq!(log.reached, [0, 1]);
    let worst = log
        .outs
        .iter()
        .filter(|o| o.1.current_seq == Some(1))
        .filter_map(|o| o.1.guidance.map(|g| g.cross_track.abs()))
        .fold(0.0_f32, f32::max);
    assert!(
        worst < 10.0,
        "cross-track on the leg after the loiter {worst} m"
    );
}

/// A navigator with the guidance matched to the kinematic aircraft's 1 s course lag.
fn navigator() -> Navigator {
    // The glide geometry is checked without the approach's integral (the test's altitude
    // lag is part of the expectation).
    let mut p = NavParams::default();
    EXEC_PARAMS.set(&mut p, "NAV_APP_I", 0.0).expect("in range");
    // The glide geometry these tests were written for: 6 deg, flare from 4 m.
    EXEC_PARAMS
        .set(&mut p, "NAV_LND_SLP_DEG", 6.0)
        .expect("in range");
    EXEC_PARAMS
        .set(&mut p, "NAV_FLR_ALT", 4.0)
        .expect("in range");
    Navigator::new(
        p,
        Guidance::for_course_lag(1.0, 0.03),
        PathManager::default(),
    )
}

#[test]
fn warning_texts_fit_one_statustext() {
    for w in [
        NavWarning::UnknownCommand { seq: 0, command: 0 },
        NavWarning::BadJump { seq: 0 },
        NavWarning::JumpLoop { seq: 0 },
        NavWarning::UnsupportedSpeed { seq: 0 },
        NavWarning::NoMission,
    ] {
        assert!(w.text().len() <= crate::gcs::STATUSTEXT_LEN, "{w:?}");
    }
}

/// A landing begun high above the glide slope closes the gap without diving: on the approach
/// the altitude command never lies more than `NAV_APP_DIVE_M` below the aircraft, and the
/// aircraft is on the slope (within 1 m) before the flare.
#[test]
fn a_high_approach_comes_down_to_the_slope_without_diving() {
    let items = [item(NAV_LAND, [0.0; 4], 0.0, 0.0, 0.0)];
    let mut nav = navigator();
    let dive = nav.params().approach_dive;
    // 300 m out at 33 m, heading for the point: the 6-degree slope there is some 5 m lower, a
    // gap the model's altitude loop (2 s) closes at 0.5 m/s with the 1 m limit, in 10 s.
    let mut plane = Plane::flying(300.0, 0.0, 33.0, core::f32::consts::PI);
    nav.start_mission(0);
    let mut prev_height = 33.0;
    let mut saw_limit = false;
    let log = fly(&mut nav, &mut plane, &items, 120.0, |o| {
        o.phase == Phase::Flare
    });
    for (_, o, p) in &log.outs {
        if o.phase != Phase::Approach {
            continue;
        }
        let Some(LonMode::Glide { altitude, .. }) = o.commands.map(|c| c.lon) else {
            panic!("approach without a glide command: {:?}", o.commands);
        };
        let altitude = altitude - home().alt_amsl_m;
        // The command was made from the height before this step.
        assert!(
            altitude >= prev_height - dive - 1e-3,
            "command {altitude} m with the aircraft at {prev_height} m"
        );
        if let Some(g) = o.guidance {
            saw_limit |= altitude > g.altitude + 1.0;
        }
        prev_height = -p.z;
    }
    assert!(
        saw_limit,
        "the slope was never more than 1 m below the command"
    );
    let (_, last_approach, p) = log
        .outs
        .iter()
        .rev()
        .find(|o| o.1.phase == Phase::Approach)
        .expect("an approach");
    let slope = last_approach.guidance.expect("guidance").altitude;
    assert!(
        (-p.z - slope).abs() < 1.0,
        "{} m vs the slope's {slope} m",
        -p.z
    );
}

/// The landing `items` (one, on the point under home) flown by `nav` from 300 m north at
/// 30 m until the navigator is in `phase`; the plane as it is then.
fn land_here_until(nav: &mut Navigator, items: &[MissionItem], phase: Phase) -> Plane {
    let mut plane = Plane::flying(300.0, 0.0, 30.0, core::f32::consts::PI);
    nav.start_mission(0);
    fly(nav, &mut plane, items, 200.0, |o| o.phase == phase);
    plane
}

/// A flare that has floated past the land point aims for a faster sink and may lower the
/// nose below the flare's pitch: 15 m past at 1 m, `NAV_FLR_PAST_K` 0.05 asks for 0.75 m/s
/// more sink than the schedule (up to 1 m/s), each m/s of it `NAV_FLR_K` (0.35 rad) less
/// pitch, down to level at most; without it the pitch stays at or above the floor short of
/// the point, `NAV_FLR_PTCH_DEG` times (1 - 1 m / `NAV_FLR_ALT`).
#[test]
fn a_flare_past_the_point_pitches_down_for_the_runway() {
    let items = [item(NAV_LAND, [0.0; 4], 0.0, 0.0, 0.0)];
    let pitch_past = |k: f32| {
        let mut nav = navigator();
        let mut p = *nav.params();
        EXEC_PARAMS
            .set(&mut p, "NAV_FLR_PAST_K", k)
            .expect("in range");
        nav.set_params(&p);
        let mut plane = land_here_until(&mut nav, &items, Phase::Flare);
        // Floated on: 15 m past the point, 1 m up, sinking as the flare left it.
        plane.k.pos = Vector3::new(-15.0, 0.0, -1.0);
        let state = plane.state();
        let out = nav.step(&items, &home(), &state, DT);
        assert_eq!(out.phase, Phase::Flare);
        match out.commands.map(|c| c.lon) {
            Some(LonMode::Pitch { pitch, .. }) => (pitch, state, *nav.params()),
            other => panic!("flare without a pitch command: {other:?}"),
        }
    };
    let (plain, state, p) = pitch_past(0.0);
    let (steered, _, _) = pitch_past(0.05);
    let sink = state.vel_ned.z;
    // The schedule at 1 m of the flare's height: from the slope's sink to the touchdown's.
    let s_a = state.ground_speed() * libm::tanf(p.glide_slope);
    let aim = p.flare_sink + (s_a - p.flare_sink) * (1.0 / p.flare_alt);
    let aim_past = (aim + 0.05 * 15.0).min(aim.max(1.0));
    let law = |aim: f32, floor: f32| {
        (p.flare_pitch + p.flare_k * (sink - aim)).clamp(floor, 15f32.to_radians())
    };
    let floor = p.flare_pitch * (1.0 - 1.0 / p.flare_alt);
    for (got, expected, what) in [
        (plain, law(aim, floor), "plain"),
        (steered, law(aim_past, 0.0), "steered"),
    ] {
        assert!(
            (got - expected).abs() < 0.05f32.to_radians(),
            "{what} {} deg, expected {} deg",
            got.to_degrees(),
            expected.to_degrees()
        );
    }
    assert!(steered < plain, "steered {steered} not below plain {plain}");
}

/// The flare's pitch at `h` m over the land point, `dist` m short of it (negative: past it),
/// climbing at `climb` m/s, after the steps `before` (each a height and climb rate) flown in
/// the flare first, on the default parameters.
fn flare_pitch_at(
    before: &[(f32, f32)],
    h: f32,
    climb: f32,
    dist: f32,
) -> (f32, NavState, NavParams) {
    let items = [item(NAV_LAND, [0.0; 4], 0.0, 0.0, 0.0)];
    let mut nav = navigator();
    let mut plane = land_here_until(&mut nav, &items, Phase::Flare);
    let mut pitch = None;
    for &(h, climb) in before.iter().chain(&[(h, climb)]) {
        plane.k.pos = Vector3::new(dist, 0.0, -h);
        plane.climb = climb;
        let out = nav.step(&items, &home(), &plane.state(), DT);
        assert_eq!(out.phase, Phase::Flare);
        pitch = match out.commands.map(|c| c.lon) {
            Some(LonMode::Pitch { pitch, .. }) => Some(pitch),
            other => panic!("flare without a pitch command: {other:?}"),
        };
    }
    (pitch.expect("a step"), plane.state(), *nav.params())
}

/// Lifted by an updraft short of the point, the flare lowers the nose to its floor, which
/// widens from `NAV_FLR_PTCH_DEG` at the ground to level at the flare's top: at 1.2 m of the
/// 1.5 m flare, climbing 0.5 m/s (far above the schedule's sink), the pitch is 3 deg times
/// 0.2, 0.6 deg, where the flare's pitch held all the way up floated the aircraft on.
#[test]
fn a_flare_lifted_by_an_updraft_short_of_the_point_lowers_the_nose_towards_level() {
    let (pitch, _, p) = flare_pitch_at(&[], 1.2, 0.5, 20.0);
    let expected = p.flare_pitch * (1.0 - 1.2 / p.flare_alt);
    assert!(
        (pitch - expected).abs() < 0.01f32.to_radians(),
        "{} deg, expected {} deg",
        pitch.to_degrees(),
        expected.to_degrees()
    );
}

/// A rise near the ground reads as the wheels' kick and levels the pitch (a wheel landing);
/// sinking again faster than 0.6 m/s shows the aircraft is still flying, and the flare's law
/// takes over again: at 0.3 m sinking 1 m/s, `NAV_FLR_PTCH_DEG` plus `NAV_FLR_K` times the
/// sink above the schedule's, well above level.
#[test]
fn a_flare_that_sinks_again_after_a_seeming_touch_pitches_up_again() {
    let kicked = [(0.3, 0.5)];
    let (level, _, _) = flare_pitch_at(&kicked[..0], 0.3, 0.5, 20.0);
    assert!(level.abs() < 1e-6, "after the kick {level} rad, not level");
    let (pitch, state, p) = flare_pitch_at(&kicked, 0.3, -1.0, 20.0);
    assert_flare_law(pitch, &state, &p, 0.3, 1.0);
}

/// The flare's law short of the point, unclamped: `NAV_FLR_PTCH_DEG` plus `NAV_FLR_K` times
/// the sink (m/s) above the schedule's at height `h` (m), from the approach's sink at this
/// ground speed to `NAV_FLR_SINK`; `pitch` within 0.05 deg of it.
fn assert_flare_law(pitch: f32, state: &NavState, p: &NavParams, h: f32, sink: f32) {
    let approach_sink = state.ground_speed() * libm::tanf(p.glide_slope);
    let aim = p.flare_sink + (approach_sink - p.flare_sink) * (h / p.flare_alt);
    let expected = p.flare_pitch + p.flare_k * (sink - aim);
    assert!(
        (pitch - expected).abs() < 0.05f32.to_radians(),
        "{} deg, expected {} deg",
        pitch.to_degrees(),
        expected.to_degrees()
    );
}

/// Given the simulator's truth (`SIM_USE_TRUTH` = 2), the flare flies the true height and sink
/// instead of the estimate's: the estimate 1.2 m up and climbing 0.5 m/s (the updraft's
/// floor, 0.6 deg), the truth 0.5 m up sinking 1 m/s: `NAV_FLR_PTCH_DEG` plus `NAV_FLR_K`
/// times the true sink above the schedule's at the true height.
#[test]
fn given_the_truth_the_flare_pitches_for_the_true_height_and_sink_not_the_estimates() {
    let items = [item(NAV_LAND, [0.0; 4], 0.0, 0.0, 0.0)];
    let mut nav = navigator();
    let mut plane = land_here_until(&mut nav, &items, Phase::Flare);
    plane.k.pos = Vector3::new(20.0, 0.0, -1.2);
    plane.climb = 0.5;
    let state = NavState {
        oracle: Some(HeightOracle {
            height_m: 0.5,
            vel_down_mps: 1.0,
        }),
        ..plane.state()
    };
    let out = nav.step(&items, &home(), &state, DT);
    assert_eq!(out.phase, Phase::Flare);
    let pitch = match out.commands.map(|c| c.lon) {
        Some(LonMode::Pitch { pitch, .. }) => pitch,
        other => panic!("flare without a pitch command: {other:?}"),
    };
    assert_flare_law(pitch, &state, nav.params(), 0.5, 1.0);
}

/// A rangefinder that reads 0.8 m more than the estimate's height above the runway (the
/// estimate low by 0.8 m) moves the approach's slope 0.8 m down in the estimate's frame, so
/// that it meets the ground the rangefinder sees: after 5 s, five of `RANGE_EXCESS_TAU_S`, the
/// altitude command is 0.8 m x (1 - e^-5) = 0.795 m under the one flown without it (the
/// slope's integral trim `NAV_APP_I` off, so that only the rangefinder differs; a larger
/// difference is taken up as the aircraft sinks, the command held within `NAV_APP_DIVE_M`,
/// 1 m, under the present height).
#[test]
fn a_rangefinder_reading_over_the_estimate_lowers_the_approach_onto_the_ground_it_sees() {
    let items = [item(NAV_LAND, [0.0; 4], 0.0, 0.0, 0.0)];
    let command_with = |extra: Option<f32>| {
        let mut nav = navigator();
        let mut p = *nav.params();
        EXEC_PARAMS.set(&mut p, "NAV_APP_I", 0.0).expect("in range");
        nav.set_params(&p);
        let mut plane = land_here_until(&mut nav, &items, Phase::Approach);
        // On the slope, where the command is not held within the dive limit of the height.
        let on_slope = nav.step(&items, &home(), &plane.state(), DT).guidance;
        plane.k.pos.z = -on_slope.expect("guidance").altitude;
        let state = NavState {
            range_hagl: extra.map(|e| plane.height() + e),
            ..plane.state()
        };
        let mut altitude = f32::NAN;
        for _ in 0..(5.0 / DT).round() as usize {
            let out = nav.step(&items, &home(), &state, DT);
            assert_eq!(out.phase, Phase::Approach);
            altitude = match out.commands.map(|c| c.lon) {
                Some(LonMode::Glide { altitude, .. }) => altitude,
                other => panic!("approach without a glide: {other:?}"),
            };
        }
        altitude
    };
    let drop = command_with(None) - command_with(Some(0.8));
    let expected = 0.8 * (1.0 - (-5.0f32).exp());
    assert!(
        (drop - expected).abs() < 0.01,
        "{drop} m, expected {expected} m"
    );
}

/// The truth starts the flare too: 5 m up by the estimate on the approach, 1.4 m by the truth
/// (under `NAV_FLR_ALT`, 1.5 m), the landing is in its flare; without the truth, not.
#[test]
fn given_the_truth_the_flare_starts_at_the_true_height() {
    let items = [item(NAV_LAND, [0.0; 4], 0.0, 0.0, 0.0)];
    let phase_with = |oracle: Option<HeightOracle>| {
        let mut nav = navigator();
        let mut plane = land_here_until(&mut nav, &items, Phase::Approach);
        plane.k.pos = Vector3::new(80.0, 0.0, -5.0);
        let state = NavState {
            oracle,
            ..plane.state()
        };
        nav.step(&items, &home(), &state, DT).phase
    };
    let truth = HeightOracle {
        height_m: 1.4,
        vel_down_mps: 1.0,
    };
    assert_eq!(phase_with(None), Phase::Approach);
    assert_eq!(phase_with(Some(truth)), Phase::Flare);
}

/// A landed aircraft that keeps rolling (sailing along the runway before a crosswind, its tail
/// wheel a keel) is disarmed `NAV_LND_DISARM_S` (30 s) after the touchdown once its airspeed
/// is under 10 m/s (10/11 of `NAV_LIFTOFF_ASPD`), where it cannot fly off with its surfaces at
/// rest; faster through the air, it stays armed and steered; slower than 3 m/s over ground it
/// is disarmed at once. An aircraft that lifts off at 22 m/s is disarmed under 20 m/s.
#[test]
fn a_landed_aircraft_still_rolling_is_disarmed_after_the_roll_out_time_when_it_cannot_fly() {
    let items = [item(NAV_LAND, [0.0; 4], 0.0, 0.0, 0.0)];
    let landed_after_with = |liftoff: f32, speed: f32, seconds: f32| {
        let mut nav = navigator();
        let mut p = *nav.params();
        EXEC_PARAMS
            .set(&mut p, "NAV_LIFTOFF_ASPD", liftoff)
            .expect("in range");
        nav.set_params(&p);
        let mut plane = land_here_until(&mut nav, &items, Phase::Landed);
        // Rolling on along the runway at `speed` over ground and through the air.
        plane.k.pos.z = 0.0;
        plane.climb = 0.0;
        plane.k.airspeed = speed;
        let mut landed = false;
        let steps = (seconds / DT).round() as usize;
        for _ in 0..steps {
            let out = nav.step(&items, &home(), &plane.state(), DT);
            assert_eq!(out.phase, Phase::Landed);
            landed = out.landed;
        }
        (landed, nav.params().land_disarm_s)
    };
    let landed_after = |speed, seconds| landed_after_with(11.0, speed, seconds);
    let (early, limit) = landed_after(8.0, 29.0);
    assert_eq!(limit, 30.0);
    assert!(!early, "disarmed 29 s after the touchdown at 8 m/s");
    assert!(
        landed_after(8.0, 31.0).0,
        "still armed 31 s after it at 8 m/s"
    );
    assert!(
        !landed_after(12.0, 31.0).0,
        "disarmed at 12 m/s of airspeed"
    );
    assert!(landed_after(2.5, 0.1).0, "armed at a walking pace");
    assert!(
        landed_after_with(22.0, 19.0, 31.0).0,
        "armed at 19 of 22 m/s"
    );
    assert!(
        !landed_after_with(22.0, 21.0, 31.0).0,
        "disarmed at 21 of 22 m/s"
    );
}

/// The flare banks less than the approach near the ground: at 0.85 m the approach would allow
/// 5 + 85 x 0.85 / 3 = 29 deg, the flare `NAV_GND_RLL_DEG` plus 85 deg x 0.85 / 10 m = 12.2 deg,
/// under the 17 deg at which the Ultra Stick's wing tip meets the runway with its wheels on it.
#[test]
fn the_flare_banks_at_most_twelve_degrees_at_085_m() {
    let items = [item(NAV_LAND, [0.0; 4], 0.0, 0.0, 0.0)];
    let mut nav = navigator();
    let mut plane = land_here_until(&mut nav, &items, Phase::Flare);
    plane.k.pos.z = -0.85;
    let out = nav.step(&items, &home(), &plane.state(), DT);
    assert_eq!(out.phase, Phase::Flare);
    match out.commands.map(|c| c.roll) {
        Some(RollMode::CourseWithin { roll_max, .. }) => assert!(
            (roll_max.to_degrees() - 12.225).abs() < 0.01,
            "{} deg",
            roll_max.to_degrees()
        ),
        other => panic!("flare roll mode {other:?}"),
    }
}

/// A landed aircraft that a gust lifts off the runway (0.8 m up, climbing 1 m/s, at 15 m/s of
/// airspeed) is flying again: the flare's sink-rate law brings it down rather than the
/// roll-out's level pitch, which dropped such hops onto the runway at 2-3.8 m/s in moderate
/// turbulence (`docs/RESULTS-MONTECARLO.md`). It does not go around from the roll-out.
#[test]
fn a_landed_aircraft_lifted_by_a_gust_flares_again_and_does_not_go_around() {
    let items = [item(NAV_LAND, [0.0; 4], 0.0, 0.0, 0.0)];
    let mut nav = navigator();
    let mut plane = land_here_until(&mut nav, &items, Phase::Landed);
    plane.k.pos.z = -0.8;
    plane.climb = 1.0;
    plane.k.airspeed = 15.0;
    let out = nav.step(&items, &home(), &plane.state(), DT);
    assert_eq!(out.phase, Phase::Flare, "lifted 0.8 m after the touchdown");
    // Sinking back at 1 m/s the flare pitches up (above level) rather than holding level.
    plane.climb = -1.0;
    let out = nav.step(&items, &home(), &plane.state(), DT);
    assert_eq!(out.phase, Phase::Flare);
    match out.commands.map(|c| c.lon) {
        Some(LonMode::Pitch { pitch, .. }) => assert!(pitch > 0.0, "{pitch} rad"),
        other => panic!("no pitch command: {other:?}"),
    }
    // Far past the point and lifted higher, still no go-around: the aircraft has landed once.
    plane.k.pos.z = -4.0;
    let out = nav.step(&items, &home(), &plane.state(), DT);
    assert_ne!(out.phase, Phase::GoAround);
}

/// An approach still above the flare's height past the land point goes around once it is
/// `NAV_LND_ABORT_M` (20 m) past, as a floating flare does: not 19 m past, at 21 m.
#[test]
fn an_approach_still_high_past_the_abort_distance_goes_around() {
    let items = [item(NAV_LAND, [0.0; 4], 0.0, 0.0, 0.0)];
    let mut nav = navigator();
    let mut plane = land_here_until(&mut nav, &items, Phase::Approach);
    // Held 10 m up (over the flare's 4 m) down the runway's line, heading south.
    for (north, phase) in [(-19.0, Phase::Approach), (-21.0, Phase::GoAround)] {
        plane.k.pos = Vector3::new(north, 0.0, -10.0);
        let out = nav.step(&items, &home(), &plane.state(), DT);
        assert_eq!(out.phase, phase, "{north} m north of the point");
    }
}

/// An approach that begins more than twice the glide slope's height above the point (6 deg in
/// these tests: under 21 m at 200 m, the flare's overrun taken off) flies the circuit instead
/// of diving onto the slope, and lands from it; one that begins at 30 m flies the approach.
#[test]
fn an_approach_begun_over_twice_the_slopes_height_flies_the_circuit() {
    let items = [item(NAV_LAND, [0.0; 4], 0.0, 0.0, 0.0)];
    for (height, phase) in [(30.0, Phase::Approach), (45.0, Phase::GoAround)] {
        let mut nav = navigator();
        let plane = Plane::flying(200.0, 0.0, height, core::f32::consts::PI);
        nav.start_mission(0);
        let out = nav.step(&items, &home(), &plane.state(), DT);
        assert_eq!(out.phase, phase, "begun {height} m up");
        if phase == Phase::GoAround {
            let log = fly(&mut nav, &mut { plane }, &items, 600.0, |o| {
                o.phase == Phase::Landed
            });
            assert_eq!(log.outs.last().map(|o| o.1.phase), Some(Phase::Landed));
        }
    }
}

/// A flare still in the air 20 m past the land point (`NAV_LND_ABORT_M`) goes around: it
/// climbs away on the runway's line at full throttle (the take-off regime) to the approach's
/// start height (30 m here), flies back on a leg parallel to the runway two loiter radii
/// (2 x 60 m) to its left, turns onto a new approach far enough out to meet the glide slope
/// from that height (6 deg in these tests), and lands there on the point.
#[test]
fn a_flare_floating_past_the_abort_distance_goes_around_and_lands_on_a_new_approach() {
    let items = [item(NAV_LAND, [0.0; 4], 0.0, 0.0, 0.0)];
    let mut nav = navigator();
    let mut plane = land_here_until(&mut nav, &items, Phase::Flare);
    // The approach runs south; floated on 19 m past the point, 1 m up, it keeps flaring.
    plane.k.pos = Vector3::new(-19.0, 0.0, -1.0);
    let out = nav.step(&items, &home(), &plane.state(), DT);
    assert_eq!(out.phase, Phase::Flare, "19 m past");
    plane.k.pos = Vector3::new(-21.0, 0.0, -1.0);
    let out = nav.step(&items, &home(), &plane.state(), DT);
    assert_eq!(out.phase, Phase::GoAround, "21 m past");
    assert!(
        matches!(out.commands.map(|c| c.lon), Some(LonMode::TakeOff { .. })),
        "{:?}",
        out.commands
    );
    let log = fly(&mut nav, &mut plane, &items, 600.0, |o| {
        o.phase == Phase::Landed
    });
    let circuit: Vec<_> = log
        .outs
        .iter()
        .filter(|o| o.1.phase == Phase::GoAround)
        .collect();
    let top = circuit.iter().map(|o| -o.2.z).fold(0.0, f32::max);
    assert!((top - 30.0).abs() < 2.0, "circuit at {top} m");
    // The downwind leg: east of the runway (left of an approach heading south), 120 m off.
    let abeam = circuit
        .iter()
        .find(|o| o.2.x > 200.0)
        .expect("the circuit passes abeam the approach");
    assert!(
        (abeam.2.y - 120.0).abs() < 5.0,
        "downwind leg at {}",
        abeam.2
    );
    let landed = log.outs.last().expect("steps");
    assert_eq!(landed.1.phase, Phase::Landed);
    assert!(
        landed.2.x.abs() < 30.0 && landed.2.y.abs() < 5.0,
        "second landing at {}",
        landed.2
    );
    assert!(log.reached.contains(&0));
}

/// A go-around that a gust puts back on the runway below the lift-off airspeed
/// (`NAV_LIFTOFF_ASPD`) finishes the landing on the ground after `TOUCHDOWN_S` (1 s): the
/// roll-out, throttle closed, not the climb's full throttle on the wheels. Above the lift-off
/// airspeed, or off the ground, it keeps climbing away.
#[test]
fn a_go_around_put_back_on_the_runway_too_slow_to_lift_off_finishes_the_landing_on_the_ground() {
    let items = [item(NAV_LAND, [0.0; 4], 0.0, 0.0, 0.0)];
    let mut nav = navigator();
    let mut plane = land_here_until(&mut nav, &items, Phase::Approach);
    assert!(nav.go_around());
    let liftoff = nav.params().liftoff_airspeed;
    plane.k.pos.z = 0.0;
    plane.climb = 0.0;
    // On the wheels at the lift-off airspeed: a take-off, climbing on (5 s of 50 ms steps).
    plane.k.airspeed = liftoff + 0.5;
    for _ in 0..100 {
        let out = nav.step(&items, &home(), &plane.state(), DT);
        assert_eq!(out.phase, Phase::GoAround);
    }
    // Slower than it for 0.95 s: still the climb.
    plane.k.airspeed = liftoff - 2.0;
    for _ in 0..19 {
        let out = nav.step(&items, &home(), &plane.state(), DT);
        assert_eq!(out.phase, Phase::GoAround);
    }
    // A second: the roll-out, throttle closed.
    let out = nav.step(&items, &home(), &plane.state(), DT);
    assert_eq!(out.phase, Phase::Landed);
    match out.commands.map(|c| c.lon) {
        Some(LonMode::Pitch { throttle, .. }) => assert_eq!(throttle, 0.0),
        other => panic!("roll-out's longitudinal mode {other:?}"),
    }
    assert!(!nav.go_around(), "went around from the roll-out");
}

/// A landing goes around at most twice: a flare lifted out of itself (above twice
/// `NAV_FLR_ALT`, 8 m in these tests) goes around each of the first two times, and lands from the third.
#[test]
fn a_landing_goes_around_at_most_twice() {
    let items = [item(NAV_LAND, [0.0; 4], 0.0, 0.0, 0.0)];
    let mut nav = navigator();
    let mut plane = land_here_until(&mut nav, &items, Phase::Approach);
    for attempt in 0..3 {
        fly(&mut nav, &mut plane, &items, 600.0, |o| {
            o.phase == Phase::Flare
        });
        plane.k.pos.z = -(2.0 * nav.params().flare_alt + 0.1);
        let out = nav.step(&items, &home(), &plane.state(), DT);
        let expected = if attempt < 2 {
            Phase::GoAround
        } else {
            Phase::Flare
        };
        assert_eq!(out.phase, expected, "ballooned flare {attempt}");
    }
    assert!(!nav.go_around(), "a third go-around was accepted");
}

/// A go-around asked for (`MAV_CMD_DO_GO_AROUND`) is flown only from a landing's approach
/// or flare: not on a waypoint leg, nor once rolling out.
#[test]
fn a_go_around_is_flown_only_from_an_approach_or_a_flare() {
    let items = [item(NAV_LAND, [0.0; 4], 0.0, 0.0, 0.0)];
    let mut nav = navigator();
    let mut plane = land_here_until(&mut nav, &items, Phase::Approach);
    assert!(nav.go_around());
    let out = nav.step(&items, &home(), &plane.state(), DT);
    assert_eq!(out.phase, Phase::GoAround);
    fly(&mut nav, &mut plane, &items, 900.0, |o| {
        o.phase == Phase::Landed
    });
    assert!(!nav.go_around(), "went around from the roll-out");
    let mut nav = navigator();
    let mut plane = Plane::flying(0.0, 0.0, 30.0, 0.0);
    let legs = [wp(500.0, 0.0, 30.0)];
    nav.start_mission(0);
    fly(&mut nav, &mut plane, &legs, 1.0, |_| false);
    assert!(!nav.go_around(), "went around from a waypoint leg");
}

/// A leg that starts where the aircraft is (no waypoint before it, as after a take-off or a
/// loiter) 90 deg off its heading is joined by turning towards the waypoint, the line drawn
/// anew from the aircraft until its course is within 15 deg of it: the turn is not a straight
/// leg, and on the straight leg that follows the cross-track stays within what the 15 deg
/// left carries the aircraft over its 1 s course lag, 17 m/s x 1 s x sin 15 deg = 4.4 m.
/// Drawn once from where the turn began, the line is overshot by about a turn radius (29 m
/// at 17 m/s and this model's largest turn rate, g / V).
#[test]
fn a_leg_from_the_present_position_is_joined_without_overshooting_its_line() {
    let items = [wp(0.0, 500.0, 30.0)];
    let mut nav = navigator();
    let mut plane = Plane::flying(0.0, 0.0, 30.0, 0.0);
    nav.start_mission(0);
    let log = fly(&mut nav, &mut plane, &items, 120.0, |o| o.reached.is_some());
    assert_eq!(log.reached, [0]);
    let turning = log.outs.iter().take_while(|o| !o.1.straight).count();
    assert!(turning > 10, "the turn onto the leg took {turning} steps");
    let straight_xt = log
        .outs
        .iter()
        .filter(|o| o.1.straight)
        .filter_map(|o| o.1.guidance.map(|g| g.cross_track.abs()))
        .fold(0.0, f32::max);
    let bound = 17.0 * 1.0 * libm::sinf(15f32.to_radians());
    assert!(straight_xt < bound, "{straight_xt} m off the straight leg");
}

/// With `NAV_FLR_TIME` 3 s the flare begins where the glide slope's sink at the ground speed
/// (15 m/s on the 6 deg slope: 1.577 m/s) brings the ground within 3 s: 4.73 m, over the
/// 4 m `NAV_FLR_ALT`; with it 0 the flare waits for 4 m. A downdraft's sink does not bring
/// it forward.
#[test]
fn a_fast_approach_flares_where_the_ground_is_nav_flr_time_away() {
    let items = [item(NAV_LAND, [0.0; 4], 0.0, 0.0, 0.0)];
    let phase_at = |flare_time: f32, h: f32, sink: f32| {
        let mut nav = navigator();
        let mut p = *nav.params();
        EXEC_PARAMS
            .set(&mut p, "NAV_FLR_TIME", flare_time)
            .expect("in range");
        nav.set_params(&p);
        let mut plane = land_here_until(&mut nav, &items, Phase::Approach);
        plane.k.pos = Vector3::new(80.0, 0.0, -h);
        plane.k.airspeed = 15.0;
        plane.climb = -sink;
        nav.step(&items, &home(), &plane.state(), DT).phase
    };
    assert_eq!(phase_at(3.0, 4.70, 1.58), Phase::Flare);
    assert_eq!(phase_at(3.0, 4.76, 1.58), Phase::Approach);
    assert_eq!(phase_at(0.0, 4.70, 1.58), Phase::Approach);
    assert_eq!(phase_at(0.0, 3.99, 1.58), Phase::Flare);
    assert_eq!(phase_at(1.0, 4.70, 5.0), Phase::Approach, "in a downdraft");
}

/// The approach's airspeed command in steady air: `NAV_LND_ASPD` (15 m/s) plus
/// `NAV_LND_WIND_K` (0.5) times the 2 m/s wind: 16 m/s; in a 6 m/s wind the cruise airspeed's 17 m/s.
#[test]
fn the_approach_is_flown_half_the_wind_faster_up_to_the_cruise_airspeed() {
    let items = [item(NAV_LAND, [0.0; 4], 0.0, 0.0, 0.0)];
    let approach_airspeed = |wind: f32| {
        let mut nav = navigator();
        let mut p = *nav.params();
        EXEC_PARAMS
            .set(&mut p, "NAV_LND_WIND_K", 0.5)
            .expect("in range");
        // The test aircraft's deceleration onto the approach would read as gusts.
        EXEC_PARAMS
            .set(&mut p, "NAV_LND_GUST_K", 0.0)
            .expect("in range");
        nav.set_params(&p);
        let mut plane = land_here_until(&mut nav, &items, Phase::Approach);
        plane.k.wind = Vector3::new(wind, 0.0, 0.0);
        let out = nav.step(&items, &home(), &plane.state(), DT);
        match out.commands.map(|c| c.lon) {
            Some(LonMode::Altitude { airspeed, .. } | LonMode::Glide { airspeed, .. }) => airspeed,
            other => panic!("no approach command: {other:?}"),
        }
    };
    assert!((approach_airspeed(0.0) - 15.0).abs() < 1e-4);
    assert!((approach_airspeed(2.0) - 16.0).abs() < 1e-4);
    assert!((approach_airspeed(6.0) - 17.0).abs() < 1e-4);
}
