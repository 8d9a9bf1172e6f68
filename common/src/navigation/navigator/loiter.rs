//! Loiter items: circling a point until the item's goal is met.
//!
//! Loiters orbit their point (the item's radius, or `NAV_LOIT_RAD` when it gives none; see
//! [`crate::navigation::item`]), widened to the narrowest circle `NAV_TURN_BNK_DEG` allows at
//! the airspeed ([`crate::navigation::path_manager::PathManager::circle_radius`]).
//! `LOITER_TURNS` counts the angle swept round the centre once on the circle; `LOITER_TIME`
//! the time on the circle; `LOITER_TO_ALT` waits for the altitude. `LOITER_UNLIM` is reported
//! reached on arrival and never ends.

use super::guide::{Flight, Orbit};
use super::io::{NavOutput, Phase};
use super::params::NavParams;
use crate::math::wrap_pi;
use crate::navigation::item::{Circle, LoiterEnd};
use core::f32::consts::TAU;
use nalgebra::Vector3;

/// What ends a loiter.
#[derive(Clone, Copy, Debug, PartialEq)]
enum LoiterGoal {
    Unlimited,
    Turns {
        goal: f32,
        swept: f32,
        last: Option<f32>,
    },
    Time {
        goal: f32,
        elapsed: f32,
    },
    Altitude,
}

/// A loiter item in progress.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Loiter {
    orbit: Orbit,
    goal: LoiterGoal,
    /// On the circle (the goal counts from then on).
    arrived: bool,
}

impl Loiter {
    /// The loiter item's `circle` round `center` (NED from home), ended `until`.
    pub fn item(circle: Circle, until: LoiterEnd, center: Vector3<f32>, p: &NavParams) -> Self {
        let goal = match until {
            LoiterEnd::Turns(turns) => LoiterGoal::Turns {
                goal: turns * TAU,
                swept: 0.0,
                last: None,
            },
            LoiterEnd::Time(goal) => LoiterGoal::Time { goal, elapsed: 0.0 },
            LoiterEnd::Altitude => LoiterGoal::Altitude,
            LoiterEnd::Unlimited => LoiterGoal::Unlimited,
        };
        Self {
            orbit: Orbit {
                center,
                radius: circle.radius_m.unwrap_or(p.loiter_radius),
                direction: circle.direction,
            },
            goal,
            arrived: false,
        }
    }

    /// The circle flown.
    pub fn orbit(&self) -> Orbit {
        self.orbit
    }

    /// One step round the circle: its commands into `out`, and `seq` (the item) reported
    /// reached on arriving at an unlimited loiter. True once the goal is met.
    pub fn step(&mut self, f: &Flight, seq: Option<u16>, out: &mut NavOutput) -> bool {
        let p = f.params;
        let pos = f.state.pos_ned;
        let orbit = self.orbit;
        let path = f.circle(&orbit, f.cruise);
        let g = f.emit(&path, Some(orbit.center), Phase::Loiter, out);
        let on_circle = g.cross_track.abs() <= p.accept_radius.max(0.1 * orbit.radius);
        let mut done = false;
        if on_circle || self.arrived {
            let first = !self.arrived;
            self.arrived = true;
            let phi = libm::atan2f(pos.y - orbit.center.y, pos.x - orbit.center.x);
            match &mut self.goal {
                LoiterGoal::Unlimited => {
                    if first {
                        out.reached = seq;
                    }
                }
                LoiterGoal::Turns { goal, swept, last } => {
                    if let Some(l) = *last {
                        *swept += orbit.direction.lambda() * wrap_pi(phi - l);
                    }
                    *last = Some(phi);
                    done = *swept >= *goal;
                }
                LoiterGoal::Time { goal, elapsed } => {
                    *elapsed += f.dt;
                    done = *elapsed >= *goal;
                }
                LoiterGoal::Altitude => {
                    done = (f.state.height() + orbit.center.z).abs() <= p.alt_accept;
                }
            }
        }
        done
    }
}
