//! Firmware in the loop: the plant flies the autopilot's commands over the simulator link,
//! while a scripted ground station commands the autopilot as a pilot with QGroundControl would.
//!
//! One frame (the IMU period of the aircraft file, 10 ms for the Ultra Stick 25e):
//!
//! ```text
//! plant truth -> sensors -> HIL_GPS (when a fix is delivered), HIL_STATE_QUATERNION (truth),
//!                           HIL_SENSOR -> lock-step exchange -> HIL_ACTUATOR_CONTROLS
//!   -> servos and plant (RK4, several steps of `dt_s` per frame)
//! ```
//!
//! The surfaces the autopilot answers are held over the frame; the servos move towards them
//! inside each RK4 step, with the rigid body ([`crate::plant::Plant::step_servos`]).
//!
//! The HIL_SENSOR frame goes last in each batch, because the autopilot answers it: when the
//! answer arrives, the autopilot has taken in the whole batch, whatever the transport, so the
//! state it is in (logged beside the truth) is the same on every link.
//!
//! Launch: the flight starts trimmed, level, 100 m above home at 17 m/s, as after a hand
//! launch. Until the autopilot reports itself armed (HIL_ACTUATOR_CONTROLS `mode` bit 128) the
//! simulator holds the trim controls itself, as a safety pilot would while the autopilot's
//! estimator converges and the ground station arms it; from arming on, the autopilot flies.
//!
//! The ground station ([`script`]) speaks MAVLink 2 as system 255, component 190 (QGC's
//! identity) to the autopilot's ground link. It waits for each COMMAND_ACK before the next
//! sensor frame, so a command takes effect at the same frame on every transport.

pub mod compare;
pub mod config;
pub mod criteria;
pub mod landed;
pub mod measures;
pub mod mission_summary;
pub mod missions;
pub mod onboard;
pub mod plots;
pub mod record;
pub mod runner;
pub mod script;
pub mod strikes;
pub mod summary;

pub use config::{
    parse_fault, parse_turbulence, turbulence_name, Fault, FaultWindow, FlightConfig, RcSticks,
};
pub use onboard::{spawn_firmware, InprocOnboard, Onboard, OutsideOnboard, ThreadOnboard};
pub use record::Sample;
pub use runner::{fly, FlightError, FlightOutcome};
pub use script::{Action, Script, ScriptStep};
pub use summary::FlightSummary;
