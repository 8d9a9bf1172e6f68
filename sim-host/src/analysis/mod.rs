//! The thesis's analysis: trim, linearisation, transfer functions, the doublet check.

pub mod doublet;
pub mod linearize;
pub mod references;
pub mod transfer;
pub mod trim;
