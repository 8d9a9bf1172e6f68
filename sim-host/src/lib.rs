//! The Ultra Stick 25e simulator: plant, analysis and the simulator side of the MAVLink link.

pub mod analysis;
pub mod environment;
pub mod link;
pub mod sensors;
