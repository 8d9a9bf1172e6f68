//! The air the airplane flies in: steady wind plus Dryden turbulence.

pub mod wind;
