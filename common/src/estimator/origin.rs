//! Home and the NED origin: the first good fix sets a provisional home whose altitude follows
//! what the estimator learns of the barometer's offset; arming or `DO_SET_HOME` moves it and
//! holds it where it was put. Heights above home follow the barometer from the moment home
//! was set.

use super::ins::Ins;
use crate::math::geodetic::{flight_ned_offset, GeoPoint, LocalFrame};
use crate::sensors::limits;
use nalgebra::Vector3;

/// The reference of the local NED frame, set at the first good 3D fix.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Home {
    /// Horizontal position of the NED origin.
    pub point: GeoPoint,
    /// Altitude of the NED origin above mean sea level, m.
    pub alt_amsl_m: f32,
}

/// Where the estimator's NED frame stands, and the home reported from it.
#[derive(Clone, Debug)]
pub(super) struct Origin {
    /// The NED origin the filter works from.
    home: Option<Home>,
    /// The local frame about home's point, worked out when home moves (see [`LocalFrame`]).
    frame: Option<LocalFrame>,
    /// The barometer offset when home was set: heights above home follow the barometer.
    home_baro_offset: f32,
    /// Home as set by arming or `DO_SET_HOME`, held as reported from then on; `None` while
    /// the first fix's provisional home follows what the estimator learns.
    home_held: Option<Home>,
}

impl Origin {
    /// No home yet.
    pub const fn new() -> Self {
        Self {
            home: None,
            frame: None,
            home_baro_offset: 0.0,
            home_held: None,
        }
    }

    /// The NED origin the filter works from (not the home reported: see [`Origin::home`]).
    pub fn datum(&self) -> Option<Home> {
        self.home
    }

    /// The first good fix sets the provisional home at `home`.
    pub fn set_first(&mut self, home: Home) {
        self.home = Some(home);
        self.frame = Some(LocalFrame::new(home.point));
    }

    /// Heights above home follow the barometer from the filter's offset `baro_offset`, m.
    pub fn anchor_baro(&mut self, baro_offset: f32) {
        self.home_baro_offset = baro_offset;
    }

    /// The filter's barometer offset moved by `jump`, m, with no change of height above home.
    pub fn shift_baro(&mut self, jump: f32) {
        self.home_baro_offset += jump;
    }

    /// Sets home (see `Estimator::set_home`); `ins` is moved to the new origin.
    pub fn set_home(&mut self, ins: &mut Ins, home: Home) -> bool {
        let Some(old) = self.home else {
            return false;
        };
        if !home.point.is_valid() || !limits::in_range(home.alt_amsl_m, limits::GPS_ALT_M) {
            return false;
        }
        let reported = self
            .home_held
            .map_or(old.alt_amsl_m - self.baro_drift_m(ins), |h| h.alt_amsl_m);
        // The origin and the altitude it is fused at move together, so the barometer's
        // offset, and with it the height above home, carry on from where they were.
        let up = home.alt_amsl_m - reported;
        let (n, e) = flight_ned_offset(home.point, old.point);
        ins.shift_origin(&Vector3::new(n, e, up));
        self.home = Some(Home {
            point: home.point,
            alt_amsl_m: old.alt_amsl_m + up,
        });
        self.frame = Some(LocalFrame::new(home.point));
        self.home_held = Some(home);
        true
    }

    /// What `ins` has learnt of the barometer's offset since the first fix set home, m.
    pub fn baro_drift_m(&self, ins: &Ins) -> f32 {
        ins.baro_offset() - self.home_baro_offset
    }

    /// North and east of `p` from `origin`, m: through the cached frame when it is about
    /// `origin`.
    pub fn ned_of(&self, origin: GeoPoint, p: GeoPoint) -> (f32, f32) {
        match self.frame.filter(|f| f.origin() == origin) {
            Some(f) => f.ned_offset(p),
            None => flight_ned_offset(origin, p),
        }
    }

    /// The cached local frame, when it is about `point`.
    pub fn frame_about(&self, point: GeoPoint) -> Option<LocalFrame> {
        self.frame.filter(|f| f.origin() == point)
    }

    /// Home as reported, given the barometer's `drift` (see `Estimator::home`).
    pub fn home(&self, drift: f32) -> Option<Home> {
        match (self.home_held, self.home) {
            (Some(held), _) => Some(held),
            (None, Some(h)) if drift.is_finite() => Some(Home {
                alt_amsl_m: h.alt_amsl_m - drift,
                ..h
            }),
            (None, h) => h,
        }
    }
}
