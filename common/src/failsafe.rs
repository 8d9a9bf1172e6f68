//! Failsafes: what the aircraft does on its own when the ground link, GPS, the airspeed sensor,
//! the geofence or the battery fails it. Part of the navigator stage: it watches, decides and reports;
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
//! - Battery (the monitor's warning level, PX4's `COM_LOW_BAT_ACT` in spirit): low, a warning
//!   only; critical, return (`FS_BAT_ACT` 1; latched until the pilot chooses a mode, like the
//!   fence's return); emergency, land (`FlightMode::Land`: home, then the landing). The level
//!   only rises in a flight, each step reported once; a battery nobody monitors (no power
//!   monitor, or an outside simulator that sends no `BATTERY_STATUS`) triggers nothing.
//!
//! Without GPS there is no home to fly to: the GPS reaction comes before every other. The
//! emergency landing comes before a return.
//!
//! Near the ground the commander flies a reaction otherwise (`vehicle::commander`): on the
//! take-off roll, which is watched from its first metre, it aborts the take-off; past the
//! rotation it waits, wings level, for `NAV_TKO_CLR_M`; in a flare or roll-out it lets the
//! landing finish.
//!
//! Each failsafe is reported once when it is raised and once when its cause clears (the
//! battery's never clears in flight).

use crate::battery::Warning;
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
        param!(
            ParamDef::choice(
                "FS_BAT_ACT",
                1,
                &["Warning only", "Return, then land"],
                "What a critical (return) or emergency (land) battery does in flight",
            ),
            FailsafeConfig => battery_acts, flag
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
    /// `FS_BAT_ACT`: return at a critical battery, land at an emergency.
    pub battery_acts: bool,
}

const ZERO: FailsafeConfig = FailsafeConfig {
    gcs_timeout_s: 0.0,
    gps_wings_level_s: 0.0,
    fence_returns: false,
    battery_acts: false,
};

impl Default for FailsafeConfig {
    fn default() -> Self {
        PARAMS.defaults()
    }
}

/// What the failsafes see at one tick.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FailsafeInputs {
    /// Time, µs (any monotonic clock).
    pub t_us: u64,
    /// Armed and off the ground: only then do failsafes change what the aircraft does.
    pub flying: bool,
    /// When the ground station was last heard, µs (`None`: never, then there is nothing to
    /// lose).
    pub gcs_heard_us: Option<u64>,
    /// GPS healthy.
    pub gps_ok: bool,
    /// Airspeed sensor healthy.
    pub airspeed_ok: bool,
    /// Outside the geofence (polygon or altitude).
    pub fence_breached: bool,
    /// The battery monitor's warning level; `None` when no battery is monitored.
    pub battery: Option<Warning>,
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
    /// Fly home and land there.
    Land,
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
    /// Battery low: a warning.
    BatteryLow,
    /// Battery critical, `FS_BAT_ACT` 0: a warning.
    BatteryCritical,
    /// Battery critical: returning.
    BatteryCriticalReturn,
    /// Battery emergency, `FS_BAT_ACT` 0: a warning.
    BatteryEmergency,
    /// Battery emergency: landing.
    BatteryEmergencyLand,
}

impl Event {
    /// Every event.
    pub const ALL: [Event; 14] = [
        Event::GcsLost,
        Event::GcsRegained,
        Event::GpsLost,
        Event::GpsLoiter,
        Event::GpsRegained,
        Event::AirspeedFailed,
        Event::AirspeedRegained,
        Event::FenceBreached,
        Event::FenceCleared,
        Event::BatteryLow,
        Event::BatteryCritical,
        Event::BatteryCriticalReturn,
        Event::BatteryEmergency,
        Event::BatteryEmergencyLand,
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
            Event::BatteryLow => "Battery low, return advised",
            Event::BatteryCritical => "Battery critical, land as soon as possible",
            Event::BatteryCriticalReturn => "Failsafe: battery critical, returning home",
            Event::BatteryEmergency => "Battery emergency, land immediately",
            Event::BatteryEmergencyLand => "Failsafe: battery emergency, landing",
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
                | Event::BatteryLow
                | Event::BatteryCritical
                | Event::BatteryCriticalReturn
                | Event::BatteryEmergency
                | Event::BatteryEmergencyLand
        )
    }

    /// True for the events that only advise (a warning, not a critical message).
    pub fn advisory(self) -> bool {
        self == Event::BatteryLow
    }
}

/// Events of one tick (at most one per failsafe).
pub type Events = heapless::Vec<Event, 5>;

/// The failsafe monitor.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Failsafes {
    gcs_lost: bool,
    gcs_return: bool,
    gps_lost_since_us: Option<u64>,
    gps_loiter: bool,
    airspeed_failed: bool,
    fence_breached: bool,
    fence_return: bool,
    /// The highest battery warning reported this flight.
    battery_level: Warning,
    battery_return: bool,
    battery_land: bool,
}

impl Failsafes {
    /// No failsafe active.
    pub fn new() -> Self {
        Self::default()
    }

    /// True while any failsafe is raised.
    pub fn active(&self) -> bool {
        self.gcs_lost
            || self.gps_lost_since_us.is_some()
            || self.airspeed_failed
            || self.fence_breached
            || self.battery_level >= Warning::Critical
    }

    /// Forgets the latched returns and landing: the pilot has chosen a mode, or the aircraft
    /// has landed. The battery's level stays, so the same warning is not raised again.
    pub fn acknowledge(&mut self) {
        self.gcs_return = false;
        self.fence_return = false;
        self.battery_return = false;
        self.battery_land = false;
    }

    /// A new flight (arming): the battery's warnings will be reported again as it flies.
    pub fn new_flight(&mut self) {
        self.acknowledge();
        self.battery_level = Warning::None;
    }

    /// Evaluates one tick; returns the reaction and the events raised or cleared.
    pub fn update(&mut self, cfg: &FailsafeConfig, i: &FailsafeInputs) -> (Reaction, Events) {
        let mut ev = Events::new();
        let mut push = |e| {
            let _ = ev.push(e);
        };
        // Ground link.
        let silent = match i.gcs_heard_us {
            Some(t) => cfg.gcs_timeout_s > 0.0 && seconds_since(i.t_us, t) > cfg.gcs_timeout_s,
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
        match (i.gps_ok, self.gps_lost_since_us) {
            (false, None) if i.flying => {
                self.gps_lost_since_us = Some(i.t_us);
                push(Event::GpsLost);
            }
            (false, Some(t0))
                if !self.gps_loiter && seconds_since(i.t_us, t0) >= cfg.gps_wings_level_s =>
            {
                self.gps_loiter = true;
                push(Event::GpsLoiter);
            }
            (true, Some(_)) => {
                self.gps_lost_since_us = None;
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
        // Battery: only a monitored one, only in flight, each level once.
        if let Some(level) = i.battery.filter(|&l| i.flying && l > self.battery_level) {
            self.battery_level = level;
            let act = cfg.battery_acts;
            match (level, act) {
                (Warning::None, _) => {}
                (Warning::Low, _) => push(Event::BatteryLow),
                (Warning::Critical, false) => push(Event::BatteryCritical),
                (Warning::Critical, true) => push(Event::BatteryCriticalReturn),
                (Warning::Emergency, false) => push(Event::BatteryEmergency),
                (Warning::Emergency, true) => push(Event::BatteryEmergencyLand),
            }
            self.battery_return |= act && level == Warning::Critical;
            self.battery_land |= act && level == Warning::Emergency;
        }
        // Without GPS there is no home to fly to: the GPS reaction comes first.
        let reaction = if self.gps_lost_since_us.is_some() {
            if self.gps_loiter {
                Reaction::Loiter
            } else {
                Reaction::WingsLevel
            }
        } else if self.battery_land {
            Reaction::Land
        } else if self.fence_return || self.gcs_return || self.battery_return {
            Reaction::Return
        } else {
            Reaction::None
        };
        (reaction, ev)
    }
}

/// Seconds from `then_us` to `now_us` (zero if the clock went back; past 71 minutes, 71
/// minutes: longer than any failsafe waits), in the board's `f32` without software 64-bit
/// arithmetic.
fn seconds_since(now_us: u64, then_us: u64) -> f32 {
    let us = u32::try_from(now_us.saturating_sub(then_us)).unwrap_or(u32::MAX);
    us as f32 * 1e-6
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Seconds on the failsafes' microsecond clock.
    fn us(t_s: f64) -> u64 {
        (t_s * 1e6) as u64
    }

    fn flying(t_s: f64) -> FailsafeInputs {
        FailsafeInputs {
            t_us: us(t_s),
            flying: true,
            gcs_heard_us: Some(us(t_s)),
            gps_ok: true,
            airspeed_ok: true,
            fence_breached: false,
            battery: None,
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
        // COM_LOW_BAT_ACT's spirit: return at critical, land at emergency.
        assert!(cfg.battery_acts);
    }

    #[test]
    fn ground_link_loss_returns_after_the_timeout_and_stays_until_acknowledged() {
        let cfg = FailsafeConfig::default();
        let mut f = Failsafes::new();
        let mut i = flying(0.0);
        assert_eq!(f.update(&cfg, &i).0, Reaction::None);
        i.t_us = us(4.9);
        i.gcs_heard_us = Some(0);
        assert_eq!(f.update(&cfg, &i), (Reaction::None, Events::new()));
        i.t_us = us(5.1);
        let (r, ev) = f.update(&cfg, &i);
        assert_eq!(r, Reaction::Return);
        assert_eq!(ev.as_slice(), &[Event::GcsLost]);
        // Heard again: reported, but the return stays until the pilot picks a mode.
        i.gcs_heard_us = Some(us(5.2));
        i.t_us = us(5.3);
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
        i.gcs_heard_us = None;
        assert_eq!(f.update(&cfg, &i).0, Reaction::None);
        i.flying = false;
        i.gcs_heard_us = Some(0);
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
        i.t_us = us(19.9);
        i.gcs_heard_us = Some(us(19.9));
        assert_eq!(f.update(&cfg, &i), (Reaction::WingsLevel, Events::new()));
        i.t_us = us(20.0);
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

    #[test]
    fn a_low_battery_only_warns_a_critical_one_returns_until_the_pilot_chooses_a_mode() {
        let cfg = FailsafeConfig::default();
        let mut f = Failsafes::new();
        let mut i = flying(0.0);
        i.battery = Some(Warning::None);
        assert_eq!(f.update(&cfg, &i), (Reaction::None, Events::new()));
        i.battery = Some(Warning::Low);
        let (r, ev) = f.update(&cfg, &i);
        assert_eq!(
            (r, ev.as_slice()),
            (Reaction::None, &[Event::BatteryLow][..])
        );
        assert!(!f.active(), "a warning, not a failsafe");
        assert!(Event::BatteryLow.advisory());
        i.battery = Some(Warning::Critical);
        let (r, ev) = f.update(&cfg, &i);
        assert_eq!(
            (r, ev.as_slice()),
            (Reaction::Return, &[Event::BatteryCriticalReturn][..])
        );
        assert!(f.active());
        // Said once; the return holds.
        assert_eq!(f.update(&cfg, &i), (Reaction::Return, Events::new()));
        // The pilot takes over: the same level does not return again.
        f.acknowledge();
        assert_eq!(f.update(&cfg, &i), (Reaction::None, Events::new()));
    }

    #[test]
    fn an_emergency_battery_lands_before_any_return_but_after_a_gps_loss() {
        let cfg = FailsafeConfig::default();
        let mut f = Failsafes::new();
        let mut i = flying(0.0);
        i.fence_breached = true;
        i.battery = Some(Warning::Critical);
        assert_eq!(f.update(&cfg, &i).0, Reaction::Return);
        i.battery = Some(Warning::Emergency);
        let (r, ev) = f.update(&cfg, &i);
        assert_eq!(
            (r, ev.as_slice()),
            (Reaction::Land, &[Event::BatteryEmergencyLand][..])
        );
        // No home without GPS: wings level first, the landing once GPS is back.
        i.gps_ok = false;
        assert_eq!(f.update(&cfg, &i).0, Reaction::WingsLevel);
        i.gps_ok = true;
        assert_eq!(f.update(&cfg, &i).0, Reaction::Land);
        // Straight from no warning to emergency: one event, the landing.
        let mut g = Failsafes::new();
        let (r, ev) = g.update(&cfg, &i);
        assert_eq!(r, Reaction::Land);
        assert!(ev.contains(&Event::BatteryEmergencyLand), "{ev:?}");
    }

    #[test]
    fn no_monitored_battery_and_no_flight_trigger_nothing() {
        let cfg = FailsafeConfig::default();
        let mut f = Failsafes::new();
        let mut i = flying(0.0);
        // An outside simulator that sends no BATTERY_STATUS.
        i.battery = None;
        for t in 0..100 {
            i.t_us = us(f64::from(t));
            i.gcs_heard_us = Some(i.t_us);
            assert_eq!(f.update(&cfg, &i), (Reaction::None, Events::new()));
        }
        // An empty pack on the ground: the pre-arm check's business, not a failsafe.
        i.flying = false;
        i.battery = Some(Warning::Emergency);
        assert_eq!(f.update(&cfg, &i), (Reaction::None, Events::new()));
        assert!(!f.active());
        // Once off the ground, it is.
        i.flying = true;
        assert_eq!(f.update(&cfg, &i).0, Reaction::Land);
    }

    #[test]
    fn warning_only_says_critical_and_emergency_without_a_change_of_mode() {
        let cfg = FailsafeConfig {
            battery_acts: false,
            ..FailsafeConfig::default()
        };
        let mut f = Failsafes::new();
        let mut i = flying(0.0);
        i.battery = Some(Warning::Critical);
        let (r, ev) = f.update(&cfg, &i);
        assert_eq!(
            (r, ev.as_slice()),
            (Reaction::None, &[Event::BatteryCritical][..])
        );
        i.battery = Some(Warning::Emergency);
        let (r, ev) = f.update(&cfg, &i);
        assert_eq!(
            (r, ev.as_slice()),
            (Reaction::None, &[Event::BatteryEmergency][..])
        );
        // A new flight reports the pack again.
        f.new_flight();
        let (r, ev) = f.update(&cfg, &i);
        assert_eq!(
            (r, ev.as_slice()),
            (Reaction::None, &[Event::BatteryEmergency][..])
        );
    }
}
