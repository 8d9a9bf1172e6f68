//! Monte Carlo campaigns: thousands of flights of one mission, each with its own draw of
//! everything that is uncertain, judged by named criteria and summarised in a report.
//!
//! - [`spec`]: the campaign file (TOML): what is dispersed and by how much;
//! - [`draws`]: one flight's draws, from the campaign seed and the flight's index alone,
//!   applied to a copy of the aircraft (aerodynamics, mass, CG, inertia, thrust, servos,
//!   sensors) and to the day (wind, turbulence, runway);
//! - [`mission`]: the default mission, a mission file or one generated per flight, turned
//!   with the runway;
//! - [`record`]: one flight flown in-process, its figures and facts;
//! - [`verdict`]: the verdict by the criteria ([`crate::flight::criteria`]), in one place;
//! - [`run`]: the campaign, its shards, its flights flown on every core;
//! - [`output`]: its directory, the merge of shards, the document;
//! - [`report`], [`plots`], [`stats`]: the report made from the records;
//! - [`groups`]: pass rates by turbulence and rangefinder, and beside another campaign of the
//!   same flights.
//!
//! Flights run in parallel on a [rayon] pool: each flight is an independent, CPU-bound,
//! allocation-light loop of about half a second, so a work-stealing pool over the flight
//! indices keeps every core busy without a hand-made scheduler, and `--jobs` bounds it
//! where a batch system gives a task fewer cores than the node has. Progress is an
//! [indicatif] bar on standard error (the crate the simulator already uses for single
//! flights), with the rate and the pass count; indicatif hides it by itself when standard
//! error is not a terminal, so batch logs stay clean.
//!
//! Beyond one machine, a campaign is split with `--shard I/N` (contiguous ranges of flight
//! indices, so each shard's flights are exactly those of the unsharded run) and joined with
//! `sim-host campaign merge`, which writes the unsharded run's files byte for byte. Slurm
//! job arrays run the shards on a cluster (`sim-host/slurm/`).

pub mod draws;
pub mod groups;
pub mod mission;
pub mod output;
pub mod plots;
pub mod record;
pub mod report;
pub mod run;
pub mod spec;
pub mod stats;
pub mod verdict;

pub use mission::MissionChoice;
pub use record::FlightRecord;
pub use report::Report;
pub use run::{Campaign, CampaignMeta, Shard};
pub use spec::{CampaignSpec, SpecError};
pub use verdict::Criterion;
