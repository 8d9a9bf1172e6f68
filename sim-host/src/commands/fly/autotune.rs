//! What `sim-host fly --autotune` reports: the coefficients the vehicle identified on board
//! (read back as its `ATUN_A_*` parameters, as a station reads them) against the aircraft
//! file's linearisation at the airspeed it was flown at, the gains before and after, each
//! loop's margins as designed on the identified model, and the thesis's script (or, with
//! `--mission`, the mission) flown on the default gains beside the same flown after the
//! autotune.

use crate::aircraft::Aircraft;
use crate::commands::linearize::linearize_report_at;
use crate::commands::mission_tables::meets_targets;
use crate::flight::missions::AUTOTUNE_GAINS;
use crate::flight::summary::{MissionSummary, Segment};
use crate::flight::FlightOutcome;
use crate::report::table::Table;
use crate::report::{sig, sig_or_dash};
use common::control::autopilot::GainSet;
use common::tuning::autotune::params::{IDENTIFIED, UNIDENTIFIED};
use common::tuning::design::{judge, DesignInputs, DesignModel, Designer, Loop, Step};
use serde::Serialize;

/// The model the vehicle identified, read back from its `ATUN_A_*` parameters (by the
/// vehicle's own declarations of them) at `airspeed`, with the servo it fitted through
/// (`SERVO_BW`); `None` while any is unset (0).
fn identified_model(after: &Values, airspeed: f64) -> Option<DesignModel> {
    let get = |name: &str| value(after, name).map(|v| v as f32);
    let mut model = DesignModel {
        va: airspeed as f32,
        servo_bandwidth_hz: get("SERVO_BW")?,
        ..UNIDENTIFIED
    };
    for q in IDENTIFIED.params {
        (q.set)(&mut model, get(q.def.name).filter(|v| *v != 0.0)?);
    }
    Some(model)
}

/// One identified coefficient beside the linearisation's.
#[derive(Clone, Debug, Serialize)]
pub struct Identified {
    /// Beard and McLain's name.
    pub name: String,
    /// Identified on board.
    pub value: f64,
    /// The aircraft file's linearisation at the same airspeed.
    pub linearised: f64,
    /// The difference, % of the linearised value.
    pub diff_pct: f64,
}

/// A gain before and after the autotune.
#[derive(Clone, Debug, Serialize)]
pub struct GainChange {
    /// Parameter.
    pub name: String,
    /// Before the autotune.
    pub before: f64,
    /// After it.
    pub after: f64,
}

/// One loop's margins as designed on the identified model, against its targets.
#[derive(Clone, Debug, Serialize)]
pub struct LoopMargins {
    /// The loop (`roll`, `course`, `pitch`, `altitude`, `aspd-pitch`, `aspd-thr`).
    pub name: String,
    /// Gain margin, dB (`None`: the phase never crosses -180 deg in the band, unbounded).
    pub gain_margin_db: Option<f64>,
    /// Phase margin, deg (`None`: the gain never crosses 1 in the band).
    pub phase_margin_deg: Option<f64>,
    /// The gain margin it must keep, dB.
    pub gain_margin_min_db: f64,
    /// The phase margin it must keep, deg.
    pub phase_margin_min_deg: f64,
    /// Both kept, by the vehicle's own verdict (`common::tuning::design::judge`).
    pub met: bool,
}

/// The design's margins on the identified model.
#[derive(Clone, Debug, Serialize)]
pub struct DesignMargins {
    /// Where they come from.
    pub source: String,
    /// Every loop's.
    pub loops: Vec<LoopMargins>,
    /// Largest difference between a gain the host's design gives and the one the vehicle
    /// applied, % of the applied (`None`: no gains were applied to compare with).
    pub gains_diff_max_pct: Option<f64>,
}

/// The mission flown on the default gains and after the autotune.
#[derive(Clone, Debug, Serialize)]
pub struct MissionBeforeAfter {
    /// In calm air (no wind, no turbulence): held to the calm-air cross-track target.
    pub calm: bool,
    /// The mission flown on the default gains (a separate flight, as `fly --mission`).
    pub default_gains: MissionSummary,
    /// The mission's part of the autotune flight, from its start.
    pub after_autotune: MissionSummary,
    /// The default gains' flight meets docs/NAVIGATION.md's targets.
    pub default_meets_targets: bool,
    /// The flight after the autotune meets them.
    pub after_meets_targets: bool,
}

/// What the autotune flight reports.
#[derive(Clone, Debug, Serialize)]
pub struct AutotuneReport {
    /// The airspeed the autotune held and identified at, m/s.
    pub airspeed_mps: f64,
    /// The autotune's status texts, with their time, s.
    pub texts: Vec<(f64, String)>,
    /// The coefficients identified (none when it did not finish).
    pub identified: Vec<Identified>,
    /// The gains before and after.
    pub gains: Vec<GainChange>,
    /// The script's commands flown on the default gains (a separate flight).
    pub default_gains: Vec<Segment>,
    /// The same commands flown after the autotune.
    pub after_autotune: Vec<Segment>,
    /// Each loop's margins as designed on the identified model (`None`: nothing identified).
    pub margins: Option<DesignMargins>,
    /// With `--mission`: the mission flown on the default gains and after the autotune.
    pub mission: Option<MissionBeforeAfter>,
}

/// Parameter values by name.
type Values = Vec<(String, f64)>;

/// The value of parameter `name` in `set`, if it was read.
fn value(set: &Values, name: &str) -> Option<f64> {
    set.iter().find(|(n, _)| n == name).map(|(_, v)| *v)
}

/// The values of the parameters the station read at its first and last reading.
fn readings(o: &FlightOutcome) -> (Values, Values) {
    let reads = &o.summary.params_read;
    let (Some(first), Some(last)) = (reads.first(), reads.last()) else {
        return (Vec::new(), Vec::new());
    };
    let at = |t: f64| {
        reads
            .iter()
            .filter(|(s, _, _)| *s == t)
            .map(|(_, n, v)| (n.clone(), f64::from(*v)))
            .collect()
    };
    (at(first.0), at(last.0))
}

/// The design's margins recomputed on the host, as the vehicle designed: the vehicle reports
/// its verdict (a STATUSTEXT) but not its margins, so its own design code
/// (`common::tuning::design`) runs here on what the station read back: the identified
/// coefficients (`ATUN_A_*`), the airspeed they are scaled to (`airspeed`), the servo
/// (`SERVO_BW`) and, as the base set, the gains read before the autotune (`FB_LPF_POLE`
/// among them) over the flight defaults. `None` when nothing was identified.
fn margins_on_host(before: &Values, after: &Values, airspeed: f64) -> Option<DesignMargins> {
    let model = identified_model(after, airspeed)?;
    let mut base = GainSet::FLIGHT;
    for (name, value) in before {
        // The parameters read that are not gains (the servo, the coefficients) are no error.
        let _ = base.set_param(name, *value as f32);
    }
    let mut designer = Designer::new(&model, &DesignInputs::AUTOTUNE, &base);
    // Bounded: every step evaluates points or finishes (`common::tuning::design::design`).
    while designer.step() == Step::Pending {}
    let mut diff_max: Option<f64> = None;
    let loops = Loop::ALL
        .iter()
        .filter_map(|&l| {
            let d = designer.loop_design(l)?;
            let g = [d.gains.kp, d.gains.ki, d.gains.kd];
            for (name, host) in l.params().iter().zip(g) {
                if let Some(applied) = value(after, name).map(|v| v as f32).filter(|v| *v != 0.0) {
                    let pct = 100.0 * f64::from((host - applied) / applied).abs();
                    diff_max = Some(diff_max.map_or(pct, |m| m.max(pct)));
                }
            }
            let m = &d.margins;
            Some(LoopMargins {
                name: l.name().into(),
                gain_margin_db: m.gain_margin_db.map(f64::from),
                phase_margin_deg: m.phase_margin_deg.map(f64::from),
                gain_margin_min_db: f64::from(common::tuning::design::GAIN_MARGIN_MIN_DB),
                phase_margin_min_deg: f64::from(l.phase_margin_min_deg()),
                met: judge(l, m).is_ok(),
            })
        })
        .collect();
    Some(DesignMargins {
        source: "recomputed on the host by the vehicle's design code (common::tuning::design) \
                 from the coefficients read back (ATUN_A_*), SERVO_BW and the gains read \
                 before the autotune: the vehicle reports its verdict, not its margins"
            .into(),
        loops,
        gains_diff_max_pct: diff_max,
    })
}

/// The mission flown on the default gains (`plain`) beside the autotune flight's (`tuned`),
/// when both flew one.
fn mission_before_after(
    tuned: &FlightOutcome,
    plain: &FlightOutcome,
) -> Option<MissionBeforeAfter> {
    let (after, before) = (
        tuned.summary.mission.clone()?,
        plain.summary.mission.clone()?,
    );
    let calm = tuned.summary.wind_ned == [0.0; 3] && tuned.summary.turbulence == "none";
    Some(MissionBeforeAfter {
        calm,
        default_meets_targets: meets_targets(&before, calm),
        after_meets_targets: meets_targets(&after, calm),
        default_gains: before,
        after_autotune: after,
    })
}

/// The report of the autotune flight `tuned`, beside the default gains' flight `plain` of the
/// same script or mission.
pub fn autotune_report(
    aircraft: &Aircraft,
    tuned: &FlightOutcome,
    plain: &FlightOutcome,
) -> anyhow::Result<AutotuneReport> {
    let (before, after) = readings(tuned);
    let airspeed = value(&after, "ASPD_SCL_REF").unwrap_or(aircraft.cruise_airspeed_mps());
    let lin = linearize_report_at(aircraft, "level", airspeed)?.reduced;
    let identified = identified_model(&after, airspeed)
        .iter()
        .flat_map(|m| m.coefficients())
        .filter_map(|(name, v)| {
            let v = f64::from(v);
            let r = lin.named().iter().find(|(n, _)| *n == name)?.1;
            Some(Identified {
                name: name.into(),
                value: v,
                linearised: r,
                diff_pct: 100.0 * (v - r) / r,
            })
        })
        .collect();
    let gains = before
        .iter()
        .filter(|(n, _)| AUTOTUNE_GAINS.contains(&n.as_str()))
        .filter_map(|(n, b)| {
            Some(GainChange {
                name: n.clone(),
                before: *b,
                after: value(&after, n)?,
            })
        })
        .collect();
    Ok(AutotuneReport {
        airspeed_mps: airspeed,
        texts: tuned
            .summary
            .texts
            .iter()
            .filter(|(_, t)| t.starts_with("Autotune"))
            .cloned()
            .collect(),
        identified,
        gains,
        default_gains: plain.summary.segments.clone(),
        after_autotune: tuned.summary.segments.clone(),
        margins: margins_on_host(&before, &after, airspeed),
        mission: mission_before_after(tuned, plain),
    })
}

impl AutotuneReport {
    /// The tables: identified against linearised, the gains, the script side by side.
    pub fn tables(&self) -> Vec<Table> {
        let mut id = Table::new(
            format!(
                "Identified on board against the aircraft file's linearisation at {} m/s",
                sig(self.airspeed_mps, 3)
            ),
            &["coefficient", "identified", "linearised", "difference"],
        );
        for c in &self.identified {
            id.row([
                c.name.clone(),
                sig(c.value, 4),
                sig(c.linearised, 4),
                format!("{:+.1} %", c.diff_pct),
            ]);
        }
        let mut g = Table::new("Gains", &["parameter", "default", "after autotune"]);
        for c in &self.gains {
            g.row([c.name.clone(), sig(c.before, 4), sig(c.after, 4)]);
        }
        let mut texts = Table::new("The autotune's messages", &["t (s)", "text"]);
        for (t, s) in &self.texts {
            texts.row([format!("{t:.1}"), s.clone()]);
        }
        let mut out = vec![texts, id, g];
        out.extend(self.margins.as_ref().map(DesignMargins::table));
        if !self.default_gains.is_empty() {
            out.push(self.script_table());
        }
        out.extend(self.mission.as_ref().map(MissionBeforeAfter::table));
        out
    }

    /// The thesis's script on the default gains beside the same after the autotune.
    fn script_table(&self) -> Table {
        let mut side = Table::new(
            "The thesis's script: default gains | after autotune",
            &[
                "command",
                "rise (s)",
                "overshoot (%)",
                "final error",
                "rise (s)",
                "overshoot (%)",
                "final error",
            ],
        );
        let figures = |g: &Segment| {
            let unit = if g.signal == "altitude" { "m" } else { "deg" };
            [
                g.metrics
                    .rise_time_s
                    .map_or("-".into(), |x| format!("{x:.1}")),
                format!("{:.1}", g.metrics.overshoot_pct),
                format!("{:.2} {unit}", g.final_error_max),
            ]
        };
        for (a, b) in self.default_gains.iter().zip(&self.after_autotune) {
            side.row(
                std::iter::once(a.what.clone())
                    .chain(figures(a))
                    .chain(figures(b)),
            );
        }
        side
    }
}

impl DesignMargins {
    /// Each loop's margins against its targets.
    pub fn table(&self) -> Table {
        let mut t = Table::new(
            format!(
                "The design's margins on the identified model ({}{})",
                self.source,
                self.gains_diff_max_pct.map_or(String::new(), |d| format!(
                    "; its gains within {} of those the vehicle applied",
                    if d < 1e-3 {
                        "0.001 %".to_string()
                    } else {
                        format!("{} %", sig(d, 2))
                    }
                ))
            ),
            &[
                "loop",
                "gain margin (dB)",
                "phase margin (deg)",
                "targets (dB, deg)",
                "met",
            ],
        );
        for l in &self.loops {
            t.row([
                l.name.clone(),
                sig_or_dash(l.gain_margin_db, 3),
                sig_or_dash(l.phase_margin_deg, 3),
                format!(">= {}, >= {}", l.gain_margin_min_db, l.phase_margin_min_deg),
                if l.met { "yes" } else { "no" }.into(),
            ]);
        }
        t
    }
}

/// A cell of the mission's table, from one flight's figures.
type Cell = fn(&MissionSummary) -> String;

impl MissionBeforeAfter {
    /// The mission's figures side by side, with docs/NAVIGATION.md's targets.
    pub fn table(&self) -> Table {
        let mut t = Table::new(
            "The mission: default gains | after autotune (the autotune flight's figures from the mission's start)",
            &["quantity", "target", "default gains", "after autotune"],
        );
        let xt = if self.calm {
            "under 0.5 RMS (calm air)"
        } else {
            "under 2 RMS"
        };
        let rows: [(&str, &str, Cell); 12] = [
            ("navigation items reached", "all", |m| {
                format!("{} of {}", m.reached.len(), m.nav_items.len())
            }),
            ("cross-track, straight legs (m)", "", |m| {
                format!(
                    "{} RMS, {} max",
                    sig(m.xtrack_rms_m, 3),
                    sig(m.xtrack_max_m, 3)
                )
            }),
            ("cross-track, on loiter circles (m)", "-", |m| {
                format!("{} RMS", sig(m.orbit_xtrack_rms_m, 3))
            }),
            ("altitude error (m)", "under 1.5 RMS", |m| {
                format!("{} RMS", sig(m.alt_rms_m, 3))
            }),
            ("airspeed error (m/s)", "under 1 RMS", |m| {
                format!("{} RMS", sig(m.airspeed_rms_mps, 3))
            }),
            ("throttle on a stop in level cruise (%)", "-", |m| {
                sig(m.throttle_at_stops_pct, 3)
            }),
            ("touchdown from the landing point (m)", "within 20", |m| {
                m.touchdown.map_or("none".into(), |d| {
                    format!("{:.1} ({:+.1} along)", d.distance_m, d.along_m)
                })
            }),
            ("sink at touchdown (m/s)", "under 1.5", |m| {
                m.touchdown
                    .map_or("-".into(), |d| format!("{:.2}", d.sink_rate_mps))
            }),
            ("strikes", "none", |m| m.strikes.len().to_string()),
            ("mission time (s)", "-", |m| {
                format!("{:.1}", m.flight_time_s)
            }),
            ("motor energy (Wh)", "-", |m| format!("{:.2}", m.energy_wh)),
            ("verdict", "pass", |m| {
                if m.pass {
                    "pass".into()
                } else {
                    format!("fail: {}", m.failed.join(", "))
                }
            }),
        ];
        for (q, target, f) in rows {
            let target = if target.is_empty() { xt } else { target };
            t.row([
                q.to_string(),
                target.to_string(),
                f(&self.default_gains),
                f(&self.after_autotune),
            ]);
        }
        let yes = |b: bool| if b { "yes" } else { "no" }.to_string();
        t.row([
            "meets docs/NAVIGATION.md's targets".to_string(),
            "yes".into(),
            yes(self.default_meets_targets),
            yes(self.after_meets_targets),
        ]);
        t
    }
}
