//! The choices a loop designer makes, with the thesis's as defaults: the on-board design's own
//! (`common::tuning::design::DesignInputs`, `f32`), which the host's design runs with.

pub use common::tuning::design::DesignInputs;
