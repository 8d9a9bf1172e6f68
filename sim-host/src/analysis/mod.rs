//! The thesis's analysis: linear-systems tools and response figures.

pub mod lti;
pub mod metrics;
