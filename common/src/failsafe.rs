//! Failsafes: what the aircraft does on its own when the ground link, GPS, the airspeed sensor
//! or the geofence fails it. Part of the navigator stage: it watches, decides and reports;
//! the application turns its [`Reaction`] into the mode it flies.
//!
//! - Ground link lost for `FS_GCS_TOUT_S` while flying: return (PX4's data-link-loss RTL).
//!   The return stays engaged when the link comes back; the pilot takes over by choosing a mode.
//! - GPS lost while flying: wings level at the current altitude on dead reckoning for
//!   `FS_GPS_WL_S`, then circle the dead-reckoned position; the previous mode resumes when GPS
//!   comes back.
//! - Airspeed sensor failed: the estimator flies on a synthetic airspeed (ground velocity
//!   minus the last wind estimate); reported, no change of mode.
//! - Geofence breached (polygon or `GF_MAX_ALT_M`): return.
//!
//! Each failsafe is reported once when it is raised and once when its cause clears.

use crate::param;
use crate::params::{independent, Group, ParamDef};

/// Parameters of the failsafes.
pub const PARAMS: Group<FailsafeConfig> = Group {
    name: "Failsafes",
    params: &[
        param!(
            ParamDef::real(
                "FS_GCS_TOUT_S",
                5.0,
                0.0,
                300.0,
                "s",
                "Ground link silent this long while flying: return home (0 disables)",
            ),
            FailsafeConfig => gcs_timeout_s
        ),
        param!(
            ParamDef::real(
                "FS_GPS_WL_S",
                10.0,
                0.0,
                300.0,
                "s",
                "GPS lost: wings level at altitude this long on dead reckoning, then circle",
            ),
            FailsafeConfig => gps_wings_level_s
        ),
        param!(
            ParamDef::choice(
                "GF_ACTION",
                1,
                &["Report only", "Return home"],
                "What a geofence breach does",
            ),
            FailsafeConfig => fence_returns, flag
        ),
    ],
    base: || ZERO,
    check: independent,
};

/// Failsafe settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FailsafeConfig {
    /// `FS_GCS_TOUT_S`: ground-link timeout, s (0: no ground-link failsafe).
    pub gcs_timeout_s: f32,
    /// `FS_GPS_WL_S`: wings-level time after a GPS loss, s.
    pub gps_wings_level_s: f32,
    /// `GF_ACTION`: return on a geofence breach.
    pub fence_returns: bool,
}

const ZERO: FailsafeConfig = FailsafeConfig {
    gcs_timeout_s: 0.0,
    gps_wings_level_s: 0.0,
    fence_returns: false,
};

impl Default for FailsafeConfig {
    fn default() -> Self {
        PARAMS.defaults()
    }
}

/// What the failsafes see at one tick.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FailsafeInputs {
    /// Time, s (any monotonic clock).
    pub t_s: f64,
    /// Armed and off the ground: only then do failsafes change what the aircraft does.
    pub flying: bool,
    /// When the ground station was last heard, s (`None`: never, then there is nothing to
    /// lose).
    pub gcs_heard_s: Option<f64>,
    /// GPS healthy.
    pub gps_ok: bool,
    /// Airspeed sensor healthy.
    pub airspeed_ok: bool,
    /// Outside the geofence (polygon or altitude).
    pub fence_breached: bool,
}

/// What the aircraft should do instead of its chosen mode.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Reaction {
    /// Fly the chosen mode.
    #[default]
    None,
    /// Wings level (roll held at zero) at the altitude of the moment it began.
    WingsLevel,
    /// Circle the current (dead-reckoned) position.
    Loiter,
    /// Fly home.
    Return,
}

/// One failsafe being raised or cleared, for the ground station's log.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Event {
    /// Ground link lost: returning.
    GcsLost,
    /// Ground link back.
    GcsRegained,
    /// GPS lost: wings level on dead reckoning.
    GpsLost,
    /// GPS still lost: circling.
    GpsLoiter,
    /// GPS back: the chosen mode resumes.
    GpsRegained,
    /// Airspeed sensor failed: synthetic airspeed.
    AirspeedFailed,
    /// Airspeed sensor back.
    AirspeedRegained,
    /// Geofence breached.
    FenceBreached,
    /// Back inside the geofence.
    FenceCleared,
}

impl Event {
    /// Every event.
    pub const ALL: [Event; 9] = [
        Event::GcsLost,
        Event::GcsRegained,
        Event::GpsLost,
        Event::GpsLoiter,
        Event::GpsRegained,
        Event::AirspeedFailed,
        Event::AirspeedRegained,
        Event::FenceBreached,
        Event::FenceCleared,
    ];

    /// The text the ground station shows.
    pub fn text(self) -> &'static str {
        match self {
            Event::GcsLost => "Failsafe: ground link lost, returning home",
            Event::GcsRegained => "Ground link regained",
            Event::GpsLost => "Failsafe: GPS lost, wings level on dead reckoning",
            Event::GpsLoiter => "Failsafe: GPS still lost, circling",
            Event::GpsRegained => "GPS regained, resuming",
            Event::AirspeedFailed => "Failsafe: airspeed sensor failed, synthetic speed",
            Event::AirspeedRegained => "Airspeed sensor regained",
            Event::FenceBreached => "Failsafe: geofence breached",
            Event::FenceCleared => "Back inside the geofence",
        }
    }

    /// True for the events that raise a failsafe (reported as warnings or worse).
    pub fn raises(self) -> bool {
        matches!(
            self,
            Event::GcsLost
                | Event::GpsLost
                | Event::GpsLoiter
                | Event::AirspeedFailed
                | Event::FenceBreached
        )
    }
}

/// Events of one tick (at most one per failsafe).
pub type Events = heapless::Vec<Event, 4>;

/// The failsafe monitor.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Failsafes {
    gcs_lost: bool,
    gcs_return: bool,
    gps_lost_since: Option<f64>,
    gps_loiter: bool,
    airspeed_failed: bool,
    fence_breached: bool,
    fence_return: bool,
}

impl Failsafes {
    /// No failsafe active.
    pub fn new() -> Self {
        Self::default()
    }

    /// True while any failsafe is raised.
    pub fn active(&self) -> bool {
        self.gcs_lost
            || self.gps_lost_since.is_some()
            || self.airspeed_failed
            || self.fence_breached
    }

    /// Forgets the latched returns: the pilot has chosen a mode, or the aircraft has landed.
    pub fn acknowledge(&mut self) {
        self.gcs_return = false;
        self.fence_return = false;
    }

    /// Evaluates one tick; returns the reaction and the events raised or cleared.
    pub fn update(&mut self, cfg: &FailsafeConfig, i: &FailsafeInputs) -> (Reaction, Events) {
        let mut ev = Events::new();
        let mut push = |e| {
            let _ = ev.push(e);
        };
        // Ground link.
        let silent = match i.gcs_heard_s {
            Some(t) => cfg.gcs_timeout_s > 0.0 && i.t_s - t > f64::from(cfg.gcs_timeout_s),
            None => false,
        };
        if silent && !self.gcs_lost && i.flying {
            self.gcs_lost = true;
            self.gcs_return = true;
            push(Event::GcsLost);
        } else if !silent && self.gcs_lost {
            self.gcs_lost = false;
            push(Event::GcsRegained);
        }
        // GPS.
        match (i.gps_ok, self.gps_lost_since) {
            (false, None) if i.flying => {
                self.gps_lost_since = Some(i.t_s);
                push(Event::GpsLost);
            }
            (false, Some(t0))
                if !self.gps_loiter && i.t_s - t0 >= f64::from(cfg.gps_wings_level_s) =>
            {
                self.gps_loiter = true;
                push(Event::GpsLoiter);
            }
            (true, Some(_)) => {
                self.gps_lost_since = None;
                self.gps_loiter = false;
                push(Event::GpsRegained);
            }
            _ => {}
        }
        // Airspeed.
        if !i.airspeed_ok && !self.airspeed_failed && i.flying {
            self.airspeed_failed = true;
            push(Event::AirspeedFailed);
        } else if i.airspeed_ok && self.airspeed_failed {
            self.airspeed_failed = false;
            push(Event::AirspeedRegained);
        }
        // Geofence.
        if i.fence_breached && !self.fence_breached && i.flying {
            self.fence_breached = true;
            self.fence_return = cfg.fence_returns;
            push(Event::FenceBreached);
        } else if !i.fence_breached && self.fence_breached {
            self.fence_breached = false;
            push(Event::FenceCleared);
        }
        // Without GPS there is no home to fly to: the GPS reaction comes first.
        let reaction = if self.gps_lost_since.is_some() {
            if self.gps_loiter {
                Reaction::Loiter
            } else {
                Reaction::WingsLevel
            }
        } else if self.fence_return || self.gcs_return {
            Reaction::Return
        } else {
            Reaction::None
        };
        (reaction, ev)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flying(t_s: f64) -> FailsafeInputs {
        FailsafeInputs {
            t_s,
            flying: true,
            gcs_heard_s: Some(t_s),
            gps_ok: true,
            airspeed_ok: true,
            fence_breached: false,
        }
    }

    #[test]
    fn every_text_fits_one_statustext() {
        for e in Event::ALL {
            assert!(
                e.text().len() <= crate::gcs::STATUSTEXT_LEN,
                "{e:?}: {}",
                e.text()
            );
        }
    }

    #[test]
    fn parameters_are_well_formed_and_default_to_px4_like_reactions() {
        crate::params::validate_defs(PARAMS.defs()).unwrap();
        // PX4's data-link loss and geofence defaults: return after 5 s, return on a breach.
        let cfg = FailsafeConfig::default();
        assert_eq!((cfg.gcs_timeout_s, cfg.fence_returns), (5.0, true));
        assert_eq!(cfg.gps_wings_level_s, 10.0);
    }

    #[test]
    fn ground_link_loss_returns_after_the_timeout_and_stays_until_acknowledged() {
        let cfg = FailsafeConfig::default();
        let mut f = Failsafes::new();
        let mut i = flying(0.0);
        assert_eq!(f.update(&cfg, &i).0, Reaction::None);
        i.t_s = 4.9;
        i.gcs_heard_s = Some(0.0);
        assert_eq!(f.update(&cfg, &i), (Reaction::None, Events::new()));
        i.t_s = 5.1;
        let (r, ev) = f.update(&cfg, &i);
        assert_eq!(r, Reaction::Return);
        assert_eq!(ev.as_slice(), &[Event::GcsLost]);
        // Heard again: reported, but the return stays until the pilot picks a mode.
        i.gcs_heard_s = Some(5.2);
        i.t_s = 5.3;
        let (r, ev) = f.update(&cfg, &i);
        assert_eq!(
            (r, ev.as_slice()),
            (Reaction::Return, &[Event::GcsRegained][..])
        );
        f.acknowledge();
        assert_eq!(f.update(&cfg, &i).0, Reaction::None);
    }

    #[test]
    fn no_failsafe_on_the_ground_or_without_a_ground_station() {
        let cfg = FailsafeConfig::default();
        let mut f = Failsafes::new();
        let mut i = flying(100.0);
        i.gcs_heard_s = None;
        assert_eq!(f.update(&cfg, &i).0, Reaction::None);
        i.flying = false;
        i.gcs_heard_s = Some(0.0);
        i.gps_ok = false;
        i.fence_breached = true;
        assert_eq!(f.update(&cfg, &i), (Reaction::None, Events::new()));
        assert!(!f.active());
    }

    #[test]
    fn gps_loss_flies_wings_level_then_circles_then_resumes() {
        let cfg = FailsafeConfig::default();
        let mut f = Failsafes::new();
        let mut i = flying(10.0);
        i.gps_ok = false;
        assert_eq!(f.update(&cfg, &i).0, Reaction::WingsLevel);
        i.t_s = 19.9;
        i.gcs_heard_s = Some(19.9);
        assert_eq!(f.update(&cfg, &i), (Reaction::WingsLevel, Events::new()));
        i.t_s = 20.0;
        let (r, ev) = f.update(&cfg, &i);
        assert_eq!(
            (r, ev.as_slice()),
            (Reaction::Loiter, &[Event::GpsLoiter][..])
        );
        i.gps_ok = true;
        let (r, ev) = f.update(&cfg, &i);
        assert_eq!(
            (r, ev.as_slice()),
            (Reaction::None, &[Event::GpsRegained][..])
        );
    }

    #[test]
    fn gps_loss_outranks_a_return() {
        let cfg = FailsafeConfig::default();
        let mut f = Failsafes::new();
        let mut i = flying(0.0);
        i.fence_breached = true;
        assert_eq!(f.update(&cfg, &i).0, Reaction::Return);
        i.gps_ok = false;
        assert_eq!(f.update(&cfg, &i).0, Reaction::WingsLevel);
    }

    #[test]
    fn airspeed_failure_is_reported_without_a_change_of_mode() {
        let cfg = FailsafeConfig::default();
        let mut f = Failsafes::new();
        let mut i = flying(0.0);
        i.airspeed_ok = false;
        let (r, ev) = f.update(&cfg, &i);
        assert_eq!(
            (r, ev.as_slice()),
            (Reaction::None, &[Event::AirspeedFailed][..])
        );
        assert!(f.active());
        assert!(f.update(&cfg, &i).1.is_empty());
        i.airspeed_ok = true;
        assert_eq!(f.update(&cfg, &i).1.as_slice(), &[Event::AirspeedRegained]);
    }

    #[test]
    fn fence_breach_returns_unless_set_to_report_only() {
        let mut f = Failsafes::new();
        let mut i = flying(0.0);
        i.fence_breached = true;
        let report_only = FailsafeConfig {
            fence_returns: false,
            ..FailsafeConfig::default()
        };
        let (r, ev) = f.update(&report_only, &i);
        assert_eq!(
            (r, ev.as_slice()),
            (Reaction::None, &[Event::FenceBreached][..])
        );
        let mut f = Failsafes::new();
        assert_eq!(f.update(&FailsafeConfig::default(), &i).0, Reaction::Return);
        i.fence_breached = false;
        let (r, ev) = f.update(&FailsafeConfig::default(), &i);
        // Back inside: still returning until the pilot decides.
        assert_eq!(
            (r, ev.as_slice()),
            (Reaction::Return, &[Event::FenceCleared][..])
        );
    }
}
