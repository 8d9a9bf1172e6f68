//! The flight log: what the autopilot records of each flight, at what rate, as ULog.

pub mod topics;

#[cfg(test)]
mod tests;
