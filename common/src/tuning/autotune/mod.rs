//! The autotune the vehicle flies (`MAV_CMD_DO_AUTOTUNE_ENABLE`): it excites each loop in turn
//! within its limits, fits the thesis's reduced models to what it flew, designs the gains on
//! them by successive loop closure and hands them over once every loop meets its margins.
//!
//! ```text
//! Level ─► Roll ─► Level ─► Pitch ─► Level ─► Throttle ─► Level ─► Yaw ─► Level ─► fit ─► design ─► gains
//!   └──────────────────── any limit, mode change, failsafe, the station: abort, gains kept ───────────────┘
//! ```
//!
//! It flies the aircraft itself: wings level at the altitude and airspeed it started at
//! (the altitude-holding law), the roll excitation on the roll command, the rudder's on the
//! rudder (its trim the level flight's, the yaw damper off), the pitch and throttle
//! excitation on the pitch-attitude law with the level flight's pitch and throttle. Nothing
//! here reads a clock or a sensor: the vehicle hands it the estimate and the surfaces each
//! control tick and flies what it answers.

pub mod excite;
pub mod params;

#[cfg(test)]
mod tests;

use super::design::{self, DesignFailure, DesignInputs, DesignModel, Designer};
use super::identify::{
    Axis, AxisError, AxisFit, Identifier, IdentifyConfig, Sample, AIRSPEED_FILTER_TAU_S,
    ATTITUDE_FILTER_TAU_S,
};
use crate::actuators::Surfaces;
use crate::control::autopilot::{Commands, GainSet};
use crate::control::lateral::{RollMode, YawMode, RUDDER};
use crate::control::longitudinal::LonMode;
use crate::estimator::EstimatedState;
use crate::math::frames::{ned_to_body, AirData};
use crate::math::RAD2DEG;
use excite::Stage;
use nalgebra::Vector3;
use params::{AutotuneParams, UNIDENTIFIED};

/// Share of the abort limits the excitation uses: a 3-2-1-1 on a closed loop overshoots its
/// command by the loop's own overshoot (17 % for the roll loop), and the turbulence adds its
/// own, so 0.4 leaves the aircraft more than twice the excitation's room to its limit.
pub const EXCITATION_SHARE: f32 = 0.4;

/// Why an autotune stopped before its end; the values are what broke the limit.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Abort {
    /// Bank beyond `ATUN_BANK_MAX`, deg.
    Bank(f32),
    /// Pitch beyond `ATUN_PITCH_MAX` from level, deg.
    Pitch(f32),
    /// Height lost below the start beyond `ATUN_HGT_LOSS`, m.
    HeightLoss(f32),
    /// Airspeed outside the navigator's range, m/s.
    Airspeed(f32),
    /// The station or the pilot chose another mode.
    ModeChanged,
    /// A failsafe was raised.
    Failsafe,
    /// On the ground, or disarmed.
    Landed,
    /// The GPS or the airspeed sensor failed.
    Sensors,
    /// The station asked it to stop.
    Station,
}

/// Why an autotune flown to its end gave no gains.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Failure {
    /// An axis's input did not vary enough (the excitation was held back by a limit).
    NotExcited(Axis),
    /// An axis's regressors never varied independently.
    Singular(Axis),
    /// An axis's model explained too little of what was flown: the axis and its R^2.
    PoorFit(Axis, f32),
    /// The design on the models failed a loop's margins or bounds.
    Design(DesignFailure),
}

/// What the autotune has to tell the station.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Report {
    /// Started (the level flight it starts from).
    Started,
    /// A stage of the excitation began.
    Stage(Stage),
    /// An axis's model: its first three coefficients (in [`Axis::coefficients`]' order) and
    /// its R^2.
    Fitted(Axis, [f32; 3], f32),
    /// The design met every margin; the gains were handed over.
    Applied,
    /// Stopped before its end; the gains as they were.
    Aborted(Abort),
    /// Flown to its end without gains; the gains as they were.
    Failed(Failure),
}

/// Where the autotune stands, for the station's progress.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Status {
    /// Never run since boot.
    #[default]
    Idle,
    /// Running: its progress, 0-99, in QGroundControl's bands (under 20 starting, 20-39 roll,
    /// 40-59 pitch, 60-79 the third axis (here the throttle, 60-69, then the yaw, 70-79),
    /// 80-99 fitting and designing).
    Running(u8),
    /// The last one applied its gains.
    Succeeded,
    /// The last one aborted or failed.
    Failed,
}

/// What the vehicle tells the autotune each control tick besides the estimate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Situation {
    /// The mode it started in is still flown.
    pub mode_kept: bool,
    /// A failsafe is raised.
    pub failsafe: bool,
    /// Armed and in the air.
    pub flying: bool,
    /// The airspeed range it must stay in, m/s.
    pub airspeed_range: (f32, f32),
}

/// What the autotune answers a control tick.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Tick {
    /// Fly these instead of the mode's commands.
    pub commands: Option<Commands>,
    /// Tell the station.
    pub report: Option<Report>,
    /// The model identified, once every axis is fitted: publish it (whatever the design
    /// then makes of it).
    pub identified: Option<DesignModel>,
    /// The designed gains: apply them.
    pub gains: Option<GainSet>,
}

/// Where the level flight it started from is.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Start {
    /// Where it started: the height lost is counted from here.
    alt_m: f32,
    /// The height each level stage holds: where the stage began. The stages before leave the
    /// aircraft some metres off (the Aerosonde's throttle steps, 11 m low), and climbing back
    /// to the start took the Aerosonde's altitude loop to 17 deg of pitch, beyond the pitch
    /// change that aborts it.
    hold_alt_m: f32,
    airspeed: f32,
    /// Pitch, throttle and rudder of level flight: followed (slowly) in the level stages.
    pitch: f32,
    throttle: f32,
    rudder: f32,
    /// The wind estimate, NED, m/s, followed the same way and held through the excitation:
    /// the wind filter takes a sideslip that lasts for its own wind (it assumes none), a third
    /// of the rudder doublets' on the 25e, and the side-force fit read through it put
    /// `a_beta2` 32 % short; the air mass does not move with the rudder.
    wind: Vector3<f32>,
}

// The designer in place, not boxed: no heap, and one autotune per vehicle.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
enum Phase {
    Idle,
    /// Flying the timeline, `t_s` into it, fitting what it flies.
    Flying {
        t_s: f32,
        id: Identifier,
    },
    /// Fitting axis `next` of [`FITTED`] (one a tick: a solve is a few thousand
    /// instructions), then the model handed to the parameters (`next` one past the last
    /// axis) and the designer set up (two past), the design's steps following.
    Fitting {
        next: usize,
        id: Identifier,
    },
    Designing(Designer),
}

/// Where a tick takes the autotune ([`Autotune::advance`]).
// The designer in place, as in `Phase`.
#[allow(clippy::large_enum_variant)]
enum Next {
    Idle,
    Fitting,
    Designing(Designer),
}

/// About the steps a design takes (199 for the 25e), for the progress reported.
const DESIGN_STEPS: f32 = 200.0;

/// The axes the design needs, in the order they are fitted.
const FITTED: [Axis; 5] = [
    Axis::Roll,
    Axis::Sideslip,
    Axis::Pitch,
    Axis::Airspeed,
    Axis::FlightPath,
];

/// Time constant of the level pitch and throttle's average, s: longer than the altitude
/// loop's oscillation, shorter than a level stage.
const LEVEL_TC_S: f32 = 1.0;

/// Height from the one it holds within which a level stage's flight is level, m: outside it
/// the altitude loop is climbing or diving back to it, and its pitch and throttle are not the
/// level flight's.
const LEVEL_BAND_M: f32 = 2.0;

/// The autotune.
#[derive(Clone, Debug)]
pub struct Autotune {
    /// What it does now; the identifier and the designer, each in its phase, share their
    /// memory (the application's 40 KiB).
    phase: Phase,
    status: Status,
    start: Start,
    stage: Option<Stage>,
    /// The model as fitted so far.
    model: DesignModel,
}

impl Default for Autotune {
    fn default() -> Self {
        Self::new()
    }
}

impl Autotune {
    /// Not running.
    pub fn new() -> Self {
        Self {
            phase: Phase::Idle,
            status: Status::Idle,
            start: Start {
                alt_m: 0.0,
                hold_alt_m: 0.0,
                airspeed: 0.0,
                pitch: 0.0,
                throttle: 0.0,
                rudder: 0.0,
                wind: Vector3::zeros(),
            },
            stage: None,
            model: UNIDENTIFIED,
        }
    }

    /// Where it stands.
    pub fn status(&self) -> Status {
        self.status
    }

    /// Running (flying its excitation, fitting or designing).
    pub fn running(&self) -> bool {
        !matches!(self.phase, Phase::Idle)
    }

    /// Starts from level flight at `e`'s altitude, holding `airspeed` (m/s), from the
    /// surfaces `s` flown now.
    pub fn start(&mut self, e: &EstimatedState, airspeed: f32, s: &Surfaces, p: &AutotuneParams) {
        let tau = 1.0 / (2.0 * core::f32::consts::PI * p.servo_bw_hz);
        let id = Identifier::new(IdentifyConfig {
            airspeed_ref: airspeed,
            servo_tau_s: tau,
            servo_rate_radps: p.servo_rate,
            airspeed_filter_tau_s: AIRSPEED_FILTER_TAU_S,
            attitude_filter_tau_s: ATTITUDE_FILTER_TAU_S,
        });
        self.start = Start {
            alt_m: e.alt_amsl_m,
            hold_alt_m: e.alt_amsl_m,
            airspeed,
            pitch: e.euler.theta,
            throttle: s.throttle,
            rudder: s.rudder,
            wind: e.wind_ned,
        };
        self.stage = None;
        self.model = DesignModel {
            va: airspeed,
            servo_bandwidth_hz: p.servo_bw_hz,
            ..UNIDENTIFIED
        };
        self.phase = Phase::Flying { t_s: 0.0, id };
        self.status = Status::Running(0);
    }

    /// The gains it designed were refused where they were to be applied: it failed.
    pub fn refused(&mut self) {
        self.status = Status::Failed;
    }

    /// Stops it for `why` (nothing if it is not running).
    pub fn abort(&mut self, why: Abort) -> Option<Report> {
        if !self.running() {
            return None;
        }
        self.phase = Phase::Idle;
        self.status = Status::Failed;
        Some(Report::Aborted(why))
    }

    /// The wind the sideslip is read against while it runs ([`sample`]'s `wind_ned`): the
    /// estimate's, held through each stage of the excitation.
    pub fn wind(&self) -> Vector3<f32> {
        self.start.wind
    }

    /// What the tick flew: `sample` of the estimate at the tick's time with the surfaces the
    /// loops commanded then (held until the next), `dt` s after the last. The models read
    /// each command against the motion it makes after it, so the sample is taken after the
    /// loops' step, not before.
    pub fn observe(&mut self, dt: f32, sample: &Sample) {
        if let Phase::Flying { id, .. } = &mut self.phase {
            id.push(dt, sample);
        }
    }

    /// One control tick, `dt` s after the last: `e` the estimate, `s` the surfaces flown
    /// over the interval, `base` the gains flown now.
    pub fn step(
        &mut self,
        dt: f32,
        e: &EstimatedState,
        s: &Surfaces,
        situation: &Situation,
        p: &AutotuneParams,
        base: &GainSet,
    ) -> Tick {
        if let Some(why) = self.broken(e, situation, p) {
            return Tick {
                report: self.abort(why),
                ..Tick::default()
            };
        }
        // The identifier and the designer stay where they are (some 1.2 KB each: moved out of
        // the phase and back, they cost the MCU a few thousand instructions a tick): each arm
        // takes what it needs of them, then the tick is worked out on the rest.
        let (next, mut tick) = match &mut self.phase {
            Phase::Idle => (None, Tick::default()),
            Phase::Flying { t_s, .. } => {
                let t = *t_s;
                self.fly(t, dt, e, s, p, base)
            }
            Phase::Fitting { next, id } => {
                let n = *next;
                let fitted = FITTED.get(n).map(|&axis| (axis, id.fit(axis)));
                self.fit(n, fitted, p, base)
            }
            Phase::Designing(d) => match d.step() {
                design::Step::Pending => {
                    let share = d.steps() as f32 / DESIGN_STEPS;
                    self.status = Status::Running(85 + (share.min(1.0) * 14.0) as u8);
                    (None, Tick::default())
                }
                design::Step::Done(g) => {
                    self.status = Status::Succeeded;
                    // Designed at the airspeed flown: where the loops scale with the airspeed,
                    // this is the one at which they hold as designed.
                    let mut gains = g.gains;
                    if gains.scaling_airspeed > 0.0 {
                        gains.scaling_airspeed = self.model.va;
                    }
                    let tick = Tick {
                        report: Some(Report::Applied),
                        gains: Some(gains),
                        ..Tick::default()
                    };
                    (Some(Next::Idle), tick)
                }
                design::Step::Failed(f) => self.fail(Failure::Design(f)),
            },
        };
        if let Some(next) = next {
            self.advance(next);
        }
        if self.running() && tick.commands.is_none() {
            tick.commands = Some(self.level());
        }
        tick
    }

    /// The limit broken, if one is.
    fn broken(&self, e: &EstimatedState, c: &Situation, p: &AutotuneParams) -> Option<Abort> {
        if !self.running() {
            return None;
        }
        let pitch_change = e.euler.theta - self.start.pitch;
        let lost = self.start.alt_m - e.alt_amsl_m;
        let (lo, hi) = c.airspeed_range;
        // A failed sensor raises its failsafe in the same tick: named first, as the cause.
        if !c.flying {
            Some(Abort::Landed)
        } else if !e.health.gps.healthy || !e.health.pitot.healthy {
            Some(Abort::Sensors)
        } else if c.failsafe {
            Some(Abort::Failsafe)
        } else if !c.mode_kept {
            Some(Abort::ModeChanged)
        } else if e.euler.phi.abs() > p.bank_max {
            Some(Abort::Bank(e.euler.phi * RAD2DEG))
        } else if pitch_change.abs() > p.pitch_max {
            Some(Abort::Pitch(pitch_change * RAD2DEG))
        } else if lost > p.height_loss_m {
            Some(Abort::HeightLoss(lost))
        } else if !(lo..=hi).contains(&e.airspeed) {
            Some(Abort::Airspeed(e.airspeed))
        } else {
            None
        }
    }

    /// Wings level at the start's altitude and airspeed.
    fn level(&self) -> Commands {
        Commands {
            roll: RollMode::Roll(0.0),
            yaw: RUDDER,
            lon: LonMode::Altitude {
                altitude: self.start.hold_alt_m,
                airspeed: self.start.airspeed,
            },
        }
    }

    /// A tick of the excitation's timeline.
    #[allow(clippy::too_many_arguments)]
    fn fly(
        &mut self,
        t_s: f32,
        dt: f32,
        e: &EstimatedState,
        s: &Surfaces,
        p: &AutotuneParams,
        base: &GainSet,
    ) -> (Option<Next>, Tick) {
        let Some((stage, into_s, share)) = excite::at(t_s) else {
            self.status = Status::Running(80);
            return (Some(Next::Fitting), Tick::default());
        };
        let report = if self.stage != Some(stage) {
            self.stage = Some(stage);
            if stage == Stage::Level && e.alt_amsl_m.is_finite() {
                self.start.hold_alt_m = e.alt_amsl_m;
            }
            Some(if t_s == 0.0 {
                Report::Started
            } else {
                Report::Stage(stage)
            })
        } else {
            None
        };
        // QGroundControl's bands: the stage in its band, the level stages between.
        let band = |first: f32, width: f32| {
            first + (width - 1.0) * ((share * 80.0 - first) / width).clamp(0.0, 1.0)
        };
        let progress = match stage {
            Stage::Level => share * 80.0,
            Stage::Roll => band(20.0, 20.0),
            Stage::Pitch => band(40.0, 20.0),
            Stage::Throttle => band(60.0, 10.0),
            Stage::Yaw => band(70.0, 10.0),
        };
        // Never back: a level stage's share of the timeline can lie below the band of the
        // stage before it.
        let last = match self.status {
            Status::Running(p) => p,
            _ => 0,
        };
        // Not `clamp`: a panic site in the image, where `last` is not known to be under 79.
        self.status = Status::Running((progress as u8).min(79).max(last));
        let pitch_cmd = |offset: f32| LonMode::Pitch {
            pitch: self.start.pitch + offset,
            throttle: self.start.throttle,
        };
        // Each model on the stages that are its own: the sideslip's on the rudder doublets,
        // the others on the rest ([`Identifier::take_rows`]).
        if let Phase::Flying { t_s: at, id } = &mut self.phase {
            id.take_rows(stage == Stage::Yaw, stage != Stage::Yaw);
            *at = t_s + dt;
        }
        let commands = match stage {
            Stage::Level => {
                // The level pitch and throttle, averaged, for the pitch-attitude stages.
                let level = libm::fabsf(e.alt_amsl_m - self.start.hold_alt_m) < LEVEL_BAND_M;
                let k = if level {
                    (dt / LEVEL_TC_S).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                if e.euler.theta.is_finite() && s.throttle.is_finite() && s.rudder.is_finite() {
                    self.start.pitch += k * (e.euler.theta - self.start.pitch);
                    self.start.throttle += k * (s.throttle - self.start.throttle);
                    self.start.rudder += k * (s.rudder - self.start.rudder);
                }
                if e.wind_ned.iter().all(|w| w.is_finite()) {
                    self.start.wind += (e.wind_ned - self.start.wind) * k;
                }
                self.level()
            }
            Stage::Roll => Commands {
                roll: RollMode::Roll(EXCITATION_SHARE * p.bank_max * excite::doublets(into_s)),
                ..self.level()
            },
            Stage::Yaw => Commands {
                yaw: YawMode::Rudder(
                    self.start.rudder
                        + EXCITATION_SHARE * base.lateral.rudder_max * excite::yaw_doublets(into_s),
                ),
                ..self.level()
            },
            Stage::Pitch => Commands {
                lon: pitch_cmd(EXCITATION_SHARE * p.pitch_max * excite::doublets(into_s)),
                ..self.level()
            },
            Stage::Throttle => Commands {
                lon: LonMode::Pitch {
                    pitch: self.start.pitch,
                    throttle: (self.start.throttle + p.throttle_step * excite::steps(into_s))
                        .clamp(0.0, 1.0),
                },
                ..self.level()
            },
        };
        let tick = Tick {
            commands: Some(commands),
            report,
            ..Tick::default()
        };
        (None, tick)
    }

    /// Takes axis `next`'s fit (`fitted`, none after the last axis); after the last, hands
    /// the model to the parameters, and in the tick after that starts the design.
    fn fit(
        &mut self,
        next: usize,
        fitted: Option<(Axis, Result<AxisFit, AxisError>)>,
        p: &AutotuneParams,
        base: &GainSet,
    ) -> (Option<Next>, Tick) {
        // After the last axis, the model to the parameters in one tick and the designer
        // set up in the next: each is a share of a control period's budget.
        let Some((axis, result)) = fitted else {
            if next == FITTED.len() {
                self.status = Status::Running(85);
                if let Phase::Fitting { next: n, .. } = &mut self.phase {
                    *n = next + 1;
                }
                let tick = Tick {
                    identified: Some(self.model),
                    ..Tick::default()
                };
                return (None, tick);
            }
            let designer = Designer::new(&self.model, &DesignInputs::AUTOTUNE, base);
            return (Some(Next::Designing(designer)), Tick::default());
        };
        let fit: AxisFit = match result {
            Ok(f) => f,
            Err(AxisError::NotExcited { .. }) => return self.fail(Failure::NotExcited(axis)),
            Err(AxisError::Singular) => return self.fail(Failure::Singular(axis)),
        };
        // A NaN R^2 is a poor fit too.
        if fit.r2.is_nan() || fit.r2 < p.r2_min {
            return self.fail(Failure::PoorFit(axis, fit.r2));
        }
        let [a, b, c, ..] = fit.coef;
        let m = &mut self.model;
        match axis {
            Axis::Roll => (m.a_phi1, m.a_phi2) = (a, b),
            Axis::Sideslip => (m.a_beta1, m.a_beta2) = (a, b),
            Axis::Pitch => (m.a_theta1, m.a_theta2, m.a_theta3) = (a, b, c),
            Axis::FlightPath => m.a_gamma = a,
            _ => (m.a_v1, m.a_v2) = (a, b),
        }
        let tick = Tick {
            report: Some(Report::Fitted(axis, [a, b, c], fit.r2)),
            ..Tick::default()
        };
        if let Phase::Fitting { next: n, .. } = &mut self.phase {
            *n = next + 1;
        }
        (None, tick)
    }

    fn fail(&mut self, why: Failure) -> (Option<Next>, Tick) {
        self.status = Status::Failed;
        let tick = Tick {
            report: Some(Report::Failed(why)),
            ..Tick::default()
        };
        (Some(Next::Idle), tick)
    }

    /// Goes on to `next`: the identifier moves from the flight to the fits once, and the
    /// designer takes its memory after them.
    fn advance(&mut self, next: Next) {
        self.phase = match (next, core::mem::replace(&mut self.phase, Phase::Idle)) {
            (Next::Fitting, Phase::Flying { id, .. }) => Phase::Fitting { next: 0, id },
            (Next::Designing(d), _) => Phase::Designing(d),
            _ => Phase::Idle,
        };
    }
}

/// What the models read, from the estimate, the surfaces flown and the specific force
/// measured (body axes, m/s^2; `None` before the first IMU sample, which no sample is made
/// of). In the roll model the sideslip's lateral force is read through the estimated sideslip
/// (`beta Va^2`, as the force goes), not the accelerometer, whose noise is larger than that
/// force ([`Sample::ay`]); the sideslip model's side force is the accelerometer's own, on its
/// measured side, and its sideslip the velocity's through the air against `wind_ned`
/// ([`Autotune::wind`]).
pub fn sample(
    e: &EstimatedState,
    s: &Surfaces,
    specific_force: Option<Vector3<f32>>,
    wind_ned: Vector3<f32>,
) -> Sample {
    let air = AirData::from_body_velocity(&ned_to_body(&e.attitude, &(e.vel_ned - wind_ned)));
    Sample {
        beta: air.beta,
        air_speed: air.va,
        accel_y: specific_force.map_or(f32::NAN, |f| f.y),
        rudder: s.rudder,
        p: e.body_rates.x,
        q: e.body_rates.y,
        r: e.body_rates.z,
        ay: e.sideslip * e.airspeed * e.airspeed,
        phi: e.euler.phi,
        theta: e.euler.theta,
        airspeed: e.airspeed,
        alpha: e.alpha,
        climb_rate: -e.vel_ned.z,
        course: e.course,
        ground_speed: e.ground_speed,
        aileron: s.aileron,
        elevator: s.elevator,
        throttle: s.throttle,
    }
}
