//! Longitudinal autopilot (thesis section 3.5, Figures 3-16 to 3-21): elevator and throttle.
//!
//! ```text
//! theta_c source (by regime) --[+-pitch_max]-- theta_c --(+)-- PI pitch --(+)-- trim --[+-elev_max]--> elevator
//!   altitude:  PI on (h_c - LPF(h))                       theta        -kd (q - q_turn)
//!   airspeed:  PI on (Va_c - LPF(Va))   (negative gain: too slow -> nose down)
//!   take-off:  fixed takeoff pitch
//! throttle source (by regime): full | zero | PI on (Va_c - LPF(Va)) + trim --[min..max]--> throttle
//! ```
//!
//! Regimes of Figure 3-16 ([`Regime`]), chosen from the altitude error `e = h_c - LPF(h)` by
//! [`RegimeMachine`]: take-off (full throttle, fixed pitch) until the clear altitude; climb (full
//! throttle, airspeed by pitch) while `e` is above the band; altitude hold (altitude by pitch,
//! airspeed by throttle) inside it; descent (zero throttle, airspeed by pitch) below it. The band
//! is entered at `|e| < band` and left only at `|e| > band + hysteresis`, so altitude noise at the
//! edge does not make the regime chatter. When a regime changes the source of the pitch or
//! throttle command, the new source starts from the command the old one gave (bumpless).
//!
//! With `LON_LAW` = 1 ([`TecsGains::enabled`]) the altitude modes fly the total energy control
//! ([`tecs`]) instead of the climb, hold and descent regimes: it gives the throttle and the pitch
//! command, which the same pitch attitude loop flies. The take-off regime (fixed pitch, full
//! throttle below the clear altitude) and the pitch modes stay as they are under either law.
//!
//! Signs (UMN): positive elevator pitches the nose down, so the pitch gains are negative and
//! `-kd q` with `kd < 0` adds elevator against the pitch rate.
//!
//! The damper leaves alone the pitch rate a coordinated turn has of itself,
//! `q_turn = g sin(phi) tan(phi) / Va` ([`turn_pitch_rate`], PX4's turn coordination; the
//! thesis's law damps all of it): at 40 deg of bank and 25 m/s that is 0.21 rad/s, which a
//! damper of `PTCH_RATE_KD` -0.34 (the Aerosonde's designed one) met with 4 deg of elevator
//! pushing the nose down through every turn, 2.8 m RMS of altitude error in its loiters
//! against 1.8 m without. On the 25e's default gains it takes the default mission's altitude
//! error from 0.49 to 0.41 m RMS.

pub mod gains;
pub mod regime;
pub mod tecs;

use super::filters::LowPass;
use super::inputs::{InputFlags, Measurements};
use super::pid::{Bumpless, Derivative, Pid, PidGains};
use crate::actuators::SURFACE_LIMIT_RAD;
use crate::math::{clamp, wrap_pi};

pub use gains::{LongitudinalGains, FLIGHT, PARAMS, THESIS};
pub use regime::{Regime, RegimeMachine};
pub use tecs::{Tecs, TecsDemand, TecsGains};

/// What the elevator and throttle do. Angles rad, altitudes m, airspeeds m/s.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LonMode {
    /// Not engaged: elevator and throttle at trim, loops at rest.
    Off,
    /// Hold this pitch angle; throttle as given (0..1).
    Pitch {
        /// Pitch angle, rad (limited to the pitch limit).
        pitch: f32,
        /// Throttle, 0..1.
        throttle: f32,
    },
    /// Hold this airspeed with the elevator (by commanded pitch); throttle as given.
    AirspeedPitch {
        /// Airspeed, m/s.
        airspeed: f32,
        /// Throttle, 0..1.
        throttle: f32,
    },
    /// Reach and hold this altitude and airspeed through the climb / hold / descent regimes.
    Altitude {
        /// Altitude, m (same datum as the measured altitude).
        altitude: f32,
        /// Airspeed, m/s.
        airspeed: f32,
    },
    /// As [`LonMode::Altitude`] for an altitude command that moves at `climb_rate` (a glide
    /// slope): in the hold regime the pitch command carries the flight-path angle that rate
    /// asks for, `asin(climb_rate / airspeed)`, so the altitude loop no longer lags the ramp
    /// by the error its proportional gain needs to make that pitch.
    Glide {
        /// Altitude, m (same datum as the measured altitude).
        altitude: f32,
        /// Airspeed, m/s.
        airspeed: f32,
        /// Rate at which `altitude` moves, m/s, up positive.
        climb_rate: f32,
    },
    /// As [`LonMode::Altitude`], starting in the take-off regime while below `clear_altitude`.
    TakeOff {
        /// Altitude, m.
        altitude: f32,
        /// Airspeed, m/s.
        airspeed: f32,
        /// Altitude at which the take-off regime ends, m.
        clear_altitude: f32,
    },
}

impl LonMode {
    /// The same mode with every altitude in it moved by `dz` m: from one datum to another
    /// (the navigator's heights above home to the autopilot's altitudes above sea level).
    pub fn shifted(mut self, dz: f32) -> Self {
        match &mut self {
            LonMode::Altitude { altitude, .. } | LonMode::Glide { altitude, .. } => *altitude += dz,
            LonMode::TakeOff {
                altitude,
                clear_altitude,
                ..
            } => {
                *altitude += dz;
                *clear_altitude += dz;
            }
            LonMode::Off | LonMode::Pitch { .. } | LonMode::AirspeedPitch { .. } => {}
        }
        self
    }
}

/// Output of one longitudinal step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LongitudinalOutput {
    /// Elevator, rad (UMN sign).
    pub elevator: f32,
    /// Throttle, 0..1.
    pub throttle: f32,
    /// Pitch angle the pitch loop was asked for, rad (NaN when off).
    pub pitch_cmd: f32,
    /// Regime, in the altitude modes.
    pub regime: Option<Regime>,
    /// The elevator was held at its last good value this step.
    pub elevator_held: bool,
    /// The throttle was held at its last good value this step.
    pub throttle_held: bool,
    /// Inputs refused this step.
    pub rejected: InputFlags,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum PitchSource {
    Fixed(f32),
    Airspeed(f32),
    /// Altitude command and the pitch feed-forward added to the loop's output, rad.
    Altitude(f32, f32),
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum ThrottleSource {
    Fixed(f32),
    Airspeed(f32),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum SourceKind {
    Off,
    Fixed,
    Airspeed,
    Altitude,
}

impl PitchSource {
    fn kind(self) -> SourceKind {
        match self {
            PitchSource::Fixed(_) => SourceKind::Fixed,
            PitchSource::Airspeed(_) => SourceKind::Airspeed,
            PitchSource::Altitude(..) => SourceKind::Altitude,
        }
    }
}

impl ThrottleSource {
    fn kind(self) -> SourceKind {
        match self {
            ThrottleSource::Fixed(_) => SourceKind::Fixed,
            ThrottleSource::Airspeed(_) => SourceKind::Airspeed,
        }
    }
}

/// The body pitch rate of a level coordinated turn at bank `roll` (rad) and airspeed
/// `airspeed` (m/s): the turn rate `g tan(phi) / Va` seen about the banked pitch axis, `sin(phi)`
/// of it. 0 where either is not finite or the airspeed is under 1 m/s (on the ground); the
/// bank is held to 60 deg (twice the load factor), beyond which a turn is not level.
pub fn turn_pitch_rate(roll: f32, airspeed: f32) -> f32 {
    if !(roll.is_finite() && airspeed.is_finite() && airspeed >= 1.0) {
        return 0.0;
    }
    let phi = roll.clamp(-TURN_BANK_MAX, TURN_BANK_MAX);
    crate::math::GRAVITY * crate::math::elementary::sin(phi) * crate::math::elementary::tan(phi)
        / airspeed
}

/// The largest bank a coordinated turn's pitch rate is reckoned at, rad (60 deg).
const TURN_BANK_MAX: f32 = core::f32::consts::FRAC_PI_3;

/// The longitudinal autopilot.
#[derive(Clone, Copy, Debug)]
pub struct Longitudinal {
    gains: LongitudinalGains,
    pitch: Pid,
    alt: Pid,
    aspd_pitch: Pid,
    aspd_thr: Pid,
    alt_lpf: LowPass,
    aspd_lpf: LowPass,
    machine: RegimeMachine,
    tecs: Tecs,
    pitch_src: SourceKind,
    thr_src: SourceKind,
    elevator: f32,
    throttle: f32,
    pitch_cmd: f32,
    elev_resume: bool,
    thr_resume: bool,
    surface_scale: f32,
}

fn pitch_gains(g: &LongitudinalGains) -> PidGains {
    PidGains::symmetric(
        g.pitch_kp,
        g.pitch_ki,
        g.pitch_rate_kd,
        g.elevator_max.min(SURFACE_LIMIT_RAD),
    )
}

fn alt_gains(g: &LongitudinalGains) -> PidGains {
    PidGains::symmetric(g.alt_kp, g.alt_ki, 0.0, g.pitch_max)
}

fn aspd_pitch_gains(g: &LongitudinalGains) -> PidGains {
    PidGains::symmetric(g.aspd_pitch_kp, g.aspd_pitch_ki, 0.0, g.pitch_max)
}

fn aspd_thr_gains(g: &LongitudinalGains) -> PidGains {
    PidGains {
        kp: g.aspd_thr_kp,
        ki: g.aspd_thr_ki,
        kd: 0.0,
        out_min: g.throttle_min,
        out_max: g.throttle_max,
    }
}

/// The sources of the pitch command and the throttle in regime `r` (Figure 3-16).
fn regime_sources(
    r: Regime,
    g: &LongitudinalGains,
    alt_c: f32,
    aspd_c: f32,
    pitch_ff: f32,
) -> (PitchSource, ThrottleSource) {
    match r {
        Regime::TakeOff => (
            PitchSource::Fixed(g.takeoff_pitch),
            ThrottleSource::Fixed(g.throttle_max),
        ),
        Regime::Climb => (
            PitchSource::Airspeed(aspd_c),
            ThrottleSource::Fixed(g.throttle_max),
        ),
        Regime::AltitudeHold => (
            PitchSource::Altitude(alt_c, pitch_ff),
            ThrottleSource::Airspeed(aspd_c),
        ),
        Regime::Descent => (
            PitchSource::Airspeed(aspd_c),
            ThrottleSource::Fixed(g.throttle_min),
        ),
    }
}

impl Longitudinal {
    /// A disengaged longitudinal autopilot; `transfer_tc` is the bumpless fade time constant, s.
    /// Gains are expected to have passed [`super::GainSet::validate`].
    pub fn new(gains: &LongitudinalGains, transfer_tc: f32) -> Self {
        Self {
            gains: *gains,
            pitch: Pid::new(pitch_gains(gains), transfer_tc),
            alt: Pid::new(alt_gains(gains), transfer_tc),
            aspd_pitch: Pid::new(aspd_pitch_gains(gains), transfer_tc),
            aspd_thr: Pid::new(aspd_thr_gains(gains), transfer_tc),
            alt_lpf: LowPass::new(gains.feedback_lpf_pole),
            aspd_lpf: LowPass::new(gains.feedback_lpf_pole),
            machine: RegimeMachine::new(),
            tecs: Tecs::new(&tecs::gains::DESIGNED, gains, transfer_tc),
            pitch_src: SourceKind::Off,
            thr_src: SourceKind::Off,
            elevator: gains.trim_elevator,
            throttle: gains.trim_throttle,
            pitch_cmd: f32::NAN,
            elev_resume: false,
            thr_resume: false,
            surface_scale: 1.0,
        }
    }

    /// The factor on the pitch and altitude loops' inputs for this airspeed
    /// ([`super::scaling::surface_scale`]); 1 until set. A factor that is not finite and
    /// positive is ignored.
    pub fn set_surface_scale(&mut self, scale: f32) {
        if scale.is_finite() && scale > 0.0 {
            self.surface_scale = scale;
        }
    }

    /// Replaces the gains in flight; engaged loops re-initialise bumplessly on the next step.
    pub fn set_gains(&mut self, gains: &LongitudinalGains, transfer_tc: f32) {
        self.gains = *gains;
        self.pitch.set_gains(pitch_gains(gains), transfer_tc);
        self.alt.set_gains(alt_gains(gains), transfer_tc);
        self.aspd_pitch
            .set_gains(aspd_pitch_gains(gains), transfer_tc);
        self.aspd_thr.set_gains(aspd_thr_gains(gains), transfer_tc);
        self.alt_lpf.set_pole(gains.feedback_lpf_pole);
        self.aspd_lpf.set_pole(gains.feedback_lpf_pole);
        let t = *self.tecs.gains();
        self.tecs.set_gains(&t, gains, transfer_tc);
        self.elev_resume = true;
        self.thr_resume = true;
    }

    /// Chooses the law of the altitude modes and the energy control's gains
    /// ([`TecsGains::enabled`]); a change of law takes effect bumplessly on the next step.
    pub fn set_energy_law(&mut self, t: &TecsGains, transfer_tc: f32) {
        self.tecs.set_gains(t, &self.gains, transfer_tc);
    }

    /// Makes the next engagement start from these positions instead of the trim.
    pub fn handover(&mut self, elevator: f32, throttle: f32) {
        if self.pitch_src == SourceKind::Off && elevator.is_finite() {
            self.elevator = elevator;
        }
        if self.thr_src == SourceKind::Off && throttle.is_finite() {
            self.throttle = throttle;
        }
    }

    /// The present regime (altitude modes only).
    pub fn regime(&self) -> Option<Regime> {
        self.machine.regime()
    }

    /// One step. Measurements the active loops need that are not finite (or a non-finite
    /// setpoint, or a bad `dt`) hold that output at its last good value; the loops resume
    /// bumplessly when the inputs are good again. The altitude and airspeed filters run on
    /// every good sample, whatever the mode, so they are warm when a loop engages.
    pub fn step(&mut self, m: &Measurements, mode: LonMode, dt: f32) -> LongitudinalOutput {
        let g = self.gains;
        let dt_good = dt.is_finite() && dt > 0.0;
        let alt_good = m.altitude.is_finite();
        let aspd_good = m.airspeed.is_finite();
        let alt_f = if dt_good && alt_good {
            self.alt_lpf.step(m.altitude, dt)
        } else {
            self.alt_lpf.output()
        };
        let aspd_f = if dt_good && aspd_good {
            self.aspd_lpf.step(m.airspeed, dt)
        } else {
            self.aspd_lpf.output()
        };
        // The estimators skip a bad sample or dt themselves.
        self.tecs.observe(m.altitude, m.airspeed, dt);

        let mut rejected = InputFlags::empty();
        let mut pitch_ff = 0.0;
        let mut rate_ff = 0.0;
        let (alt_c, aspd_c, clear) = match mode {
            LonMode::Off => {
                self.pitch.reset();
                self.alt.reset();
                self.aspd_pitch.reset();
                self.aspd_thr.reset();
                self.machine.reset();
                self.tecs.disengage();
                self.pitch_src = SourceKind::Off;
                self.thr_src = SourceKind::Off;
                self.elev_resume = false;
                self.thr_resume = false;
                self.elevator = g.trim_elevator;
                self.throttle = g.trim_throttle;
                return LongitudinalOutput {
                    elevator: self.elevator,
                    throttle: self.throttle,
                    pitch_cmd: f32::NAN,
                    ..Default::default()
                };
            }
            LonMode::Pitch { .. } | LonMode::AirspeedPitch { .. } => {
                self.machine.reset();
                (0.0, 0.0, None)
            }
            LonMode::Altitude { altitude, airspeed } => (altitude, airspeed, None),
            LonMode::Glide {
                altitude,
                airspeed,
                climb_rate,
            } => {
                // A bad rate or airspeed only loses the feed-forward; the loop still holds
                // the altitude command.
                rate_ff = climb_rate;
                let ratio = climb_rate / airspeed;
                if ratio.is_finite() {
                    pitch_ff = clamp(
                        crate::math::elementary::asin(ratio.clamp(-1.0, 1.0)),
                        -g.pitch_max,
                        g.pitch_max,
                    );
                }
                (altitude, airspeed, None)
            }
            LonMode::TakeOff {
                altitude,
                airspeed,
                clear_altitude,
            } => (altitude, airspeed, Some(clear_altitude)),
        };

        let mut energy = false;
        let sources = match mode {
            LonMode::Pitch { pitch, throttle } => {
                Some((PitchSource::Fixed(pitch), ThrottleSource::Fixed(throttle)))
            }
            LonMode::AirspeedPitch { airspeed, throttle } => Some((
                PitchSource::Airspeed(airspeed),
                ThrottleSource::Fixed(throttle),
            )),
            _ => {
                let cmd_ok =
                    alt_c.is_finite() && aspd_c.is_finite() && clear.is_none_or(f32::is_finite);
                rejected.set(InputFlags::COMMAND, !cmd_ok);
                rejected.set(InputFlags::ALTITUDE, !alt_good);
                let regime = match alt_f {
                    Some(h) if cmd_ok && alt_good && dt_good => {
                        Some(
                            self.machine
                                .update(alt_c - h, h, clear, g.alt_band, g.alt_hysteresis),
                        )
                    }
                    // Without a good altitude the regime stays as it was.
                    _ if cmd_ok => self.machine.regime(),
                    _ => None,
                };
                energy = self.tecs.gains().enabled && regime.is_some_and(|r| r != Regime::TakeOff);
                if energy {
                    let demand = TecsDemand {
                        altitude: alt_c,
                        airspeed: aspd_c,
                        climb_rate: rate_ff,
                    };
                    self.energy_sources(m, &demand, dt, &mut rejected)
                } else {
                    regime.map(|r| regime_sources(r, &g, alt_c, aspd_c, pitch_ff))
                }
            }
        };
        if !energy {
            self.tecs.disengage();
        }
        let (elevator_held, throttle_held) = match sources {
            None => {
                // No regime (no good altitude yet, or a bad command): hold both.
                rejected.set(InputFlags::DT, !dt_good);
                self.elev_resume = true;
                self.thr_resume = true;
                (true, true)
            }
            Some((ps, ts)) => {
                let e = self.step_elevator(m, ps, alt_f, aspd_f, dt, &mut rejected);
                let t = self.step_throttle(m, ts, aspd_f, dt, &mut rejected);
                (e, t)
            }
        };
        LongitudinalOutput {
            elevator: self.elevator,
            throttle: self.throttle,
            pitch_cmd: self.pitch_cmd,
            regime: if self.tecs.engaged() {
                None
            } else {
                self.machine.regime()
            },
            elevator_held,
            throttle_held,
            rejected,
        }
    }

    /// The energy control's throttle and pitch command as fixed sources for this step, engaging
    /// it from the commands in force; `None` (hold both) when it cannot step.
    fn energy_sources(
        &mut self,
        m: &Measurements,
        demand: &TecsDemand,
        dt: f32,
        rejected: &mut InputFlags,
    ) -> Option<(PitchSource, ThrottleSource)> {
        if !self.tecs.engaged() {
            let from = if self.pitch_src == SourceKind::Off {
                m.pitch
            } else {
                self.pitch_cmd
            };
            self.tecs.engage(self.throttle, from);
        }
        rejected.set(InputFlags::AIRSPEED, !m.airspeed.is_finite());
        if !(m.airspeed.is_finite() && m.altitude.is_finite()) {
            return None;
        }
        self.tecs.step(demand, &self.gains, dt).map(|o| {
            (
                PitchSource::Fixed(o.pitch_cmd),
                ThrottleSource::Fixed(o.throttle),
            )
        })
    }

    fn step_elevator(
        &mut self,
        m: &Measurements,
        src: PitchSource,
        alt_f: Option<f32>,
        aspd_f: Option<f32>,
        dt: f32,
        rejected: &mut InputFlags,
    ) -> bool {
        let g = self.gains;
        let mut bad = InputFlags::empty();
        bad.set(InputFlags::PITCH, !m.pitch.is_finite());
        bad.set(InputFlags::PITCH_RATE, !m.pitch_rate.is_finite());
        bad.set(InputFlags::DT, !(dt.is_finite() && dt > 0.0));
        let (feedback, setpoint) = match src {
            PitchSource::Fixed(v) => (Some(0.0), v),
            PitchSource::Airspeed(v) => {
                bad.set(InputFlags::AIRSPEED, !m.airspeed.is_finite());
                (aspd_f, v)
            }
            PitchSource::Altitude(v, _) => {
                bad.set(InputFlags::ALTITUDE, !m.altitude.is_finite());
                (alt_f, v)
            }
        };
        bad.set(InputFlags::COMMAND, !setpoint.is_finite());
        let feedback = match feedback {
            Some(f) if bad.is_empty() => f,
            _ => {
                *rejected |= bad;
                self.elev_resume = true;
                return true;
            }
        };

        let prev = self.pitch_src;
        let kind = src.kind();
        if prev == SourceKind::Off || self.elev_resume {
            self.pitch.reset_to(self.elevator, Bumpless::Integrator);
        }
        if prev != kind || self.elev_resume {
            // The new source of the pitch command starts where the old one left it (from the
            // present attitude when engaging).
            let from = if prev == SourceKind::Off {
                m.pitch
            } else {
                self.pitch_cmd
            };
            match kind {
                SourceKind::Airspeed => self.aspd_pitch.reset_to(from, Bumpless::Fade),
                SourceKind::Altitude => self.alt.reset_to(from, Bumpless::Fade),
                _ => {}
            }
        }
        let theta_c = match src {
            PitchSource::Fixed(v) => clamp(v, -g.pitch_max, g.pitch_max),
            // Both outer loops were designed about the trim: their output is added to it.
            PitchSource::Airspeed(v) => {
                self.aspd_pitch
                    .step(v - feedback, Derivative::None, g.trim_pitch, dt)
            }
            // A pitch change climbs at the airspeed times it: the altitude loop takes the
            // surface loops' airspeed factor too.
            PitchSource::Altitude(v, ff) => self.alt.step(
                self.surface_scale * (v - feedback),
                Derivative::None,
                g.trim_pitch + ff,
                dt,
            ),
        };
        let e = wrap_pi(theta_c - m.pitch);
        let k = self.surface_scale;
        // The damper acts on the pitch rate beyond a coordinated turn's own (PX4's turn
        // coordination): banked, the aircraft pitches up at `g sin(phi) tan(phi) / Va` to
        // follow its turn, and damping that rate pushes the nose down through every turn.
        self.elevator = self.pitch.step(
            k * e,
            Derivative::Rate(k * (m.pitch_rate - turn_pitch_rate(m.roll, m.airspeed))),
            g.trim_elevator,
            dt,
        );
        self.pitch_cmd = theta_c;
        self.pitch_src = kind;
        self.elev_resume = false;
        false
    }

    fn step_throttle(
        &mut self,
        m: &Measurements,
        src: ThrottleSource,
        aspd_f: Option<f32>,
        dt: f32,
        rejected: &mut InputFlags,
    ) -> bool {
        let g = self.gains;
        let mut bad = InputFlags::empty();
        bad.set(InputFlags::DT, !(dt.is_finite() && dt > 0.0));
        let (feedback, setpoint) = match src {
            ThrottleSource::Fixed(v) => (Some(0.0), v),
            ThrottleSource::Airspeed(v) => {
                bad.set(InputFlags::AIRSPEED, !m.airspeed.is_finite());
                (aspd_f, v)
            }
        };
        bad.set(InputFlags::COMMAND, !setpoint.is_finite());
        let feedback = match feedback {
            Some(f) if bad.is_empty() => f,
            _ => {
                *rejected |= bad;
                self.thr_resume = true;
                return true;
            }
        };
        let kind = src.kind();
        self.throttle = match src {
            ThrottleSource::Fixed(v) => {
                self.aspd_thr.reset();
                clamp(v, g.throttle_min, g.throttle_max)
            }
            ThrottleSource::Airspeed(v) => {
                if self.thr_src != kind || self.thr_resume {
                    self.aspd_thr.reset_to(self.throttle, Bumpless::Fade);
                }
                self.aspd_thr
                    .step(v - feedback, Derivative::None, g.trim_throttle, dt)
            }
        };
        self.thr_src = kind;
        self.thr_resume = false;
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DT: f32 = 0.02;
    const D: f32 = core::f32::consts::PI / 180.0;

    #[test]
    fn regime_zones_and_sequence() {
        let mut rm = RegimeMachine::new();
        // Starting on the ground with a take-off request.
        assert_eq!(
            rm.update(100.0, 0.0, Some(20.0), 10.0, 2.0),
            Regime::TakeOff
        );
        assert_eq!(
            rm.update(85.0, 15.0, Some(20.0), 10.0, 2.0),
            Regime::TakeOff
        );
        assert_eq!(rm.update(79.0, 21.0, Some(20.0), 10.0, 2.0), Regime::Climb);
        // Sinking below the clear altitude again does not go back to take-off.
        assert_eq!(rm.update(81.0, 19.0, Some(20.0), 10.0, 2.0), Regime::Climb);
        assert_eq!(rm.update(10.5, 89.5, Some(20.0), 10.0, 2.0), Regime::Climb);
        assert_eq!(
            rm.update(9.5, 90.5, Some(20.0), 10.0, 2.0),
            Regime::AltitudeHold
        );
        // New, lower setpoint: straight to descent, then hold inside the band.
        assert_eq!(rm.update(-50.0, 100.0, None, 10.0, 2.0), Regime::Descent);
        assert_eq!(rm.update(-10.5, 60.5, None, 10.0, 2.0), Regime::Descent);
        assert_eq!(rm.update(-9.5, 59.5, None, 10.0, 2.0), Regime::AltitudeHold);
        // From scratch without take-off: by zone.
        let mut rm = RegimeMachine::new();
        assert_eq!(rm.update(30.0, 0.0, None, 10.0, 2.0), Regime::Climb);
        let mut rm = RegimeMachine::new();
        assert_eq!(rm.update(-30.0, 0.0, None, 10.0, 2.0), Regime::Descent);
        let mut rm = RegimeMachine::new();
        assert_eq!(rm.update(3.0, 0.0, None, 10.0, 2.0), Regime::AltitudeHold);
    }

    /// The altitude error wanders across the band edge (10 m) by less than the hysteresis
    /// (2 m): after entering the hold regime the machine stays there. Without hysteresis the
    /// same signal would switch on nearly every crossing.
    #[test]
    fn hysteresis_prevents_chattering_at_the_band_edge() {
        let count_switches = |hyst: f32| {
            let mut rm = RegimeMachine::new();
            let mut last = rm.update(15.0, 0.0, None, 10.0, hyst);
            let mut switches = 0;
            for k in 0..1000 {
                // 10 m +- 1.5 m, a slow sine plus a fast "noise" component.
                let t = k as f32 * DT;
                let e = 10.0 + 1.0 * libm::sinf(0.7 * t) + 0.5 * libm::sinf(37.0 * t);
                let r = rm.update(e, 0.0, None, 10.0, hyst);
                if r != last {
                    switches += 1;
                    last = r;
                }
            }
            switches
        };
        assert_eq!(count_switches(2.0), 1, "one entry into hold, then nothing");
        assert!(
            count_switches(0.0) > 20,
            "the same signal chatters without hysteresis"
        );
    }

    fn meas(pitch: f32, alt: f32, va: f32) -> Measurements {
        Measurements {
            pitch,
            altitude: alt,
            airspeed: va,
            ..Measurements::level(va, alt)
        }
    }

    #[test]
    fn regime_transfers_are_bumpless() {
        let g = THESIS;
        let mut lon = Longitudinal::new(&g, 1.0);
        let mode = LonMode::Altitude {
            altitude: 130.0,
            airspeed: 17.0,
        };
        // Climb: full throttle, pitch command from the airspeed loop, started at the attitude.
        let o = lon.step(&meas(0.1, 100.0, 17.5), mode, DT);
        assert_eq!(o.regime, Some(Regime::Climb));
        assert_eq!(o.throttle, 1.0);
        assert!((o.pitch_cmd - 0.1).abs() < 1e-6);
        let mut h = 100.0;
        let mut last = o;
        let mut saw_hold = false;
        for _ in 0..2000 {
            h += 0.05;
            let o = lon.step(&meas(0.1, h, 17.5), mode, DT);
            // The pitch command never jumps, whatever the regime does.
            assert!(
                (o.pitch_cmd - last.pitch_cmd).abs() < 0.5 * D,
                "{last:?} -> {o:?}"
            );
            if o.regime == Some(Regime::AltitudeHold) && last.regime == Some(Regime::Climb) {
                // The throttle loop takes over from full throttle without a jump.
                assert!(
                    (o.throttle - last.throttle).abs() < 0.05,
                    "{last:?} -> {o:?}"
                );
                saw_hold = true;
            }
            last = o;
            if saw_hold {
                break;
            }
        }
        assert!(saw_hold);
    }

    /// On a glide slope the pitch command carries the flight-path angle of the command's
    /// rate, `asin(climb_rate / airspeed)`, on top of what the altitude loop asks for; a rate
    /// that is not a number loses only that feed-forward.
    #[test]
    fn glide_feeds_the_flight_path_angle_forward() {
        let g = THESIS;
        let run = |mode: LonMode| {
            let mut lon = Longitudinal::new(&g, 1.0);
            let mut o = LongitudinalOutput::default();
            // Ten seconds: the engagement's bumpless offset has faded.
            for _ in 0..500 {
                o = lon.step(&meas(0.0, 40.0, 15.0), mode, DT);
            }
            o
        };
        let hold = run(LonMode::Altitude {
            altitude: 41.0,
            airspeed: 15.0,
        });
        let glide = |climb_rate| {
            run(LonMode::Glide {
                altitude: 41.0,
                airspeed: 15.0,
                climb_rate,
            })
        };
        let down = glide(-1.3);
        assert_eq!(hold.regime, Some(Regime::AltitudeHold));
        assert_eq!(down.regime, Some(Regime::AltitudeHold));
        let gamma = libm::asinf(-1.3 / 15.0);
        assert!(
            (down.pitch_cmd - hold.pitch_cmd - gamma).abs() < 1e-4,
            "{} vs {} + {gamma}",
            down.pitch_cmd,
            hold.pitch_cmd
        );
        let bad = glide(f32::NAN);
        assert!((bad.pitch_cmd - hold.pitch_cmd).abs() < 1e-6);
        assert!(bad.rejected.is_empty());
    }

    /// A glide's altitude command that is not a finite number is refused as the hold's is.
    #[test]
    fn a_bad_glide_command_is_refused() {
        for altitude in [f32::NAN, f32::NEG_INFINITY, f32::INFINITY] {
            let mut lon = Longitudinal::new(&THESIS, 1.0);
            let mode = LonMode::Glide {
                altitude,
                airspeed: 15.0,
                climb_rate: -1.3,
            };
            let o = lon.step(&meas(0.0, 40.0, 15.0), mode, DT);
            assert!(
                o.rejected.contains(InputFlags::COMMAND),
                "{altitude}: {o:?}"
            );
        }
    }

    #[test]
    fn pitch_command_and_throttle_saturate() {
        let g = THESIS;
        let mut lon = Longitudinal::new(&g, 1.0);
        let o = lon.step(
            &meas(0.0, 100.0, 17.0),
            LonMode::Pitch {
                pitch: 40.0 * D,
                throttle: 1.7,
            },
            DT,
        );
        assert!((o.pitch_cmd - 20.0 * D).abs() < 1e-6);
        assert_eq!(o.throttle, 1.0);
        let o = lon.step(
            &meas(0.0, 100.0, 17.0),
            LonMode::Pitch {
                pitch: 40.0 * D,
                throttle: 1.7,
            },
            DT,
        );
        assert!(
            o.elevator >= -SURFACE_LIMIT_RAD && o.elevator < g.trim_elevator,
            "nose up: {o:?}"
        );
        // Far below the setpoint in altitude hold (band 500 m): pitch command at +20 deg.
        let mut g2 = g;
        g2.alt_band = 500.0;
        let mut lon = Longitudinal::new(&g2, 0.01);
        let mode = LonMode::Altitude {
            altitude: 300.0,
            airspeed: 17.0,
        };
        let mut o = lon.step(&meas(0.0, 100.0, 17.0), mode, DT);
        for _ in 0..100 {
            o = lon.step(&meas(0.0, 100.0, 12.0), mode, DT);
        }
        assert_eq!(o.regime, Some(Regime::AltitudeHold));
        assert!((o.pitch_cmd - 20.0 * D).abs() < 1e-5, "{}", o.pitch_cmd / D);
        // Too slow by 5 m/s: throttle at its maximum, not beyond.
        assert_eq!(o.throttle, 1.0);
    }

    #[test]
    fn signs_follow_umn_convention() {
        let mut g = THESIS;
        g.trim_elevator = 0.0;
        let mut lon = Longitudinal::new(&g, 1.0);
        let m = meas(0.0, 100.0, 17.0);
        let level = LonMode::Pitch {
            pitch: 0.0,
            throttle: 0.5,
        };
        // Engaged first (bumpless: output = trim), then asked for nose up: negative elevator.
        lon.step(&m, level, DT);
        let o = lon.step(
            &m,
            LonMode::Pitch {
                pitch: 5.0 * D,
                throttle: 0.5,
            },
            DT,
        );
        assert!(o.elevator < 0.0);
        // Pitching up with no error: positive elevator against it.
        let mut lon = Longitudinal::new(&g, 1.0);
        let m2 = Measurements {
            pitch_rate: 0.3,
            ..m
        };
        lon.step(&m, level, DT);
        let o = lon.step(&m2, level, DT);
        assert!((o.elevator - 0.072 * 0.3).abs() < 1e-6, "{o:?}");
        // Too slow, airspeed by pitch: nose down.
        let mut lon = Longitudinal::new(&g, 1.0);
        lon.step(
            &m,
            LonMode::AirspeedPitch {
                airspeed: 17.0,
                throttle: 0.5,
            },
            DT,
        );
        let mut o = LongitudinalOutput::default();
        for _ in 0..50 {
            o = lon.step(
                &meas(0.0, 100.0, 16.0),
                LonMode::AirspeedPitch {
                    airspeed: 17.0,
                    throttle: 0.5,
                },
                DT,
            );
        }
        assert!(o.pitch_cmd < 0.0, "{o:?}");
    }

    /// A level coordinated turn at 45 deg and 17 m/s turns at `g tan(phi) / Va` = 0.577 rad/s
    /// about the vertical, which the banked body sees as 0.408 rad/s of pitch rate (`sin(phi)`
    /// of it) and 0.408 of yaw rate (`cos(phi)`): that pitch rate leaves the elevator where
    /// wings level at no rate puts it, and 0.1 rad/s beyond it is damped as 0.1 rad/s is wings
    /// level (0.072 times it, `PTCH_RATE_KD`, unscaled at the thesis's 17 m/s).
    #[test]
    fn a_coordinated_turn_s_own_pitch_rate_is_not_damped() {
        let (phi, va) = (45.0 * D, 17.0);
        let turn_rate = crate::math::GRAVITY * libm::tanf(phi) / va;
        let q_turn = turn_rate * libm::sinf(phi);
        assert!((q_turn - 0.4079).abs() < 1e-3, "{q_turn}");
        assert!((turn_pitch_rate(phi, va) - q_turn).abs() < 1e-6);
        let mut g = THESIS;
        g.trim_elevator = 0.0;
        let level = LonMode::Pitch {
            pitch: 0.0,
            throttle: 0.5,
        };
        let elevator = |roll: f32, pitch_rate: f32| {
            let mut lon = Longitudinal::new(&g, 1.0);
            let m = meas(0.0, 100.0, va);
            lon.step(&m, level, DT);
            let turning = Measurements {
                roll,
                pitch_rate,
                ..m
            };
            lon.step(&turning, level, DT).elevator
        };
        let wings_level = elevator(0.0, 0.0);
        assert!((elevator(phi, q_turn) - wings_level).abs() < 1e-5);
        let beyond = elevator(phi, q_turn + 0.1);
        assert!((beyond - elevator(0.0, 0.1)).abs() < 1e-5);
        assert!((beyond - 0.072 * 0.1).abs() < 1e-5, "{beyond}");
        // Standing still (no airspeed to turn with) and from bad data, no turn is reckoned;
        // past 60 deg of bank, the turn of 60 deg.
        assert_eq!(turn_pitch_rate(phi, 0.5), 0.0);
        assert_eq!(turn_pitch_rate(f32::NAN, va), 0.0);
        assert_eq!(turn_pitch_rate(phi, f32::INFINITY), 0.0);
        assert_eq!(turn_pitch_rate(80.0 * D, va), turn_pitch_rate(60.0 * D, va));
    }

    fn energy_law() -> Longitudinal {
        let mut lon = Longitudinal::new(&FLIGHT, 1.0);
        lon.set_energy_law(&tecs::gains::ENGAGED, 1.0);
        lon
    }

    /// Under the energy law an altitude mode at the trim state gives the trim throttle and
    /// pitches to the trim pitch, and reports no regime; the take-off regime below the clear
    /// altitude is the same fixed pitch and full throttle as under the regimes.
    #[test]
    fn the_energy_law_holds_trim_and_keeps_the_take_off_regime() {
        let mut lon = energy_law();
        let mode = LonMode::Altitude {
            altitude: 100.0,
            airspeed: 17.0,
        };
        let mut o = LongitudinalOutput::default();
        for _ in 0..500 {
            o = lon.step(&meas(FLIGHT.trim_pitch, 100.0, 17.0), mode, DT);
        }
        assert_eq!(o.regime, None);
        assert!((o.throttle - FLIGHT.trim_throttle).abs() < 1e-4, "{o:?}");
        assert!((o.pitch_cmd - FLIGHT.trim_pitch).abs() < 1e-4, "{o:?}");
        let mut lon = energy_law();
        let take_off = LonMode::TakeOff {
            altitude: 160.0,
            airspeed: 17.0,
            clear_altitude: 120.0,
        };
        // Climbing at 2 m/s through the clear altitude.
        let mut last = lon.step(&meas(0.1, 110.0, 15.0), take_off, DT);
        let mut handed_over = false;
        for k in 1..1000 {
            let o = lon.step(&meas(0.1, 110.0 + 0.04 * k as f32, 15.0), take_off, DT);
            if o.regime == Some(Regime::TakeOff) {
                assert_eq!(o.throttle, FLIGHT.throttle_max);
                assert!((o.pitch_cmd - FLIGHT.takeoff_pitch).abs() < 1e-6);
            } else {
                // The energy law takes over from those commands, no jump.
                assert_eq!(o.regime, None);
                assert!(
                    (o.pitch_cmd - last.pitch_cmd).abs() < 1e-3,
                    "{last:?} {o:?}"
                );
                assert!((o.throttle - last.throttle).abs() < 1e-3, "{last:?} {o:?}");
                handed_over = true;
                break;
            }
            last = o;
        }
        assert!(handed_over);
    }

    /// Switching the law in flight changes neither the throttle nor the pitch command at once.
    #[test]
    fn switching_the_law_in_flight_is_bumpless() {
        let mut lon = Longitudinal::new(&FLIGHT, 1.0);
        let mode = LonMode::Altitude {
            altitude: 104.0,
            airspeed: 17.0,
        };
        let m = meas(0.05, 100.0, 16.0);
        let mut o = lon.step(&m, mode, DT);
        for _ in 0..100 {
            o = lon.step(&m, mode, DT);
        }
        assert_eq!(o.regime, Some(Regime::AltitudeHold));
        lon.set_energy_law(&tecs::gains::ENGAGED, 1.0);
        let o2 = lon.step(&m, mode, DT);
        assert_eq!(o2.regime, None);
        assert!((o2.pitch_cmd - o.pitch_cmd).abs() < 2e-3, "{o:?} {o2:?}");
        assert!((o2.throttle - o.throttle).abs() < 2e-3, "{o:?} {o2:?}");
        lon.set_energy_law(&tecs::gains::DESIGNED, 1.0);
        let o3 = lon.step(&m, mode, DT);
        assert_eq!(o3.regime, Some(Regime::AltitudeHold));
        assert!((o3.pitch_cmd - o2.pitch_cmd).abs() < 2e-3, "{o2:?} {o3:?}");
        assert!((o3.throttle - o2.throttle).abs() < 2e-3, "{o2:?} {o3:?}");
    }

    /// A bad airspeed under the energy law holds both outputs and says why; the law resumes
    /// from the held values.
    #[test]
    fn the_energy_law_holds_on_a_bad_airspeed() {
        let mut lon = energy_law();
        let mode = LonMode::Glide {
            altitude: 90.0,
            airspeed: 15.0,
            climb_rate: -1.0,
        };
        let mut prev = lon.step(&meas(0.0, 100.0, 15.0), mode, DT);
        let mut o = prev;
        for _ in 0..20 {
            prev = o;
            o = lon.step(&meas(0.0, 100.0, 15.0), mode, DT);
        }
        let bad = lon.step(&meas(0.0, 100.0, f32::NAN), mode, DT);
        assert!(bad.elevator_held && bad.throttle_held);
        assert!(bad.rejected.contains(InputFlags::AIRSPEED));
        assert_eq!((bad.elevator, bad.throttle), (o.elevator, o.throttle));
        let back = lon.step(&meas(0.0, 100.0, 15.0), mode, DT);
        // It goes on at the pace it had: no larger a step than twice the last one.
        let pace = (o.throttle - prev.throttle).abs();
        assert!(!back.throttle_held && (back.throttle - o.throttle).abs() <= 2.0 * pace + 1e-4);
    }
}
