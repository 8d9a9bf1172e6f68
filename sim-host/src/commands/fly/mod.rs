//! `sim-host fly`: the firmware flies the plant over the simulator link, commanded by a
//! scripted ground station; writes the log, a `.tlog`, plots and a JSON summary.
//!
//! One room, a file per job: the transport and the flight's options ([`options`]), the flight
//! over that transport ([`flight`]), the tables printed after it ([`tables`]), the document of
//! `--report` ([`results`]) and the command as the command line runs it ([`command`]).

pub mod autotune;
pub mod command;
pub mod flight;
pub mod options;
pub mod results;
pub mod tables;

pub use super::flying::{write_flight_files, FlyReport};
pub use flight::fly_report;
pub(crate) use options::with_params;
pub use options::{FlyOptions, LinkKind};
pub use results::results_markdown;
pub use tables::{battery_table, mission_table, summary_tables};
