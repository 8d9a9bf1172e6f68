//! Where the airframe can touch the ground: the three wheels (a taildragger's or a tricycle's)
//! and the belly points of the aircraft file's `[ground]` table, each with its spring, damper and friction.
//! The forces they take from the runway are [`super::ground`]'s.

use crate::aircraft::{GearLayout, Ground, MAX_BELLY_POINTS};
use nalgebra::Vector3;

/// Most contact points a model may have (three wheels and the belly points).
pub const MAX_CONTACTS: usize = 3 + MAX_BELLY_POINTS;

/// How a contact point resists motion along the ground.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ContactKind {
    /// A wheel: rolls along its heading, resists sliding across it.
    Wheel {
        /// Rolling friction coefficient.
        mu_roll: f64,
        /// Side (cornering) friction coefficient.
        mu_side: f64,
        /// Wheel heading per rad of rudder (0 for a fixed wheel); positive turns the wheel's
        /// front to the right, so a positive rudder turns the nose left as it does in the air.
        steer_per_rudder: f64,
    },
    /// A skid (fuselage, wing tip): slides with one coefficient in every direction.
    Skid {
        /// Sliding friction coefficient.
        mu: f64,
    },
}

/// One point of the airframe that can touch the ground.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactPoint {
    /// Position from the CG, body axes, m.
    pub pos_body: Vector3<f64>,
    /// Spring stiffness, N/m.
    pub stiffness_npm: f64,
    /// Damping, N s/m.
    pub damping_nspm: f64,
    /// Wheel or skid.
    pub kind: ContactKind,
}

/// The contact model's parameters, derived from the aircraft file's `[ground]` table.
#[derive(Clone, Debug, PartialEq)]
pub struct GroundParams {
    /// Contact points: left main wheel, right main wheel, tail or nose wheel, then the belly
    /// points.
    pub points: Vec<ContactPoint>,
    /// Whether the third wheel is a tail wheel or a nose wheel.
    pub layout: GearLayout,
    /// Down position of the ground plane in the NED frame, m (0: home is on the ground).
    pub ground_down_m: f64,
    /// Slip speed of the friction law, m/s.
    pub slip_speed_mps: f64,
    /// Largest distance of a contact point from the CG, m (the early-out bound).
    pub reach_m: f64,
}

/// Index of the left main wheel in [`GroundParams::points`].
pub const MAIN_LEFT: usize = 0;
/// Index of the right main wheel.
pub const MAIN_RIGHT: usize = 1;
/// Index of the third wheel: the tail wheel of a taildragger, the nose wheel of a tricycle.
pub const TAIL: usize = 2;
/// Index of a tricycle's nose wheel (the same slot as a taildragger's tail wheel).
pub const NOSE: usize = TAIL;

impl GroundParams {
    /// The contact points of a validated `[ground]` table (one without a complete third wheel
    /// stands on its mains and belly points alone).
    pub fn new(g: &Ground) -> Self {
        let wheel = |pos: [f64; 3], k: f64, c: f64, steer: f64| ContactPoint {
            pos_body: Vector3::from(pos),
            stiffness_npm: k,
            damping_nspm: c,
            kind: ContactKind::Wheel {
                mu_roll: g.mu_roll,
                mu_side: g.mu_side,
                steer_per_rudder: steer,
            },
        };
        let mut points = vec![
            wheel(
                g.main_wheel_left_m,
                g.main_stiffness_Npm,
                g.main_damping_Nspm,
                0.0,
            ),
            wheel(
                g.main_wheel_right_m,
                g.main_stiffness_Npm,
                g.main_damping_Nspm,
                0.0,
            ),
        ];
        let third = g.third_wheel();
        if let Some(w) = third {
            points.push(wheel(
                w.pos_m,
                w.stiffness_Npm,
                w.damping_Nspm,
                w.steer_per_rudder,
            ));
        }
        points.extend(g.belly_points_m.iter().map(|&pos| ContactPoint {
            pos_body: Vector3::from(pos),
            stiffness_npm: g.belly_stiffness_Npm,
            damping_nspm: g.belly_damping_Nspm,
            kind: ContactKind::Skid { mu: g.mu_belly },
        }));
        points.truncate(MAX_CONTACTS);
        let reach_m = points.iter().map(|p| p.pos_body.norm()).fold(0.0, f64::max);
        Self {
            points,
            layout: third.map_or(GearLayout::Taildragger, |w| w.layout),
            ground_down_m: 0.0,
            slip_speed_mps: g.slip_speed_mps,
            reach_m,
        }
    }

    /// True when the CG is so high that no contact point can reach the ground.
    #[inline]
    pub fn clear_of_ground(&self, pos_down_m: f64) -> bool {
        pos_down_m + self.reach_m < self.ground_down_m
    }
}
