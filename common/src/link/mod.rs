//! MAVLink plumbing shared by every transport: byte framing with counted rejections, and the
//! simulator interface's message conversions.

pub mod framing;
pub mod simlink;
