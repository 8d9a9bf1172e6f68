//! The loops of the design, the margins each must keep, and why a design fails.

use super::inputs::{GAIN_MARGIN_MIN_DB, INNER_PHASE_MARGIN_MIN_DEG, OUTER_PHASE_MARGIN_MIN_DEG};
use super::margins::Margins;
use crate::control::autopilot::GainError;
use crate::decimal::trimmed;
use core::fmt;

/// The loops the design closes, inner to outer (the order they are designed in: each outer
/// loop is designed with the loop inside it closed).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Loop {
    /// Roll attitude, PID on the aileron (`RLL_KP`, `RLL_KI`, `RLL_RATE_KD`).
    Roll,
    /// Course, PI on the commanded roll (`CRS_KP`, `CRS_KI`).
    Course,
    /// Sideslip, PI on the rudder (`SLIP_KP`, `SLIP_KI`): designed where the model has a
    /// sideslip model, else the base set's gains stay.
    Sideslip,
    /// Pitch attitude, PID on the elevator (`PTCH_KP`, `PTCH_KI`, `PTCH_RATE_KD`).
    Pitch,
    /// Altitude, PI on the commanded pitch (`ALT_KP`, `ALT_KI`).
    Altitude,
    /// Airspeed by pitch, the climb and descent regimes (`ASPD_PTCH_KP`, `ASPD_PTCH_KI`).
    AirspeedPitch,
    /// Airspeed by throttle, the altitude-hold regime (`ASPD_THR_KP`, `ASPD_THR_KI`).
    AirspeedThrottle,
}

impl Loop {
    /// Every loop, in the order of the design.
    pub const ALL: [Loop; 7] = [
        Loop::Roll,
        Loop::Course,
        Loop::Sideslip,
        Loop::Pitch,
        Loop::Altitude,
        Loop::AirspeedPitch,
        Loop::AirspeedThrottle,
    ];

    /// A short name, for a STATUSTEXT.
    pub const fn name(self) -> &'static str {
        match self {
            Loop::Roll => "roll",
            Loop::Course => "course",
            Loop::Sideslip => "sideslip",
            Loop::Pitch => "pitch",
            Loop::Altitude => "altitude",
            Loop::AirspeedPitch => "aspd-pitch",
            Loop::AirspeedThrottle => "aspd-thr",
        }
    }

    /// Whether it is an inner (attitude) loop.
    pub const fn is_inner(self) -> bool {
        matches!(self, Loop::Roll | Loop::Pitch)
    }

    /// The phase margin it must keep, deg.
    pub const fn phase_margin_min_deg(self) -> f32 {
        if self.is_inner() {
            INNER_PHASE_MARGIN_MIN_DEG
        } else {
            OUTER_PHASE_MARGIN_MIN_DEG
        }
    }

    /// Its gain parameters: proportional, integral and, for the attitude loops, the rate
    /// damper's.
    pub const fn params(self) -> &'static [&'static str] {
        match self {
            Loop::Roll => &["RLL_KP", "RLL_KI", "RLL_RATE_KD"],
            Loop::Course => &["CRS_KP", "CRS_KI"],
            Loop::Sideslip => &["SLIP_KP", "SLIP_KI"],
            Loop::Pitch => &["PTCH_KP", "PTCH_KI", "PTCH_RATE_KD"],
            Loop::Altitude => &["ALT_KP", "ALT_KI"],
            Loop::AirspeedPitch => &["ASPD_PTCH_KP", "ASPD_PTCH_KI"],
            Loop::AirspeedThrottle => &["ASPD_THR_KP", "ASPD_THR_KI"],
        }
    }

    /// The loop whose gain `param` is (`None`: a parameter the design does not set).
    pub fn of_param(param: &str) -> Option<Loop> {
        Loop::ALL.into_iter().find(|l| l.params().contains(&param))
    }
}

/// Why a design fails.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Reason {
    /// A coefficient, input or gain that is NaN or infinite (named).
    NotFinite(&'static str),
    /// A coefficient or input outside the range the rules hold for (named: an airspeed,
    /// gravity, servo bandwidth, feedback pole or delay that is not positive).
    OutOfRange(&'static str),
    /// `|L|` never crosses 1 in the band: there is no loop gain to judge, so the loop cannot be
    /// shown stable.
    NoCrossover,
    /// The gain margin, dB, is below [`GAIN_MARGIN_MIN_DB`] (or NaN).
    GainMargin(f32),
    /// The phase margin, deg, is below the loop's target ([`Loop::phase_margin_min_deg`]).
    PhaseMargin {
        /// The margin, deg.
        deg: f32,
        /// The target, deg.
        min_deg: f32,
    },
    /// The gain set refused a designed gain (the parameter named in the error).
    GainSet(GainError),
}

impl fmt::Display for Reason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Reason::NotFinite(what) => write!(f, "{what} not finite"),
            Reason::OutOfRange(what) => write!(f, "{what} out of range"),
            Reason::NoCrossover => f.write_str("no crossover"),
            Reason::GainMargin(db) => write!(
                f,
                "gain margin {} dB < {}",
                trimmed(*db, 1),
                trimmed(GAIN_MARGIN_MIN_DB, 1)
            ),
            Reason::PhaseMargin { deg, min_deg } => write!(
                f,
                "phase margin {} deg < {}",
                trimmed(*deg, 1),
                trimmed(*min_deg, 1)
            ),
            // Shorter than the gain set's own text, for a STATUSTEXT.
            Reason::GainSet(GainError::NotFinite(n)) => write!(f, "{n} not finite"),
            Reason::GainSet(GainError::OutOfBounds(n)) => write!(f, "{n} out of bounds"),
            Reason::GainSet(GainError::Inconsistent(n)) => write!(f, "{n} inconsistent"),
            Reason::GainSet(GainError::Unknown) => f.write_str("unknown gain"),
        }
    }
}

/// A design that failed: the loop, and why (`None`: a gain of the base set that no loop
/// designs was refused).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DesignFailure {
    /// The loop that failed.
    pub loop_: Option<Loop>,
    /// Why.
    pub reason: Reason,
}

impl fmt::Display for DesignFailure {
    /// `roll: gain margin 3.2 dB < 6`: with a prefix of up to 8 characters, within a
    /// STATUSTEXT's 50.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = self.loop_.map_or("gains", Loop::name);
        write!(f, "{name}: {}", self.reason)
    }
}

/// Whether `margins` meet `loop_`'s targets ([`judge_margins`] with the loop's phase margin).
pub fn judge(loop_: Loop, margins: &Margins) -> Result<(), Reason> {
    judge_margins(margins, loop_.phase_margin_min_deg())
}

/// Whether `margins` meet the targets: at least [`GAIN_MARGIN_MIN_DB`] of gain margin where the
/// phase crosses -180 deg (none crossing: unbounded), and a gain crossover with at least
/// `phase_margin_min_deg` of phase margin. The gain margin is judged first.
pub fn judge_margins(margins: &Margins, phase_margin_min_deg: f32) -> Result<(), Reason> {
    if let Some(gm) = margins.gain_margin_db {
        if gm.is_nan() || gm < GAIN_MARGIN_MIN_DB {
            return Err(Reason::GainMargin(gm));
        }
    }
    let min_deg = phase_margin_min_deg;
    match margins.phase_margin_deg {
        None => Err(Reason::NoCrossover),
        Some(deg) if deg.is_nan() || deg < min_deg => Err(Reason::PhaseMargin { deg, min_deg }),
        Some(_) => Ok(()),
    }
}
