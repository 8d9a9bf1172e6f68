//! The default mission in a wind from every direction: the take-off and the landing meet a
//! tailwind, a headwind and crosswinds from either side; a table for `docs/NAVIGATION.md`.

use super::mission_tables::{seed_span, spread_summary, touchdown_cells, verdict_cell};
use crate::environment::wind::along_runway;
use crate::flight::runner::FlightOutcome;
use crate::flight::summary::MissionSummary;
use anyhow::Context;
use std::fmt::Write as _;

/// Directions the wind blows towards in the wind-rose flights, degrees clockwise from north:
/// every 30 degrees, so that the take-off and the landing (both northbound) meet a tailwind, a
/// headwind and crosswinds from either side.
pub const ROSE_TOWARDS_DEG: [u32; 12] = [0, 30, 60, 90, 120, 150, 180, 210, 240, 270, 300, 330];
/// Wind speed of the wind-rose flights, m/s: the wind the default mission's windy case and the
/// missions from other runways fly in.
pub const ROSE_SPEED_MPS: f64 = 5.0;
/// Seeds of the wind-rose flights (turbulence and sensor noise).
pub const ROSE_SEEDS: [u64; 3] = [1, 2, 3];

/// The wind-rose wind blowing towards `towards_deg` (NED, m/s).
pub fn rose_wind(towards_deg: u32) -> [f64; 3] {
    let (s, c) = f64::from(towards_deg).to_radians().sin_cos();
    [ROSE_SPEED_MPS * c, ROSE_SPEED_MPS * s, 0.0]
}

/// The default mission in [`ROSE_SPEED_MPS`] of wind towards each of [`ROSE_TOWARDS_DEG`] with
/// light turbulence, on [`ROSE_SEEDS`]: a row per direction into `md`, each flight judged by
/// `judge` (the navigation command's `flies_well`); the flights for the results table. `fly`
/// flies the default mission in a wind (NED, m/s) with light turbulence on a seed.
pub(super) fn rose_section(
    mut fly: impl FnMut([f64; 3], u64) -> anyhow::Result<FlightOutcome>,
    judge: fn(&FlightOutcome, bool) -> Result<(), String>,
    md: &mut String,
) -> anyhow::Result<Vec<MissionSummary>> {
    let _ = writeln!(
        md,
        "## {ROSE_SPEED_MPS} m/s wind from every direction, light Dryden turbulence\n\n\
         The default mission (take-off and landing northbound) in a {ROSE_SPEED_MPS} m/s wind \
         blowing towards each of {} directions, seeds {}, each flight held to the targets above \
         and to what the missions from other runways are held to below (no strike, throttle, \
         landed state). Headwind and crosswind are those on the runway: a negative headwind is \
         a tailwind on the take-off roll, a crosswind from the left blows towards the east. \
         Each cell: verdict, touchdown along the runway from the point (m), sink (m/s).\n\n\
         | towards deg | from deg | headwind m/s | crosswind m/s | {} |\n\
         |---|---|---|---|{}",
        ROSE_TOWARDS_DEG.len(),
        seed_span(&ROSE_SEEDS),
        ROSE_SEEDS
            .iter()
            .map(|s| format!("seed {s}"))
            .collect::<Vec<_>>()
            .join(" | "),
        "---|".repeat(ROSE_SEEDS.len()),
    );
    let mut flights = Vec::with_capacity(ROSE_TOWARDS_DEG.len() * ROSE_SEEDS.len());
    let mut well = 0;
    for towards in ROSE_TOWARDS_DEG {
        let wind = rose_wind(towards);
        let mut cells = Vec::with_capacity(ROSE_SEEDS.len());
        for &seed in &ROSE_SEEDS {
            let o = fly(wind, seed)?;
            let verdict = judge(&o, false);
            well += usize::from(verdict.is_ok());
            let m = o.summary.mission.context("no mission flown")?;
            let (_, sink) = touchdown_cells(&m);
            let along = m
                .touchdown
                .map_or("none".to_string(), |t| format!("{:+.1}", t.along_m));
            cells.push(format!("{}, {along}, {sink}", verdict_cell(&verdict)));
            flights.push(m);
        }
        // The default mission's runway heads north.
        let (along, from_left) = along_runway(wind, 0.0);
        let _ = writeln!(
            md,
            "| {towards} | {} | {:+.1} | {from_left:+.1} | {} |",
            (towards + 180) % 360,
            -along,
            cells.join(" | ")
        );
    }
    let _ = writeln!(
        md,
        "\nFlies well on **{well} of {}**. {}",
        flights.len(),
        spread_summary(&flights)
    );
    Ok(flights)
}
