//! One flight of a campaign: flown in-process, its figures and facts read from the log, the
//! summary and the autopilot's own state at the end, judged, and written as one JSON line.

use super::draws::Quantities;
use super::mission::Landing;
use super::verdict::{judge, Facts, Verdict};
use crate::aircraft::Aircraft;
use crate::flight::config::FlightConfig;
use crate::flight::measures::HomeDatum;
use crate::flight::onboard::InprocOnboard;
use crate::flight::record::Sample;
use crate::flight::runner::{fly, FlightOutcome};
use crate::flight::strikes::{clearance, phase_name, strike_points, survey, Point, Survey};
use crate::link::lockstep::Lockstep;
use crate::link::transport::Inproc;
use common::math::wrap_pi;
use common::vehicle::snapshot::LandedState;
use firmware::app::App;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// The figures of one flight. `None` (JSON `null`): not measured, e.g. no touchdown.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Figures {
    /// Simulated time, s.
    pub sim_s: Option<f64>,
    /// Armed time, s.
    pub flight_time_s: Option<f64>,
    /// Motor energy, Wh.
    pub energy_wh: Option<f64>,
    /// Charge drawn from the flight pack, mAh.
    pub battery_mah: Option<f64>,
    /// Lowest voltage of the flight pack, V.
    pub battery_min_v: Option<f64>,
    /// Charge left in the flight pack at the end, %.
    pub battery_left_pct: Option<f64>,
    /// Navigation items reached.
    pub items_reached: Option<f64>,
    /// Navigation items of the mission.
    pub items: Option<f64>,
    /// Cross-track error on straight legs, RMS, m.
    pub xtrack_rms_m: Option<f64>,
    /// Largest cross-track error on straight legs, m.
    pub xtrack_max_m: Option<f64>,
    /// Cross-track error on loiter circles, RMS, m.
    pub orbit_xtrack_rms_m: Option<f64>,
    /// Altitude error, RMS, m.
    pub alt_rms_m: Option<f64>,
    /// Airspeed error, RMS, m/s.
    pub airspeed_rms_mps: Option<f64>,
    /// Touchdown distance from the landing point, m.
    pub touchdown_m: Option<f64>,
    /// Touchdown along the approach from the landing point (positive: past it), m.
    pub touchdown_along_m: Option<f64>,
    /// Touchdown across the approach (positive: right of it), m.
    pub touchdown_cross_m: Option<f64>,
    /// Sink rate at touchdown, m/s.
    pub sink_mps: Option<f64>,
    /// Ground speed at touchdown, m/s.
    pub touchdown_ground_speed_mps: Option<f64>,
    /// Bounces after the first contact.
    pub bounces: Option<f64>,
    /// The wind lifted the aircraft off the runway for a second or more after the disarm
    /// (not its landing: [`crate::flight::FlightSummary::lifted_after_disarm`]).
    pub lifted_after_disarm: Option<bool>,
    /// Go-arounds flown (each entry into the navigator's go-around while armed).
    pub go_arounds: Option<f64>,
    /// Largest |bank| while armed, deg.
    pub max_bank_deg: Option<f64>,
    /// Largest |pitch| while armed, deg.
    pub max_pitch_deg: Option<f64>,
    /// Smallest clearance of a non-wheel point while armed, m.
    pub min_clearance_m: Option<f64>,
    /// Which point that was.
    pub min_clearance_point: Option<String>,
    /// When, s of simulated time.
    pub min_clearance_t_s: Option<f64>,
    /// The navigator's phase then.
    pub min_clearance_phase: Option<String>,
    /// When bank or pitch first went beyond the loss-of-control limits, s.
    pub loss_of_control_t_s: Option<f64>,
    /// The navigator's phase then.
    pub loss_of_control_phase: Option<String>,
    /// Time of the landing's first contact, s.
    pub touchdown_t_s: Option<f64>,
    /// Horizontal position error of the estimate at arming, m.
    pub est_position_error_at_arm_m: Option<f64>,
    /// Altitude error of the estimate at arming, m.
    pub est_alt_error_at_arm_m: Option<f64>,
    /// Heading error of the estimate at arming, deg.
    pub est_heading_error_at_arm_deg: Option<f64>,
    /// Heading error of the estimate 30 s after convergence to the end, RMS, deg.
    pub est_heading_rms_deg: Option<f64>,
    /// The autopilot's landed state at the end.
    pub landed_state: Option<String>,
    /// The autopilot armed at the end.
    pub armed_at_end: Option<bool>,
    /// Failsafes raised (their STATUSTEXT).
    pub failsafes: Vec<String>,
    /// Why the flight did not run to its end.
    pub error: Option<String>,
}

/// One line of a campaign's `flights.jsonl`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FlightRecord {
    /// Index of the flight in the campaign.
    pub index: u64,
    /// Seed of its sensor noise and turbulence.
    pub flight_seed: u64,
    /// Every dispersed quantity as drawn (factors for spreads, values otherwise), then the
    /// quantities that follow from them (`derived.*`).
    pub draws: Quantities,
    /// What the flight did.
    pub figures: Figures,
    /// The criteria.
    pub verdict: Verdict,
    /// The command that flies it again, with its log and plots.
    pub reproduce: String,
}

/// A JSON number for a figure: `None` unless finite (JSON has no NaN).
fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

/// What the log shows while armed: the largest bank and pitch, when control was first lost,
/// and the clearances of the non-wheel points.
#[derive(Clone, Debug, Default)]
struct Excursions {
    bank_deg: Option<f64>,
    pitch_deg: Option<f64>,
    loss_of_control: Option<(f64, String)>,
    clearances: Survey,
}

fn excursions(samples: &[Sample], points: &[Point], home_alt: f64) -> Excursions {
    use super::verdict::{LOC_BANK_DEG, LOC_PITCH_DEG};
    let mut x = Excursions::default();
    for s in samples.iter().filter(|s| s.armed) {
        let (bank, pitch) = (s.roll.abs().to_degrees(), s.pitch.abs().to_degrees());
        x.bank_deg = Some(x.bank_deg.unwrap_or(0.0).max(bank));
        x.pitch_deg = Some(x.pitch_deg.unwrap_or(0.0).max(pitch));
        if x.loss_of_control.is_none() && (bank > LOC_BANK_DEG || pitch > LOC_PITCH_DEG) {
            x.loss_of_control = Some((s.t, phase_name(s.nav_phase)));
        }
    }
    x.clearances = survey(samples, points, home_alt);
    x
}

/// The truth is on the ground: some point of the airframe, wheel or not, within 5 cm of it
/// (the main legs compress 1.4 cm at rest; an aircraft on its back is on the ground too).
fn on_ground(s: &Sample, a: &Aircraft, points: &[Point], home_alt: f64) -> bool {
    let g = &a.ground;
    let third = g.third_wheel().map(|w| w.pos_m);
    let wheels = [Some(g.main_wheel_left_m), Some(g.main_wheel_right_m), third]
        .into_iter()
        .flatten()
        .map(|w| Point {
            name: String::new(),
            body: Vector3::from(w),
            disc_radius: 0.0,
        })
        .collect::<Vec<_>>();
    wheels
        .iter()
        .chain(points)
        .any(|p| clearance(s, home_alt, p) < 0.05)
}

/// What the autopilot says of itself once the flight has stopped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AutopilotEnd {
    /// Its landed state.
    pub landed: LandedState,
    /// Armed.
    pub armed: bool,
}

/// Flies `cfg` with the firmware in-process and reads the autopilot's state at the end.
pub fn fly_inproc(
    aircraft: &Aircraft,
    cfg: &FlightConfig,
) -> Result<(FlightOutcome, AutopilotEnd), String> {
    let mut link = Lockstep::new(Inproc::new(App::new()), cfg.link_timeout);
    let outcome = fly(aircraft, cfg, &mut link, &mut InprocOnboard).map_err(|e| e.to_string())?;
    let snap = link.transport_mut().app_mut().snapshot();
    Ok((
        outcome,
        AutopilotEnd {
            landed: snap.landed,
            armed: snap.armed,
        },
    ))
}

/// The failsafe texts the autopilot raised (not those clearing one).
fn failsafes_raised(texts: &[(f64, String)]) -> Vec<String> {
    use common::failsafe::Event;
    let raising: Vec<&str> = Event::ALL
        .iter()
        .filter(|e| e.raises())
        .map(|e| e.text())
        .collect();
    texts
        .iter()
        .filter(|(_, t)| raising.contains(&t.as_str()))
        .map(|(t, text)| format!("{t:.1} s: {text}"))
        .collect()
}

/// The figures and the facts of a flown flight (or of one that could not be flown).
pub fn figures_and_facts(
    plan: &Plan,
    flown: &Result<(FlightOutcome, AutopilotEnd), String>,
) -> (Figures, Facts) {
    let (aircraft, landing) = (&plan.aircraft, plan.landing);
    let (outcome, end) = match flown {
        Ok(x) => x,
        Err(e) => {
            let figures = Figures {
                error: Some(e.clone()),
                ..Figures::default()
            };
            let facts = Facts {
                error: Some(e.clone()),
                ..Facts::default()
            };
            return (figures, facts);
        }
    };
    let home_alt = aircraft.environment.home_alt_msl_m;
    let s = &outcome.summary;
    let samples = &outcome.samples;
    let points = strike_points(aircraft, plan.propeller_hub_m);
    let x = excursions(samples, &points, home_alt);
    let closest = x.clearances.closest.as_ref();
    let mut f = Figures {
        sim_s: finite(s.sim_s),
        max_bank_deg: x.bank_deg,
        max_pitch_deg: x.pitch_deg,
        loss_of_control_t_s: x.loss_of_control.as_ref().map(|l| l.0),
        loss_of_control_phase: x.loss_of_control.as_ref().map(|l| l.1.clone()),
        min_clearance_m: closest.map(|c| c.clearance_m),
        min_clearance_point: closest.map(|c| c.point.clone()),
        min_clearance_t_s: closest.map(|c| c.t_s),
        min_clearance_phase: closest.map(|c| c.phase.clone()),
        est_heading_rms_deg: s
            .estimator_settled
            .as_ref()
            .and_then(|e| finite(e.heading_rms_deg)),
        landed_state: Some(format!("{:?}", end.landed)),
        armed_at_end: Some(end.armed),
        failsafes: failsafes_raised(&s.texts),
        ..Figures::default()
    };
    if let Some(a) = samples.iter().find(|x| x.armed) {
        f.est_position_error_at_arm_m = finite((a.est_north - a.north).hypot(a.est_east - a.east));
        // Home is set at arming to the altitude estimated then: the error it is held with.
        f.est_alt_error_at_arm_m = finite(HomeDatum::of(samples).error_m);
        f.est_heading_error_at_arm_deg = finite(wrap_pi(a.est_yaw - a.yaw).to_degrees());
    }
    if let Some(b) = &s.battery {
        f.battery_mah = finite(b.charge_mah);
        f.battery_min_v = finite(b.min_voltage_v);
        f.battery_left_pct = finite(b.final_remaining_pct);
    }
    if let Some(m) = &s.mission {
        f.lifted_after_disarm = Some(s.lifted_after_disarm.is_some());
        f.go_arounds = Some(go_arounds(samples) as f64);
        f.flight_time_s = finite(m.flight_time_s);
        f.energy_wh = finite(m.energy_wh);
        f.items = Some(m.nav_items.len() as f64);
        f.items_reached = Some(m.nav_items.iter().filter(|i| m.reached.contains(i)).count() as f64);
        f.xtrack_rms_m = finite(m.xtrack_rms_m);
        f.xtrack_max_m = finite(m.xtrack_max_m);
        f.orbit_xtrack_rms_m = finite(m.orbit_xtrack_rms_m);
        f.alt_rms_m = finite(m.alt_rms_m);
        f.airspeed_rms_mps = finite(m.airspeed_rms_mps);
        if let Some(t) = &m.touchdown {
            f.sink_mps = finite(t.sink_rate_mps);
            f.touchdown_ground_speed_mps = finite(t.ground_speed_mps);
            f.bounces = Some(f64::from(t.bounces));
            f.touchdown_t_s = finite(t.time_s);
            if let Some(l) = landing {
                let (dn, de) = (t.north_m - l.point_ne.0, t.east_m - l.point_ne.1);
                let (sin, cos) = l.direction_rad.sin_cos();
                f.touchdown_m = finite(dn.hypot(de));
                f.touchdown_along_m = finite(dn * cos + de * sin);
                f.touchdown_cross_m = finite(-dn * sin + de * cos);
            }
        }
    }
    let truth_on_ground = samples
        .last()
        .is_some_and(|x| on_ground(x, aircraft, &points, home_alt));
    let says_on_ground = end.landed == LandedState::OnGround;
    let facts = Facts {
        error: None,
        max_bank_deg: f.max_bank_deg,
        max_pitch_deg: f.max_pitch_deg,
        all_items_reached: s.mission.as_ref().is_some_and(|m| m.all_reached),
        touchdown_m: f.touchdown_m,
        sink_mps: f.sink_mps,
        min_clearance_m: f.min_clearance_m,
        landed_state_agrees: says_on_ground == truth_on_ground,
        disarmed_on_ground: truth_on_ground && !end.armed,
        on_ground: truth_on_ground,
        failsafes: f.failsafes.clone(),
        loss_of_control: x.loss_of_control,
        closest_call: closest.map(|c| (c.t_s, c.point.clone(), c.phase.clone())),
        touchdown_at: f.touchdown_t_s.zip(f.touchdown_along_m),
        items: (
            f.items_reached.unwrap_or(0.0) as u32,
            f.items.unwrap_or(0.0) as u32,
        ),
    };
    (f, facts)
}

/// One flight, planned: its draws applied.
#[derive(Clone, Debug)]
pub struct Plan {
    /// Index in the campaign.
    pub index: u64,
    /// Seed of its sensor noise and turbulence.
    pub flight_seed: u64,
    /// The dispersed quantities, as drawn.
    pub draws: Quantities,
    /// The dispersed aircraft.
    pub aircraft: Aircraft,
    /// Where its propeller's hub is, from the CG, body axes, m
    /// ([`crate::flight::strikes::propeller_hub_m`]).
    pub propeller_hub_m: [f64; 3],
    /// The flight.
    pub config: FlightConfig,
    /// Where it lands.
    pub landing: Option<Landing>,
}

/// Flies a planned flight and builds its record; a panic inside the flight is caught and
/// recorded as an error, so one flight cannot end a campaign.
pub fn fly_record(plan: &Plan, reproduce: String) -> (FlightRecord, Option<FlightOutcome>) {
    let flown = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        fly_inproc(&plan.aircraft, &plan.config)
    }))
    .unwrap_or_else(|p| {
        let what = p
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_else(|| "unknown panic".into());
        Err(format!("panicked: {what}"))
    });
    let (figures, facts) = figures_and_facts(plan, &flown);
    let record = FlightRecord {
        index: plan.index,
        flight_seed: plan.flight_seed,
        draws: plan.draws.clone(),
        figures,
        verdict: judge(&facts),
        reproduce,
    };
    (record, flown.ok().map(|f| f.0))
}

/// Go-arounds in a flight's log: the armed frames where the navigator enters its go-around.
fn go_arounds(samples: &[Sample]) -> usize {
    let ga = common::navigation::Phase::GoAround as u8;
    samples
        .windows(2)
        .filter(|w| w[1].armed && w[1].nav_phase == ga && w[0].nav_phase != ga)
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flight::strikes::propeller_hub_m;
    use crate::flight::strikes::tests::at_rest;

    #[test]
    fn the_truth_is_on_the_ground_at_rest_and_on_its_back_but_not_a_metre_up() {
        let a = Aircraft::ultrastick25e().unwrap();
        let points = strike_points(&a, propeller_hub_m(&a, [0.0; 3]));
        let home = a.environment.home_alt_msl_m;
        let rest = at_rest(&a);
        assert!(on_ground(&rest, &a, &points, home));
        let aloft = Sample {
            alt: rest.alt + 1.0,
            ..rest
        };
        assert!(!on_ground(&aloft, &a, &points, home));
        // On its back, wheels up: on the ground all the same.
        let inverted = Sample {
            roll: std::f64::consts::PI,
            alt: home + 0.05,
            ..rest
        };
        assert!(on_ground(&inverted, &a, &points, home));
    }
}
