//! The thesis's analysis: trim, linearisation, transfer functions, the doublet check.

pub mod linearize;
pub mod transfer;
pub mod trim;
