//! Lateral-directional autopilot (thesis section 3.4, Figures 3-7 to 3-15): ailerons and rudder.
//!
//! ```text
//! chi_c --(+)-- PI course --[+-roll_max]-- phi_c --(+)-- PI roll --(+)-- trim --[+-ail_max]--> aileron
//!        wrap(chi_c - chi)                        phi          -kd p
//! beta_c --(+)-- PI sideslip --(+)-- trim --(+)-- k * s/(s+a) * r --[+-rud_max]--> rudder
//!          beta
//! ```
//!
//! Signs (UMN): positive aileron rolls left, so the roll gains are negative and `-kd p` with
//! `kd < 0` adds aileron against the roll rate (the thesis's pole shift -16.09 -> -25.76 with
//! `kd = -0.0618` on `p/da = -156.5/(s + 16.09)`). Positive rudder yaws the nose left and raises
//! sideslip: the yaw damper adds `+k r` (right yaw -> rudder that yaws left) and the sideslip PI
//! has positive gains (see [`super::gains`] for the Table 3.5 sign).

use super::filters::Washout;
use super::inputs::{InputFlags, Measurements};
use super::pid::{Bumpless, Derivative, Pid, PidGains};
use crate::actuators::SURFACE_LIMIT_RAD;
use crate::math::{clamp, wrap_pi, DEG, RAD2DEG};
use crate::param;
use crate::params::{Group, ParamDef};
use serde::{Deserialize, Serialize};

/// Gains and limits of the lateral-directional autopilot (ailerons and rudder).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LateralGains {
    /// Roll attitude, proportional: aileron rad per rad of roll error (negative, UMN).
    pub roll_kp: f32,
    /// Roll attitude, integral: aileron rad per rad s of roll error (negative, UMN).
    pub roll_ki: f32,
    /// Roll-rate damper: aileron rad per rad/s of roll rate, applied as `-kd p` (negative, UMN).
    pub roll_rate_kd: f32,
    /// Course hold, proportional: commanded roll rad per rad of course error.
    pub course_kp: f32,
    /// Course hold, integral: commanded roll rad per rad s of course error.
    pub course_ki: f32,
    /// Sideslip hold, proportional: rudder rad per rad of sideslip error (positive, UMN).
    pub slip_kp: f32,
    /// Sideslip hold, integral: rudder rad per rad s of sideslip error (positive, UMN).
    pub slip_ki: f32,
    /// Yaw damper: rudder rad per rad/s of washed-out yaw rate, `+k r` (positive: opposes r).
    pub yaw_damper_k: f32,
    /// Pole of the yaw-damper washout `s / (s + a)`, rad/s.
    pub washout_pole: f32,
    /// Largest commanded roll angle, rad.
    pub roll_max: f32,
    /// Fastest the course loop's roll command grows, rad/s (0: unlimited; absent from older
    /// gain files: 90 deg/s).
    #[serde(default = "default_roll_cmd_rate")]
    pub roll_cmd_rate: f32,
    /// Aileron travel the loops may use, rad (at most the servo limit).
    pub aileron_max: f32,
    /// Rudder travel the loops may use, rad (at most the servo limit).
    pub rudder_max: f32,
    /// Aileron trim, the feed-forward of the roll loop, rad.
    pub trim_aileron: f32,
    /// Rudder trim, the feed-forward of the rudder loops, rad.
    pub trim_rudder: f32,
}

fn default_roll_cmd_rate() -> f32 {
    90.0 * DEG
}

/// The thesis's designed lateral gains, chapter-3 tables: roll Table 3.3, course Table 3.4,
/// sideslip Table 3.5 (sign corrected, see [`super::gains`]); roll limit 45 deg and surface
/// travel 25 deg (section 3.3, Appendix F); washout Appendix D; trims Table 2.3 trim I.
pub const THESIS: LateralGains = LateralGains {
    roll_kp: -1.1216,
    roll_ki: -0.1,
    roll_rate_kd: -0.0618,
    course_kp: 4.0511,
    course_ki: 0.01,
    slip_kp: 3.0,
    slip_ki: 0.8,
    yaw_damper_k: 0.065,
    washout_pole: 2.0,
    roll_max: 45.0 * DEG,
    roll_cmd_rate: 90.0 * DEG,
    aileron_max: 25.0 * DEG,
    rudder_max: 25.0 * DEG,
    trim_aileron: 0.01,
    trim_rudder: 0.00317,
};

/// The flight defaults: [`THESIS`] with the sideslip gains of the computed design
/// (`sim-host design`). Table 3.5's magnitudes (3 and 0.8, sign corrected) leave the sideslip
/// loop unstable on the full linear model once the servo, the two-sample delay and the yaw
/// damper are in it (-25 deg of phase margin, docs/GAIN-DESIGN.md); 0.44 / 1.4 keep 53 deg.
pub const FLIGHT: LateralGains = LateralGains {
    slip_kp: 0.44,
    slip_ki: 1.4,
    ..THESIS
};

const L: LateralGains = FLIGHT;

/// Trims inside the travel the loops may use: otherwise the loop could not return to trim.
fn consistent(g: &LateralGains) -> Result<(), &'static str> {
    if libm::fabsf(g.trim_aileron) > g.aileron_max {
        return Err("TRIM_AIL_DEG");
    }
    if libm::fabsf(g.trim_rudder) > g.rudder_max {
        return Err("TRIM_RUD_DEG");
    }
    Ok(())
}

/// Parameters of the lateral autopilot; defaults are the thesis's designed set. The bounds of
/// the loop gains admit only the sign that stabilises the loop in the UMN convention.
pub const PARAMS: Group<LateralGains> = Group {
    name: "Lateral autopilot",
    params: &[
        param!(
            ParamDef::real(
                "RLL_KP",
                L.roll_kp,
                -10.0,
                0.0,
                "rad/rad",
                "Roll attitude P gain, aileron per roll error (UMN sign: negative)",
            ),
            LateralGains => roll_kp
        ),
        param!(
            ParamDef::real(
                "RLL_KI",
                L.roll_ki,
                -10.0,
                0.0,
                "1/s",
                "Roll attitude I gain, aileron per integrated roll error",
            ),
            LateralGains => roll_ki
        ),
        param!(
            ParamDef::real(
                "RLL_RATE_KD",
                L.roll_rate_kd,
                -2.0,
                0.0,
                "s",
                "Roll-rate damper, aileron per roll rate, applied as -kd*p",
            ),
            LateralGains => roll_rate_kd
        ),
        param!(
            ParamDef::real(
                "CRS_KP",
                L.course_kp,
                0.0,
                20.0,
                "rad/rad",
                "Course hold P gain, commanded roll per course error",
            ),
            LateralGains => course_kp
        ),
        param!(
            ParamDef::real(
                "CRS_KI",
                L.course_ki,
                0.0,
                20.0,
                "1/s",
                "Course hold I gain, commanded roll per integrated course error",
            ),
            LateralGains => course_ki
        ),
        param!(
            ParamDef::real(
                "SLIP_KP",
                L.slip_kp,
                0.0,
                20.0,
                "rad/rad",
                "Sideslip hold P gain, rudder per sideslip error (positive)",
            ),
            LateralGains => slip_kp
        ),
        param!(
            ParamDef::real(
                "SLIP_KI",
                L.slip_ki,
                0.0,
                20.0,
                "1/s",
                "Sideslip hold I gain, rudder per integrated sideslip error",
            ),
            LateralGains => slip_ki
        ),
        param!(
            ParamDef::real(
                "YAW_DAMP_K",
                L.yaw_damper_k,
                0.0,
                2.0,
                "s",
                "Yaw damper, rudder per washed-out yaw rate (+k*r)",
            ),
            LateralGains => yaw_damper_k
        ),
        param!(
            ParamDef::real(
                "YAW_WO_POLE",
                L.washout_pole,
                0.1,
                20.0,
                "rad/s",
                "Pole of the yaw-damper washout s/(s+a)",
            ),
            LateralGains => washout_pole
        ),
        param!(
            ParamDef::real(
                "LIM_ROLL_DEG",
                L.roll_max * RAD2DEG,
                5.0,
                80.0,
                "deg",
                "Largest commanded roll angle",
            ),
            LateralGains => roll_max, scale RAD2DEG
        ),
        param!(
            ParamDef::real(
                "LIM_RLL_RATE_DEG",
                L.roll_cmd_rate * RAD2DEG,
                0.0,
                720.0,
                "deg/s",
                "Fastest the course loop's roll command grows away from level (PX4's FW_R_RMAX); 0: unlimited",
            ),
            LateralGains => roll_cmd_rate, scale RAD2DEG
        ),
        param!(
            ParamDef::real(
                "LIM_AIL_DEG",
                25.0,
                1.0,
                25.0,
                "deg",
                "Aileron travel the autopilot may use",
            ),
            LateralGains => aileron_max, scale RAD2DEG
        ),
        param!(
            ParamDef::real(
                "LIM_RUD_DEG",
                25.0,
                1.0,
                25.0,
                "deg",
                "Rudder travel the autopilot may use",
            ),
            LateralGains => rudder_max, scale RAD2DEG
        ),
        param!(
            ParamDef::real(
                "TRIM_AIL_DEG",
                L.trim_aileron * RAD2DEG,
                -25.0,
                25.0,
                "deg",
                "Aileron trim, feed-forward of the roll loop (trim I)",
            ),
            LateralGains => trim_aileron, scale RAD2DEG
        ),
        param!(
            ParamDef::real(
                "TRIM_RUD_DEG",
                L.trim_rudder * RAD2DEG,
                -25.0,
                25.0,
                "deg",
                "Rudder trim, feed-forward of the rudder loops (trim I)",
            ),
            LateralGains => trim_rudder, scale RAD2DEG
        ),
    ],
    base: || FLIGHT,
    check: consistent,
};

/// What the ailerons do.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RollMode {
    /// Not engaged: aileron at trim, loops at rest.
    Off,
    /// Hold this roll angle, rad (limited to the roll limit).
    Roll(f32),
    /// Hold this course over ground, rad (any value; the error is wrapped to +-pi); the roll
    /// command grows at most `LIM_RLL_RATE_DEG`.
    Course(f32),
    /// Hold `course` (rad) banking no further than `roll_max` (rad; the roll limit when
    /// larger): close to the ground, where a wing tip would touch. The roll command is not
    /// slewed.
    CourseWithin {
        /// Course over ground, rad.
        course: f32,
        /// Largest roll angle, rad.
        roll_max: f32,
    },
}

/// What the rudder does in every mode the autopilot flies by itself: the yaw damper. The
/// airframe has no sideslip sensor, and the sideslip the estimator derives from the wind
/// triangle is circular (its wind filter assumes zero sideslip to find the wind), so a
/// sideslip-hold loop on it steers by the wind estimate's error: in light turbulence that held
/// 2-3 deg of sideslip and made the course error five times that of a flight on truth
/// (`docs/RESULTS-SITL.md`).
pub const RUDDER: YawMode = YawMode::Damper;

/// What the rudder does.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum YawMode {
    /// Not engaged: rudder at trim.
    Off,
    /// Yaw damper only.
    Damper,
    /// Yaw damper with this rudder added to it, rad (UMN sign): a pilot's yaw stick in
    /// Stabilized, as PX4's Stabilized passes the yaw stick to the rudder.
    DamperPlus(f32),
    /// Hold this sideslip angle, rad (normally 0), with the yaw damper.
    Sideslip(f32),
    /// The rudder at this deflection, rad (UMN sign, limited to the rudder limit): ground
    /// steering through the tail wheel, computed by the caller.
    Rudder(f32),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum RollKind {
    Off,
    Roll,
    Course,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum YawKind {
    Off,
    Damper,
    Sideslip,
}

/// Output of one lateral step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LateralOutput {
    /// Aileron, rad (UMN sign).
    pub aileron: f32,
    /// Rudder, rad (UMN sign).
    pub rudder: f32,
    /// Roll angle the roll loop was asked for, rad (NaN when the roll axis is off).
    pub roll_cmd: f32,
    /// The aileron was held at its last good value this step.
    pub aileron_held: bool,
    /// The rudder was held at its last good value this step.
    pub rudder_held: bool,
    /// Inputs refused this step.
    pub rejected: InputFlags,
}

/// The lateral autopilot: roll-rate damper inside PI roll inside PI course; PI sideslip plus
/// washed-out yaw damper on the rudder.
#[derive(Clone, Copy, Debug)]
pub struct Lateral {
    gains: LateralGains,
    roll: Pid,
    course: Pid,
    slip: Pid,
    washout: Washout,
    roll_kind: RollKind,
    yaw_kind: YawKind,
    aileron: f32,
    rudder: f32,
    roll_cmd: f32,
    roll_resume: bool,
    yaw_resume: bool,
    surface_scale: f32,
    course_scale: f32,
}

fn roll_gains(g: &LateralGains) -> PidGains {
    PidGains::symmetric(
        g.roll_kp,
        g.roll_ki,
        g.roll_rate_kd,
        g.aileron_max.min(SURFACE_LIMIT_RAD),
    )
}

fn course_gains(g: &LateralGains) -> PidGains {
    PidGains::symmetric(g.course_kp, g.course_ki, 0.0, g.roll_max)
}

fn slip_gains(g: &LateralGains) -> PidGains {
    PidGains::symmetric(
        g.slip_kp,
        g.slip_ki,
        0.0,
        g.rudder_max.min(SURFACE_LIMIT_RAD),
    )
}

fn dt_ok(dt: f32) -> bool {
    dt.is_finite() && dt > 0.0
}

impl Lateral {
    /// A disengaged lateral autopilot with these gains; `transfer_tc` is the bumpless fade time
    /// constant, s. Gains are expected to have passed [`super::GainSet::validate`].
    pub fn new(gains: &LateralGains, transfer_tc: f32) -> Self {
        Self {
            gains: *gains,
            roll: Pid::new(roll_gains(gains), transfer_tc),
            course: Pid::new(course_gains(gains), transfer_tc),
            slip: Pid::new(slip_gains(gains), transfer_tc),
            washout: Washout::new(gains.washout_pole),
            roll_kind: RollKind::Off,
            yaw_kind: YawKind::Off,
            aileron: gains.trim_aileron,
            rudder: gains.trim_rudder,
            roll_cmd: f32::NAN,
            roll_resume: false,
            yaw_resume: false,
            surface_scale: 1.0,
            course_scale: 1.0,
        }
    }

    /// The factor on the roll and rudder loops' inputs for this airspeed
    /// ([`super::scaling::surface_scale`]); 1 until set. A factor that is not finite and
    /// positive is ignored.
    pub fn set_surface_scale(&mut self, scale: f32) {
        if scale.is_finite() && scale > 0.0 {
            self.surface_scale = scale;
        }
    }

    /// Sets the factor on the course loop's error ([`super::scaling::course_scale`]); 1 until
    /// set. A factor that is not finite and positive is ignored.
    pub fn set_course_scale(&mut self, scale: f32) {
        if scale.is_finite() && scale > 0.0 {
            self.course_scale = scale;
        }
    }

    /// Replaces the gains in flight; engaged loops re-initialise bumplessly on the next step.
    pub fn set_gains(&mut self, gains: &LateralGains, transfer_tc: f32) {
        self.gains = *gains;
        self.roll.set_gains(roll_gains(gains), transfer_tc);
        self.course.set_gains(course_gains(gains), transfer_tc);
        self.slip.set_gains(slip_gains(gains), transfer_tc);
        self.washout.set_pole(gains.washout_pole);
        self.roll_resume = true;
        self.yaw_resume = true;
    }

    /// Makes the next engagement start from these surface positions (e.g. where the pilot held
    /// them) instead of the trim.
    pub fn handover(&mut self, aileron: f32, rudder: f32) {
        if self.roll_kind == RollKind::Off && aileron.is_finite() {
            self.aileron = aileron;
        }
        if self.yaw_kind == YawKind::Off && rudder.is_finite() {
            self.rudder = rudder;
        }
    }

    /// One step. Measurements a mode needs that are not finite (or a non-finite setpoint, or a
    /// bad `dt`) hold that surface at its last good value; the loops resume bumplessly when the
    /// inputs are good again.
    pub fn step(
        &mut self,
        m: &Measurements,
        roll: RollMode,
        yaw: YawMode,
        dt: f32,
    ) -> LateralOutput {
        let mut rejected = InputFlags::empty();
        let aileron_held = self.step_roll(m, roll, dt, &mut rejected);
        let rudder_held = self.step_yaw(m, yaw, dt, &mut rejected);
        LateralOutput {
            aileron: self.aileron,
            rudder: self.rudder,
            roll_cmd: if self.roll_kind == RollKind::Off {
                f32::NAN
            } else {
                self.roll_cmd
            },
            aileron_held,
            rudder_held,
            rejected,
        }
    }

    fn step_roll(
        &mut self,
        m: &Measurements,
        mode: RollMode,
        dt: f32,
        rejected: &mut InputFlags,
    ) -> bool {
        let g = &self.gains;
        let slewed = matches!(mode, RollMode::Course(_));
        let (kind, setpoint, within) = match mode {
            RollMode::Off => {
                self.roll.reset();
                self.course.reset();
                self.roll_kind = RollKind::Off;
                self.roll_resume = false;
                self.aileron = g.trim_aileron;
                return false;
            }
            RollMode::Roll(phi_c) => (RollKind::Roll, phi_c, g.roll_max),
            RollMode::Course(chi_c) => (RollKind::Course, chi_c, g.roll_max),
            // NaN (never from the navigator) leaves the roll limit alone.
            RollMode::CourseWithin { course, roll_max } if roll_max >= 0.0 => {
                (RollKind::Course, course, roll_max)
            }
            RollMode::CourseWithin { course, .. } => (RollKind::Course, course, g.roll_max),
        };
        let mut bad = InputFlags::empty();
        bad.set(InputFlags::ROLL, !m.roll.is_finite());
        bad.set(InputFlags::ROLL_RATE, !m.roll_rate.is_finite());
        bad.set(
            InputFlags::COURSE,
            kind == RollKind::Course && !m.course.is_finite(),
        );
        bad.set(InputFlags::COMMAND, !setpoint.is_finite());
        bad.set(InputFlags::DT, !dt_ok(dt));
        if !bad.is_empty() {
            *rejected |= bad;
            self.roll_resume = true;
            return true;
        }

        let prev = self.roll_kind;
        let restart = prev != kind || self.roll_resume;
        if prev == RollKind::Off || self.roll_resume {
            self.roll.reset_to(self.aileron, Bumpless::Integrator);
        }
        let phi_c = match kind {
            RollKind::Course => {
                if restart {
                    // From Off the course loop starts at the present bank; from Roll (or after a
                    // hold) at the roll command it replaces.
                    let from = if prev == RollKind::Off {
                        m.roll
                    } else {
                        self.roll_cmd
                    };
                    self.course.reset_to(from, Bumpless::Fade);
                }
                let e = wrap_pi(setpoint - m.course);
                // The tighter limit clamps the loop's output, not its integrator: the course
                // integral is slow (CRS_KI 0.01/s) and close to the ground lasts seconds.
                let phi = clamp(
                    self.course
                        .step(self.course_scale * e, Derivative::None, 0.0, dt),
                    -within,
                    within,
                );
                // A large course change asks the full bank at once: the roll loop, designed on
                // small steps, answers a 45 deg step on saturated ailerons at up to 200 deg/s
                // and an aircraft with the dispersion's weaker roll damping overshot to 60 deg
                // (docs/RESULTS-MONTECARLO.md). The command grows no faster than the roll loop
                // follows unsaturated; back towards level it moves at once. A course held
                // within a limit (the navigator's near the runway) is not slewed: there the
                // lag of the course loop's answer to gusts put wing tips on the runway in the
                // flare (11 -> 21 of 300 moderate-air landings).
                let from = if prev == RollKind::Off || !self.roll_cmd.is_finite() {
                    m.roll
                } else {
                    self.roll_cmd
                };
                let base = if phi * from > 0.0 { from } else { 0.0 };
                let step = g.roll_cmd_rate * dt;
                let grows = libm::fabsf(phi) > libm::fabsf(base);
                if g.roll_cmd_rate > 0.0 && slewed && grows {
                    clamp(base + clamp(phi - base, -step, step), -within, within)
                } else {
                    phi
                }
            }
            _ => {
                self.course.reset();
                clamp(setpoint, -g.roll_max, g.roll_max)
            }
        };
        let e = wrap_pi(phi_c - m.roll);
        let k = self.surface_scale;
        self.aileron = self
            .roll
            .step(k * e, Derivative::Rate(k * m.roll_rate), g.trim_aileron, dt);
        self.roll_cmd = phi_c;
        self.roll_kind = kind;
        self.roll_resume = false;
        false
    }

    fn step_yaw(
        &mut self,
        m: &Measurements,
        mode: YawMode,
        dt: f32,
        rejected: &mut InputFlags,
    ) -> bool {
        let g = &self.gains;
        // The sideslip commanded, and the rudder a pilot adds over the damper.
        let (kind, beta_c, added) = match mode {
            YawMode::Off => {
                self.slip.reset();
                self.washout.reset();
                self.yaw_kind = YawKind::Off;
                self.yaw_resume = false;
                self.rudder = g.trim_rudder;
                return false;
            }
            YawMode::Damper => (YawKind::Damper, 0.0, 0.0),
            YawMode::DamperPlus(d) => (YawKind::Damper, 0.0, d),
            YawMode::Sideslip(b) => (YawKind::Sideslip, b, 0.0),
            YawMode::Rudder(d) => {
                if !d.is_finite() {
                    rejected.set(InputFlags::COMMAND, true);
                    self.yaw_resume = true;
                    return true;
                }
                // The loops restart from here when a flying mode takes over again.
                self.yaw_kind = YawKind::Off;
                self.yaw_resume = false;
                self.slip.reset();
                self.washout.reset();
                self.rudder = clamp(d, -g.rudder_max, g.rudder_max);
                return false;
            }
        };
        let mut bad = InputFlags::empty();
        bad.set(InputFlags::YAW_RATE, !m.yaw_rate.is_finite());
        bad.set(
            InputFlags::SIDESLIP,
            kind == YawKind::Sideslip && !m.sideslip.is_finite(),
        );
        bad.set(
            InputFlags::COMMAND,
            !beta_c.is_finite() || !added.is_finite(),
        );
        bad.set(InputFlags::DT, !dt_ok(dt));
        if !bad.is_empty() {
            *rejected |= bad;
            self.yaw_resume = true;
            return true;
        }

        let prev = self.yaw_kind;
        if prev == YawKind::Off || self.yaw_resume {
            // Restart the washout from the present yaw rate: a steady turn gives no kick.
            self.washout.reset();
        }
        if prev != kind || self.yaw_resume {
            // Damper only: whatever the sideslip integrator held fades out. Sideslip hold: the
            // integrator takes over the present rudder.
            let how = if kind == YawKind::Damper {
                Bumpless::Fade
            } else {
                Bumpless::Integrator
            };
            self.slip.reset_to(self.rudder, how);
        }
        let k = self.surface_scale;
        let damper = k * g.yaw_damper_k * self.washout.step(m.yaw_rate, dt);
        let e = if kind == YawKind::Sideslip {
            beta_c - m.sideslip
        } else {
            0.0
        };
        self.rudder = self
            .slip
            .step(k * e, Derivative::None, g.trim_rudder + damper + added, dt);
        self.yaw_kind = kind;
        self.yaw_resume = false;
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DT: f32 = 0.02;
    const D: f32 = core::f32::consts::PI / 180.0;

    /// The thesis's gains without trims, and the course loop's roll command unslewed (the
    /// laws' algebra is checked one step at a time).
    fn zero_trim() -> LateralGains {
        let mut g = THESIS;
        g.trim_aileron = 0.0;
        g.trim_rudder = 0.0;
        g.roll_cmd_rate = 0.0;
        g
    }

    #[test]
    fn a_right_angle_course_change_banks_at_the_command_rate_and_holds_a_tighter_limit_at_once() {
        let g = THESIS;
        let m = Measurements::level(17.0, 100.0);
        let mut lat = Lateral::new(&g, 1.0);
        lat.step(&m, RollMode::Course(0.0), YawMode::Off, DT);
        // 90 deg/s: 1.8 deg a 20 ms step, the 45 deg limit after 25 steps.
        let mut o = lat.step(&m, RollMode::Course(90.0 * D), YawMode::Off, DT);
        assert!((o.roll_cmd - 1.8 * D).abs() < 1e-5, "{}", o.roll_cmd / D);
        for _ in 0..23 {
            o = lat.step(&m, RollMode::Course(90.0 * D), YawMode::Off, DT);
        }
        assert!((o.roll_cmd - 43.2 * D).abs() < 1e-4, "{}", o.roll_cmd / D);
        o = lat.step(&m, RollMode::Course(90.0 * D), YawMode::Off, DT);
        assert!((o.roll_cmd - 45.0 * D).abs() < 1e-4, "{}", o.roll_cmd / D);
        let within = RollMode::CourseWithin {
            course: 90.0 * D,
            roll_max: 10.0 * D,
        };
        o = lat.step(&m, within, YawMode::Off, DT);
        assert!((o.roll_cmd - 10.0 * D).abs() < 1e-5, "{}", o.roll_cmd / D);
        // Under the tighter limit the command is not slewed: the other way at once.
        let within_left = RollMode::CourseWithin {
            course: -90.0 * D,
            roll_max: 10.0 * D,
        };
        o = lat.step(&m, within_left, YawMode::Off, DT);
        assert!((o.roll_cmd + 10.0 * D).abs() < 1e-5, "{}", o.roll_cmd / D);
        o = lat.step(&m, within, YawMode::Off, DT);
        assert!((o.roll_cmd - 10.0 * D).abs() < 1e-5, "{}", o.roll_cmd / D);
        // Turned the other way: level at once, then the other bank at the command rate.
        o = lat.step(&m, RollMode::Course(-90.0 * D), YawMode::Off, DT);
        assert!((o.roll_cmd + 1.8 * D).abs() < 1e-5, "{}", o.roll_cmd / D);
        for _ in 0..30 {
            o = lat.step(&m, RollMode::Course(-90.0 * D), YawMode::Off, DT);
        }
        assert!((o.roll_cmd + 45.0 * D).abs() < 1e-4, "{}", o.roll_cmd / D);
        // Back towards level at once: a course error worth 4 deg of bank (and the little the
        // course integral holds).
        let near = RollMode::Course(-(4.0 / g.course_kp) * D);
        o = lat.step(&m, near, YawMode::Off, DT);
        assert!((o.roll_cmd + 4.0 * D).abs() < 1.0 * D, "{}", o.roll_cmd / D);
    }

    #[test]
    fn signs_follow_umn_convention() {
        // Each loop is engaged first (bumpless: output = trim), then disturbed.
        let mut lat = Lateral::new(&zero_trim(), 1.0);
        let m = Measurements::level(17.0, 100.0);
        lat.step(&m, RollMode::Roll(0.0), YawMode::Off, DT);
        // Asked to bank right: aileron negative (positive aileron rolls left).
        let o = lat.step(&m, RollMode::Roll(10.0 * D), YawMode::Off, DT);
        assert!(o.aileron < 0.0, "{o:?}");
        // Rolling right with no error: the damper adds positive aileron against it.
        let mut lat = Lateral::new(&zero_trim(), 1.0);
        let m2 = Measurements {
            roll_rate: 0.5,
            ..m
        };
        lat.step(&m, RollMode::Roll(0.0), YawMode::Off, DT);
        let o = lat.step(&m2, RollMode::Roll(0.0), YawMode::Off, DT);
        assert!((o.aileron - 0.0618 * 0.5).abs() < 1e-6, "{o:?}");
        // Yawing right (r > 0): the damper deflects the rudder positive (nose left).
        let mut lat = Lateral::new(&zero_trim(), 1.0);
        lat.step(&m, RollMode::Off, YawMode::Damper, DT);
        let o = lat.step(
            &Measurements { yaw_rate: 0.2, ..m },
            RollMode::Off,
            YawMode::Damper,
            DT,
        );
        assert!((o.rudder - 0.065 * 0.2).abs() < 1e-6, "{o:?}");
        // Positive sideslip: negative rudder (yaw the nose right, into the wind).
        let mut lat = Lateral::new(&zero_trim(), 1.0);
        lat.step(&m, RollMode::Off, YawMode::Sideslip(0.0), DT);
        let o = lat.step(
            &Measurements {
                sideslip: 0.05,
                ..m
            },
            RollMode::Off,
            YawMode::Sideslip(0.0),
            DT,
        );
        assert!(o.rudder < 0.0, "{o:?}");
        // Course to the right of the present one: bank right.
        let mut lat = Lateral::new(&zero_trim(), 1.0);
        lat.step(&m, RollMode::Course(0.0), YawMode::Off, DT);
        let o = lat.step(&m, RollMode::Course(5.0 * D), YawMode::Off, DT);
        assert!(o.roll_cmd > 0.0 && o.aileron < 0.0, "{o:?}");
    }

    /// A pilot's yaw stick in Stabilized: its rudder is added to the damper's, to the
    /// radian, within the rudder's limit; a stick that is not a number is refused and the
    /// last rudder kept.
    #[test]
    fn the_yaw_stick_s_rudder_adds_to_the_damper_s_within_the_limit_and_a_nan_keeps_the_last() {
        let g = zero_trim();
        let mut lat = Lateral::new(&g, 1.0);
        let m = Measurements {
            yaw_rate: 0.2,
            ..Measurements::level(17.0, 100.0)
        };
        lat.step(&m, RollMode::Off, YawMode::Damper, DT);
        let damped = lat.step(&m, RollMode::Off, YawMode::Damper, DT).rudder;
        let o = lat.step(&m, RollMode::Off, YawMode::DamperPlus(-0.1), DT);
        assert!((o.rudder - (damped - 0.1)).abs() < 1e-6, "{o:?} {damped}");
        let o = lat.step(&m, RollMode::Off, YawMode::DamperPlus(-1.0), DT);
        assert!((o.rudder + g.rudder_max).abs() < 1e-6, "{o:?}");
        let held = o.rudder;
        let o = lat.step(&m, RollMode::Off, YawMode::DamperPlus(f32::NAN), DT);
        assert_eq!(o.rudder, held);
        assert!(o.rejected.contains(InputFlags::COMMAND), "{o:?}");
    }

    #[test]
    fn course_error_wraps_across_180_deg() {
        let g = zero_trim();
        let m = Measurements {
            course: 179.0 * D,
            ..Measurements::level(17.0, 100.0)
        };
        // Command -179 deg from 179 deg: 2 deg to the right, not 358 to the left.
        let mut lat = Lateral::new(&g, 1.0);
        lat.step(&m, RollMode::Course(179.0 * D), YawMode::Off, DT);
        let o = lat.step(&m, RollMode::Course(-179.0 * D), YawMode::Off, DT);
        let expected = g.course_kp * 2.0 * D + g.course_ki * 2.0 * D * DT;
        assert!(
            (o.roll_cmd - expected).abs() < 1e-4,
            "{} vs {expected}",
            o.roll_cmd
        );
        // And the other way round.
        let m = Measurements {
            course: -179.0 * D,
            ..m
        };
        let mut lat = Lateral::new(&g, 1.0);
        lat.step(&m, RollMode::Course(-179.0 * D), YawMode::Off, DT);
        let o = lat.step(&m, RollMode::Course(179.0 * D), YawMode::Off, DT);
        assert!((o.roll_cmd + expected).abs() < 1e-4, "{}", o.roll_cmd);
        // Commands beyond +-pi are the same course.
        let mut lat = Lateral::new(&g, 1.0);
        lat.step(&m, RollMode::Course(-179.0 * D), YawMode::Off, DT);
        let o2 = lat.step(
            &m,
            RollMode::Course(179.0 * D + 4.0 * core::f32::consts::PI),
            YawMode::Off,
            DT,
        );
        assert!((o2.roll_cmd - o.roll_cmd).abs() < 1e-3);
    }

    #[test]
    fn roll_command_limited_to_45_deg() {
        let mut lat = Lateral::new(&zero_trim(), 1.0);
        let m = Measurements::level(17.0, 100.0);
        let o = lat.step(&m, RollMode::Course(0.0), YawMode::Off, DT);
        assert_eq!(o.roll_cmd, 0.0);
        let o = lat.step(&m, RollMode::Course(150.0 * D), YawMode::Off, DT);
        assert!((o.roll_cmd - 45.0 * D).abs() < 1e-6, "{}", o.roll_cmd / D);
        let o = lat.step(&m, RollMode::Roll(-80.0 * D), YawMode::Off, DT);
        assert!((o.roll_cmd + 45.0 * D).abs() < 1e-6);
        // Aileron inside the servo limit whatever the error.
        let wild = Measurements { roll: 3.0, ..m };
        let o = lat.step(&wild, RollMode::Roll(-80.0 * D), YawMode::Off, DT);
        assert!(o.aileron.abs() <= SURFACE_LIMIT_RAD + 1e-6);
    }

    /// Close to the ground the course loop banks no further than it is allowed, either way,
    /// whatever the course error; a limit above the roll limit leaves the roll limit, and a
    /// NaN limit is ignored.
    #[test]
    fn a_course_held_within_a_bank_limit_banks_no_further() {
        let mut lat = Lateral::new(&zero_trim(), 1.0);
        let m = Measurements::level(17.0, 100.0);
        for (course, roll_max, expected) in [
            (150.0f32, 5.0f32, 5.0f32),
            (-150.0, 5.0, -5.0),
            (150.0, 20.0, 20.0),
            (150.0, 80.0, 45.0),
            (150.0, f32::NAN, 45.0),
        ] {
            // Past the bumpless fade from the previous command.
            let mut o = LateralOutput::default();
            for _ in 0..500 {
                o = lat.step(
                    &m,
                    RollMode::CourseWithin {
                        course: course * D,
                        roll_max: roll_max * D,
                    },
                    YawMode::Off,
                    DT,
                );
                assert!(o.roll_cmd.abs() <= expected.abs() * D + 1e-6);
            }
            assert!(
                (o.roll_cmd - expected * D).abs() < 1e-6,
                "{course} within {roll_max}: {}",
                o.roll_cmd / D
            );
        }
    }

    #[test]
    fn engaging_and_mode_changes_are_bumpless() {
        let g = THESIS;
        let mut lat = Lateral::new(&g, 1.0);
        let m = Measurements {
            roll: 12.0 * D,
            roll_rate: 0.1,
            yaw_rate: 0.05,
            sideslip: 0.02,
            ..Measurements::level(17.0, 100.0)
        };
        // Pilot held some aileron and rudder; engaging starts from there.
        lat.handover(0.07, -0.03);
        let o = lat.step(&m, RollMode::Course(1.0), YawMode::Sideslip(0.0), DT);
        assert!((o.aileron - 0.07).abs() < 1e-6, "{o:?}");
        assert!((o.rudder + 0.03).abs() < 1e-6, "{o:?}");
        // Course loop started at the present bank.
        assert!((o.roll_cmd - 12.0 * D).abs() < 1e-6);
        // Course -> roll -> course: the course loop picks up the roll command it replaces.
        let o = lat.step(&m, RollMode::Roll(20.0 * D), YawMode::Damper, DT);
        let rudder_before = o.rudder;
        let o = lat.step(&m, RollMode::Course(1.0), YawMode::Damper, DT);
        assert!((o.roll_cmd - 20.0 * D).abs() < 1e-6, "{}", o.roll_cmd / D);
        // Damper-only rudder: continuous at the switch, then the sideslip loop's share fades.
        assert!((o.rudder - rudder_before).abs() < 0.01);
    }
}
