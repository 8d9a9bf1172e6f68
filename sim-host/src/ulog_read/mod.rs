//! A reader of ULog, PX4's flight-log format, as PX4's specification ("ULog File Format",
//! docs.px4.io) defines it: the header, the flag bits (appended data), formats with nested
//! types and arrays, information (`I`, `M`), parameters and their defaults (`P`, `Q`),
//! subscriptions (`A`, `R`), data (`D`), texts (`L`, `C`), sync markers (`S`) and dropouts
//! (`O`).
//!
//! It reads what any ULog writer wrote, this project's (`common::ulog`) as PX4's, and it
//! never panics on what a file holds:
//!
//! - a file that cannot be a log (empty, a wrong magic, a header cut short, flags that forbid
//!   reading on) is an error naming the byte offset and what was wrong ([`ParseError`];
//!   [`read_file`] names the file too);
//! - a file cut in the middle of a message, as a power cut leaves it, reads up to its last
//!   whole message, with a [`Warning`] saying where and how it ends;
//! - a message that makes no sense (data of no subscription, a format that does not parse) is
//!   skipped with a warning; bytes that are no message at all, and a sample its topic's
//!   format cannot hold (the size in its header is what is corrupt), are skipped up to the
//!   next sync marker, which is what the marker is for.
//!
//! Why not a crate: the two maintained Rust readers do not say where a file goes wrong.
//! `px4-ulog` (0.6) reports an error as a kind and a description, and reads a cut file's
//! prefix only since that release; `yule_log` (0.4) stops at a cut with "Unexpected End of
//! File", without a position either.
//! The format is the few hundred lines here, beside the project's own encoder
//! (`common::ulog`), and the tests hold this reader to the specification's bytes and to
//! pyulog's reading of the autopilot's logs.

// What the file holds decides every length and offset here: no indexing, no unchecked
// arithmetic, no unwrap can turn a bad file into a panic.
#![cfg_attr(
    not(test),
    deny(
        clippy::indexing_slicing,
        clippy::arithmetic_side_effects,
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic
    )
)]

pub mod format;
mod parser;
mod types;
pub use format::{FieldType, FlatField, Format, FormatField, Layout};
pub use parser::parse;
pub use types::*;

use std::path::Path;

/// Reads the log in `path`.
pub fn read_file(path: &Path) -> Result<Ulog, FileError> {
    let fail = |cause| FileError {
        path: path.to_path_buf(),
        cause,
    };
    let bytes = std::fs::read(path).map_err(|e| fail(FileErrorCause::Io(e)))?;
    parse(&bytes).map_err(|e| fail(FileErrorCause::Parse(e)))
}

/// Bytes as hex pairs.
#[cfg(test)]
pub(crate) mod tests;
