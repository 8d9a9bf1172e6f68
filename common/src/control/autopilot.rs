//! One full control tick: lateral and longitudinal autopilots from measured state and commands
//! to surface and throttle commands, with a status saying what was refused.

use super::gains::{GainError, GainSet, DESIGNED};
use super::lateral::{Lateral, RollMode, YawMode};
use super::longitudinal::{LonMode, Longitudinal, Regime};
use crate::actuators::Surfaces;
use crate::params::ParamDef;

/// Parameters of the autopilot as a whole.
pub const PARAMS: &[ParamDef] = &[ParamDef::real(
    "XFER_TC_S",
    DESIGNED.transfer_tc,
    0.05,
    20.0,
    "s",
    "Fade time constant of bumpless-transfer offsets (loops without integrator)",
)];

/// Longest time step accepted, s. A longer gap (a stalled estimator, a paused simulation) would
/// integrate one stale error over it; such a tick is refused and the outputs held instead.
pub const MAX_DT: f32 = 0.5;

/// The measured state the autopilot flies on. SI units, radians; body rates in the body frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Measurements {
    /// Roll angle phi, rad.
    pub roll: f32,
    /// Pitch angle theta, rad.
    pub pitch: f32,
    /// Course over ground chi, rad (the heading psi in still air, as the thesis assumes).
    pub course: f32,
    /// Roll rate p, rad/s.
    pub roll_rate: f32,
    /// Pitch rate q, rad/s.
    pub pitch_rate: f32,
    /// Yaw rate r, rad/s.
    pub yaw_rate: f32,
    /// Altitude h, m (any datum, the same as the altitude commands').
    pub altitude: f32,
    /// Airspeed Va, m/s.
    pub airspeed: f32,
    /// Sideslip beta, rad.
    pub sideslip: f32,
}

impl Measurements {
    /// Wings-level, straight flight at this airspeed and altitude, heading north.
    pub fn level(airspeed: f32, altitude: f32) -> Self {
        Self {
            airspeed,
            altitude,
            ..Self::default()
        }
    }
}

/// A set of inputs, as bits: which measurements (or the command, or the time step) were refused.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct InputFlags(pub u16);

impl InputFlags {
    /// Roll angle.
    pub const ROLL: Self = Self(1 << 0);
    /// Pitch angle.
    pub const PITCH: Self = Self(1 << 1);
    /// Course.
    pub const COURSE: Self = Self(1 << 2);
    /// Roll rate.
    pub const ROLL_RATE: Self = Self(1 << 3);
    /// Pitch rate.
    pub const PITCH_RATE: Self = Self(1 << 4);
    /// Yaw rate.
    pub const YAW_RATE: Self = Self(1 << 5);
    /// Altitude.
    pub const ALTITUDE: Self = Self(1 << 6);
    /// Airspeed.
    pub const AIRSPEED: Self = Self(1 << 7);
    /// Sideslip.
    pub const SIDESLIP: Self = Self(1 << 8);
    /// A setpoint of the commands.
    pub const COMMAND: Self = Self(1 << 9);
    /// The time step.
    pub const DT: Self = Self(1 << 10);

    /// No flag.
    pub const fn empty() -> Self {
        Self(0)
    }

    /// No flag set.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// All flags of `other` are set.
    pub const fn contains(self, other: Self) -> bool {
        self.0 & other.0 == other.0
    }

    /// Sets (`on`) or clears the flags of `other`.
    pub fn set(&mut self, other: Self, on: bool) {
        if on {
            self.0 |= other.0;
        } else {
            self.0 &= !other.0;
        }
    }
}

impl core::ops::BitOr for InputFlags {
    type Output = Self;
    fn bitor(self, rhs: Self) -> Self {
        Self(self.0 | rhs.0)
    }
}

impl core::ops::BitOrAssign for InputFlags {
    fn bitor_assign(&mut self, rhs: Self) {
        self.0 |= rhs.0;
    }
}

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

impl Autopilot {
    /// A disengaged autopilot flying `gains`, which must pass [`GainSet::validate`].
    pub fn new(gains: &GainSet) -> Result<Self, GainError> {
        gains.validate()?;
        Ok(Self {
            gains: *gains,
            lat: Lateral::new(&gains.lateral, gains.transfer_tc),
            lon: Longitudinal::new(&gains.longitudinal, gains.transfer_tc),
            counters: HoldCounters::default(),
        })
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
        }
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
        for (_, g, _) in NAMED {
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
