//! How a mission was flown: the items reached, the tracking errors of the truth against what
//! guidance asked for, the throttle's time on its stops, the touchdown, and the verdict on
//! them a campaign names.

use super::criteria::Criterion;
use super::measures::{rms, HomeDatum};
use super::record::Sample;
use super::strikes::{StrikeEvent, Survey};
use crate::plant::Touchdown;
use common::navigation::Phase;
use serde::Serialize;

/// How a mission was flown: tracking errors of the truth against what guidance asked for.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct MissionSummary {
    /// Items uploaded.
    pub items: usize,
    /// The navigation items (waypoints, loiters, take-off, landing): each must be reached.
    pub nav_items: Vec<u16>,
    /// MISSION_ITEM_REACHED as the ground station received them, in order.
    pub reached: Vec<u16>,
    /// Every navigation item reached.
    pub all_reached: bool,
    /// Cross-track error on straight legs (waypoint items, fillets excluded), RMS, m.
    pub xtrack_rms_m: f64,
    /// Largest cross-track error on straight legs, m.
    pub xtrack_max_m: f64,
    /// Cross-track error while circling a loiter item, RMS, m.
    pub orbit_xtrack_rms_m: f64,
    /// Altitude error (guidance's altitude minus the true altitude, in home's datum: see
    /// [`HomeDatum`]) over the waypoint and loiter
    /// items, RMS, m.
    pub alt_rms_m: f64,
    /// Airspeed error (commanded minus true) over the same items, RMS, m/s.
    pub airspeed_rms_mps: f64,
    /// Share of level cruise (the same items, within the altitude-hold band of their
    /// altitude, where the throttle holds the airspeed) with the throttle on a stop, %.
    pub throttle_at_stops_pct: f64,
    /// Armed time, s.
    pub flight_time_s: f64,
    /// Energy the motor drew (the UMN motor-power curve at the commanded throttle), Wh.
    pub energy_wh: f64,
    /// The landing, when there was one.
    pub touchdown: Option<TouchdownSummary>,
    /// Each contact of a point of the airframe other than its wheels with the ground while
    /// armed ([`crate::flight::strikes`]).
    pub strikes: Vec<StrikeEvent>,
    /// Smallest clearance of such a point while armed, m (`None`: never armed).
    pub min_clearance_m: Option<f64>,
    /// Every criterion in `failed` met.
    pub pass: bool,
    /// The criteria not met, as a campaign judges and names them: `items` (a navigation item
    /// not reached), `no_strike` (a strike, or never armed).
    pub failed: Vec<String>,
}

impl MissionSummary {
    /// Judges the mission with the clearances of its flight, and keeps its strikes.
    pub fn judge(&mut self, clearances: Survey) {
        let met = [
            (Criterion::Items, self.all_reached),
            (Criterion::NoStrike, clearances.strike_free()),
        ];
        self.failed = met
            .iter()
            .filter(|(_, ok)| !ok)
            .map(|(c, _)| c.name().to_string())
            .collect();
        self.pass = self.failed.is_empty();
        self.min_clearance_m = clearances.closest.map(|c| c.clearance_m);
        self.strikes = clearances.strikes;
    }
}

/// The first contact of a landing.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct TouchdownSummary {
    /// Simulated time, s.
    pub time_s: f64,
    /// Where, north of home, m.
    pub north_m: f64,
    /// Where, east of home, m.
    pub east_m: f64,
    /// Horizontal distance from the mission's landing point, m (NaN without a NAV_LAND).
    pub distance_m: f64,
    /// Along the landing direction (positive: past the point), m.
    pub along_m: f64,
    /// Sink rate, m/s.
    pub sink_rate_mps: f64,
    /// Ground speed, m/s.
    pub ground_speed_mps: f64,
    /// Bounces after the first contact.
    pub bounces: u32,
}

/// Cross-track error within which a loiter counts as arrived on its circle, m (the
/// navigator's default acceptance radius, `NAV_ACC_RAD`).
const ORBIT_ARRIVAL_M: f64 = 15.0;

/// Share of the time the throttle sits on a stop (within 0.01 of the flight defaults'
/// `THR_MIN` or `THR_MAX`), %; NaN without samples.
pub fn share_on_stop_pct(throttle: &[f64]) -> f64 {
    if throttle.is_empty() {
        return f64::NAN;
    }
    let g = &common::control::longitudinal::FLIGHT;
    let (lo, hi) = (f64::from(g.throttle_min), f64::from(g.throttle_max));
    let on = throttle
        .iter()
        .filter(|t| **t <= lo + 0.01 || **t >= hi - 0.01)
        .count();
    100.0 * on as f64 / throttle.len() as f64
}

/// Figures of a mission flight. `land_point` is the NAV_LAND item north and east of home;
/// the errors and the flight time count over the samples from `from_s` on (the mission's
/// part of a flight that flew something else first; `-inf`: the whole flight), in home's
/// datum as set at arming; `energy_j` is the motor's over the same part.
#[allow(clippy::too_many_arguments)]
pub fn mission_summary(
    mission: &[mavlink::dialects::common::MISSION_ITEM_INT_DATA],
    land_point: Option<(f64, f64)>,
    flight: &[Sample],
    from_s: f64,
    reached: &[u16],
    touchdown: Option<&Touchdown>,
    energy_j: f64,
    frame_s: f64,
) -> MissionSummary {
    use mavlink::dialects::common::MavCmd as C;
    let nav_items: Vec<u16> = mission
        .iter()
        .filter(|i| {
            matches!(
                i.command,
                C::MAV_CMD_NAV_WAYPOINT
                    | C::MAV_CMD_NAV_LOITER_TURNS
                    | C::MAV_CMD_NAV_LOITER_TIME
                    | C::MAV_CMD_NAV_LOITER_TO_ALT
                    | C::MAV_CMD_NAV_TAKEOFF
                    | C::MAV_CMD_NAV_LAND
            )
        })
        .map(|i| i.seq)
        .collect();
    let datum = HomeDatum::of(flight);
    let samples = &flight[flight.partition_point(|s| s.t < from_s)..];
    let leg: Vec<f64> = samples
        .iter()
        .filter(|s| s.armed && s.straight && s.nav_phase == Phase::Waypoint as u8)
        .map(|s| s.xtrack)
        .filter(|x| x.is_finite())
        .collect();
    // On the circle: from the first sample of each loiter within the acceptance radius (the
    // navigator's own test for arrival) to the end of that loiter.
    let mut orbit = Vec::new();
    let mut on_circle = false;
    for s in samples {
        if !(s.armed && s.nav_phase == Phase::Loiter as u8 && s.xtrack.is_finite()) {
            on_circle = false;
            continue;
        }
        on_circle |= s.xtrack.abs() <= ORBIT_ARRIVAL_M;
        if on_circle {
            orbit.push(s.xtrack);
        }
    }
    let cruising = samples.iter().filter(|s| {
        s.armed && (s.nav_phase == Phase::Waypoint as u8 || s.nav_phase == Phase::Loiter as u8)
    });
    let (alt, va): (Vec<f64>, Vec<f64>) = cruising
        .clone()
        .map(|s| (s.sp_alt - datum.truth_alt(s), s.sp_airspeed - s.airspeed))
        .unzip();
    let band = f64::from(common::control::longitudinal::FLIGHT.alt_band);
    let level: Vec<f64> = cruising
        .filter(|s| (s.sp_alt - s.est_alt).abs() < band)
        .map(|s| s.throttle)
        .collect();
    let touchdown = touchdown.map(|t| touchdown_summary(t, land_point));
    MissionSummary {
        items: mission.len(),
        all_reached: nav_items.iter().all(|i| reached.contains(i)),
        nav_items,
        reached: reached.to_vec(),
        xtrack_rms_m: rms(&leg),
        // No straight leg known (an autopilot not looked into): no figure rather than 0.
        xtrack_max_m: leg.iter().fold(f64::NAN, |m, x| m.max(x.abs())),
        orbit_xtrack_rms_m: rms(&orbit),
        alt_rms_m: rms(&alt),
        airspeed_rms_mps: rms(&va),
        throttle_at_stops_pct: share_on_stop_pct(&level),
        flight_time_s: samples.iter().filter(|s| s.armed).count() as f64 * frame_s,
        energy_wh: energy_j / 3600.0,
        touchdown,
        ..MissionSummary::default()
    }
}

/// The figures of a touchdown; distances from `land_point` (north, east of home), NaN without.
pub fn touchdown_summary(t: &Touchdown, land_point: Option<(f64, f64)>) -> TouchdownSummary {
    let (n, e) = (t.pos_ned.x, t.pos_ned.y);
    let (distance_m, along_m) = match land_point {
        Some((ln, le)) => {
            let v = t.vel_ned;
            let h = v.x.hypot(v.y).max(1e-9);
            (
                (n - ln).hypot(e - le),
                ((n - ln) * v.x + (e - le) * v.y) / h,
            )
        }
        None => (f64::NAN, f64::NAN),
    };
    TouchdownSummary {
        time_s: t.time_s,
        north_m: n,
        east_m: e,
        distance_m,
        along_m,
        sink_rate_mps: t.sink_rate_mps(),
        ground_speed_mps: t.vel_ned.x.hypot(t.vel_ned.y),
        bounces: t.bounces,
    }
}
