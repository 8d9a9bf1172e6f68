//! Return: home at the return altitude, a circle there, and a landing if asked for.
//!
//! The return flies the line from where it began to above home at `NAV_RTL_ALT`, then
//! circles home at `NAV_LOIT_RAD` (a mission's `NAV_RETURN_TO_LAUNCH` item counts as reached
//! on arriving there). A return that lands waits until the aircraft is settled on the circle
//! at the return altitude, flies through a fillet onto the final approach (along the runway
//! of the last take-off, or from where the aircraft is) at the gate where the glide slope
//! meets the return altitude, and lands on home.

use super::guide::{horizontal_dist, Flight, Orbit};
use super::io::{NavOutput, Phase};
use super::land::Landing;
use crate::guidance::Path;
use crate::navigation::path_manager::{PathManager, Waypoint};
use nalgebra::Vector3;

#[derive(Clone, Copy, Debug, PartialEq)]
enum ReturnPhase {
    /// Flying home from `origin`.
    Home { origin: Vector3<f32> },
    /// Circling home.
    Circle,
    /// From the circle (at `origin`) to the final approach's `gate`.
    ToFinal {
        origin: Vector3<f32>,
        gate: Vector3<f32>,
    },
    /// Landing on home.
    Land(Landing),
}

/// A return in progress.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Return {
    phase: ReturnPhase,
    /// Land at home after the circle.
    land: bool,
}

impl Return {
    /// A return from `origin` (NED from home), landing at home if `land`.
    pub fn new(origin: Vector3<f32>, land: bool) -> Self {
        Self {
            phase: ReturnPhase::Home { origin },
            land,
        }
    }

    /// Gives up the return's landing for a go-around, if it is landing.
    pub fn go_around(&mut self) -> bool {
        match &mut self.phase {
            ReturnPhase::Land(l) => l.go_around(),
            _ => false,
        }
    }

    /// In its landing's flare or roll-out: a failsafe lets the landing finish.
    pub fn touching_down(&self) -> bool {
        matches!(self.phase, ReturnPhase::Land(l) if l.touching_down())
    }

    /// One step of the return: its commands into `out`. `runway` is the course of the last
    /// take-off (the landing's final approach), `seq` the mission item reported reached on
    /// arriving home.
    pub fn step(
        &mut self,
        f: &Flight,
        paths: &mut PathManager,
        runway: Option<f32>,
        seq: Option<u16>,
        out: &mut NavOutput,
    ) {
        let p = f.params;
        let state = f.state;
        let pos = state.pos_ned;
        let home_ned = Vector3::new(0.0, 0.0, -p.rtl_alt);
        let circle = Orbit::loiter(home_ned, p);
        self.phase = match self.phase {
            ReturnPhase::Home { origin } => {
                let path = Path::line_between(&origin, &home_ned, f.cruise)
                    .unwrap_or(f.circle(&circle, f.cruise));
                f.emit(&path, Some(home_ned), Phase::Return, out);
                if horizontal_dist(&pos, &home_ned) <= p.loiter_radius {
                    // A mission's return item counts as reached at home.
                    out.reached = seq;
                    ReturnPhase::Circle
                } else {
                    self.phase
                }
            }
            ReturnPhase::Circle => {
                let g = f.emit(
                    &f.circle(&circle, f.cruise),
                    Some(home_ned),
                    Phase::ReturnLoiter,
                    out,
                );
                let settled = g.cross_track.abs() <= p.accept_radius
                    && (state.height() - p.rtl_alt).abs() <= p.alt_accept;
                if self.land && settled {
                    // Final approach along the runway of the last take-off (or from where
                    // the aircraft is), starting where the glide slope meets the return
                    // altitude.
                    let course = runway.unwrap_or_else(|| libm::atan2f(-pos.y, -pos.x));
                    let run = p.rtl_alt / crate::math::elementary::tan(p.glide_slope);
                    let (s, c) = crate::math::elementary::sin_cos(course);
                    let gate = Vector3::new(-c * run, -s * run, -p.rtl_alt);
                    paths.reset();
                    ReturnPhase::ToFinal { origin: pos, gate }
                } else {
                    self.phase
                }
            }
            ReturnPhase::ToFinal { origin, gate } => {
                let airspeed = f.cruise;
                let mk = |id, ned| Waypoint {
                    id,
                    ned,
                    airspeed,
                    accept_radius: p.accept_radius,
                };
                let window = [mk(0, origin), mk(1, gate), mk(2, Vector3::zeros())];
                let step = paths.step(&pos, &window, f.state.wind_speed);
                let reached = step.as_ref().and_then(|s| s.reached).is_some();
                let path = step.map(|s| s.path).unwrap_or(f.circle(&circle, airspeed));
                f.emit(&path, Some(gate), Phase::Return, out);
                if reached {
                    ReturnPhase::Land(Landing::new(gate, Vector3::zeros()))
                } else {
                    self.phase
                }
            }
            ReturnPhase::Land(mut l) => {
                l.step(f, out);
                ReturnPhase::Land(l)
            }
        };
    }
}
