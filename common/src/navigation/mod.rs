//! Navigation: what path to fly now.
//!
//! - [`navigator`]: the [`Navigator`]: mission items to commands for the autopilot, plus the
//!   take-off, loiter, landing, return and loiter-here behaviours.
//! - [`path_manager`]: waypoint switching with fillets (Beard & McLain 11.2).
//! - [`plan`]: the stored mission, geofence and rally lists, and their capacities.
//! - [`items`]: MAVLink mission items' commands, frames, positions and altitudes.
//! - [`item`]: each item decoded once into a [`NavItem`], as the navigator flies it.
//! - [`validate`]: mission checks at upload, with the `MAV_MISSION_RESULT` of the first fault.
//! - [`fence`]: the geofence (inclusion/exclusion polygons and circles, maximum height).

pub mod fence;
pub mod item;
pub mod items;
pub mod navigator;
pub mod path_manager;
pub mod plan;
pub mod validate;

#[cfg(test)]
pub(crate) mod sim;
#[cfg(test)]
mod tests;

pub use fence::{breached, validate_fence, Breach, FenceParams};
pub use item::{NavCommand, NavItem, Route};
pub use navigator::io::{HomeRequest, NavOutput, NavState, NavWarning, Phase};
pub use navigator::params::NavParams;
pub use navigator::Navigator;
pub use path_manager::{PathManager, PathParams, Waypoint};
pub use plan::{MissionItem, MissionStore, PlanKind};
pub use validate::{validate_mission, MissionLimits, Rejection, Validation, ValidationWarning};
