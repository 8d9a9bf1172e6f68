//! What `sim-host fly --autotune` reports: the coefficients the vehicle identified on board
//! (read back as its `ATUN_A_*` parameters, as a station reads them) against the aircraft
//! file's linearisation at the airspeed it was flown at, the gains before and after, and the
//! thesis's script flown on the default gains beside the same script flown after the autotune.

use crate::aircraft::Aircraft;
use crate::commands::linearize::linearize_report_at;
use crate::flight::summary::Segment;
use crate::flight::FlightOutcome;
use crate::report::sig;
use crate::report::table::Table;
use serde::Serialize;

/// The identified coefficients' parameters and the names the linearisation gives them.
const IDENTIFIED: [(&str, &str); 7] = [
    ("ATUN_A_PHI1", "a_phi1"),
    ("ATUN_A_PHI2", "a_phi2"),
    ("ATUN_A_THT1", "a_theta1"),
    ("ATUN_A_THT2", "a_theta2"),
    ("ATUN_A_THT3", "a_theta3"),
    ("ATUN_A_V1", "a_V1"),
    ("ATUN_A_V2", "a_V2"),
];

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
}

/// Parameter values by name.
type Values = Vec<(String, f64)>;

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

/// The report of the autotune flight `tuned`, beside the default gains' flight `plain` of the
/// same script.
pub fn autotune_report(
    aircraft: &Aircraft,
    tuned: &FlightOutcome,
    plain: &FlightOutcome,
) -> anyhow::Result<AutotuneReport> {
    let (before, after) = readings(tuned);
    let value =
        |set: &[(String, f64)], name: &str| set.iter().find(|(n, _)| n == name).map(|(_, v)| *v);
    let airspeed = value(&after, "ASPD_SCL_REF").unwrap_or(aircraft.cruise_airspeed_mps());
    let lin = linearize_report_at(aircraft, "level", airspeed)?.reduced;
    let identified = IDENTIFIED
        .iter()
        .filter_map(|(param, name)| {
            let v = value(&after, param).filter(|v| *v != 0.0)?;
            let r = lin.named().iter().find(|(n, _)| n == name)?.1;
            Some(Identified {
                name: (*name).into(),
                value: v,
                linearised: r,
                diff_pct: 100.0 * (v - r) / r,
            })
        })
        .collect();
    let gains = before
        .iter()
        .filter(|(n, _)| !n.starts_with("ATUN_"))
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
        let mut texts = Table::new("The autotune's messages", &["t (s)", "text"]);
        for (t, s) in &self.texts {
            texts.row([format!("{t:.1}"), s.clone()]);
        }
        vec![texts, id, g, side]
    }
}
