//! Take-off: the runway roll, rotation and climb-out of a `NAV_TAKEOFF` item.
//!
//! Take-off is a runway take-off: the throttle opened to full over `NAV_TKO_RAMP_S` (closed
//! again while the heading swings more than 135 deg off the line, and opened anew), wings
//! level, pitch 0 until the rotation airspeed, then the thesis's take-off regime
//! (`LonMode::TakeOff`: fixed pitch, full throttle to the clear height, then climb) to the
//! item's altitude. The runway is the line
//! along the heading the aircraft stands on when the roll starts, as a pilot lines it up
//! (`NAV_TKO_TO_ITEM` takes the line to the item's position instead): the tail wheel holds
//! it until the wheels are off, and the bank allowed near the ground is small
//! (`NAV_GND_RLL_DEG`), widening with height.
//!
//! A failsafe on the roll, below the rotation airspeed, gives the take-off up
//! (`Takeoff::abort`): the throttle closed, wings level, the tail wheel steering along the
//! runway's line, the roll-out of a landing (`land::roll_out`) to a stop, and the
//! disarm. So does the roll itself when it goes wrong, as a pilot closes the throttle: no
//! rotation airspeed within `NAV_TKO_ROLL_S` (in moderate turbulence at 2-5 m/s of airspeed, a
//! tail-dragger pirouetted on its runway at full throttle for 20 s and more), and, when it is
//! set, a heading swung off the runway's line by more than `NAV_TKO_HDG_DEG` beyond where it
//! stood when the roll began. Past the rotation the aircraft is committed: a failsafe waits
//! until the climb has reached `NAV_TKO_CLR_M` (`Takeoff::ground_stage`).

use super::guide::{climb_from_runway, horizontal_dist, Flight, Orbit};
use super::io::{GroundStage, NavOutput, NavState, NavWarning, Phase};
use super::land::roll_out;
use super::params::NavParams;
use crate::control::autopilot::Commands;
use crate::control::lateral::{RollMode, RUDDER};
use crate::control::longitudinal::LonMode;
use crate::estimator::Home;
use crate::guidance::Path;
use crate::math::frames::wrap_pi;
use crate::navigation::items::Place;
use nalgebra::Vector3;

/// A take-off in progress.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Takeoff {
    /// Where the roll began, NED from home.
    start: Vector3<f32>,
    /// Runway course, rad.
    course: f32,
    /// Height above home the climb ends at, m.
    height: f32,
    /// Still on the runway, below the rotation airspeed.
    rolling: bool,
    /// Time on the take-off roll so far, s.
    roll_s: f32,
    /// Height above where the roll began at the last step, m.
    climbed: f32,
    /// Given up on the runway: the time rolled out since, s.
    aborted: Option<f32>,
    /// How far off the runway's course the aircraft stood when the roll began, rad (0 but
    /// for a line to the item, `NAV_TKO_TO_ITEM`): a ground loop is a swing beyond it.
    start_off: f32,
    /// Time the throttle has been opening since the roll began, or since the heading last
    /// came back within [`SWING_CUT_RAD`] of the line, s.
    power_s: f32,
}

/// Swing off the runway's line (beyond where the roll began) past which the take-off roll
/// closes the throttle until the heading comes back within it, rad (135 deg), then opens it
/// again over `NAV_TKO_RAMP_S`, as a pilot takes the power off to get a swinging tail-dragger
/// straight. On full throttle at a walking pace in moderate turbulence the campaign's aircraft
/// spun on the runway at 100-150 deg/s for seconds: one of seed 2 (flight 13) through three
/// turns and over onto its nose; others spun out of it and flew (seed 1's flight 3, 971).
/// Swings of 60 to 120 deg in quartering tailwinds are flown out on full throttle: cut at 90
/// deg, the wind rose's 5 m/s towards 60 deg (seed 1, docs/NAVIGATION.md) lifted off 6 s
/// later, finished its climb at the first corner and overshot it by 47 m.
const SWING_CUT_RAD: f32 = 0.75 * core::f32::consts::PI;

impl Takeoff {
    /// The take-off of an item whose position is `target` (NED from home): along the present
    /// heading; with `NAV_TKO_TO_ITEM`, along the line to that point when it lies more than
    /// 20 m away, else on the item's `yaw` (rad), else on the present heading; `place` is
    /// the item's.
    pub fn item(
        place: &Place,
        yaw: Option<f32>,
        target: Vector3<f32>,
        home: &Home,
        state: &NavState,
        p: &NavParams,
    ) -> Self {
        let pos = state.pos_ned;
        let course = if !p.takeoff_to_item {
            state.heading
        } else if place.point.is_some() && horizontal_dist(&target, &pos) > 20.0 {
            libm::atan2f(target.y - pos.y, target.x - pos.x)
        } else if let Some(yaw) = yaw {
            yaw
        } else {
            state.heading
        };
        Self {
            start: pos,
            course,
            height: place.height(home).unwrap_or(p.rtl_alt),
            rolling: state.airspeed.is_nan() || state.airspeed < p.takeoff_vr,
            roll_s: 0.0,
            climbed: 0.0,
            aborted: None,
            start_off: wrap_pi(state.heading - course).abs(),
            power_s: 0.0,
        }
    }

    /// Gives the take-off up if it is still on its roll (below the rotation airspeed); returns
    /// whether it did. Past the rotation the take-off goes on.
    pub fn abort(&mut self) -> bool {
        if self.rolling && self.aborted.is_none() {
            self.aborted = Some(0.0);
            return true;
        }
        false
    }

    /// Why the roll must be given up now, if it must: a ground loop, or a roll too long.
    fn gone_wrong(&self, state: &NavState, p: &NavParams) -> Option<NavWarning> {
        let off = wrap_pi(state.heading - self.course).abs();
        // Not `>` on a NaN start: a heading unknown at the start takes no abort for it.
        if p.takeoff_heading_max > 0.0 && off > p.takeoff_heading_max + self.start_off {
            Some(NavWarning::TakeoffOffLine)
        } else if p.takeoff_roll_max > 0.0 && self.roll_s > p.takeoff_roll_max {
            Some(NavWarning::TakeoffTooSlow)
        } else {
            None
        }
    }

    /// Where the take-off stands for a failsafe (`NAV_TKO_CLR_M` is `clear`, m).
    pub fn ground_stage(&self, clear: f32) -> GroundStage {
        if self.aborted.is_some() {
            GroundStage::Touchdown
        } else if self.rolling {
            GroundStage::TakeoffRoll
        } else if self.climbed.is_nan() || self.climbed < clear {
            // An unknown height counts as low: a reaction waits for a known one.
            GroundStage::ClimbOut
        } else {
            GroundStage::Clear
        }
    }

    /// The runway's course, rad.
    pub fn runway(&self) -> f32 {
        self.course
    }

    /// One step of the take-off: its commands into `out`. Once the climb has reached the
    /// item's altitude (less `NAV_ALT_ACC`), the circle to hold there if the mission does not
    /// go on.
    pub fn step(&mut self, f: &Flight, out: &mut NavOutput) -> Option<Orbit> {
        let p = f.params;
        let state = f.state;
        let pos = state.pos_ned;
        let vg = state.ground_speed();
        self.climbed = state.height() + self.start.z;
        if self.rolling && self.aborted.is_none() && state.airspeed >= p.takeoff_vr {
            self.rolling = false;
        }
        let (de, dn) = crate::math::elementary::sin_cos(self.course);
        let far = self.start + Vector3::new(dn, de, 0.0) * 1000.0;
        let line = Path::line_between(&self.start, &far, f.cruise);
        out.target = Some(far);
        if self.rolling && self.aborted.is_none() {
            if let Some(why) = self.gone_wrong(state, p) {
                self.aborted = Some(0.0);
                out.warn(why);
            }
        }
        if let Some(rolled) = &mut self.aborted {
            out.phase = Phase::TakeoffAbort;
            let course = line
                .map(|l| f.guidance.step(&l, &pos, vg).course)
                .unwrap_or(self.course);
            roll_out(f, course, rolled, out);
            return None;
        }
        if self.rolling {
            out.phase = Phase::TakeoffRoll;
            // Along the runway line: the course to hold comes from the line's vector
            // field, so a drift sideways is steered back, not just stopped.
            let course = line
                .map(|l| f.guidance.step(&l, &pos, vg).course)
                .unwrap_or(self.course);
            // The throttle is opened over `NAV_TKO_RAMP_S`, as a pilot opens it (PX4's
            // RWTO_RAMP_TIME): the propeller's spin-up reacts on the airframe in roll, and
            // opened at once from idle it rolled the aircraft 15 deg onto a wing tip before
            // the ailerons had any air (34 of 1000 dispersed take-offs).
            self.roll_s += f.dt;
            // Swung far off the line, power off until it is back (a heading that is not a
            // number keeps the power as it was going).
            if wrap_pi(state.heading - self.course).abs() > SWING_CUT_RAD + self.start_off {
                self.power_s = 0.0;
            } else {
                self.power_s += f.dt;
            }
            let throttle = if p.takeoff_ramp > 0.0 {
                (self.power_s / p.takeoff_ramp).clamp(0.0, 1.0)
            } else if self.power_s > 0.0 {
                1.0
            } else {
                0.0
            };
            out.commands = Some(Commands {
                roll: RollMode::Roll(0.0),
                yaw: f.steer(course),
                lon: LonMode::Pitch {
                    pitch: 0.0,
                    throttle,
                },
            });
        } else {
            out.phase = Phase::TakeoffClimb;
            let g = line.map(|l| f.guidance.step(&l, &pos, vg));
            out.guidance = g;
            let height = self.climbed;
            let roll = match g {
                Some(g) => climb_from_runway(g.course, height, p),
                None => RollMode::Roll(0.0),
            };
            // Rotated but still on its wheels, the aircraft is steered as on the roll: a
            // yaw damper alone lets the tail wheel, pressed down by the rotation, swing it.
            let yaw = match g {
                Some(g) if height < p.touchdown_alt => f.steer(g.course),
                _ => RUDDER,
            };
            out.commands = Some(Commands {
                roll,
                yaw,
                lon: LonMode::TakeOff {
                    altitude: self.height,
                    airspeed: f.cruise.min(p.takeoff_airspeed),
                    clear_altitude: -self.start.z + p.takeoff_clear,
                },
            });
        }
        if !self.rolling && state.height() >= self.height - p.alt_accept {
            Some(Orbit::loiter(Vector3::new(pos.x, pos.y, -self.height), p))
        } else {
            None
        }
    }
}
