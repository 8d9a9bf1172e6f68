//! The thesis's analysis: trim, linearisation, transfer functions, the doublet check, and the
//! linear-systems tools and response figures the loop design and the scenarios use.

pub mod design;
pub mod doublet;
pub mod linearize;
pub mod lti;
pub mod metrics;
pub mod reduced;
pub mod references;
pub mod sampled;
pub mod transfer;
pub mod trim;
