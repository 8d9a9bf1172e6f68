//! A campaign: what defines it, the plan of each flight, its shards, and the flights flown
//! on every core.

use super::draws::{disperse_aircraft, draw_day, Sampler};
use super::mission::{mission_for, MissionChoice};
use super::record::{fly_record, FlightRecord, Plan};
use super::spec::CampaignSpec;
use super::verdict::Criterion;
use crate::aircraft::Aircraft;
use crate::environment::wind::along_runway;
use crate::flight::config::FlightConfig;
use crate::flight::missions::{autotune_then_mission, runway_mission};
use crate::flight::runner::FlightOutcome;
use crate::flight::strikes::propeller_hub_m;
use crate::plant::ModelParams;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};

/// Version of the files a campaign writes; `merge` refuses shards of another.
pub const FORMAT: u32 = 1;

/// Part `index` of `count` of a campaign: the flights `[index * runs / count, (index + 1) *
/// runs / count)`, contiguous so a shard's records are a slice of the whole.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// This shard, from 0.
    pub index: u64,
    /// Number of shards.
    pub count: u64,
}

impl Shard {
    /// The whole campaign.
    pub const WHOLE: Shard = Shard { index: 0, count: 1 };

    /// `I/N` as Slurm's array variables give it (`$SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT`).
    pub fn parse(s: &str) -> Result<Self, String> {
        let (i, n) = s
            .split_once('/')
            .ok_or_else(|| format!("shard `{s}`: expected I/N, e.g. 0/4"))?;
        let parse = |x: &str, what: &str| {
            x.trim()
                .parse::<u64>()
                .map_err(|e| format!("shard `{s}`: {what} `{x}`: {e}"))
        };
        let (index, count) = (parse(i, "index")?, parse(n, "count")?);
        if count == 0 || index >= count {
            return Err(format!(
                "shard `{s}`: the index must be below the count (0/{count} .. {}/{count})",
                count.saturating_sub(1)
            ));
        }
        Ok(Self { index, count })
    }

    /// The flight indices of this shard among `runs`.
    pub fn indices(self, runs: u64) -> std::ops::Range<u64> {
        let at = |k: u64| (u128::from(k) * u128::from(runs) / u128::from(self.count)) as u64;
        at(self.index)..at(self.index + 1)
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// Everything that defines a campaign's flights.
#[derive(Clone, Debug)]
pub struct Campaign {
    /// Campaign seed.
    pub seed: u64,
    /// Flights in the whole campaign.
    pub runs: u64,
    /// The dispersions.
    pub spec: CampaignSpec,
    /// The campaign file, as named on the command line.
    pub spec_file: Option<PathBuf>,
    /// The mission.
    pub mission: MissionChoice,
    /// The nominal aircraft.
    pub aircraft: Aircraft,
    /// The aircraft file, as named on the command line.
    pub aircraft_file: Option<PathBuf>,
}

/// What identifies a campaign's output (`campaign.json`): shards merge only when all of it
/// but the shard agrees.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CampaignMeta {
    /// File format version ([`FORMAT`]).
    pub format: u32,
    /// The simulator's version.
    pub sim_host_version: String,
    /// Campaign seed.
    pub seed: u64,
    /// Flights in the whole campaign.
    pub runs: u64,
    /// `default`, `generated` or the mission file.
    pub mission: String,
    /// FNV-1a hash of the mission file's items, when one is flown.
    pub mission_hash: Option<String>,
    /// The campaign file, if any.
    pub campaign_file: Option<String>,
    /// The dispersions, every key resolved.
    pub campaign: CampaignSpec,
    /// The aircraft file, if any.
    pub aircraft_file: Option<String>,
    /// FNV-1a hash of the nominal aircraft's parameters.
    pub aircraft_hash: String,
    /// The criteria and their thresholds.
    pub criteria: Vec<(String, String)>,
    /// This output's part of the campaign.
    pub shard: Shard,
}

impl CampaignMeta {
    /// The command that runs the campaign again (no output directory: it names none).
    pub fn command(&self) -> String {
        let mut cmd = String::from("sim-host");
        if let Some(a) = &self.aircraft_file {
            cmd += &format!(" --aircraft {a}");
        }
        cmd += &format!(
            " campaign --runs {} --seed {} --mission {}",
            self.runs, self.seed, self.mission
        );
        if let Some(c) = &self.campaign_file {
            cmd += &format!(" --campaign {c}");
        }
        cmd
    }
}

/// FNV-1a, 64 bits: a stable fingerprint for identity checks (not for security).
pub fn fnv1a(bytes: &[u8]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        h ^= u64::from(*b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    format!("{h:016x}")
}

impl Campaign {
    /// What identifies this campaign's output for `shard`.
    pub fn meta(&self, shard: Shard) -> CampaignMeta {
        let mission_hash = match &self.mission {
            MissionChoice::File { mission, fence, .. } => {
                Some(fnv1a(format!("{mission:?}{fence:?}").as_bytes()))
            }
            _ => None,
        };
        CampaignMeta {
            format: FORMAT,
            sim_host_version: env!("CARGO_PKG_VERSION").into(),
            seed: self.seed,
            runs: self.runs,
            mission: self.mission.name(),
            mission_hash,
            campaign_file: self.spec_file.as_ref().map(|p| p.display().to_string()),
            campaign: self.spec.clone(),
            aircraft_file: self.aircraft_file.as_ref().map(|p| p.display().to_string()),
            aircraft_hash: fnv1a(format!("{:?}", self.aircraft).as_bytes()),
            criteria: Criterion::ALL
                .iter()
                .map(|c| (c.name().to_string(), c.describe()))
                .collect(),
            shard,
        }
    }

    /// The command that flies flight `index` again and writes its log and plots.
    pub fn reproduce_command(&self, index: u64) -> String {
        let mut cmd = String::from("sim-host");
        if let Some(a) = &self.aircraft_file {
            cmd += &format!(" --aircraft {}", a.display());
        }
        cmd += &format!(
            " campaign --seed {} --mission {}",
            self.seed,
            self.mission.name()
        );
        if let Some(c) = &self.spec_file {
            cmd += &format!(" --campaign {}", c.display());
        }
        cmd + &format!(" --index {index} --out out/campaign-flight-{index}")
    }

    /// Flight `index`'s draws, applied: the dispersed aircraft, the day, the mission.
    pub fn plan(&self, index: u64) -> Plan {
        let mut s = Sampler::new(self.seed, index);
        let flight_seed = s.seed();
        let mut aircraft = disperse_aircraft(&mut s, &self.spec, &self.aircraft);
        let day = draw_day(&mut s, &self.spec);
        let home = ModelParams::new(&self.aircraft).home;
        let mission = mission_for(
            &mut s,
            &self.mission,
            &self.spec.mission,
            home,
            day.runway_heading_rad,
            self.spec.runway.into_wind,
        );
        // Drawn last, and only when asked for, so that every other draw stays as it was.
        let share = self.spec.rangefinder.fitted_share;
        if share > 0.0 {
            let fitted = s.unit_silent() < share;
            s.record("rangefinder.fitted", if fitted { 1.0 } else { 0.0 });
            aircraft.sensors.rangefinder = fitted.then(|| {
                self.aircraft
                    .sensors
                    .rangefinder
                    .clone()
                    .unwrap_or_default()
            });
        }
        let mut draws = s.drawn;
        let shift =
            ["mass.cg_x_m", "mass.cg_y_m", "mass.cg_z_m"].map(|k| draws.get(k).unwrap_or(0.0));
        if let Some(l) = mission.landing {
            // The wind as the landing meets it: what a pilot reads off the windsock.
            let (along, across) = along_runway(day.wind_ned, l.direction_rad);
            draws.0.push(("derived.headwind_mps".into(), -along));
            draws
                .0
                .push(("derived.crosswind_from_right_mps".into(), -across));
        }
        let mut config = FlightConfig {
            wind_ned: day.wind_ned,
            turbulence: day.turbulence,
            seed: flight_seed,
            runway_heading: Some(day.runway_heading_rad),
            ..runway_mission(mission.items)
        };
        // Nothing a user would not set: no gain tuning (runway_mission's airspeed-loop
        // tuning is dropped). The receiver's latency is set as an operator sets it, to the
        // datasheet's (the nominal aircraft's) value, whatever this receiver's really is.
        config.script.params = vec![(
            "EKF_GPS_DELAY".into(),
            self.aircraft.sensors.gps.latency_s as f32,
        )];
        if self.spec.oracle.flare_on_truth {
            // Not a user's setting: the experiment that measures the flare's ceiling.
            config.script.params.push(("SIM_USE_TRUTH".into(), 2.0));
        }
        config.script.fence = mission.fence;
        if self.spec.station.autotune {
            config = autotune_then_mission(config);
        }
        Plan {
            index,
            flight_seed,
            draws,
            aircraft,
            propeller_hub_m: propeller_hub_m(&self.aircraft, shift),
            config,
            landing: mission.landing,
        }
    }

    /// Flies flight `index` and returns its record and, when it ran, its log.
    pub fn fly(&self, index: u64) -> (FlightRecord, Option<FlightOutcome>) {
        fly_record(&self.plan(index), self.reproduce_command(index))
    }

    /// Flies the flights of `shard` on `jobs` threads (0: every core), showing a progress
    /// bar on a terminal when `progress`; the records come back in index order.
    pub fn run(
        &self,
        shard: Shard,
        jobs: usize,
        progress: bool,
    ) -> anyhow::Result<Vec<FlightRecord>> {
        let indices: Vec<u64> = shard.indices(self.runs).collect();
        let bar = if progress {
            let b = indicatif::ProgressBar::new(indices.len() as u64);
            if let Ok(style) = indicatif::ProgressStyle::with_template(
                "{bar:30} {pos}/{len} flights, {per_sec}, {msg} [{elapsed_precise}, {eta} left]",
            ) {
                b.set_style(style.progress_chars("=> "));
            }
            b
        } else {
            indicatif::ProgressBar::hidden()
        };
        let passed = AtomicU64::new(0);
        let pool = rayon::ThreadPoolBuilder::new().num_threads(jobs).build()?;
        let mut records: Vec<FlightRecord> = pool.install(|| {
            indices
                .par_iter()
                .map(|&i| {
                    let (r, _) = self.fly(i);
                    let k = passed.fetch_add(u64::from(r.verdict.pass), Ordering::Relaxed)
                        + u64::from(r.verdict.pass);
                    bar.inc(1);
                    bar.set_message(format!("{k} passed"));
                    r
                })
                .collect()
        });
        bar.finish_and_clear();
        records.sort_by_key(|r| r.index);
        Ok(records)
    }
}
