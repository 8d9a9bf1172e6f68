//! The flight log: one sample per frame of the truth beside what the autopilot holds, and
//! its CSV form.

use crate::plant::battery::Battery;
use crate::sensors::models::Truth;
use common::actuators::Surfaces;
use common::estimator::EstimatedState;
use common::gcs::modes::FlightMode;
use common::math::{course_and_speed, Euler};
use common::navigation::Phase;
use common::vehicle::LoopCommands;
use firmware::app::Setpoints;
use nalgebra::Vector3;
use serde::Serialize;

/// Degrees per radian: the log holds radians, its readers want degrees.
pub(crate) const DEG: f64 = 180.0 / std::f64::consts::PI;

/// One frame of the flight, SI units and radians.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Sample {
    /// Simulated time, s.
    pub t: f64,
    /// The autopilot flies (its answer has the armed bit).
    pub armed: bool,
    /// Mode (PX4 main mode of the heartbeat's custom mode).
    pub mode: u8,
    /// The estimator's `converged` flag.
    pub converged: bool,
    /// Truth: north, east from home, m.
    pub north: f64,
    /// Truth east, m.
    pub east: f64,
    /// Truth altitude AMSL, m.
    pub alt: f64,
    /// Truth roll, pitch, yaw, rad.
    pub roll: f64,
    /// Truth pitch, rad.
    pub pitch: f64,
    /// Truth yaw (heading), rad.
    pub yaw: f64,
    /// Truth course over ground, rad.
    pub course: f64,
    /// Truth airspeed, m/s.
    pub airspeed: f64,
    /// Truth wind (steady + turbulence), NED, m/s.
    pub wind: [f64; 3],
    /// Steady wind, NED, m/s.
    pub wind_steady: [f64; 3],
    /// Estimate: north, east from the simulator's home, m.
    pub est_north: f64,
    /// Estimated east, m.
    pub est_east: f64,
    /// Estimated altitude AMSL, m.
    pub est_alt: f64,
    /// Estimated roll, rad.
    pub est_roll: f64,
    /// Estimated pitch, rad.
    pub est_pitch: f64,
    /// Estimated yaw, rad.
    pub est_yaw: f64,
    /// Estimated course, rad.
    pub est_course: f64,
    /// Estimated airspeed, m/s.
    pub est_airspeed: f64,
    /// Estimated wind, NED, m/s.
    pub est_wind: [f64; 3],
    /// Setpoint course, rad.
    pub sp_course: f64,
    /// Setpoint altitude AMSL, m.
    pub sp_alt: f64,
    /// Setpoint airspeed, m/s.
    pub sp_airspeed: f64,
    /// Bank angle the course loop asked the roll loop for, rad (NaN: the loop is off).
    pub sp_roll: f64,
    /// Pitch angle the outer loops asked the pitch loop for, rad (NaN: the loop is off).
    pub sp_pitch: f64,
    /// Commanded surfaces (UMN signs), rad, and throttle 0..1.
    pub elevator: f64,
    /// Commanded aileron, rad.
    pub aileron: f64,
    /// Commanded rudder, rad.
    pub rudder: f64,
    /// Commanded throttle.
    pub throttle: f64,
    /// Cross-track error of the true position from the path being followed, m (NaN outside
    /// navigation modes).
    pub xtrack: f64,
    /// The same error as the navigator sees it, from the estimated position, m.
    pub est_xtrack: f64,
    /// The navigator's phase (`common::navigation::Phase` as its index).
    pub nav_phase: u8,
    /// Mission item being flown (-1: none).
    pub mission_seq: i32,
    /// The path followed is a straight leg.
    pub straight: bool,
    /// Truth: the battery's terminal voltage, V.
    pub bat_voltage: f64,
    /// Truth: the battery's current, A.
    pub bat_current: f64,
    /// Truth: the charge drawn from the battery since power-up, mAh.
    pub bat_drawn_mah: f64,
    /// Truth: the energy drawn from the battery since power-up, Wh.
    pub bat_energy_wh: f64,
    /// Truth: the battery's state of charge, 0..1.
    pub bat_soc: f64,
    /// The autopilot's estimate of the charge left, 0..1 (NaN: no battery monitored).
    pub est_bat_remaining: f64,
}

/// What the navigator was doing at one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NavView {
    /// Cross-track error from the estimated position, m (NaN without a path).
    pub xtrack: f64,
    /// Unit vector (north, east) along which a position error adds to the cross-track error:
    /// right of a line, outward from a circle's centre.
    pub across: (f64, f64),
    /// Phase.
    pub phase: Phase,
    /// Mission item.
    pub seq: Option<u16>,
    /// On a straight leg.
    pub straight: bool,
}

impl NavView {
    /// The view of an autopilot's navigator (only a navigation mode has a path); `pos_ned` is
    /// the estimated position the navigator flew on.
    pub fn of(
        nav: &common::navigation::NavOutput,
        navigating: bool,
        pos_ned: &Vector3<f32>,
    ) -> Self {
        let across = match (nav.straight, nav.guidance, nav.target) {
            (true, Some(g), _) => {
                let c = f64::from(g.path_course);
                (-c.sin(), c.cos())
            }
            (false, _, Some(t)) => {
                let (dn, de) = (f64::from(pos_ned.x - t.x), f64::from(pos_ned.y - t.y));
                let r = dn.hypot(de);
                if r > 1e-6 {
                    (dn / r, de / r)
                } else {
                    (0.0, 0.0)
                }
            }
            _ => (0.0, 0.0),
        };
        Self {
            across,
            xtrack: match (navigating, nav.guidance) {
                (true, Some(g)) => f64::from(g.cross_track),
                _ => f64::NAN,
            },
            phase: if navigating { nav.phase } else { Phase::Idle },
            seq: nav.current_seq,
            straight: navigating && nav.straight,
        }
    }
}

/// What the autopilot holds at one frame, for the log: only an autopilot running in this
/// process can be looked into.
#[derive(Clone, Copy, Debug)]
pub struct AutopilotView {
    /// The estimator's state.
    pub estimate: EstimatedState,
    /// The estimated position north and east of the simulator's home, m.
    pub est_ne: (f64, f64),
    /// What the autopilot holds.
    pub setpoints: Setpoints,
    /// The angles its outer loops asked the inner loops for.
    pub loops: LoopCommands,
    /// The mode flown.
    pub mode: FlightMode,
    /// The navigator.
    pub nav: NavView,
}

impl Sample {
    /// Builds a sample from the truth, the autopilot's answer and, when it can be looked
    /// into, what the autopilot holds (without it those columns are NaN, the mode 0).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        t: f64,
        truth: &Truth,
        alt_amsl: f64,
        wind: &Vector3<f64>,
        wind_steady: &Vector3<f64>,
        view: Option<&AutopilotView>,
        armed: bool,
        s: &Surfaces,
    ) -> Self {
        let (eu, course, _) = truth_angles(truth);
        let mut sample = Self {
            t,
            armed,
            north: truth.pos_ned.x,
            east: truth.pos_ned.y,
            alt: alt_amsl,
            roll: eu.phi,
            pitch: eu.theta,
            yaw: eu.psi,
            course,
            airspeed: truth.airspeed_mps,
            wind: [wind.x, wind.y, wind.z],
            wind_steady: [wind_steady.x, wind_steady.y, wind_steady.z],
            elevator: f64::from(s.elevator),
            aileron: f64::from(s.aileron),
            rudder: f64::from(s.rudder),
            throttle: f64::from(s.throttle),
            ..Self::unknown_autopilot()
        };
        if let Some(v) = view {
            sample.hold(truth, v);
        }
        sample
    }

    /// The sample with the battery's truth and the autopilot's estimate of the charge left.
    pub fn with_battery(self, b: &Battery, est_remaining: Option<f32>) -> Self {
        let o = b.output();
        Self {
            bat_voltage: o.voltage_v,
            bat_current: o.current_a,
            bat_drawn_mah: b.drawn_mah(),
            bat_energy_wh: b.energy_wh(),
            bat_soc: b.soc(),
            est_bat_remaining: est_remaining.map_or(f64::NAN, f64::from),
            ..self
        }
    }

    /// A sample whose autopilot columns say "not known".
    fn unknown_autopilot() -> Self {
        let nan = f64::NAN;
        Self {
            mode: 0,
            converged: false,
            est_north: nan,
            est_east: nan,
            est_alt: nan,
            est_roll: nan,
            est_pitch: nan,
            est_yaw: nan,
            est_course: nan,
            est_airspeed: nan,
            est_wind: [nan; 3],
            sp_course: nan,
            sp_alt: nan,
            sp_airspeed: nan,
            sp_roll: nan,
            sp_pitch: nan,
            xtrack: nan,
            est_xtrack: nan,
            nav_phase: Phase::Idle as u8,
            mission_seq: -1,
            straight: false,
            ..Self::default()
        }
    }

    /// Fills the autopilot's columns.
    fn hold(&mut self, truth: &Truth, v: &AutopilotView) {
        let (e, sp, nav) = (&v.estimate, &v.setpoints, &v.nav);
        // The true position's error from the path: the estimate's, plus the estimate's own
        // error across the path.
        let (dn, de) = (truth.pos_ned.x - v.est_ne.0, truth.pos_ned.y - v.est_ne.1);
        self.xtrack = nav.xtrack + dn * nav.across.0 + de * nav.across.1;
        self.mode = v.mode.px4().0;
        self.converged = e.converged;
        self.est_north = if e.position_valid {
            v.est_ne.0
        } else {
            f64::NAN
        };
        self.est_east = if e.position_valid {
            v.est_ne.1
        } else {
            f64::NAN
        };
        self.est_alt = f64::from(e.alt_amsl_m);
        self.est_roll = f64::from(e.euler.phi);
        self.est_pitch = f64::from(e.euler.theta);
        self.est_yaw = f64::from(e.euler.psi);
        self.est_course = f64::from(e.course);
        self.est_airspeed = f64::from(e.airspeed);
        self.est_wind = [
            f64::from(e.wind_ned.x),
            f64::from(e.wind_ned.y),
            f64::from(e.wind_ned.z),
        ];
        self.sp_course = f64::from(sp.course);
        self.sp_alt = f64::from(sp.alt_amsl_m);
        self.sp_airspeed = f64::from(sp.airspeed);
        self.sp_roll = f64::from(v.loops.roll_cmd);
        self.sp_pitch = f64::from(v.loops.pitch_cmd);
        self.est_xtrack = nav.xtrack;
        self.nav_phase = nav.phase as u8;
        self.mission_seq = nav.seq.map_or(-1, i32::from);
        self.straight = nav.straight;
    }
}

/// Course over ground and Euler angles of the truth (helpers for the log).
fn truth_angles(t: &Truth) -> (Euler<f64>, f64, f64) {
    let (course, gs) = course_and_speed(&t.vel_ned);
    (Euler::from_quaternion(&t.attitude), course, gs)
}

/// Column names of the CSV log (degrees for angles, as a user reads them).
pub fn csv_headers() -> Vec<String> {
    [
        "t_s",
        "armed",
        "mode",
        "converged",
        "north_m",
        "east_m",
        "alt_amsl_m",
        "roll_deg",
        "pitch_deg",
        "yaw_deg",
        "course_deg",
        "airspeed_mps",
        "wind_n_mps",
        "wind_e_mps",
        "wind_d_mps",
        "est_north_m",
        "est_east_m",
        "est_alt_amsl_m",
        "est_roll_deg",
        "est_pitch_deg",
        "est_yaw_deg",
        "est_course_deg",
        "est_airspeed_mps",
        "est_wind_n_mps",
        "est_wind_e_mps",
        "sp_course_deg",
        "sp_alt_amsl_m",
        "sp_airspeed_mps",
        "sp_roll_deg",
        "sp_pitch_deg",
        "elevator_deg",
        "aileron_deg",
        "rudder_deg",
        "throttle",
        "xtrack_m",
        "est_xtrack_m",
        "nav_phase",
        "mission_seq",
        "straight",
        "bat_voltage_v",
        "bat_current_a",
        "bat_drawn_mah",
        "bat_energy_wh",
        "bat_soc",
        "est_bat_remaining",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect()
}

/// One CSV row per sample.
pub fn csv_row(s: &Sample) -> Vec<f64> {
    let b = |x: bool| if x { 1.0 } else { 0.0 };
    vec![
        s.t,
        b(s.armed),
        f64::from(s.mode),
        b(s.converged),
        s.north,
        s.east,
        s.alt,
        s.roll * DEG,
        s.pitch * DEG,
        s.yaw * DEG,
        s.course * DEG,
        s.airspeed,
        s.wind[0],
        s.wind[1],
        s.wind[2],
        s.est_north,
        s.est_east,
        s.est_alt,
        s.est_roll * DEG,
        s.est_pitch * DEG,
        s.est_yaw * DEG,
        s.est_course * DEG,
        s.est_airspeed,
        s.est_wind[0],
        s.est_wind[1],
        s.sp_course * DEG,
        s.sp_alt,
        s.sp_airspeed,
        s.sp_roll * DEG,
        s.sp_pitch * DEG,
        s.elevator * DEG,
        s.aileron * DEG,
        s.rudder * DEG,
        s.throttle,
        s.xtrack,
        s.est_xtrack,
        f64::from(s.nav_phase),
        f64::from(s.mission_seq),
        b(s.straight),
        s.bat_voltage,
        s.bat_current,
        s.bat_drawn_mah,
        s.bat_energy_wh,
        s.bat_soc,
        s.est_bat_remaining,
    ]
}
