//! The verdict on one flight: the named criteria ([`crate::flight::criteria`], each with its
//! threshold), all judged here, from the facts a flight leaves ([`Facts`]).
//!
//! The facts come from what the simulator has today: the flight summary's figures, the
//! plant's first contact of the landing, the autopilot's own landed state at the end, and
//! the clearance of every non-wheel point of the airframe, computed from the plant's
//! ground-contact geometry at each frame ([`crate::flight::strikes`], which the flight summary
//! judges strikes by as well). When the plant reports strikes itself, or the autopilot gains a
//! land detector, [`judge`] is the one place to read them instead.

use crate::flight::strikes::{kind, strike_free};
use serde::{Deserialize, Serialize};

pub use crate::flight::criteria::{Criterion, LOC_BANK_DEG, LOC_PITCH_DEG, SINK_MPS, TOUCHDOWN_M};

/// Clearance that counts as a full margin against a strike, m: about what the undispersed
/// aircraft keeps at rest under its tail and its propeller (5 cm).
pub const CLEARANCE_REF_M: f64 = 0.05;

/// What a flight left that the criteria read. `None`: not measured (no touchdown, or the
/// flight did not run).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Facts {
    /// Why the flight did not run to its end, if it did not.
    pub error: Option<String>,
    /// Largest |bank| while armed, deg.
    pub max_bank_deg: Option<f64>,
    /// Largest |pitch| while armed, deg.
    pub max_pitch_deg: Option<f64>,
    /// Every navigation item reached.
    pub all_items_reached: bool,
    /// Touchdown distance from the landing point, m.
    pub touchdown_m: Option<f64>,
    /// Sink rate at touchdown, m/s.
    pub sink_mps: Option<f64>,
    /// Smallest clearance of a non-wheel point while armed, m (negative: it touched).
    pub min_clearance_m: Option<f64>,
    /// The autopilot's landed state agrees with the truth at the end.
    pub landed_state_agrees: bool,
    /// The truth is on the ground at the end and the autopilot has disarmed.
    pub disarmed_on_ground: bool,
    /// The truth is on the ground at the end.
    pub on_ground: bool,
    /// Failsafes raised.
    pub failsafes: Vec<String>,
    /// When control was first lost, s, and the navigator's phase then.
    pub loss_of_control: Option<(f64, String)>,
    /// When the smallest clearance came, s, the point and the phase then.
    pub closest_call: Option<(f64, String, String)>,
    /// When the landing's first contact came, s, and where along the approach, m.
    pub touchdown_at: Option<(f64, f64)>,
    /// Items reached and the mission's navigation items.
    pub items: (u32, u32),
}

/// The verdict on one flight.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Verdict {
    /// Every criterion met.
    pub pass: bool,
    /// The criteria not met, by name, in [`Criterion::ALL`] order.
    pub failed: Vec<String>,
    /// The smallest margin to a threshold: `1 - value / limit` over touchdown distance, sink
    /// rate, bank and pitch, and the smallest clearance over [`CLEARANCE_REF_M`] (1: far from
    /// every limit, 0: on one, negative: beyond); -1 when a criterion without a continuous
    /// figure failed. Orders flights from worst to best.
    pub margin: f64,
    /// What went wrong first (`None` for a passing flight): the earliest of the failures
    /// that have a time, in words, with the phase of flight.
    pub cause: Option<String>,
}

/// Judges the facts.
pub fn judge(f: &Facts) -> Verdict {
    let ran = f.error.is_none();
    let within = |v: Option<f64>, limit: f64, strict: bool| {
        v.is_some_and(|v| if strict { v < limit } else { v <= limit })
    };
    let met = |c: Criterion| match c {
        Criterion::Flown => ran,
        Criterion::Control => {
            ran && within(f.max_bank_deg, LOC_BANK_DEG, false)
                && within(f.max_pitch_deg, LOC_PITCH_DEG, false)
        }
        Criterion::Items => ran && f.all_items_reached,
        Criterion::Touchdown => ran && within(f.touchdown_m, TOUCHDOWN_M, false),
        Criterion::Sink => ran && within(f.sink_mps, SINK_MPS, true),
        Criterion::NoStrike => ran && strike_free(f.min_clearance_m),
        Criterion::LandedState => {
            ran && f.landed_state_agrees && (!f.on_ground || f.disarmed_on_ground)
        }
        Criterion::Failsafe => ran && f.failsafes.is_empty(),
    };
    let failed: Vec<String> = Criterion::ALL
        .into_iter()
        .filter(|&c| !met(c))
        .map(|c| c.name().to_string())
        .collect();
    let ratios = [
        (f.touchdown_m, TOUCHDOWN_M),
        (f.sink_mps, SINK_MPS),
        (f.max_bank_deg, LOC_BANK_DEG),
        (f.max_pitch_deg, LOC_PITCH_DEG),
    ];
    let clearance = f
        .min_clearance_m
        .map_or(-1.0, |c| (c / CLEARANCE_REF_M).min(1.0));
    let mut margin = ratios
        .iter()
        .map(|(v, limit)| v.map_or(-1.0, |v| 1.0 - v / limit))
        .fold(clearance, f64::min);
    let continuous = ["control", "touchdown", "sink", "no_strike"];
    if failed.iter().any(|c| !continuous.contains(&c.as_str())) {
        margin = margin.min(-1.0);
    }
    let cause = (!failed.is_empty()).then(|| cause(f, &failed));
    Verdict {
        pass: failed.is_empty(),
        failed,
        margin,
        cause,
    }
}

/// The first thing that went wrong: timed events in order, then what has no time.
fn cause(f: &Facts, failed: &[String]) -> String {
    if let Some(e) = &f.error {
        return format!("not flown: {e}");
    }
    let has = |c: Criterion| failed.iter().any(|n| n == c.name());
    let mut timed: Vec<(f64, String)> = Vec::new();
    if has(Criterion::Control) {
        if let Some((t, phase)) = &f.loss_of_control {
            timed.push((*t, format!("loss of control in {phase}")));
        }
    }
    if has(Criterion::NoStrike) {
        if let Some((t, point, phase)) = &f.closest_call {
            timed.push((*t, format!("{} strike in {phase}", kind(point))));
        }
    }
    if let Some((t, along)) = f.touchdown_at {
        let how_far = if along >= 0.0 { "long" } else { "short" };
        if has(Criterion::Sink) {
            let sink = f.sink_mps.unwrap_or(f64::NAN);
            timed.push((t, format!("hard landing ({sink:.1} m/s)")));
        } else if has(Criterion::Touchdown) {
            let d = f.touchdown_m.unwrap_or(f64::NAN);
            timed.push((t, format!("landing {d:.0} m {how_far}")));
        }
    }
    timed.sort_by(|a, b| a.0.total_cmp(&b.0));
    if let Some((t, what)) = timed.first() {
        return format!("{what} at {t:.1} s");
    }
    if has(Criterion::Items) {
        return format!("{} of {} items reached", f.items.0, f.items.1);
    }
    if has(Criterion::Touchdown) || has(Criterion::Sink) {
        return "no touchdown".into();
    }
    if has(Criterion::Failsafe) {
        return format!("failsafe: {}", f.failsafes.join("; "));
    }
    "landed state: the autopilot's at the end disagrees with the truth".into()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn good() -> Facts {
        Facts {
            max_bank_deg: Some(40.0),
            max_pitch_deg: Some(12.0),
            all_items_reached: true,
            touchdown_m: Some(6.0),
            sink_mps: Some(0.8),
            min_clearance_m: Some(0.05),
            landed_state_agrees: true,
            disarmed_on_ground: true,
            on_ground: true,
            ..Facts::default()
        }
    }

    #[test]
    fn a_good_flight_passes_with_its_margin_set_by_the_bank() {
        let v = judge(&good());
        assert!(v.pass && v.cause.is_none(), "{v:?}");
        // 1 - 40/60 = 0.333 is the smallest of 0.8, 0.6, 0.333, 0.657 and 0.05/0.05 = 1.
        assert!((v.margin - 1.0 / 3.0).abs() < 1e-12, "{}", v.margin);
    }

    #[test]
    fn each_broken_threshold_fails_its_own_criterion_only() {
        type Spoil = fn(&mut Facts);
        let cases: [(Spoil, &str); 7] = [
            (|f| f.max_bank_deg = Some(61.0), "control"),
            (|f| f.all_items_reached = false, "items"),
            (|f| f.touchdown_m = Some(30.5), "touchdown"),
            (|f| f.sink_mps = Some(2.0), "sink"),
            (|f| f.min_clearance_m = Some(-0.01), "no_strike"),
            (|f| f.landed_state_agrees = false, "landed_state"),
            (
                |f| f.failsafes = vec!["Failsafe: GPS lost".into()],
                "failsafe",
            ),
        ];
        for (spoil, name) in cases {
            let mut f = good();
            spoil(&mut f);
            let v = judge(&f);
            assert_eq!(v.failed, vec![name.to_string()], "{name}");
            assert!(v.margin <= 0.0, "{name}: {}", v.margin);
            assert!(v.cause.is_some(), "{name}");
        }
    }

    #[test]
    fn the_cause_is_the_earliest_timed_failure_with_its_phase() {
        let f = Facts {
            max_bank_deg: Some(90.0),
            loss_of_control: Some((120.0, "waypoint".into())),
            min_clearance_m: Some(-0.01),
            closest_call: Some((
                14.2,
                "left wing tip (belly_points_m[3])".into(),
                "take-off climb".into(),
            )),
            ..good()
        };
        let v = judge(&f);
        assert_eq!(v.failed, ["control", "no_strike"]);
        assert_eq!(
            v.cause.as_deref(),
            Some("left wing tip strike in take-off climb at 14.2 s")
        );
    }

    #[test]
    fn a_flight_that_did_not_run_fails_every_criterion() {
        let f = Facts {
            error: Some("level trim did not converge".into()),
            ..good()
        };
        assert_eq!(judge(&f).failed.len(), Criterion::ALL.len());
    }
}
