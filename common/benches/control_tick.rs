//! Cost of one full control tick (lateral + longitudinal autopilot) on the host.
//!
//! All loops engaged: course hold over roll over the roll-rate damper, sideslip hold with the
//! yaw damper, altitude hold (regime machine, both feedback filters, altitude-by-pitch over
//! pitch over the pitch-rate damper, airspeed by throttle). The measurements change every tick
//! so nothing can be hoisted out of the loop.

use common::control::gains::DESIGNED;
use common::control::{Autopilot, Commands, LonMode, Measurements, RollMode, YawMode};
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

fn control_tick(c: &mut Criterion) {
    let mut ap = Autopilot::new(&DESIGNED).expect("designed set is valid");
    let cmd = Commands {
        roll: RollMode::Course(0.5),
        yaw: YawMode::Sideslip(0.0),
        lon: LonMode::Altitude {
            altitude: 105.0,
            airspeed: 17.0,
        },
    };
    let mut k = 0u32;
    c.bench_function("control_tick", |b| {
        b.iter(|| {
            k = k.wrapping_add(1);
            let wobble = (k % 64) as f32 * 1e-3;
            let m = Measurements {
                roll: 0.05 + wobble,
                pitch: 0.06 - wobble,
                course: 0.4 + wobble,
                roll_rate: 0.01,
                pitch_rate: -0.02 + wobble,
                yaw_rate: 0.03,
                altitude: 100.0 + wobble,
                airspeed: 16.8 + wobble,
                sideslip: 0.01,
                ground_speed: 16.8 + wobble,
            };
            black_box(ap.step(black_box(&m), black_box(&cmd), black_box(0.02)))
        })
    });
}

criterion_group!(benches, control_tick);
criterion_main!(benches);
