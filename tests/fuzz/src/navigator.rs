//! The navigator flying any plan (`Navigator::step`): a mission as flash may hold it, which is
//! not checked again when it is loaded (a record written by another firmware, with other
//! limits), so any command, frame, position and parameter; started at any item, interrupted
//! by a return or a loiter, home moved, flown by a simple aircraft that follows what guidance
//! commands, with any navigation, path and guidance settings the parameter store accepts.
//!
//! Asserted: every step ends (the walk through `DO_JUMP`s is bounded); the guidance output is
//! finite (course, altitude, airspeed, cross-track); the commands to the autopilot hold no NaN
//! or infinity; the current and reached items are items of the plan.

use arbitrary::{Arbitrary, Unstructured};
use common::estimator::Home;
use common::math::geodetic::GeoPoint;
use common::navigation::plan::MissionItem;
use common::navigation::{NavState, Navigator};
use nalgebra::Vector3;

use crate::frames::{HOME, HOME_ALT_M};
use crate::gcs::{Item, ParamValue};
use common::guidance;
use common::navigation::{navigator, path_manager};
use common::params::ParamStore;
use common::vehicle::params::REGISTRY;

#[derive(Arbitrary, Clone, Copy, Debug)]
pub enum Event {
    /// Fly this many steps of 20 ms.
    Fly(u8),
    Start(u8),
    Return(bool),
    Loiter,
    SetCurrent(u8),
    /// Home moves (a `DO_SET_HOME`, a re-arm elsewhere).
    Home {
        north: i8,
        alt: i8,
    },
    /// A gust: the aircraft is pushed off its path.
    Push {
        north: i8,
        east: i8,
        down: i8,
    },
}

#[derive(Arbitrary, Debug)]
pub struct Input {
    /// Parameter sets (those the store accepts), as a ground station may have made them.
    params: Vec<(u16, ParamValue)>,
    items: Vec<Item>,
    events: Vec<Event>,
}

/// Runs one input.
pub fn run(data: &[u8]) {
    let Ok(input) = Input::arbitrary_take_rest(Unstructured::new(data)) else {
        return;
    };
    if crate::trace() {
        eprintln!("{input:?}");
    }
    let items: Vec<MissionItem> = input
        .items
        .iter()
        .take(common::navigation::plan::MISSION_CAPACITY)
        .map(|i| i.raw())
        .collect();
    let mut home = Home {
        point: HOME,
        alt_amsl_m: HOME_ALT_M,
    };
    let mut store = ParamStore::new(REGISTRY);
    for (i, v) in input.params.iter().take(16) {
        let i = usize::from(*i) % store.len();
        let value = v.get(&store, i);
        let _ = store.set_index(i, value);
    }
    let mut nav = Navigator::default();
    nav.configure(
        &store.load(&navigator::params::PARAMS),
        &store.load(&path_manager::PARAMS),
        &store.load(&guidance::PARAMS),
    );
    nav.start_mission(0);
    let mut pos = Vector3::new(0.0f32, 0.0, -50.0);
    let mut heading = 0.0f32;
    // The bank of the turn the aircraft last flew, rad (the navigator's turn airspeed floor).
    let mut roll = 0.0f32;
    let airspeed = 18.0f32;
    let dt = 0.02;
    for e in input.events.iter().take(64) {
        match *e {
            Event::Fly(n) => {
                for _ in 0..n {
                    let vel = Vector3::new(airspeed * heading.cos(), airspeed * heading.sin(), 0.0);
                    let state = NavState {
                        pos_ned: pos,
                        vel_ned: vel,
                        heading,
                        roll,
                        airspeed,
                        yaw_rate: 0.0,
                        wind_speed: airspeed - 17.0,
                        // No rangefinder: the navigator flies on the estimate's height, as
                        // with a failed one.
                        range_hagl: None,
                        // The simulator's truth is not flown here: only SIM_USE_TRUTH gives it.
                        oracle: None,
                    };
                    let out = nav.step(&items, &home, &state, dt);
                    if let Some(g) = out.guidance {
                        for (what, v) in [
                            ("course", g.course),
                            ("altitude", g.altitude),
                            ("airspeed", g.airspeed),
                            ("cross-track", g.cross_track),
                        ] {
                            assert!(v.is_finite(), "guidance {what} {v}: {out:?}");
                        }
                        // A first-order turn and climb towards what guidance asks.
                        let err = common::math::wrap_pi(g.course - heading);
                        let rate = err.clamp(-0.5, 0.5) * 2.0;
                        heading = common::math::wrap_pi(heading + rate * dt);
                        roll = (airspeed * rate / common::math::GRAVITY).atan();
                        pos.z += (-g.altitude - pos.z).clamp(-3.0, 3.0) * dt;
                    }
                    // NaN and infinities print as such in the commands' fields.
                    let c = format!("{:?}", out.commands);
                    assert!(!c.contains("NaN") && !c.contains("inf"), "commands {c}");
                    for s in [out.current_seq, out.reached].into_iter().flatten() {
                        assert!(usize::from(s) < items.len(), "item {s} of {}", items.len());
                    }
                    pos += vel * dt;
                }
            }
            Event::Start(s) => nav.start_mission(u16::from(s)),
            Event::Return(land) => nav.start_return(land),
            Event::Loiter => nav.start_loiter(None),
            Event::SetCurrent(s) => nav.set_current(u16::from(s)),
            Event::Home { north, alt } => {
                home = Home {
                    point: GeoPoint {
                        lat_e7: HOME.lat_e7 + i32::from(north) * 1000,
                        lon_e7: HOME.lon_e7,
                    },
                    alt_amsl_m: HOME_ALT_M + f32::from(alt),
                }
            }
            Event::Push { north, east, down } => {
                pos += Vector3::new(f32::from(north), f32::from(east), f32::from(down)) * 10.0;
            }
        }
    }
}
