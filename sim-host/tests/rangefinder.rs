//! The landing with a downward rangefinder, flown end to end: the default mission from the
//! runway on the firmware's defaults (`NAV_LND_USE_RNG` on), with the rangefinder healthy,
//! stuck, reading a short false echo, or dropping out. The expectation is the physics: the
//! flare starts where the true height above the runway crosses `NAV_FLR_ALT` (the height the
//! rangefinder sees, range x cos(roll) cos(pitch)), and a failed rangefinder is never believed
//! where it would flare early or pitch the nose down. Beside them, the oracle the campaign
//! measures any height sensor's ceiling with (`SIM_USE_TRUTH` = 2).

use common::navigation::Phase;
use sim_host::aircraft::Aircraft;
use sim_host::commands::fly::{fly_report, FlyOptions};
use sim_host::flight::criteria::{SINK_MPS, TOUCHDOWN_M};
use sim_host::flight::missions::{default_mission, runway_mission};
use sim_host::flight::{Fault, FaultWindow, FlightConfig, FlightOutcome, Sample};
use sim_host::plant::ModelParams;
use sim_host::sensors::models::RangeFault;
use sim_host::sensors::RangefinderConfig;

mod support;
use support::default_of;

/// Highest true height above the runway at which a flare may start, m: the nominal flare
/// height plus 2 m (an early flare from a short reading would start far above it).
const EARLY_MARGIN_M: f64 = 2.0;
/// Least height above the runway at which the flare must have started, m, below the nominal:
/// a stuck reading believed would hold the flare off to the ground.
const LATE_MARGIN_M: f64 = 0.7;
/// Pitch under the approach's least pitch that the final descent may show, deg.
const PITCH_MARGIN_DEG: f64 = 1.0;

/// The default mission from the runway, the built-in aircraft and the flight changed by
/// `change`; the flight and the runway's altitude above sea level.
fn fly_mission(change: impl FnOnce(&mut Aircraft, &mut FlightConfig)) -> (FlightOutcome, f64) {
    let mut a = Aircraft::ultrastick25e().expect("built-in aircraft");
    let mut cfg = runway_mission(default_mission(ModelParams::new(&a).home));
    change(&mut a, &mut cfg);
    let home_alt = ModelParams::new(&a).home_alt_msl_m;
    let o = fly_report(&a, &cfg, &FlyOptions::default())
        .expect("flight")
        .outcome;
    (o, home_alt)
}

/// The default mission from the runway with a rangefinder, failed as `fault` from `from_s`.
fn landing(fault: Option<(RangeFault, f64)>) -> (FlightOutcome, f64) {
    fly_mission(|a, cfg| {
        a.sensors.rangefinder = Some(RangefinderConfig::default());
        if let Some((kind, from_s)) = fault {
            cfg.faults.push(FaultWindow {
                fault: Fault::Range(kind),
                from_s,
                to_s: f64::INFINITY,
            });
        }
    })
}

fn in_phase(s: &Sample, p: Phase) -> bool {
    s.nav_phase == p as u8
}

/// What the landing showed: the true height at the flare's start, the approach's least pitch
/// below 15 m (deg), the least pitch from the flare's start to the touchdown (deg).
struct Landing {
    flare_start_m: f64,
    approach_min_pitch_deg: f64,
    flare_min_pitch_deg: f64,
}

fn landing_figures(o: &FlightOutcome, home_alt: f64) -> Landing {
    let s = &o.samples;
    let k = s
        .iter()
        .position(|x| in_phase(x, Phase::Flare))
        .expect("a flare");
    let td = o.summary.touchdown.as_ref().expect("a touchdown").time_s;
    let approach = s[..k]
        .iter()
        .filter(|x| in_phase(x, Phase::Approach) && x.alt - home_alt < 15.0)
        .map(|x| x.pitch.to_degrees())
        .fold(f64::INFINITY, f64::min);
    let flare = s[k..]
        .iter()
        .take_while(|x| x.t <= td)
        .map(|x| x.pitch.to_degrees())
        .fold(f64::INFINITY, f64::min);
    Landing {
        flare_start_m: s[k].alt - home_alt,
        approach_min_pitch_deg: approach,
        flare_min_pitch_deg: flare,
    }
}

/// When the approach's true height first falls below `h` m, s.
fn approach_below(o: &FlightOutcome, home_alt: f64, h: f64) -> f64 {
    o.samples
        .iter()
        .find(|x| in_phase(x, Phase::Approach) && x.alt - home_alt < h)
        .expect("an approach")
        .t
}

fn check_safe(o: &FlightOutcome, home_alt: f64, what: &str) -> Landing {
    let flare_alt = default_of("NAV_FLR_ALT");
    let l = landing_figures(o, home_alt);
    let td = o.summary.touchdown.as_ref().expect("a touchdown");
    eprintln!(
        "{what}: flare at {:.2} m (nominal {flare_alt}), least pitch approach {:.2} deg, flare {:.2} deg; touchdown {:.1} m from the point, sink {:.2} m/s",
        l.flare_start_m, l.approach_min_pitch_deg, l.flare_min_pitch_deg, td.distance_m, td.sink_rate_mps
    );
    assert!(
        l.flare_start_m <= flare_alt + EARLY_MARGIN_M,
        "{what}: flare started at {:.2} m",
        l.flare_start_m
    );
    assert!(
        l.flare_start_m >= flare_alt - LATE_MARGIN_M,
        "{what}: flare started only at {:.2} m",
        l.flare_start_m
    );
    assert!(
        l.flare_min_pitch_deg >= l.approach_min_pitch_deg - PITCH_MARGIN_DEG,
        "{what}: pitch {:.2} deg in the flare, approach {:.2} deg",
        l.flare_min_pitch_deg,
        l.approach_min_pitch_deg
    );
    assert!(
        td.distance_m < TOUCHDOWN_M,
        "{what}: {:.1} m",
        td.distance_m
    );
    assert!(
        td.sink_rate_mps < SINK_MPS,
        "{what}: {:.2} m/s",
        td.sink_rate_mps
    );
    l
}

#[test]
fn a_healthy_rangefinder_flares_at_the_nominal_height_and_lands_within_the_criteria() {
    let (o, home_alt) = landing(None);
    let l = check_safe(&o, home_alt, "healthy");
    // Measured by the rangefinder, the flare starts within a few tenths of the nominal
    // height (one 50 Hz period of the approach's 1-1.5 m/s sink is 3 cm).
    let flare_alt = default_of("NAV_FLR_ALT");
    assert!(
        (l.flare_start_m - flare_alt).abs() < 0.3,
        "{:.2} m",
        l.flare_start_m
    );
}

#[test]
fn a_stuck_rangefinder_on_the_approach_never_holds_off_the_flare_nor_flares_early() {
    // Frozen at what it read at 8 m on the approach.
    let (clean, home_alt) = landing(None);
    let from = approach_below(&clean, home_alt, 8.0);
    let (o, _) = landing(Some((RangeFault::Stuck, from)));
    check_safe(&o, home_alt, "stuck");
}

#[test]
fn a_short_false_echo_from_take_off_never_flares_early() {
    let (o, home_alt) = landing(Some((RangeFault::Short, 0.0)));
    check_safe(&o, home_alt, "short");
}

#[test]
fn a_dropping_rangefinder_never_flares_early() {
    // From the approach's 20 m on: readings at the minimum and out of range between bursts.
    let (clean, home_alt) = landing(None);
    let from = approach_below(&clean, home_alt, 20.0);
    let (o, _) = landing(Some((RangeFault::Dropping, from)));
    check_safe(&o, home_alt, "dropping");
}

/// The flare's oracle (`SIM_USE_TRUTH` = 2: the simulator's true height above home and
/// sink), without a rangefinder and with the GPS altitude 5 m off at start: the flare starts
/// where the true height of the centre of gravity above where it stood at arming crosses
/// `NAV_FLR_ALT`, within one 50 Hz period of the approach's 1-1.5 m/s sink (3 cm) and one
/// of the flight's samples (as much again), and the landing meets the criteria.
#[test]
fn given_the_truth_the_flare_starts_at_the_true_flare_height_to_a_period_of_sink() {
    let (o, home_alt) = fly_mission(|a, cfg| {
        a.sensors.gps.startup_offset_m = [0.0, 0.0, 5.0];
        cfg.script.params.push(("SIM_USE_TRUTH".into(), 2.0));
    });
    let armed_at = o.samples.iter().find(|x| x.armed).expect("armed").alt;
    let l = landing_figures(&o, armed_at);
    let flare_alt = default_of("NAV_FLR_ALT");
    eprintln!(
        "oracle: flare at {:.3} m above the arming height ({:.3} m above the runway)",
        l.flare_start_m,
        armed_at - home_alt
    );
    assert!(
        l.flare_start_m <= flare_alt && l.flare_start_m > flare_alt - 0.06,
        "flare at {:.3} m",
        l.flare_start_m
    );
    let td = o.summary.touchdown.as_ref().expect("a touchdown");
    assert!(td.distance_m < TOUCHDOWN_M, "{:.1} m", td.distance_m);
    assert!(td.sink_rate_mps < SINK_MPS, "{:.2} m/s", td.sink_rate_mps);
}
