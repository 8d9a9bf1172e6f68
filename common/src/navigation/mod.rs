//! Navigation: what path to fly now.
//!
//! - [`path_manager`]: waypoint switching with fillets (Beard & McLain 11.2).

pub mod path_manager;

#[cfg(test)]
pub(crate) mod sim;
