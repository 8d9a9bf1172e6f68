//! The vehicle: every stage of one autopilot tick, wired together, with its parameters and
//! its plan.
//!
//! ```text
//! SensorFrame, GpsFix ─► estimator ─► commander (mode, failsafes) ─► navigator ─► guidance
//!                                          │                                         │
//!                            requests ─────┘           autopilot ◄── Commands ◄──────┘
//!                                                          │
//!                                                      Surfaces
//! ```
//!
//! [`Vehicle`] is what a board runs: one way in for sensors ([`Vehicle::on_sensors`], fed by
//! HIL decoding in SITL and by drivers on a board; [`Vehicle::on_gps`] and
//! [`Vehicle::on_battery`] and [`Vehicle::on_range`] beside it), the ground station's requests handed in
//! with them, surfaces out, a [`snapshot::VehicleSnapshot`] for telemetry and [`Notice`]s to
//! report. It reads no clock: its time is the sensor frames' timestamps.
//!
//! - [`modes`]: the flight modes and what each asks of the vehicle.
//! - [`requests`]: requests a ground link accepted, for the vehicle to act on.
//! - [`commander`]: arming, mode entry, failsafe reactions, the navigator hand-off, mode to
//!   commands.
//! - [`land_detector`]: on the ground or flying, told from the estimate and the accelerometer.
//! - [`params`]: the one registry of every parameter.
//! - [`report`], [`snapshot`]: the state the vehicle reports each tick.

pub mod clock;
pub mod commander;
pub mod land_detector;
pub mod log;
pub mod modes;
pub mod params;
pub mod report;
pub mod requests;
pub mod snapshot;
pub mod tune;

#[cfg(test)]
mod tests;

use crate::actuators::Surfaces;
use crate::battery::{self, BatteryMonitor};
use crate::control::autopilot::{Autopilot, GainSet};
use crate::control::gains::SETS;
use crate::control::inputs::{course_or_crabbed_heading, Measurements};
use crate::estimator::{self, config as estimator_config, EstimatedState, Estimator};
use crate::navigation::navigator::io::HeightOracle;
use crate::navigation::navigator::Navigator;
use crate::navigation::plan::MissionStore;
use crate::navigation::validate::{MissionLimits, PlanRules};
use crate::navigation::{fence, navigator, path_manager, validate};
use crate::params::ParamStore;
use crate::sensors::{BatterySample, GpsFix, ManualInput, RangeSample, SensorFrame};
use crate::tuning::autotune::Autotune;
use crate::{failsafe, guidance};
use clock::{Clock, ClockStats, Step};
use commander::{
    above_home, trim_surfaces, Commander, CommanderInputs, Demand, Setpoints, Severity, Watch,
};
use modes::FlightMode;
use params::TruthUse;
use requests::VehicleRequests;

pub use commander::Notice;

/// The simulator's truth of one frame (HIL_STATE_QUATERNION), for the `SIM_USE_TRUTH`
/// experiments.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TruthSample {
    /// What the control loops would measure, the altitude above mean sea level.
    pub loops: Measurements,
    /// Vertical speed, down positive, m/s.
    pub vel_down_mps: f32,
}

/// Control period, us: the thesis's 50 Hz.
pub const CONTROL_PERIOD_US: u64 = 20_000;

/// The angles the outer loops asked the inner loops for, rad (NaN: the loop is off).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoopCommands {
    /// Roll angle asked of the roll loop.
    pub roll_cmd: f32,
    /// Pitch angle asked of the pitch loop.
    pub pitch_cmd: f32,
}

impl LoopCommands {
    /// Both loops off.
    pub const OFF: Self = Self {
        roll_cmd: f32::NAN,
        pitch_cmd: f32::NAN,
    };
}

/// What the ground link hands the vehicle with each sensor frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FromGround {
    /// Requests accepted since the last frame.
    pub requests: VehicleRequests,
    /// When a ground station was last heard, us (for the link-loss failsafe).
    pub heard_us: Option<u64>,
}

/// The vehicle.
#[derive(Clone, Debug)]
pub struct Vehicle {
    params: ParamStore,
    plan: MissionStore,
    estimator: Estimator,
    autopilot: Autopilot,
    commander: Commander,
    /// The navigator, lent to the commander for each request and control tick.
    navigator: Navigator,
    battery: BatteryMonitor,
    watch: Watch,
    land: land_detector::LandParams,
    /// Magnitude of the last accelerometer sample, m/s^2.
    specific_force: Option<f32>,
    limits: MissionLimits,
    use_truth: TruthUse,
    params_seen: Option<u32>,
    gain_set_seen: u8,
    clock: Clock,
    last_imu_us: Option<u64>,
    last_control_us: Option<u64>,
    last_gps: Option<GpsFix>,
    /// The last rangefinder reading and the vehicle's time it came at, us (for the log).
    last_range: Option<(u64, RangeSample)>,
    truth: Option<TruthSample>,
    /// Home's true altitude above mean sea level, m: the truth's altitude when home was last
    /// put (less the estimate's height above it then), for the flare's oracle.
    truth_home_m: Option<f32>,
    surfaces: Surfaces,
    /// The angles the outer loops asked the inner loops for in the last tick (NaN when a
    /// loop was off), for the flight log.
    loops: LoopCommands,
    /// The last frame was refused for its time.
    refusing: bool,
    autotune: Autotune,
    /// The mode the running autotune started in.
    tune_mode: FlightMode,
    /// The gains the last autotune replaced, for a revert.
    tuned_from: Option<GainSet>,
    /// Course over the ground less heading at the last tick fast enough over the ground to
    /// give a course, rad: slower, the course loop reads the heading turned by it.
    crab: f32,
}

impl Default for Vehicle {
    fn default() -> Self {
        Self::new()
    }
}

impl Vehicle {
    /// A freshly booted vehicle with default parameters: disarmed, in Manual.
    pub fn new() -> Self {
        let mut v = Self::fresh();
        v.apply_params();
        v
    }

    /// The vehicle's state before the parameters are applied to its stages
    /// ([`Vehicle::apply_params`]; [`Vehicle::new`] does both). Not inlined, nor are the
    /// constructors of its large parts: a call builds its result in the caller's destination
    /// (the variable it is bound to), where an inlined literal is built on the stack and
    /// copied; the MCU builds its application this way, in `main`'s frame, with no copy of it.
    #[inline(never)]
    pub fn fresh() -> Self {
        Self {
            params: ParamStore::new(params::REGISTRY),
            plan: MissionStore::default(),
            estimator: Estimator::default(),
            autopilot: Autopilot::default(),
            commander: Commander::new(),
            navigator: Navigator::default(),
            battery: BatteryMonitor::default(),
            watch: Watch::default(),
            land: land_detector::LandParams::default(),
            specific_force: None,
            limits: MissionLimits::default(),
            use_truth: TruthUse::Off,
            params_seen: None,
            gain_set_seen: 0,
            clock: Clock::default(),
            last_imu_us: None,
            last_control_us: None,
            last_gps: None,
            last_range: None,
            truth: None,
            truth_home_m: None,
            surfaces: trim_surfaces(&GainSet::default()),
            loops: LoopCommands::OFF,
            refusing: false,
            autotune: Autotune::new(),
            tune_mode: FlightMode::Manual,
            tuned_from: None,
            crab: 0.0,
        }
    }

    /// The parameters.
    pub fn params(&self) -> &ParamStore {
        &self.params
    }

    /// The parameters, writable (loading from flash, marking saved).
    pub fn params_mut(&mut self) -> &mut ParamStore {
        &mut self.params
    }

    /// The stored mission, geofence and rally lists.
    pub fn plan(&self) -> &MissionStore {
        &self.plan
    }

    /// The stored lists, writable (loading from flash).
    pub fn plan_mut(&mut self) -> &mut MissionStore {
        &mut self.plan
    }

    /// What a ground link reads and writes: the parameters, the plan, and what an upload is
    /// checked against.
    pub fn stores(&mut self) -> (&mut ParamStore, &mut MissionStore, PlanRules) {
        let rules = PlanRules {
            home: self.estimator.home(),
            limits: self.limits,
            nav: *self.navigator.params(),
        };
        (&mut self.params, &mut self.plan, rules)
    }

    /// The estimator's current state.
    pub fn estimate(&self) -> EstimatedState {
        self.estimator.state()
    }

    /// The commander (mode, arming, failsafes, the navigator's last output).
    pub fn commander(&self) -> &Commander {
        &self.commander
    }

    /// The navigator (its parameters).
    pub fn navigator(&self) -> &Navigator {
        &self.navigator
    }

    /// The vehicle's clock, us (see [`clock`]); `None` before the first sensor frame.
    pub fn time_us(&self) -> Option<u64> {
        self.clock.now_us()
    }

    /// Sensor frames the clock found stale, refused for a jump, or re-synchronised on.
    pub fn clock_stats(&self) -> ClockStats {
        self.clock.stats()
    }

    /// Sensor frames whose time did not advance.
    pub fn stale_frames(&self) -> u32 {
        self.clock.stats().stale
    }

    /// The last accepted GPS fix.
    pub fn last_gps(&self) -> Option<GpsFix> {
        self.last_gps
    }

    /// The last surface commands.
    pub fn surfaces(&self) -> Surfaces {
        self.surfaces
    }

    /// Armed (throttle live).
    pub fn armed(&self) -> bool {
        self.commander.armed()
    }

    /// The angles the outer loops last asked the roll and pitch loops for.
    pub fn loop_commands(&self) -> LoopCommands {
        self.loops
    }

    /// What the autopilot is holding: the guided modes' set points, or in a navigation mode
    /// what guidance commands (its altitude as AMSL).
    pub fn setpoints(&self) -> Setpoints {
        let sp = self.commander.setpoints();
        if !self.commander.flown_mode().needs_navigator() {
            return sp;
        }
        match self.commander.navigation().guidance {
            Some(g) => Setpoints {
                course: g.course,
                alt_amsl_m: above_home(self.estimator.home(), g.altitude).unwrap_or(g.altitude),
                airspeed: g.airspeed,
            },
            None => sp,
        }
    }

    /// What the ground link reports and checks.
    pub fn snapshot(&self) -> snapshot::VehicleSnapshot {
        let extras = report::Extras {
            time_us: self.clock.now_us(),
            gps: self.last_gps,
            outputs: self.surfaces,
            clock: self.clock.stats(),
            battery: self.battery.report(self.clock.now_us()),
            airspeed_range_m_s: {
                let p = self.navigator.params();
                (p.airspeed_min, p.airspeed_max)
            },
            autotune: self.autotune.status(),
        };
        report::snapshot(&self.estimator.state(), &self.commander, &extras)
    }

    /// The next thing the vehicle has to report, oldest first.
    pub fn next_notice(&mut self) -> Option<Notice> {
        self.commander.next_notice()
    }

    /// One sensor frame: the samples to the estimator, then, with what the ground link
    /// handed over, requests, parameters and (every [`CONTROL_PERIOD_US`]) the control tick.
    #[deny(clippy::arithmetic_side_effects)]
    pub fn on_sensors(&mut self, f: &SensorFrame, ground: &FromGround) {
        let step = self.clock.on_frame(f.time_us, f.reset);
        let t = self.clock.now_us().unwrap_or(0);
        match step {
            Step::Refused => {
                // A frame whose time jumped is not used; one notice per run of them.
                if !self.refusing {
                    self.commander.notify(Notice::Text(
                        Severity::Warning,
                        "Sensor frame refused: its time jumped",
                    ));
                }
                self.refusing = true;
                self.tick(t, ground);
                return;
            }
            Step::Resynced => self.commander.notify(Notice::Text(
                Severity::Info,
                "Sensor time base changed: clock resynchronised",
            )),
            Step::Started | Step::Advanced(_) | Step::Stale => {}
        }
        self.refusing = false;
        // The gyro integrates over the time since the last *accepted* IMU sample, so a
        // rejected sample does not lose its share of the rotation.
        if let Some(imu) = f.imu {
            let force = imu.accel.norm();
            if force.is_finite() {
                self.specific_force = Some(force);
            }
            if let Some(last) = self.last_imu_us.filter(|&l| t > l) {
                self.estimator
                    .update_imu(&imu, t.saturating_sub(last) as f32 * 1e-6);
            }
            self.last_imu_us = Some(t);
        }
        if let Some(m) = f.mag {
            self.estimator.update_mag(&m);
        }
        if let Some(b) = f.baro {
            self.estimator.update_baro(&b);
        }
        if let Some(p) = f.pitot {
            self.estimator.update_pitot(&p);
        }
        self.tick(t, ground);
    }

    /// A GPS fix.
    pub fn on_gps(&mut self, fix: &GpsFix) {
        self.last_gps = Some(*fix);
        self.estimator.update_gps(fix);
    }

    /// A reading of the battery's power monitor, taken now (the vehicle's clock: the last
    /// sensor frame's time). Before the first sensor frame there is no clock to integrate on,
    /// and the reading is dropped.
    pub fn on_battery(&mut self, s: &BatterySample) {
        if let Some(t) = self.clock.now_us() {
            self.battery.update(t, s);
        }
    }

    /// A reading of the downward rangefinder.
    pub fn on_range(&mut self, s: &RangeSample) {
        self.estimator.update_range(s);
        self.last_range = self.clock.now_us().map(|t| (t, *s));
    }

    /// What the battery monitor knows now.
    pub fn battery(&self) -> battery::Battery {
        self.battery.report(self.clock.now_us())
    }

    /// The simulator's truth, flown instead of the estimate where `SIM_USE_TRUTH` says.
    pub fn on_truth(&mut self, t: TruthSample) {
        self.truth = Some(t);
    }

    /// The radio's sticks.
    pub fn on_sticks(&mut self, s: ManualInput) {
        self.commander.on_sticks(s);
    }

    /// Acts on requests a ground link accepted.
    pub fn apply(&mut self, r: &VehicleRequests) {
        // Nothing asked (most sensor frames): the estimate is not worth forming.
        if *r == VehicleRequests::default() {
            return;
        }
        let e = self.estimator.state();
        let home = self.commander.apply(r, &e, &mut self.navigator);
        self.move_home(home);
        if let Some(enable) = r.autotune {
            self.request_autotune(enable);
        }
    }

    /// Hands a home the commander decided to the estimator, which holds it (the one place
    /// home is written after the first fix set it).
    fn move_home(&mut self, home: Option<estimator::Home>) {
        let Some(h) = home else {
            return;
        };
        // Only in a simulation that sends its truth: the true home sits as far under the
        // truth's altitude as the estimate's height above the new home says.
        let above = self
            .truth
            .map(|_| self.estimator.state().alt_amsl_m - h.alt_amsl_m);
        if self.estimator.set_home(h) {
            self.truth_home_m = self
                .truth
                .zip(above)
                .map(|(t, above)| t.loops.altitude - above);
        }
    }

    /// The truth the flare flies on, when `SIM_USE_TRUTH` asks for it.
    fn height_oracle(&self) -> Option<HeightOracle> {
        if self.use_truth != TruthUse::Flare {
            return None;
        }
        let t = self.truth?;
        Some(HeightOracle {
            height_m: t.loops.altitude - self.truth_home_m?,
            vel_down_mps: t.vel_down_mps,
        })
        .filter(|o| o.height_m.is_finite() && o.vel_down_mps.is_finite())
    }

    /// Everything after the sensors: requests, parameters, control at 50 Hz.
    #[deny(clippy::arithmetic_side_effects)]
    fn tick(&mut self, now_us: u64, ground: &FromGround) {
        self.apply(&ground.requests);
        self.apply_params();
        let due = self
            .last_control_us
            .is_none_or(|t| now_us >= t.saturating_add(CONTROL_PERIOD_US));
        if !due {
            return;
        }
        let dt = self
            .last_control_us
            .map_or(CONTROL_PERIOD_US as f32 * 1e-6, |t| {
                now_us.saturating_sub(t) as f32 * 1e-6
            });
        self.last_control_us = Some(now_us);
        // One estimate for the whole control step.
        let e = self.estimator.state();
        let b = self.battery.report(Some(now_us));
        let gains = *self.autopilot.gains();
        let oracle = self.height_oracle();
        let out = self.commander.step(CommanderInputs {
            now_us,
            dt,
            estimate: &e,
            navigator: &mut self.navigator,
            plan: &self.plan,
            gains: &gains,
            watch: &self.watch,
            land: &self.land,
            specific_force: self.specific_force,
            gcs_heard_us: ground.heard_us,
            battery: b.present.then_some(b.warning),
            oracle,
        });
        self.move_home(out.home);
        let m = self.measurements(&e);
        match self.step_autotune(dt, out.demand) {
            Demand::Surfaces(s) => {
                self.surfaces = s;
                self.loops = LoopCommands::OFF;
                // The loops start from these positions when a stabilised mode engages.
                self.autopilot.handover(s);
            }
            Demand::Commands(c) => {
                let out = self.autopilot.step(&m, &c, dt);
                self.surfaces = out.surfaces;
                self.loops = LoopCommands {
                    roll_cmd: out.status.roll_cmd,
                    pitch_cmd: out.status.pitch_cmd,
                };
            }
        }
        self.observe_autotune(dt);
    }

    fn measurements(&mut self, e: &EstimatedState) -> Measurements {
        if self.use_truth == TruthUse::Loops {
            if let Some(t) = self.truth {
                return t.loops;
            }
        }
        Measurements {
            roll: e.euler.phi,
            pitch: e.euler.theta,
            // Course needs ground speed; on the ground or in a crawl into the wind, the
            // heading as far off the course as it last was.
            course: course_or_crabbed_heading(
                e.course,
                e.euler.psi,
                e.ground_speed,
                &mut self.crab,
            ),
            roll_rate: e.body_rates.x,
            pitch_rate: e.body_rates.y,
            yaw_rate: e.body_rates.z,
            altitude: e.alt_amsl_m,
            airspeed: e.airspeed,
            sideslip: e.sideslip,
            ground_speed: e.ground_speed,
        }
    }

    /// Hands the store's gains to the control laws.
    pub(super) fn apply_gains(&mut self) {
        let gains = GainSet::from_store(&self.params);
        if self.autopilot.set_gains(&gains).is_err() {
            self.commander.notify(Notice::Text(
                Severity::Warning,
                "Gains refused: inconsistent set, previous kept",
            ));
        }
    }

    /// Hands changed parameters to the stages.
    pub fn apply_params(&mut self) {
        let count = self.params.change_count();
        if self.params_seen == Some(count) {
            return;
        }
        self.params_seen = Some(count);
        let sys = self.params.load(&params::PARAMS);
        // A new gain set overwrites the control parameters with its values.
        if sys.gain_set != self.gain_set_seen {
            self.gain_set_seen = sys.gain_set;
            if let Some(g) = SETS.get(usize::from(sys.gain_set)) {
                if g.to_store(&mut self.params).is_err() {
                    self.commander
                        .notify(Notice::Text(Severity::Warning, "Gain set refused"));
                }
            }
        }
        self.apply_gains();
        let p = &self.params;
        self.estimator.set_config(p.load(&estimator_config::PARAMS));
        self.estimator
            .set_range_config(p.load(&estimator::hagl::PARAMS));
        self.navigator.configure(
            &p.load(&navigator::params::PARAMS),
            &p.load(&path_manager::PARAMS),
            &p.load(&guidance::PARAMS),
        );
        self.limits = p.load(&validate::PARAMS);
        self.battery.set_config(p.load(&battery::PARAMS));
        self.land = p.load(&land_detector::PARAMS);
        self.watch = Watch {
            failsafe: p.load(&failsafe::PARAMS),
            fence: p.load(&fence::PARAMS),
        };
        self.use_truth = sys.use_truth;
        // The cruise airspeed is the altitude-holding modes' until a ground station changes it.
        if count == 0 || self.commander.chosen_mode() == FlightMode::Manual {
            let cruise = self.navigator.params().airspeed;
            self.commander.set_cruise_airspeed(cruise);
        }
    }
}
