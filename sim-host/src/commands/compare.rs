//! `sim-host fly --compare-host`: the same flight flown again by the host build in this
//! process, and the two autopilots' answers compared frame by frame, with the pace of both.

use super::fly::{fly_report, with_params, FlyOptions, LinkKind};
use super::flying::{uart_truth_frames, SIM_TLOG};
use crate::aircraft::Aircraft;
use crate::flight::compare::{answers, compare_answers, AnswerComparison};
use crate::flight::config::FlightConfig;
use crate::flight::runner::FlightOutcome;
use crate::report::table::Table;
use anyhow::Context;
use std::path::Path;

/// A flight flown again by the host build in this process, and the two autopilots' answers
/// compared.
#[derive(Clone, Debug)]
pub struct HostComparison {
    /// The host build's flight.
    pub host: FlightOutcome,
    /// The answers of the flight compared (first) with the host build's (second).
    pub answers: AnswerComparison,
}

impl HostComparison {
    /// The comparison as a table, with the pace of both flights.
    pub fn table(&self, flight: &FlightOutcome, link: LinkKind) -> Table {
        let a = &self.answers;
        let mut t = Table::new(
            format!(
                "Answers of the {} flight against the host build's",
                link.name()
            ),
            &["quantity", "value"],
        );
        let pace = |o: &FlightOutcome| {
            format!(
                "{:.1} s simulated in {:.2} s: {:.2}x real time",
                o.summary.sim_s, o.summary.wall_s, o.summary.real_time_factor
            )
        };
        t.row([format!("pace, {}", link.name()), pace(flight)]);
        t.row(["pace, host build in-process".to_string(), pace(&self.host)]);
        t.row([
            "HIL_ACTUATOR_CONTROLS compared".to_string(),
            format!("{} ({} and {} answers)", a.compared, a.frames_a, a.frames_b),
        ]);
        t.row([
            "identical bit for bit".to_string(),
            match a.first_difference {
                None => format!("all {}", a.compared),
                Some(d) => format!(
                    "the first {}; frame {} (t = {:.2} s) differs in {}: {:e} vs {:e}",
                    a.identical_frames,
                    d.frame,
                    d.time_s,
                    d.control.map_or("time, mode or flags", |c| [
                        "roll", "pitch", "yaw", "throttle"
                    ][c]),
                    d.a,
                    d.b
                ),
            },
        ]);
        t.row([
            "largest difference (roll, pitch, yaw, throttle)".to_string(),
            a.max_abs_diff
                .iter()
                .map(|d| format!("{d:.3e}"))
                .collect::<Vec<_>>()
                .join(", "),
        ]);
        t
    }
}

/// Flies `cfg` again with the host build in this process (same seed, same script) into
/// `<out>/host`, and compares its answers with those of the flight `fly_report(aircraft,
/// cfg, opts)` flew into `<out>`, read from both `.tlog`s.
pub fn compare_with_host(
    aircraft: &Aircraft,
    cfg: &FlightConfig,
    opts: &FlyOptions,
) -> anyhow::Result<HostComparison> {
    let dir = opts
        .out
        .as_ref()
        .context("comparing answers needs an output directory for the .tlog files")?;
    let host_opts = FlyOptions {
        link: LinkKind::Inproc,
        out: Some(dir.join("host")),
        plots: false,
        ..opts.clone()
    };
    // The host flight is not for watching: no ground-station port, no pacing; the frames
    // are those the other flight had.
    let host_cfg = FlightConfig {
        ground_link: None,
        realtime: false,
        truth_frames: match opts.link {
            LinkKind::Qemu => uart_truth_frames(&with_params(cfg, opts)),
            _ => cfg.truth_frames,
        },
        ..cfg.clone()
    };
    let host = fly_report(aircraft, &host_cfg, &host_opts)?;
    let read =
        |p: &Path| std::fs::read(p).with_context(|| format!("cannot read `{}`", p.display()));
    let a = answers(&read(&dir.join(SIM_TLOG))?);
    let b = answers(&read(&dir.join("host").join(SIM_TLOG))?);
    Ok(HostComparison {
        host: host.outcome,
        answers: compare_answers(&a, &b),
    })
}
