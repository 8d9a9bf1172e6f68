//! Flights per second of a Monte Carlo campaign: a batch of dispersed flights of the default
//! mission (every dispersion of the built-in campaign file, winds to 8 m/s, light or moderate
//! turbulence), flown on a pool of every core as `sim-host campaign` flies them, records and
//! verdicts included. Criterion reports flights per second (elements); divide by the cores
//! for the per-core figure. The whole-campaign figure of `docs/PERFORMANCE.md` is the
//! campaign command's own `timing.json`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use sim_host::aircraft::Aircraft;
use sim_host::campaign::{Campaign, CampaignSpec, MissionChoice, Shard};
use std::hint::black_box;

/// Flights per iteration: two per core on this two-core machine, so both stay busy.
const BATCH: u64 = 4;

fn campaign(c: &mut Criterion) {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut seed = 0;
    let mut group = c.benchmark_group("campaign");
    group.sample_size(10);
    group.throughput(Throughput::Elements(BATCH));
    group.bench_function(
        format!("{BATCH}_dispersed_default_missions_on_{cores}_cores"),
        |b| {
            b.iter(|| {
                // A new seed each time: every iteration flies fresh draws, as a campaign does.
                seed += 1;
                let c = Campaign {
                    seed,
                    runs: BATCH,
                    spec: CampaignSpec::default(),
                    spec_file: None,
                    mission: MissionChoice::Default,
                    aircraft: Aircraft::ultrastick25e().expect("built-in aircraft"),
                    aircraft_file: None,
                };
                let records = c.run(Shard::WHOLE, cores, false).expect("campaign");
                black_box(records.len())
            })
        },
    );
    group.finish();
}

criterion_group!(benches, campaign);
criterion_main!(benches);
