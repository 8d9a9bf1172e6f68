//! What the navigator takes in (the estimate it flies on) and hands out (commands, progress,
//! warnings, home requests).

use crate::control::autopilot::Commands;
use crate::estimator::{EstimatedState, Home};
use crate::guidance::GuidanceOutput;
use nalgebra::Vector3;

/// What the navigator needs of the estimate.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NavState {
    /// Position NED from home, m.
    pub pos_ned: Vector3<f32>,
    /// Velocity over ground NED, m/s.
    pub vel_ned: Vector3<f32>,
    /// Heading (yaw), rad.
    pub heading: f32,
    /// Bank (roll), rad.
    pub roll: f32,
    /// Airspeed, m/s.
    pub airspeed: f32,
    /// Yaw rate about the body's z axis, rad/s (the heading's rate on the runway).
    pub yaw_rate: f32,
    /// Horizontal wind speed, m/s (0 until the estimator has a wind).
    pub wind_speed: f32,
    /// Height above the ground from the rangefinder, m, while it passes its gates.
    pub range_hagl: Option<f32>,
    /// The simulator's truth for the flare, when `SIM_USE_TRUTH` asks for it (never on a real
    /// aircraft).
    pub oracle: Option<HeightOracle>,
}

/// The true height and vertical speed the flare flies on in place of the estimate's: an
/// oracle that measures the best any height sensor could give the landing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeightOracle {
    /// Height above home, m, on the same datum as [`NavState::height`].
    pub height_m: f32,
    /// Vertical speed, down positive, m/s.
    pub vel_down_mps: f32,
}

impl NavState {
    /// The navigator's view of the estimator's state.
    pub fn from_estimate(s: &EstimatedState) -> Self {
        Self {
            pos_ned: s.pos_ned,
            vel_ned: s.vel_ned,
            heading: s.euler.psi,
            roll: s.euler.phi,
            airspeed: s.airspeed,
            yaw_rate: s.body_rates.z,
            wind_speed: if s.wind_valid {
                crate::math::elementary::hypot(s.wind_ned.x, s.wind_ned.y)
            } else {
                0.0
            },
            range_hagl: s.range_hagl_m,
            oracle: None,
        }
    }

    /// Height above home, m.
    pub fn height(&self) -> f32 {
        -self.pos_ned.z
    }

    /// Horizontal speed over ground, m/s.
    pub fn ground_speed(&self) -> f32 {
        crate::math::elementary::hypot(self.vel_ned.x, self.vel_ned.y)
    }
}

/// Something the mission asked for that was not flown as written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum NavWarning {
    /// An item with a command this navigator does not execute was skipped.
    UnknownCommand {
        /// Its sequence number.
        seq: u16,
        /// Its `MAV_CMD`.
        command: u16,
    },
    /// A `DO_JUMP` with a target outside the mission was skipped.
    BadJump {
        /// Its sequence number.
        seq: u16,
    },
    /// A jump loop with no navigation item in it: the mission was ended.
    JumpLoop {
        /// Sequence number where the walk stopped.
        seq: u16,
    },
    /// A `DO_CHANGE_SPEED` this navigator cannot apply (climb or descent speed) was skipped.
    UnsupportedSpeed {
        /// Its sequence number.
        seq: u16,
    },
    /// The mission is empty.
    NoMission,
    /// The take-off roll left the runway's line by more than `NAV_TKO_HDG_DEG` and was given
    /// up.
    TakeoffOffLine,
    /// The take-off roll did not reach the rotation airspeed in `NAV_TKO_ROLL_S` and was
    /// given up.
    TakeoffTooSlow,
}

impl NavWarning {
    /// The text the ground station shows (one STATUSTEXT).
    pub fn text(&self) -> &'static str {
        match self {
            NavWarning::UnknownCommand { .. } => "Mission: unsupported item skipped",
            NavWarning::BadJump { .. } => "Mission: DO_JUMP to a missing item skipped",
            NavWarning::JumpLoop { .. } => "Mission: DO_JUMP loop, nothing to fly; ended",
            NavWarning::UnsupportedSpeed { .. } => "Mission: speed change not supported, skipped",
            NavWarning::NoMission => "Mission: nothing to fly",
            NavWarning::TakeoffOffLine => "Take-off aborted: off the runway's line",
            NavWarning::TakeoffTooSlow => "Take-off aborted: no rotation speed in time",
        }
    }
}

/// Where the home should move (`DO_SET_HOME`); the firmware applies it to the estimator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum HomeRequest {
    /// Home becomes the present position.
    Here,
    /// Home becomes this point.
    At(Home),
}

/// What the navigator is doing.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Phase {
    /// Nothing started.
    #[default]
    Idle,
    /// Take-off run on the runway.
    TakeoffRoll,
    /// Take-off climb.
    TakeoffClimb,
    /// Flying to a waypoint.
    Waypoint,
    /// Circling a loiter item.
    Loiter,
    /// Flying home (return).
    Return,
    /// Circling home after a return.
    ReturnLoiter,
    /// Landing approach.
    Approach,
    /// Landing flare.
    Flare,
    /// On the ground after a landing.
    Landed,
    /// Circling a point (loiter here, or an item that does not continue by itself).
    Hold,
    /// The mission is over; circling where it ended.
    Complete,
    /// A landing given up: climbing away and flying a circuit to a new approach.
    GoAround,
    /// A take-off given up on the runway (a failsafe before the rotation): throttle closed,
    /// wings level, rolling out to a stop on the runway's line.
    TakeoffAbort,
}

impl Phase {
    /// On the runway after a touchdown or a take-off given up: rolling out to a stop, its
    /// wheels seen on the ground.
    pub fn rolls_out(self) -> bool {
        matches!(self, Phase::Landed | Phase::TakeoffAbort)
    }
}

/// Where a take-off or landing stands, for what a failsafe may do there: near the ground the
/// reaction waits, or becomes the take-off's abort ([`super::Navigator::ground_stage`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum GroundStage {
    /// Neither taking off nor touching down: a failsafe's reaction is flown at once.
    Clear,
    /// On the take-off roll, below the rotation airspeed: a failsafe aborts the take-off.
    TakeoffRoll,
    /// Rotated, lower than `NAV_TKO_CLR_M` above where the roll began: a failsafe's reaction
    /// waits, wings level, until the climb has reached that height.
    ClimbOut,
    /// In a landing's flare or roll-out, or an aborted take-off's roll-out: the aircraft is
    /// brought to a stop first.
    Touchdown,
}

/// Result of one step.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NavOutput {
    /// Commands for the autopilot, their altitudes above mean sea level (`None` while idle:
    /// the caller keeps its own).
    pub commands: Option<Commands>,
    /// The guidance output behind the commands (cross-track error and so on), its altitude a
    /// height above home.
    pub guidance: Option<GuidanceOutput>,
    /// The point flown to (or circled), NED from home.
    pub target: Option<Vector3<f32>>,
    /// Horizontal distance to `target`, m (NaN without one).
    pub wp_dist_m: f32,
    /// Bearing to `target`, rad (NaN without one).
    pub target_bearing: f32,
    /// The mission item being flown.
    pub current_seq: Option<u16>,
    /// A mission item finished on this step.
    pub reached: Option<u16>,
    /// What was skipped or refused on this step.
    pub warnings: heapless::Vec<NavWarning, 4>,
    /// A `DO_SET_HOME` ran on this step.
    pub set_home: Option<HomeRequest>,
    /// What the navigator is doing.
    pub phase: Phase,
    /// Stopped on the ground after a landing: the firmware may disarm.
    pub landed: bool,
    /// The path of a waypoint or loiter item is a straight line (not a fillet or circle).
    pub straight: bool,
}

impl NavOutput {
    /// Notes something skipped or refused on this step.
    pub(super) fn warn(&mut self, w: NavWarning) {
        // A fifth warning in one step is dropped; the first four say enough.
        let _ = self.warnings.push(w);
    }
}
