//! One full control tick: lateral and longitudinal autopilots from measured state and commands
//! to surface and throttle commands, with a status saying what was refused.

pub use super::inputs::{InputFlags, Measurements};
use super::lateral::{self, Lateral, LateralGains, RollMode, YawMode};
use super::longitudinal::tecs::{self, TecsGains};
use super::longitudinal::{self, LonMode, Longitudinal, LongitudinalGains, Regime};
use super::scaling::{course_scale, surface_scale};
use crate::actuators::Surfaces;
use crate::param;
use crate::params::{Group, ParamDef, ParamError, ParamStore, Stage};
use serde::{Deserialize, Serialize};

/// Time constant with which a bumpless-transfer offset fades by default, s (not in the thesis:
/// chosen here, a few times the inner loops' rise time).
pub const TRANSFER_TC_S: f32 = 1.0;

/// The flight defaults' scaling airspeed, m/s: the trim airspeed every loop was designed at
/// (Table 2.3 trim I). The thesis's sets fly unscaled, as in the thesis.
pub const SCALING_AIRSPEED_MPS: f32 = 17.0;

/// Parameters of the autopilot as a whole.
pub const PARAMS: Group<GainSet> = Group {
    name: "Autopilot",
    params: &[
        param!(
            ParamDef::real(
                "XFER_TC_S",
                TRANSFER_TC_S,
                0.05,
                20.0,
                "s",
                "Fade time constant of bumpless-transfer offsets (loops without integrator)",
            ),
            GainSet => transfer_tc
        ),
        param!(
            ParamDef::real(
                "ASPD_SCL_REF",
                SCALING_AIRSPEED_MPS,
                0.0,
                40.0,
                "m/s",
                "Airspeed the gains are designed at: the surface and altitude loops scaled by this/airspeed elsewhere, the course loop by ground speed/this below it (0: off)",
            ),
            GainSet => scaling_airspeed
        ),
    ],
    base: || GainSet::FLIGHT,
    check: crate::params::independent,
};

/// Every number the autopilot flies with.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GainSet {
    /// Ailerons and rudder.
    pub lateral: LateralGains,
    /// Elevator and throttle.
    pub longitudinal: LongitudinalGains,
    /// The longitudinal law of the altitude modes and the total energy control's gains
    /// (absent from older gain files: then the designed gains, the law off).
    #[serde(default)]
    pub tecs: TecsGains,
    /// Time constant with which a bumpless-transfer offset fades, s.
    pub transfer_tc: f32,
    /// Airspeed at which the surface loops' gains are as given, m/s; at other airspeeds the
    /// roll, pitch and sideslip loops, the yaw damper and the altitude loop are scaled by
    /// `this / airspeed` ([`super::scaling`]). Zero: no scaling (and in older gain files,
    /// which lack it).
    #[serde(default)]
    pub scaling_airspeed: f32,
}

/// Why a gain set or a parameter value was refused; each names the parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum GainError {
    /// NaN or infinite.
    NotFinite(&'static str),
    /// Outside the parameter's bounds (which also fix each loop gain's stabilising sign).
    OutOfBounds(&'static str),
    /// Contradicts another value (a lower limit above an upper one, a trim outside its travel).
    Inconsistent(&'static str),
    /// No parameter of that name.
    Unknown,
}

impl GainError {
    /// The parameter the error is about (empty for [`GainError::Unknown`]).
    pub fn name(&self) -> &'static str {
        match *self {
            GainError::NotFinite(n) | GainError::OutOfBounds(n) | GainError::Inconsistent(n) => n,
            GainError::Unknown => "",
        }
    }
}

impl core::fmt::Display for GainError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            GainError::NotFinite(n) => write!(f, "gain {n} is not finite"),
            GainError::OutOfBounds(n) => write!(f, "gain {n} outside its bounds"),
            GainError::Inconsistent(n) => write!(f, "gain {n} contradicts another limit"),
            GainError::Unknown => f.write_str("no such gain parameter"),
        }
    }
}

impl core::error::Error for GainError {}

impl GainSet {
    /// The thesis's designed set (chapter 3), every stage's own designed gains.
    pub const THESIS: GainSet = GainSet {
        lateral: lateral::THESIS,
        longitudinal: longitudinal::THESIS,
        tecs: tecs::gains::DESIGNED,
        transfer_tc: TRANSFER_TC_S,
        scaling_airspeed: 0.0,
    };

    /// The flight defaults, every parameter's default: the thesis's designed set with the
    /// loops that the full linear model shows unstable replaced ([`lateral::FLIGHT`],
    /// [`longitudinal::FLIGHT`]).
    pub const FLIGHT: GainSet = GainSet {
        lateral: lateral::FLIGHT,
        longitudinal: longitudinal::FLIGHT,
        tecs: tecs::gains::DESIGNED,
        transfer_tc: TRANSFER_TC_S,
        scaling_airspeed: SCALING_AIRSPEED_MPS,
    };

    /// Checks every value: finite, inside its parameter's bounds (the bounds of the loop gains
    /// admit only the stabilising sign in the UMN convention), and consistent (throttle minimum
    /// below maximum, trims inside the travel). The error names the first offending parameter.
    pub fn validate(&self) -> Result<(), GainError> {
        let named = |(name, e): (&'static str, ParamError)| match e {
            ParamError::NotFinite => GainError::NotFinite(name),
            ParamError::Inconsistent => GainError::Inconsistent(name),
            _ => GainError::OutOfBounds(name),
        };
        lateral::PARAMS.validate(&self.lateral).map_err(named)?;
        longitudinal::PARAMS
            .validate(&self.longitudinal)
            .map_err(named)?;
        tecs::gains::PARAMS.validate(&self.tecs).map_err(named)?;
        PARAMS.validate(self).map_err(named)
    }

    /// The set as parameter values `(name, value)` in parameter units, stage by stage.
    pub fn params(&self) -> impl Iterator<Item = (&'static str, f32)> + Clone + '_ {
        let lat = lateral::PARAMS.params.iter();
        let lon = longitudinal::PARAMS.params.iter();
        let energy = tecs::gains::PARAMS.params.iter();
        lat.map(move |p| (p.def.name, (p.get)(&self.lateral)))
            .chain(lon.map(move |p| (p.def.name, (p.get)(&self.longitudinal))))
            .chain(energy.map(move |p| (p.def.name, (p.get)(&self.tecs))))
            .chain(
                PARAMS
                    .params
                    .iter()
                    .map(move |p| (p.def.name, (p.get)(self))),
            )
    }

    /// The value of one parameter, in parameter units.
    pub fn param(&self, name: &str) -> Option<f32> {
        self.params().find(|(n, _)| *n == name).map(|(_, v)| v)
    }

    /// Sets one parameter (parameter units) after checking it against its definition. The rest
    /// of the set is not re-validated: call [`GainSet::validate`] before flying the result.
    pub fn set_param(&mut self, name: &str, value: f32) -> Result<(), GainError> {
        let r = if lateral::PARAMS.find(name).is_some() {
            lateral::PARAMS.set(&mut self.lateral, name, value)
        } else if longitudinal::PARAMS.find(name).is_some() {
            longitudinal::PARAMS.set(&mut self.longitudinal, name, value)
        } else if tecs::gains::PARAMS.find(name).is_some() {
            tecs::gains::PARAMS.set(&mut self.tecs, name, value)
        } else {
            PARAMS.set(self, name, value)
        };
        let known = self.params().find(|(n, _)| *n == name).map(|(n, _)| n);
        r.map_err(|e| match (e, known) {
            (ParamError::NotFinite, Some(n)) => GainError::NotFinite(n),
            (_, Some(n)) => GainError::OutOfBounds(n),
            (_, None) => GainError::Unknown,
        })
    }

    /// The stages of the store a set is made of, in the order of [`GainSet::params`]'s values.
    pub const STAGES: [&'static dyn Stage; 4] = [
        &lateral::PARAMS,
        &longitudinal::PARAMS,
        &tecs::gains::PARAMS,
        &PARAMS,
    ];

    /// Writes the set into `store`'s [`GainSet::STAGES`], as one change (the inverse of
    /// [`GainSet::from_store`]); refused as a whole with the first offending name.
    pub fn to_store(&self, store: &mut ParamStore) -> Result<(), (&'static str, ParamError)> {
        store.set_stages(&Self::STAGES, self.params().map(|(_, v)| v))
    }

    /// The set the store holds (consistent by the store's own checks).
    pub fn from_store(store: &ParamStore) -> GainSet {
        let own = store.load(&PARAMS);
        GainSet {
            lateral: store.load(&lateral::PARAMS),
            longitudinal: store.load(&longitudinal::PARAMS),
            tecs: store.load(&tecs::gains::PARAMS),
            transfer_tc: own.transfer_tc,
            scaling_airspeed: own.scaling_airspeed,
        }
    }
}

/// Longest time step accepted, s. A longer gap (a stalled estimator, a paused simulation) would
/// integrate one stale error over it; such a tick is refused and the outputs held instead.
pub const MAX_DT: f32 = 0.5;

/// What each axis is asked to do.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Commands {
    /// Ailerons: off, roll angle or course.
    pub roll: RollMode,
    /// Rudder: off, yaw damper, or sideslip hold with the damper.
    pub yaw: YawMode,
    /// Elevator and throttle: off, pitch, airspeed by pitch, altitude (with regimes), take-off.
    pub lon: LonMode,
}

impl Commands {
    /// Every axis off.
    pub const OFF: Self = Self {
        roll: RollMode::Off,
        yaw: YawMode::Off,
        lon: LonMode::Off,
    };
}

/// Which outputs were held at their last good value.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Held {
    /// Aileron.
    pub aileron: bool,
    /// Rudder.
    pub rudder: bool,
    /// Elevator.
    pub elevator: bool,
    /// Throttle.
    pub throttle: bool,
}

impl Held {
    /// Any output held.
    pub fn any(&self) -> bool {
        self.aileron || self.rudder || self.elevator || self.throttle
    }
}

/// Ticks on which each output was held, since the autopilot was made (saturating).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HoldCounters {
    /// Aileron.
    pub aileron: u32,
    /// Rudder.
    pub rudder: u32,
    /// Elevator.
    pub elevator: u32,
    /// Throttle.
    pub throttle: u32,
    /// Ticks with any refused input.
    pub rejected_ticks: u32,
}

/// What happened in a tick.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Status {
    /// Longitudinal regime (altitude modes only).
    pub regime: Option<Regime>,
    /// Inputs refused this tick.
    pub rejected: InputFlags,
    /// Outputs held at their last good value this tick.
    pub held: Held,
    /// Running counts.
    pub counters: HoldCounters,
    /// Roll angle the roll loop was asked for, rad (NaN when off).
    pub roll_cmd: f32,
    /// Pitch angle the pitch loop was asked for, rad (NaN when off).
    pub pitch_cmd: f32,
}

/// Result of one tick.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Output {
    /// Surface and throttle commands, inside the servo limits, never NaN.
    pub surfaces: Surfaces,
    /// What happened.
    pub status: Status,
}

/// The whole autopilot.
#[derive(Clone, Copy, Debug)]
pub struct Autopilot {
    gains: GainSet,
    lat: Lateral,
    lon: Longitudinal,
    counters: HoldCounters,
}

fn bump(c: &mut u32, on: bool) {
    if on {
        *c = c.saturating_add(1);
    }
}

impl Default for GainSet {
    fn default() -> Self {
        GainSet::FLIGHT
    }
}

impl Default for Autopilot {
    /// A disengaged autopilot flying the flight defaults (valid: tested).
    fn default() -> Self {
        Self::build(&GainSet::FLIGHT)
    }
}

impl Autopilot {
    /// A disengaged autopilot flying `gains`, which must pass [`GainSet::validate`].
    pub fn new(gains: &GainSet) -> Result<Self, GainError> {
        gains.validate()?;
        Ok(Self::build(gains))
    }

    fn build(gains: &GainSet) -> Self {
        let mut lon = Longitudinal::new(&gains.longitudinal, gains.transfer_tc);
        lon.set_energy_law(&gains.tecs, gains.transfer_tc);
        Self {
            gains: *gains,
            lat: Lateral::new(&gains.lateral, gains.transfer_tc),
            lon,
            counters: HoldCounters::default(),
        }
    }

    /// The gains in use.
    pub fn gains(&self) -> &GainSet {
        &self.gains
    }

    /// Switches to other gains in flight (engaged loops continue without a jump). A set that
    /// fails validation is refused and the old one kept.
    pub fn set_gains(&mut self, gains: &GainSet) -> Result<(), GainError> {
        gains.validate()?;
        self.gains = *gains;
        self.lat.set_gains(&gains.lateral, gains.transfer_tc);
        self.lon.set_gains(&gains.longitudinal, gains.transfer_tc);
        self.lon.set_energy_law(&gains.tecs, gains.transfer_tc);
        Ok(())
    }

    /// The surfaces actually applied while an axis was off (e.g. the pilot's): the axis starts
    /// from them when it engages, instead of from the trim.
    pub fn handover(&mut self, applied: Surfaces) {
        self.lat.handover(applied.aileron, applied.rudder);
        self.lon.handover(applied.elevator, applied.throttle);
    }

    /// Running counts of held outputs and refused ticks.
    pub fn counters(&self) -> HoldCounters {
        self.counters
    }

    /// One control tick of length `dt` (s). Never panics; a non-finite measurement or setpoint
    /// holds the outputs that depend on it at their last good value and is reported in the
    /// status; a `dt` that is not in `(0, MAX_DT]` holds every engaged output.
    pub fn step(&mut self, m: &Measurements, c: &Commands, dt: f32) -> Output {
        let dt_ok = dt.is_finite() && dt > 0.0 && dt <= MAX_DT;
        // A refused dt reaches the stages as NaN: every engaged loop then holds.
        let dt_stage = if dt_ok { dt } else { f32::NAN };
        let scale = surface_scale(m.airspeed, self.gains.scaling_airspeed);
        self.lat.set_surface_scale(scale);
        self.lon.set_surface_scale(scale);
        self.lat
            .set_course_scale(course_scale(m.ground_speed, self.gains.scaling_airspeed));
        let lat = self.lat.step(m, c.roll, c.yaw, dt_stage);
        let lon = self.lon.step(m, c.lon, dt_stage);
        let mut rejected = lat.rejected | lon.rejected;
        rejected.set(InputFlags::DT, !dt_ok);
        let held = Held {
            aileron: lat.aileron_held,
            rudder: lat.rudder_held,
            elevator: lon.elevator_held,
            throttle: lon.throttle_held,
        };
        bump(&mut self.counters.aileron, held.aileron);
        bump(&mut self.counters.rudder, held.rudder);
        bump(&mut self.counters.elevator, held.elevator);
        bump(&mut self.counters.throttle, held.throttle);
        bump(&mut self.counters.rejected_ticks, !rejected.is_empty());
        let surfaces = Surfaces {
            elevator: lon.elevator,
            aileron: lat.aileron,
            rudder: lat.rudder,
            throttle: lon.throttle,
        }
        .saturated();
        Output {
            surfaces,
            status: Status {
                regime: lon.regime,
                rejected,
                held,
                counters: self.counters,
                roll_cmd: lat.roll_cmd,
                pitch_cmd: lon.pitch_cmd,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::gains::DESIGNED;
    use crate::control::gains::{MINNESOTA, NAMED};

    const DT: f32 = 0.02;

    fn engaged() -> Commands {
        Commands {
            roll: RollMode::Course(0.3),
            yaw: YawMode::Sideslip(0.0),
            lon: LonMode::Altitude {
                altitude: 105.0,
                airspeed: 17.0,
            },
        }
    }

    fn flying() -> Measurements {
        Measurements {
            roll: 0.05,
            pitch: 0.06,
            course: 0.1,
            roll_rate: 0.01,
            pitch_rate: -0.02,
            yaw_rate: 0.03,
            altitude: 100.0,
            airspeed: 16.5,
            sideslip: 0.01,
            ground_speed: 16.5,
        }
    }

    #[test]
    fn at_a_higher_airspeed_the_surface_loops_answer_by_the_inverse_of_it() {
        // Engaged on the present attitude, then a step of both commands: the aileron's and
        // elevator's moves scale as 17 / Va with the flight set, and not at all with the
        // thesis's set (the rates are the same on both ticks, so only the error terms move).
        let answer = |g: &GainSet, va: f32| {
            let mut ap = Autopilot::new(g).unwrap();
            let m = Measurements {
                airspeed: va,
                ..flying()
            };
            let c = |roll: f32, pitch: f32| Commands {
                roll: RollMode::Roll(roll),
                yaw: YawMode::Damper,
                lon: LonMode::Pitch {
                    pitch,
                    throttle: 0.5,
                },
            };
            let before = ap.step(&m, &c(m.roll, m.pitch), DT).surfaces;
            let after = ap.step(&m, &c(0.2, 0.15), DT).surfaces;
            (
                after.aileron - before.aileron,
                after.elevator - before.elevator,
            )
        };
        let flight = GainSet::FLIGHT;
        let (a17, e17) = answer(&flight, 17.0);
        let (a25, e25) = answer(&flight, 25.0);
        let expected = 17.0f32 / 25.0;
        assert!((a25 / a17 - expected).abs() < 1e-3, "{a17} {a25}");
        assert!((e25 / e17 - expected).abs() < 1e-3, "{e17} {e25}");
        let (t17, _) = answer(&DESIGNED, 17.0);
        let (t25, _) = answer(&DESIGNED, 25.0);
        assert_eq!(t17, t25);
    }

    #[test]
    fn nan_roll_holds_aileron_counts_and_resumes() {
        let mut ap = Autopilot::new(&DESIGNED).unwrap();
        let c = engaged();
        let mut last = ap.step(&flying(), &c, DT);
        for _ in 0..10 {
            last = ap.step(&flying(), &c, DT);
        }
        let bad = Measurements {
            roll: f32::NAN,
            ..flying()
        };
        for k in 1..=5u32 {
            let o = ap.step(&bad, &c, DT);
            assert_eq!(o.surfaces.aileron, last.surfaces.aileron);
            assert!(o.status.held.aileron);
            assert!(!o.status.held.rudder && !o.status.held.elevator && !o.status.held.throttle);
            assert!(o.status.rejected.contains(InputFlags::ROLL));
            assert_eq!(o.status.counters.aileron, k);
            // The other axes keep flying.
            assert_ne!(o.surfaces.elevator, last.surfaces.elevator);
        }
        // Good again: resumes from the held value, no jump.
        let o = ap.step(&flying(), &c, DT);
        assert!(!o.status.held.any());
        assert!(o.status.rejected.is_empty());
        assert!((o.surfaces.aileron - last.surfaces.aileron).abs() < 1e-6);
        assert_eq!(ap.counters().aileron, 5);
        assert_eq!(ap.counters().rejected_ticks, 5);
    }

    #[test]
    fn every_kind_of_bad_input_is_refused_never_propagated() {
        let mut ap = Autopilot::new(&MINNESOTA).unwrap();
        let c = engaged();
        ap.step(&flying(), &c, DT);
        type Field = fn(&mut Measurements) -> &mut f32;
        let fields: [(Field, InputFlags); 9] = [
            (|m| &mut m.roll, InputFlags::ROLL),
            (|m| &mut m.pitch, InputFlags::PITCH),
            (|m| &mut m.course, InputFlags::COURSE),
            (|m| &mut m.roll_rate, InputFlags::ROLL_RATE),
            (|m| &mut m.pitch_rate, InputFlags::PITCH_RATE),
            (|m| &mut m.yaw_rate, InputFlags::YAW_RATE),
            (|m| &mut m.altitude, InputFlags::ALTITUDE),
            (|m| &mut m.airspeed, InputFlags::AIRSPEED),
            (|m| &mut m.sideslip, InputFlags::SIDESLIP),
        ];
        for (field, flag) in fields {
            for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
                let mut m = flying();
                *field(&mut m) = bad;
                let o = ap.step(&m, &c, DT);
                assert!(o.status.rejected.contains(flag), "{flag:?} {:?}", o.status);
                assert!(o.status.held.any());
                let s = o.surfaces;
                assert!(s.aileron.is_finite() && s.elevator.is_finite());
                assert!(s.rudder.is_finite() && s.throttle.is_finite());
                ap.step(&flying(), &c, DT);
            }
        }
        // A bad command is refused too.
        let nan_cmd = Commands {
            roll: RollMode::Roll(f32::NAN),
            ..c
        };
        let o = ap.step(&flying(), &nan_cmd, DT);
        assert!(o.status.rejected.contains(InputFlags::COMMAND) && o.status.held.aileron);
    }

    #[test]
    fn bad_dt_holds_everything() {
        let mut ap = Autopilot::new(&DESIGNED).unwrap();
        let c = engaged();
        let good = ap.step(&flying(), &c, DT);
        for dt in [f32::NAN, f32::INFINITY, 0.0, -0.02, 3.0] {
            let o = ap.step(&flying(), &c, dt);
            assert_eq!(o.surfaces, good.surfaces, "dt {dt}");
            assert!(o.status.rejected.contains(InputFlags::DT));
            assert!(o.status.held.aileron && o.status.held.rudder);
            assert!(o.status.held.elevator && o.status.held.throttle);
        }
    }

    /// Deterministic pseudo-random fuzz: measurements, commands and dt drawn from a mix of
    /// ordinary, extreme and non-finite values; the surfaces stay finite and inside limits.
    #[test]
    fn fuzzed_inputs_never_give_bad_surfaces() {
        let mut seed = 0x1234_5678u32;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            seed
        };
        let mut val = |scale: f32| {
            let r = next();
            match r % 16 {
                0 => f32::NAN,
                1 => f32::INFINITY,
                2 => -1e30,
                _ => ((r >> 8) as f32 / (1u32 << 24) as f32 - 0.5) * 2.0 * scale,
            }
        };
        let mut energy = GainSet::FLIGHT;
        energy.tecs = tecs::gains::ENGAGED;
        for g in NAMED.iter().map(|(_, g, _)| g).chain([&energy]) {
            let mut ap = Autopilot::new(g).unwrap();
            for k in 0..3000 {
                let m = Measurements {
                    roll: val(3.0),
                    pitch: val(1.5),
                    course: val(10.0),
                    roll_rate: val(5.0),
                    pitch_rate: val(5.0),
                    yaw_rate: val(5.0),
                    altitude: val(500.0),
                    airspeed: val(40.0),
                    sideslip: val(0.5),
                    ground_speed: val(40.0),
                };
                let c = Commands {
                    roll: match k % 3 {
                        0 => RollMode::Off,
                        1 => RollMode::Roll(val(2.0)),
                        _ => RollMode::Course(val(10.0)),
                    },
                    yaw: match k % 5 {
                        0 => YawMode::Off,
                        1 => YawMode::Damper,
                        _ => YawMode::Sideslip(val(0.2)),
                    },
                    lon: match k % 8 {
                        0 => LonMode::Off,
                        1 => LonMode::Pitch {
                            pitch: val(1.0),
                            throttle: val(2.0),
                        },
                        2 => LonMode::AirspeedPitch {
                            airspeed: val(30.0),
                            throttle: val(1.0),
                        },
                        3 => LonMode::TakeOff {
                            altitude: val(300.0),
                            airspeed: val(30.0),
                            clear_altitude: val(50.0),
                        },
                        4 => LonMode::Glide {
                            altitude: val(300.0),
                            airspeed: val(30.0),
                            climb_rate: val(5.0),
                        },
                        _ => LonMode::Altitude {
                            altitude: val(300.0),
                            airspeed: val(30.0),
                        },
                    },
                };
                let dt = if k % 11 == 0 { val(1.0) } else { DT };
                let s = ap.step(&m, &c, dt).surfaces;
                assert_eq!(s, s.saturated(), "{s:?}");
            }
        }
    }

    #[test]
    fn refuses_invalid_gains_and_keeps_old_ones() {
        let mut bad = DESIGNED;
        bad.lateral.course_kp = f32::NAN;
        assert_eq!(
            Autopilot::new(&bad).err(),
            Some(GainError::NotFinite("CRS_KP"))
        );
        let mut ap = Autopilot::new(&DESIGNED).unwrap();
        assert!(ap.set_gains(&bad).is_err());
        assert_eq!(ap.gains(), &DESIGNED);
        // Switching sets in flight does not make the surfaces jump.
        let c = engaged();
        let mut o = ap.step(&flying(), &c, DT);
        for _ in 0..20 {
            o = ap.step(&flying(), &c, DT);
        }
        ap.set_gains(&MINNESOTA).unwrap();
        let o2 = ap.step(&flying(), &c, DT);
        assert!((o2.surfaces.aileron - o.surfaces.aileron).abs() < 2e-3);
        assert!((o2.surfaces.elevator - o.surfaces.elevator).abs() < 2e-3);
    }

    #[test]
    fn off_gives_trim() {
        let mut ap = Autopilot::new(&DESIGNED).unwrap();
        let o = ap.step(&Measurements::default(), &Commands::OFF, DT);
        assert_eq!(o.surfaces.elevator, DESIGNED.longitudinal.trim_elevator);
        assert_eq!(o.surfaces.aileron, DESIGNED.lateral.trim_aileron);
        assert_eq!(o.surfaces.throttle, DESIGNED.longitudinal.trim_throttle);
        assert!(o.status.rejected.is_empty() && o.status.regime.is_none());
    }
}
