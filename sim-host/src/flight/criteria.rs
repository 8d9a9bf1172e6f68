//! The criteria a flight is judged by, each with its threshold: named once here, where the
//! flight's own figures are, for the campaign's verdict on a flight
//! ([`crate::campaign::verdict`], which judges them all) and the mission summary's (which
//! judges the two it measures, [`Criterion::Items`] and [`Criterion::NoStrike`]).

/// Largest bank angle before the flight counts as out of control, deg: the autopilot's
/// roll limit (`LIM_ROLL_DEG`, 45) plus 15 degrees of overshoot.
pub const LOC_BANK_DEG: f64 = 60.0;
/// Largest pitch angle (either sign) before the flight counts as out of control, deg: the
/// pitch limit (`LIM_PTCH_DEG`, 20) plus 15 degrees.
pub const LOC_PITCH_DEG: f64 = 35.0;
/// Touchdown within this distance of the landing point, m.
pub const TOUCHDOWN_M: f64 = 30.0;
/// Sink rate at touchdown under this, m/s.
pub const SINK_MPS: f64 = 2.0;

/// One named criterion.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Criterion {
    /// The flight ran: the configuration was flyable and the autopilot answered throughout.
    Flown,
    /// No loss of control: bank and pitch stayed within [`LOC_BANK_DEG`] and
    /// [`LOC_PITCH_DEG`] while armed.
    Control,
    /// Every navigation item of the mission reached.
    Items,
    /// A touchdown within [`TOUCHDOWN_M`] of the landing point.
    Touchdown,
    /// A sink rate under [`SINK_MPS`] at that touchdown.
    Sink,
    /// No strike: no point of the airframe but its wheels ever touched the ground (nose,
    /// propeller, wing tips, fuselage, tail).
    NoStrike,
    /// The autopilot's landed state at the end agrees with the truth, and once on the
    /// ground it has disarmed.
    LandedState,
    /// Failsafes as specified: none raised, since the campaign injects no fault.
    Failsafe,
}

impl Criterion {
    /// Every criterion, in report order.
    pub const ALL: [Criterion; 8] = [
        Criterion::Flown,
        Criterion::Control,
        Criterion::Items,
        Criterion::Touchdown,
        Criterion::Sink,
        Criterion::NoStrike,
        Criterion::LandedState,
        Criterion::Failsafe,
    ];

    /// The name records and reports use.
    pub fn name(self) -> &'static str {
        match self {
            Criterion::Flown => "flown",
            Criterion::Control => "control",
            Criterion::Items => "items",
            Criterion::Touchdown => "touchdown",
            Criterion::Sink => "sink",
            Criterion::NoStrike => "no_strike",
            Criterion::LandedState => "landed_state",
            Criterion::Failsafe => "failsafe",
        }
    }

    /// What it asks, with its threshold.
    pub fn describe(self) -> String {
        match self {
            Criterion::Flown => "the flight ran to its end (flyable configuration, autopilot answering)".into(),
            Criterion::Control => format!(
                "no loss of control: |bank| <= {LOC_BANK_DEG} deg and |pitch| <= {LOC_PITCH_DEG} deg while armed"
            ),
            Criterion::Items => "every navigation item reached".into(),
            Criterion::Touchdown => format!("touchdown within {TOUCHDOWN_M} m of the landing point"),
            Criterion::Sink => format!("sink rate at touchdown under {SINK_MPS} m/s"),
            Criterion::NoStrike => {
                "no strike: only the wheels touch the ground (nose, propeller, wing tips, fuselage, tail clear)".into()
            }
            Criterion::LandedState => {
                "landed state honest: the autopilot's landed state at the end agrees with the truth, disarmed once on the ground".into()
            }
            Criterion::Failsafe => "failsafes as specified: none raised (no fault injected)".into(),
        }
    }

    /// The criterion of a name.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.name() == name)
    }
}
