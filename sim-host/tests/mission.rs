//! Navigation flown end to end: missions uploaded through the ground link, flown by the
//! firmware on its own estimates, from the runway to the runway.

use sim_host::aircraft::Aircraft;
use sim_host::commands::fly::{fly_report, FlyOptions};
use sim_host::flight::missions::default_mission;
use sim_host::flight::record::write_log_and_plots;
use sim_host::flight::{Action, FlightConfig, Script, ScriptStep};
use sim_host::plant::ModelParams;

fn aircraft() -> Aircraft {
    Aircraft::ultrastick25e().expect("built-in aircraft")
}

#[test]
fn explore_default_mission() {
    let a = aircraft();
    let home = ModelParams::new(&a).home;
    let cfg = FlightConfig {
        duration_s: 400.0,
        runway_heading: Some(0.0),
        script: Script {
            steps: vec![ScriptStep {
                after_arm_s: 1.0,
                action: Action::MissionStart,
            }],
            mission: default_mission(home),
            ..Script::thesis()
        },
        ..FlightConfig::default()
    };
    let o = fly_report(&a, &cfg, &FlyOptions::default())
        .expect("flight")
        .outcome;
    let _ = write_log_and_plots(std::path::Path::new("/tmp/mission"), &o.samples);
    for s in o.samples.iter().step_by(500) {
        println!(
            "t {:6.1} arm {} mode {} ph {:2} seq {:2} N {:7.1} E {:7.1} alt {:6.1} spalt {:6.1} va {:5.1} xt {:6.1} thr {:.2} pitch {:5.1}",
            s.t, s.armed as u8, s.mode, s.nav_phase, s.mission_seq, s.north, s.east, s.alt, s.sp_alt, s.airspeed, s.xtrack, s.throttle, s.pitch.to_degrees()
        );
    }
    println!("commands {:?}", o.summary.commands);
    println!("texts {:?}", o.summary.texts);
}
