//! The thesis's analysis: trim, linearisation, transfer functions, the doublet check.

pub mod trim;
