//! Wall time and real-time factor of the default mission, in-process: upload, convergence on
//! the runway, take-off, the rectangle, two loiter turns, approach, landing and roll-out to a
//! stop (about 355 s of simulated time), everything the default `cargo run` flies except the
//! files it writes. Criterion reports the time per whole mission; the real-time factor is the
//! simulated time over it (printed once before the measurement).

use criterion::{criterion_group, criterion_main, Criterion};
use sim_host::aircraft::Aircraft;
use sim_host::commands::fly::{fly_report, FlyOptions};
use sim_host::flight::missions::{default_mission, runway_mission};
use sim_host::plant::ModelParams;
use std::hint::black_box;

fn mission(c: &mut Criterion) {
    let aircraft = Aircraft::ultrastick25e().expect("built-in aircraft");
    let cfg = runway_mission(default_mission(ModelParams::new(&aircraft).home));
    let opts = FlyOptions {
        out: None,
        plots: false,
        ..FlyOptions::default()
    };
    let once = fly_report(&aircraft, &cfg, &opts).expect("flight");
    println!(
        "default mission: {:.1} s simulated in {:.3} s wall ({:.0}x real time)",
        once.outcome.summary.sim_s,
        once.outcome.summary.wall_s,
        once.outcome.summary.real_time_factor
    );
    let mut group = c.benchmark_group("default_mission");
    group.sample_size(10);
    group.bench_function("inproc_whole_mission", |b| {
        b.iter(|| {
            let r = fly_report(&aircraft, &cfg, &opts).expect("flight");
            black_box(r.outcome.summary.frames)
        })
    });
    group.finish();
}

criterion_group!(benches, mission);
criterion_main!(benches);
