//! Speed of the whole firmware-in-the-loop frame: plant (RK4, 1 ms, ten steps a frame),
//! servos, wind, sensors, MAVLink encode and decode both ways, the firmware's tick (estimator,
//! control at 50 Hz, ground link) and the scripted ground station, in-process and over TCP
//! loopback to the firmware in a thread.
//!
//! One iteration flies 60 s of the thesis's script (6000 frames at 100 Hz), including the
//! level trim and, for TCP, the firmware thread's start; the throughput is in simulated
//! milliseconds, so "Kelem/s" reads as simulated seconds per wall second (real-time factor).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use sim_host::aircraft::Aircraft;
use sim_host::commands::fly::{fly_report, FlyOptions, LinkKind};
use sim_host::flight::FlightConfig;
use std::hint::black_box;

const SIM_S: f64 = 60.0;

fn flight(c: &mut Criterion) {
    let aircraft = Aircraft::ultrastick25e().expect("built-in aircraft");
    let cfg = FlightConfig {
        duration_s: SIM_S,
        ..FlightConfig::default()
    };
    let mut group = c.benchmark_group("firmware_in_the_loop");
    group.sample_size(10);
    group.throughput(Throughput::Elements((SIM_S * 1000.0) as u64));
    for link in [LinkKind::Inproc, LinkKind::Tcp] {
        let opts = FlyOptions {
            link,
            bind: "127.0.0.1:0".into(),
            out: None,
            plots: false,
            ..FlyOptions::default()
        };
        group.bench_function(format!("{}_60s_sim_ms", link.name()), |b| {
            b.iter(|| {
                let r = fly_report(&aircraft, &cfg, &opts).expect("flight");
                black_box(r.outcome.summary.frames)
            })
        });
    }
    group.finish();
}

criterion_group!(benches, flight);
criterion_main!(benches);
