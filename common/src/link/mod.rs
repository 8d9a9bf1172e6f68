//! MAVLink plumbing shared by every transport: byte framing with counted rejections, and the
//! simulator interface's message conversions.

// Counts, lengths and offsets here come from outside: every operation on them is checked.
#![cfg_attr(not(test), deny(clippy::arithmetic_side_effects))]

pub mod dialect;
pub mod framing;
pub mod mav_cmd;
pub mod signing;
pub mod simlink;
