//! The autotune wired into the vehicle: when it may start, what it flies in place of the
//! mode, and the gains it hands over (kept beside the ones they replaced, for a revert).

use super::commander::{Demand, Notice, Severity};
use super::modes::FlightMode;
use super::Vehicle;
use crate::control::autopilot::GainSet;
use crate::failsafe::Reaction;
use crate::tuning::autotune::{params, sample, Abort, Situation};

/// The modes an autotune is flown from: the ones that hold attitude or a course and height
/// for the pilot. The navigator's modes fly a plan the excitation would fight.
pub const AUTOTUNE_MODES: [FlightMode; 3] = [
    FlightMode::Stabilized,
    FlightMode::Altitude,
    FlightMode::Hold,
];

/// Why an autotune may not start now, as the station is told.
pub fn refusal(
    armed: bool,
    in_air: bool,
    mode: FlightMode,
    failsafe: bool,
    sensors_ok: bool,
) -> Option<&'static str> {
    if !armed || !in_air {
        Some("Autotune refused: not in the air")
    } else if !AUTOTUNE_MODES.contains(&mode) {
        Some("Autotune refused: fly Stabilized, Altitude or Hold")
    } else if !sensors_ok {
        // Named before the failsafe it raises: the cause.
        Some("Autotune refused: GPS or airspeed failed")
    } else if failsafe {
        Some("Autotune refused: failsafe active")
    } else {
        None
    }
}

impl Vehicle {
    /// A station's `MAV_CMD_DO_AUTOTUNE_ENABLE`: `true` starts an autotune (when nothing
    /// refuses it: the link checked the same on its snapshot, the vehicle checks again on
    /// its state now); `false` stops one running, or else puts back the gains the last one
    /// replaced.
    pub(super) fn request_autotune(&mut self, enable: bool) {
        // An image without it never gets the request: the link answers UNSUPPORTED.
        if !cfg!(feature = "autotune") {
            return;
        }
        if !enable {
            if let Some(r) = self.autotune.abort(Abort::Station) {
                self.commander.notify(Notice::Tune(r));
            } else if let Some(previous) = self.tuned_from.take() {
                self.set_gains(&previous, "Autotune: previous gains restored");
            }
            return;
        }
        if self.autotune.running() {
            return;
        }
        let e = self.estimator.state();
        let c = &self.commander;
        let why = refusal(
            c.armed(),
            c.flying(),
            c.flown_mode(),
            c.reaction() != Reaction::None,
            e.health.gps.healthy && e.health.pitot.healthy,
        );
        if let Some(text) = why {
            self.commander.notify(Notice::Text(Severity::Warning, text));
            return;
        }
        self.tune_mode = c.flown_mode();
        let airspeed = c.setpoints().airspeed;
        let p = self.params.load(&params::PARAMS);
        self.autotune.start(&e, airspeed, &self.surfaces, &p);
    }

    /// The autotune's control tick, when one runs: its checks, its commands in place of the
    /// mode's `demand`, its reports, and its gains once designed.
    pub(super) fn step_autotune(&mut self, dt: f32, demand: Demand) -> Demand {
        if !cfg!(feature = "autotune") || !self.autotune.running() {
            return demand;
        }
        let e = self.estimator.state();
        let c = &self.commander;
        let nav = self.navigator.params();
        let situation = Situation {
            mode_kept: c.flown_mode() == self.tune_mode,
            failsafe: c.reaction() != Reaction::None,
            flying: c.flying(),
            airspeed_range: (nav.airspeed_min, nav.airspeed_max),
        };
        let p = self.params.load(&params::PARAMS);
        let base = *self.autopilot.gains();
        let tick = self
            .autotune
            .step(dt, &e, &self.surfaces, &situation, &p, &base);
        if let Some(r) = tick.report {
            self.commander.notify(Notice::Tune(r));
        }
        if let Some(identified) = tick.identified {
            // Out of the parameters' bounds only for a model the design then refuses.
            let _ = self.params.save(&params::IDENTIFIED, &identified);
        }
        if let Some(gains) = tick.gains {
            if self.set_gains(&gains, "Autotune: gains applied") {
                self.tuned_from = Some(base);
            } else {
                self.autotune.refused();
            }
        }
        match (tick.commands, demand) {
            (Some(c), Demand::Commands(_)) => Demand::Commands(c),
            _ => demand,
        }
    }

    /// Hands the autotune what this tick flew: the estimate and the surfaces just commanded.
    pub(super) fn observe_autotune(&mut self, dt: f32) {
        if cfg!(feature = "autotune") && self.autotune.running() {
            let e = self.estimator.state();
            let s = sample(
                &e,
                &self.surfaces,
                self.estimator.specific_force(),
                self.autotune.wind(),
            );
            self.autotune.observe(dt, &s);
        }
    }

    /// Writes `gains` into the parameters (saved with them, as a station's would be) and says
    /// `done`; false, and a warning, when the store refuses them.
    fn set_gains(&mut self, gains: &GainSet, done: &'static str) -> bool {
        // The store's other changes are applied at the start of each tick: when none is
        // pending, the gains are all that moved, and only the control laws re-read theirs (the
        // MCU's costliest control period was the whole reload).
        let applied = self.params_seen == Some(self.params.change_count());
        match gains.to_store(&mut self.params) {
            Ok(()) => {
                self.commander.notify(Notice::Text(Severity::Info, done));
                if applied {
                    self.params_seen = Some(self.params.change_count());
                    self.apply_gains();
                } else {
                    self.apply_params();
                }
                true
            }
            Err(_) => {
                self.commander.notify(Notice::Text(
                    Severity::Warning,
                    "Autotune: gains refused by the parameters, previous kept",
                ));
                false
            }
        }
    }
}
