//! Speed of the plant alone: RK4 steps per second on one core, from level trim (in the air) and
//! on the runway (ground contact evaluated at every step).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use sim_host::aircraft::Aircraft;
use sim_host::analysis::trim::{trim, TrimTarget};
use sim_host::plant::{Controls, Environment, Plant};
use std::hint::black_box;

fn plant_steps(c: &mut Criterion) {
    let aircraft = Aircraft::ultrastick25e().expect("built-in aircraft");
    let t = trim(&aircraft, &TrimTarget::level());
    let mut plant = Plant::new(&aircraft, t.state);
    let env = Environment::default();
    let controls = t.controls;
    const STEPS: u64 = 1000;
    let mut group = c.benchmark_group("plant");
    group.throughput(Throughput::Elements(STEPS));
    group.bench_function("rk4_step_dt_0.005", |b| {
        b.iter(|| {
            plant.set_state(t.state);
            for _ in 0..STEPS {
                plant.step(black_box(&controls), black_box(&env), 0.005);
            }
            black_box(plant.state_vector()[0])
        })
    });
    // Rolling on the runway at full throttle: every evaluation works through the contact points.
    let rest = Plant::at_rest_on_ground(&aircraft, 0.0, 0.0, 0.0).state();
    let mut ground = Plant::at_rest_on_ground(&aircraft, 0.0, 0.0, 0.0);
    let roll = Controls::new(0.0, 0.0, 0.0, 1.0);
    group.bench_function("rk4_step_on_ground_dt_0.005", |b| {
        b.iter(|| {
            ground.set_state(rest);
            for _ in 0..STEPS {
                ground.step(black_box(&roll), black_box(&env), 0.005);
            }
            black_box(ground.state_vector()[0])
        })
    });
    group.finish();
}

criterion_group!(benches, plant_steps);
criterion_main!(benches);
