//! `MAV_CMD_DO_AUTOTUNE_ENABLE` as QGroundControl's autotune speaks it, and the autotune's
//! reports in words.
//!
//! QGroundControl sends the command once to start and again every second while it waits,
//! reading the answer's `progress` (under 20 starting, 20-39 roll, 40-59 pitch, 60-79 the third
//! axis, 100 done) until a final answer: so a command while one runs is a question, answered
//! `IN_PROGRESS` with where it stands, not a second autotune. The end is told to the station
//! that started it as a final `COMMAND_ACK` (`ACCEPTED` with progress 100, or `FAILED`), and
//! for a few seconds after it a repeated command is answered with that end rather than taken
//! for a new start (a poll already on its way). A start the vehicle refuses on its own state
//! (which moved since the snapshot the link checked) is told by the vehicle's STATUSTEXT; its
//! station gets no final answer.

use super::outbox::Outbox;
use super::peer::Peer;
use super::texts::{Line, TEXT_MAX};
use crate::control::autopilot::GainError;
use crate::decimal::{trimmed, Decimal};
use crate::tuning::autotune::{excite::Stage, Abort, Failure, Report, Status};
use crate::tuning::design::{DesignFailure, Loop, Reason, GAIN_MARGIN_MIN_DB};
use crate::tuning::identify::Axis;
use crate::vehicle::snapshot::{LandedState, VehicleSnapshot};
use crate::vehicle::tune::refusal;
use mavlink::dialects::common::{MavCmd, MavResult, MavSeverity};

/// How long after an autotune's end a repeated command is answered with that end, us.
const END_ANSWERED_US: u64 = 3_000_000;

/// What the link keeps of the autotune between commands.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TuneService {
    /// The station that started the one running (owed the final answer).
    starter: Option<Peer>,
    /// The vehicle was seen running it: an end before that is the previous autotune's.
    seen_running: bool,
    /// The last one's end: its answer and when the link told it, us.
    ended: Option<(MavResult, u64)>,
}

impl TuneService {
    /// A `MAV_CMD_DO_AUTOTUNE_ENABLE` (`enable`: param1 = 1) from `from`: the answer and its
    /// progress, and whether the vehicle is to be asked to start (`Some(true)`) or stop or
    /// revert (`Some(false)`).
    pub(crate) fn command(
        &mut self,
        enable: bool,
        v: &VehicleSnapshot,
        now_us: u64,
        from: Peer,
        out: &mut Outbox,
    ) -> (MavResult, u8, Option<bool>) {
        if !enable {
            self.starter = None;
            return (MavResult::MAV_RESULT_ACCEPTED, 0, Some(false));
        }
        if let Status::Running(progress) = v.autotune {
            return (MavResult::MAV_RESULT_IN_PROGRESS, progress, None);
        }
        if let Some((result, at)) = self.ended {
            if now_us.saturating_sub(at) < END_ANSWERED_US {
                return (result, end_progress(result), None);
            }
        }
        let sensors_ok = v.health.gps_ok && v.health.airspeed_ok;
        let in_air = v.landed == LandedState::InAir;
        if let Some(why) = refusal(v.armed, in_air, v.mode, v.failsafe, sensors_ok) {
            out.texts_mut()
                .push_str(MavSeverity::MAV_SEVERITY_WARNING, why);
            return (MavResult::MAV_RESULT_DENIED, 0, None);
        }
        self.starter = Some(from);
        self.seen_running = false;
        self.ended = None;
        (MavResult::MAV_RESULT_IN_PROGRESS, 0, Some(true))
    }

    /// Watches the snapshot for the end of the autotune a station started, and answers it.
    pub(crate) fn poll(&mut self, v: &VehicleSnapshot, now_us: u64, out: &mut Outbox) {
        let result = match v.autotune {
            Status::Succeeded => MavResult::MAV_RESULT_ACCEPTED,
            Status::Failed => MavResult::MAV_RESULT_FAILED,
            Status::Running(_) => {
                self.seen_running = true;
                return;
            }
            Status::Idle => return,
        };
        if !self.seen_running {
            return;
        }
        if let Some(to) = self.starter.take() {
            out.ack_progress(
                MavCmd::MAV_CMD_DO_AUTOTUNE_ENABLE,
                result,
                end_progress(result),
                to,
            );
            self.ended = Some((result, now_us));
        }
    }
}

/// The progress a final answer carries: 100 for success, as QGroundControl reads it.
fn end_progress(result: MavResult) -> u8 {
    if result == MavResult::MAV_RESULT_ACCEPTED {
        100
    } else {
        0
    }
}

/// A report of the autotune in words, with its severity.
pub fn words(r: &Report) -> (MavSeverity, Line<TEXT_MAX>) {
    let mut l = Line::new();
    // One STATUSTEXT each (50 characters): an abort or a failure says so first; the gains are
    // only ever changed by the one report that says "gains applied".
    l.str(match r {
        Report::Aborted(_) => "Autotune aborted: ",
        Report::Failed(_) => "Autotune failed: ",
        _ => "Autotune: ",
    });
    let severity = match r {
        Report::Started => {
            l.str("started, level flight");
            MavSeverity::MAV_SEVERITY_INFO
        }
        Report::Stage(s) => {
            l.str(match s {
                Stage::Level => "level flight",
                Stage::Roll => "roll doublets",
                Stage::Yaw => "rudder doublets",
                Stage::Pitch => "pitch doublets",
                Stage::Throttle => "throttle steps",
            });
            MavSeverity::MAV_SEVERITY_INFO
        }
        Report::Fitted(axis, c, r2) => {
            // One STATUSTEXT: the values in the order of the axis's `ATUN_A_*` parameters.
            l.str(axis.name());
            let shown = if *axis == Axis::Pitch { 3 } else { 2 };
            for value in c.iter().take(shown) {
                l.str(" ").decimal(significant(*value));
            }
            l.str(" R2 ").decimal(trimmed(*r2, 2));
            MavSeverity::MAV_SEVERITY_INFO
        }
        Report::Applied => {
            l.str("every loop met its margins");
            MavSeverity::MAV_SEVERITY_NOTICE
        }
        Report::Aborted(a) => {
            abort_words(&mut l, a);
            MavSeverity::MAV_SEVERITY_WARNING
        }
        Report::Failed(f) => {
            failure_words(&mut l, f);
            MavSeverity::MAV_SEVERITY_WARNING
        }
    };
    (severity, l)
}

fn abort_words(l: &mut Line<TEXT_MAX>, a: &Abort) {
    let limit = |l: &mut Line<TEXT_MAX>, what: &str, v: f32, unit: &str| {
        l.str(what).str(" ").decimal(trimmed(v, 1)).str(unit);
    };
    match *a {
        Abort::Bank(d) => limit(l, "bank", d, " deg"),
        Abort::Pitch(d) => limit(l, "pitch change", d, " deg"),
        Abort::HeightLoss(m) => limit(l, "height lost", m, " m"),
        Abort::Airspeed(v) => limit(l, "airspeed", v, " m/s"),
        Abort::ModeChanged => {
            l.str("mode changed");
        }
        Abort::Failsafe => {
            l.str("failsafe");
        }
        Abort::Landed => {
            l.str("not flying");
        }
        Abort::Sensors => {
            l.str("GPS or airspeed sensor failed");
        }
        Abort::Station => {
            l.str("stopped by the station");
        }
    }
}

fn failure_words(l: &mut Line<TEXT_MAX>, f: &Failure) {
    match *f {
        Failure::NotExcited(axis) => {
            l.str(axis.name()).str(" not excited");
        }
        Failure::Singular(axis) => {
            l.str(axis.name()).str(" model singular");
        }
        Failure::PoorFit(axis, r2) => {
            l.str(axis.name())
                .str(" fit R2 ")
                .decimal(trimmed(r2, 2))
                .str(" too low");
        }
        Failure::Design(d) => design_words(l, &d),
    }
}

/// The design's failure as [`DesignFailure`]'s `Display` words it, built from pieces (no
/// `core::fmt` in the image).
fn design_words(l: &mut Line<TEXT_MAX>, d: &DesignFailure) {
    l.str(d.loop_.map_or("gains", Loop::name)).str(": ");
    let below = |l: &mut Line<TEXT_MAX>, what: &str, v: f32, unit: &str, min: f32| {
        l.str(what)
            .str(" ")
            .decimal(trimmed(v, 1))
            .str(unit)
            .str(" < ")
            .decimal(trimmed(min, 1));
    };
    match d.reason {
        Reason::NotFinite(what) | Reason::GainSet(GainError::NotFinite(what)) => {
            l.str(what).str(" not finite");
        }
        Reason::OutOfRange(what) => {
            l.str(what).str(" out of range");
        }
        Reason::NoCrossover => {
            l.str("no crossover");
        }
        // GM and PM, as control engineers write them: the words "phase margin" took the
        // target off the end of a 50-character STATUSTEXT for the longer loops' names.
        Reason::GainMargin(db) => below(l, "GM", db, " dB", GAIN_MARGIN_MIN_DB),
        Reason::PhaseMargin { deg, min_deg } => below(l, "PM", deg, " deg", min_deg),
        Reason::GainSet(GainError::OutOfBounds(what)) => {
            l.str(what).str(" out of bounds");
        }
        Reason::GainSet(GainError::Inconsistent(what)) => {
            l.str(what).str(" inconsistent");
        }
        Reason::GainSet(GainError::Unknown) => {
            l.str("unknown gain");
        }
    }
}

/// `v` to three or four significant figures (one decimal at least under 1000).
fn significant(v: f32) -> Decimal {
    let a = v.abs();
    let places = if a >= 100.0 {
        1
    } else if a >= 10.0 {
        2
    } else {
        3
    };
    trimmed(v, places)
}
