//! Aerodynamic forces and moments of the Minnesota linear-derivative model.
//!
//! Lift, drag and side force are wind-axis coefficients rotated into body axes by
//! `C_bw(alpha, beta)`; the rolling, pitching and yawing coefficients are used directly as
//! body-axis moments (as the Simulink model wires them), plus the moment of the aerodynamic
//! force about the CG through the 4.5 mm arm.
//!
//! The Minnesota model is linear in the angles and has no stall: it holds near the trim it
//! was identified about, and the autopilot flies within 20 degrees of angle of attack and
//! sideslip. On the ground the air can come from anywhere: a tailwind puts the angle of
//! attack near 180 deg, where `CL_alpha * alpha` lifts 14 times the wing's dynamic pressure
//! (more than the aircraft weighs in 5 m/s) and flips sign as the flow wanders across the
//! tail. Beyond [`LINEAR_LIMIT`] the coefficients are therefore blended, by a smooth step
//! complete at [`PLATE_FROM`], into a flat plate's (Beard and McLain, *Small Unmanned
//! Aircraft*, eq. 4.10: lift `2 sign(a) sin^2 a cos a`, drag `2 sin^2 a`): the surfaces'
//! effect turns with the flow (`cos alpha`, reversed from behind), the static pitching
//! moment goes as `sin alpha`, and the lift, the static pitching moment and the surfaces
//! fade as `cos^2 beta` with a flow from the side, in which a wing has no chordwise flow.
//! Beyond 20 degrees of sideslip the side force and yawing moment go as `sin beta` (fin and
//! fuselage as plates) and the rolling moment as `sin beta cos beta` (the dihedral effect is
//! the side velocity's times the forward's): linear in the angle to 90 deg, a parked
//! aircraft's crosswind rolled it with 4.5 times that moment, more than full aileron holds.
//! The side force is taken across the wind, as the Minnesota model takes it, within 15
//! degrees of sideslip, and along the body's y axis from 20 (a smooth step between): across
//! the wind, with a drag that does not grow with the sideslip, its part along the nose
//! (`-sin beta` of it) outweighed the drag from 17 degrees, and a rolling aircraft in a
//! 7.5 m/s crosswind, at 25 to 35 degrees of sideslip, sailed along the runway at 10 m/s with
//! its throttle closed. Inside 20 degrees of angle of attack and 15 of sideslip the model is
//! the Minnesota one to the last bit.
//!
//! An aircraft file may ask for Beard and McLain's drag polar instead
//! ([`crate::aircraft::DragPolar`]): the induced drag of the angle of attack's lift alone and a
//! signed elevator drag, as their Aerosonde model has it. Their lift blends into the flat plate
//! by a sigmoid about `alpha0` (0.47 rad for the Aerosonde) where this model blends from 20 to
//! 40 degrees; inside 20 degrees their sigmoid's weight is below 0.2 %, and at trim below 1e-9.

use super::inputs::Controls;
use super::params::ModelParams;
use crate::aircraft::DragPolar;
use common::math::{wind_to_body, AirData};
use nalgebra::Vector3;

/// Aerodynamic coefficients at one flight condition (for reports and tests).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AeroCoefficients {
    /// Lift (wind axes).
    pub cl: f64,
    /// Drag (wind axes).
    pub cd: f64,
    /// Side force (wind axes).
    pub cy: f64,
    /// Rolling moment (body axes).
    pub c_roll: f64,
    /// Pitching moment (body axes).
    pub c_pitch: f64,
    /// Yawing moment (body axes).
    pub c_yaw: f64,
}

/// Angle of attack or sideslip up to which the Minnesota model's linear coefficients hold
/// unchanged, rad (20 deg).
pub const LINEAR_LIMIT: f64 = 20.0 * std::f64::consts::PI / 180.0;
/// Angle from which the coefficients are wholly the flat plate's, rad (40 deg).
pub const PLATE_FROM: f64 = 40.0 * std::f64::consts::PI / 180.0;

/// How far `angle` (rad) is past the linear model's envelope: 0 within [`LINEAR_LIMIT`], 1
/// from [`PLATE_FROM`], a smooth step (continuous slope) between.
pub fn beyond_linear(angle: f64) -> f64 {
    smooth_step(angle.abs(), LINEAR_LIMIT, PLATE_FROM)
}

/// 0 up to `from`, 1 from `to`, a cubic between with no slope at either end.
fn smooth_step(x: f64, from: f64, to: f64) -> f64 {
    let t = ((x - from) / (to - from)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Sideslip from which the side force turns from the wind axes towards the body's y axis, rad
/// (15 deg; wholly turned at [`LINEAR_LIMIT`]).
pub const SIDE_AXIS_FROM: f64 = 15.0 * std::f64::consts::PI / 180.0;

/// How far the side force has turned from the wind axes to the body's: 0 within
/// [`SIDE_AXIS_FROM`], 1 from [`LINEAR_LIMIT`], a smooth step between.
fn side_axis_turned(beta: f64) -> f64 {
    smooth_step(beta.abs(), SIDE_AXIS_FROM, LINEAR_LIMIT)
}

/// The blend of the linear model into the flat plate's at one angle of attack and sideslip.
struct Beyond {
    /// Weight of the flat plate in the lift and pitching moment (0 inside the envelope).
    plate: f64,
    /// Factor on every surface's effect: 1 inside the envelope, `cos alpha cos^2 beta` far
    /// beyond it (reversed from behind, none in a flow from the side).
    surface: f64,
    /// Factor on the static lift and pitching moment: 1 inside, `cos^2 beta` far beyond.
    in_plane: f64,
    /// `sin alpha`, for the flat plate's pitching moment (0 when unused, inside the envelope).
    sin_alpha: f64,
    /// The sideslip the yawing moment sees: `beta` inside, `sin beta` (the fin and fuselage
    /// as plates) far beyond.
    side: f64,
    /// The sideslip the wind-axis side force sees: `beta` within [`SIDE_AXIS_FROM`]; from
    /// [`LINEAR_LIMIT`], the sideslip's side force ([`Beyond::side`]) taken along the body's
    /// y axis, `cos beta` of it across the wind ...
    side_force: f64,
    /// ... and `-sin beta` of it along the wind, as drag (times `CY_beta`, negative): the
    /// fuselage's and fin's force is normal to them, so it has no part along the nose.
    side_drag: f64,
    /// The sideslip the rolling moment sees: `beta` inside, `sin beta cos beta` far beyond (the
    /// dihedral effect is the side velocity's times the forward's, none in a flow from the
    /// side).
    dihedral: f64,
    /// The flat plate's lift coefficient (weighted by [`Beyond::static_part`]).
    plate_lift: f64,
    /// The flat plate's drag coefficient, already weighted by `plate`.
    plate_drag: f64,
}

impl Beyond {
    fn new(air: &AirData<f64>) -> Self {
        let s_a = beyond_linear(air.alpha);
        let s_b = beyond_linear(air.beta);
        let s_y = side_axis_turned(air.beta);
        // `s_y` is 0 only within 15 deg of sideslip, where `s_b` is too.
        if s_a == 0.0 && s_y == 0.0 {
            // The hot path in flight: no trigonometry, and the linear model bit for bit.
            return Self {
                plate: 0.0,
                surface: 1.0,
                in_plane: 1.0,
                sin_alpha: 0.0,
                side: air.beta,
                side_force: air.beta,
                side_drag: 0.0,
                dihedral: air.beta,
                plate_lift: 0.0,
                plate_drag: 0.0,
            };
        }
        let (sin_a, cos_a) = air.alpha.sin_cos();
        let (sin_b, cos_b) = air.beta.sin_cos();
        let beta = air.beta;
        let side = (1.0 - s_b) * beta + s_b * sin_b;
        let in_plane = 1.0 - s_b + s_b * cos_b * cos_b;
        Self {
            plate: s_a,
            surface: (1.0 - s_a + s_a * cos_a) * in_plane,
            in_plane,
            sin_alpha: sin_a,
            side,
            side_force: side * (1.0 - s_y + s_y * cos_b),
            side_drag: -side * s_y * sin_b,
            dihedral: (1.0 - s_b) * beta + s_b * sin_b * cos_b,
            plate_lift: 2.0 * sin_a * sin_a * cos_a * air.alpha.signum(),
            plate_drag: s_a * 2.0 * sin_a * sin_a,
        }
    }

    /// `linear` inside the envelope, `plate` far beyond it.
    fn static_part(&self, linear: f64, plate: f64) -> f64 {
        if self.plate == 0.0 {
            linear
        } else {
            (1.0 - self.plate) * linear + self.plate * plate
        }
    }
}

/// Nondimensional coefficients of the air data, body rates and surfaces.
///
/// `va_floor` keeps the rate nondimensionalisation finite at zero airspeed (where the dynamic
/// pressure, and so the force, vanishes anyway).
pub fn coefficients(
    p: &ModelParams,
    air: &AirData<f64>,
    omega_body: &Vector3<f64>,
    c: &Controls,
) -> AeroCoefficients {
    let va = air.va.max(0.1);
    let half_b_over_va = 0.5 * p.b / va;
    let p_hat = omega_body.x * half_b_over_va;
    let q_hat = omega_body.y * 0.5 * p.c / va;
    let r_hat = omega_body.z * half_b_over_va;
    let (al, ar) = (c.aileron_left, c.aileron_right);
    let (fl, fr) = (c.flap_left, c.flap_right);
    let d = &p.aero;
    let alpha = air.alpha;
    let b = Beyond::new(air);
    let cl = b.in_plane * b.static_part(d.lift.CL0 + d.lift.CL_alpha * alpha, b.plate_lift)
        + d.lift.CL_q * q_hat
        + b.surface * d.lift.CL_de * c.elevator
        + b.surface * 0.5 * d.lift.CL_da * (al + ar)
        + b.surface * 0.5 * d.lift.CL_df * (fl + fr);
    let ks = b.surface.abs();
    // The other surfaces' drag and the plate's, added after the polar and the elevator in
    // this order (the sums of the Minnesota model, to the bit).
    let others = |sum: f64| {
        sum + ks * (0.5 * d.drag.CD_da * al).abs()
            + ks * (0.5 * d.drag.CD_da * ar).abs()
            + ks * (d.drag.CD_dr * c.rudder).abs()
            + ks * (0.5 * d.drag.CD_df * fl).abs()
            + ks * (0.5 * d.drag.CD_df * fr).abs()
            + b.plate_drag
    };
    let mut cd = match d.drag.polar {
        DragPolar::TotalLift => {
            let dl = cl - d.drag.CL_at_CD_min;
            others(
                d.drag.CD_min
                    + dl * dl * p.induced_drag_factor
                    + ks * (d.drag.CD_de * c.elevator).abs(),
            )
        }
        DragPolar::AngleOfAttackLift => {
            let dl = b.in_plane * b.static_part(d.lift.CL0 + d.lift.CL_alpha * alpha, b.plate_lift)
                - d.drag.CL_at_CD_min;
            // The elevator's drag is signed, as Beard and McLain write it, and turns with the
            // flow as its lift does.
            others(
                d.drag.CD_min
                    + dl * dl * p.induced_drag_factor
                    + b.surface * d.drag.CD_de * c.elevator,
            )
        }
    };
    if d.drag.CD_q != 0.0 {
        cd += d.drag.CD_q * q_hat;
    }
    cd += d.side.CY_beta * b.side_drag;
    let cy = d.side.CY_beta * b.side_force
        + d.side.CY_p * p_hat
        + d.side.CY_r * r_hat
        + b.surface * d.side.CY_dr * c.rudder
        + b.surface * 0.5 * d.side.CY_da * (al - ar);
    let c_roll = d.roll.Cl_beta * b.dihedral
        + d.roll.Cl_p * p_hat
        + d.roll.Cl_r * r_hat
        + b.surface * 0.5 * d.roll.Cl_da * (ar - al)
        + b.surface * d.roll.Cl_dr * c.rudder
        + b.surface * 0.5 * d.roll.Cl_df * (fr - fl);
    let c_pitch = b.in_plane
        * b.static_part(
            d.pitch.Cm0 + d.pitch.Cm_alpha * alpha,
            d.pitch.Cm_alpha * b.sin_alpha,
        )
        + d.pitch.Cm_q * q_hat
        + b.surface * d.pitch.Cm_de * c.elevator
        + b.surface * 0.5 * d.pitch.Cm_da * (al + ar)
        + b.surface * 0.5 * d.pitch.Cm_df * (fl + fr);
    let c_yaw = d.yaw.Cn_beta * b.side
        + d.yaw.Cn_p * p_hat
        + d.yaw.Cn_r * r_hat
        + b.surface * 0.5 * d.yaw.Cn_da * (ar - al)
        + b.surface * d.yaw.Cn_dr * c.rudder
        + b.surface * 0.5 * d.yaw.Cn_df * (fr - fl);
    AeroCoefficients {
        cl,
        cd,
        cy,
        c_roll,
        c_pitch,
        c_yaw,
    }
}

/// Body-axis aerodynamic force (N) and moment about the CG (N m).
pub fn forces_and_moments(
    p: &ModelParams,
    air: &AirData<f64>,
    omega_body: &Vector3<f64>,
    c: &Controls,
    rho: f64,
) -> (Vector3<f64>, Vector3<f64>) {
    let k = coefficients(p, air, omega_body, c);
    let qbar_s = 0.5 * rho * air.va * air.va * p.s;
    let force = wind_to_body(air.alpha, air.beta) * Vector3::new(-k.cd, k.cy, -k.cl) * qbar_s;
    let moment = Vector3::new(p.b * k.c_roll, p.c * k.c_pitch, p.b * k.c_yaw) * qbar_s
        + p.aero_arm.cross(&force);
    (force, moment)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::aircraft::Aircraft;

    fn params() -> ModelParams {
        ModelParams::new(&Aircraft::ultrastick25e().expect("built-in"))
    }

    fn air(alpha: f64, beta: f64) -> AirData<f64> {
        AirData {
            va: 10.0,
            alpha,
            beta,
        }
    }

    /// The Minnesota model written out as its Simulink blocks sum it.
    fn linear(p: &ModelParams, a: &AirData<f64>, w: &Vector3<f64>, c: &Controls) -> [f64; 6] {
        let d = &p.aero;
        let (ph, qh, rh) = (
            w.x * 0.5 * p.b / a.va,
            w.y * 0.5 * p.c / a.va,
            w.z * 0.5 * p.b / a.va,
        );
        let (al, ar) = (c.aileron_left, c.aileron_right);
        let cl = d.lift.CL0
            + d.lift.CL_alpha * a.alpha
            + d.lift.CL_q * qh
            + d.lift.CL_de * c.elevator
            + 0.5 * d.lift.CL_da * (al + ar);
        let dl = cl - d.drag.CL_at_CD_min;
        let cd = d.drag.CD_min
            + dl * dl * p.induced_drag_factor
            + (d.drag.CD_de * c.elevator).abs()
            + (0.5 * d.drag.CD_da * al).abs()
            + (0.5 * d.drag.CD_da * ar).abs()
            + (d.drag.CD_dr * c.rudder).abs();
        let cm = d.pitch.Cm0
            + d.pitch.Cm_alpha * a.alpha
            + d.pitch.Cm_q * qh
            + d.pitch.Cm_de * c.elevator
            + 0.5 * d.pitch.Cm_da * (al + ar);
        let cn = d.yaw.Cn_beta * a.beta
            + d.yaw.Cn_p * ph
            + d.yaw.Cn_r * rh
            + 0.5 * d.yaw.Cn_da * (ar - al)
            + d.yaw.Cn_dr * c.rudder;
        let croll = d.roll.Cl_beta * a.beta
            + d.roll.Cl_p * ph
            + d.roll.Cl_r * rh
            + 0.5 * d.roll.Cl_da * (ar - al)
            + d.roll.Cl_dr * c.rudder;
        let cy = d.side.CY_beta * a.beta
            + d.side.CY_p * ph
            + d.side.CY_r * rh
            + d.side.CY_dr * c.rudder
            + 0.5 * d.side.CY_da * (al - ar);
        [cl, cd, cy, croll, cm, cn]
    }

    #[test]
    fn within_twenty_degrees_of_angle_of_attack_and_fifteen_of_sideslip_the_coefficients_are_the_minnesota_models_to_the_bit(
    ) {
        let p = params();
        let w = Vector3::new(0.3, -0.2, 0.1);
        let c = Controls::new(-0.1, 0.05, 0.02, 0.5);
        for &(alpha, beta) in &[(0.055, 0.0), (-0.3, 0.2), (0.34, -0.25), (0.1, 0.25)] {
            let a = air(alpha, beta);
            let k = coefficients(&p, &a, &w, &c);
            let got = [k.cl, k.cd, k.cy, k.c_roll, k.c_pitch, k.c_yaw];
            assert_eq!(got, linear(&p, &a, &w, &c), "alpha {alpha}, beta {beta}");
        }
    }

    #[test]
    fn a_tailwind_lifts_as_a_flat_plate_would_not_fourteen_times_the_dynamic_pressure() {
        // Flow from behind and a little below: the linear model's CL_alpha * alpha is 14.
        let p = params();
        let c = Controls::new(0.0, 0.0, 0.0, 0.0);
        for &alpha in &[3.0, -3.0, 2.5, -2.5] {
            let k = coefficients(&p, &air(alpha, 0.0), &Vector3::zeros(), &c);
            let (s, co) = f64::sin_cos(alpha);
            let plate = 2.0 * s * s * co * f64::signum(alpha);
            assert!(
                (k.cl - plate).abs() < 1e-12,
                "alpha {alpha}: {} vs {plate}",
                k.cl
            );
            assert!(k.cl.abs() < 0.8, "a flat plate lifts at most 0.77");
        }
    }

    #[test]
    fn the_lift_falls_without_a_jump_past_the_linear_envelope() {
        let p = params();
        let c = Controls::new(0.0, 0.0, 0.0, 0.0);
        let cl = |a: f64| coefficients(&p, &air(a, 0.0), &Vector3::zeros(), &c).cl;
        let step = 1e-4;
        let mut a = 0.0;
        while a < std::f64::consts::PI - step {
            let jump = (cl(a + step) - cl(a)).abs();
            // No step anywhere: the steepest slope is the stall's, 6.7 per rad, under twice
            // CL_alpha (4.58); the linear model's flip at 180 deg is a step of 28.8.
            assert!(jump < 2.0 * 4.58 * step, "jump of {jump} at {a} rad");
            a += step;
        }
        assert!(
            cl(PLATE_FROM) < cl(LINEAR_LIMIT),
            "past the envelope the wing has stalled"
        );
    }

    #[test]
    fn a_wing_in_a_flow_from_its_side_lifts_nothing() {
        let p = params();
        let c = Controls::new(-0.2, 0.0, 0.0, 0.0);
        let k = coefficients(
            &p,
            &air(0.3, std::f64::consts::FRAC_PI_2),
            &Vector3::zeros(),
            &c,
        );
        assert!(k.cl.abs() < 1e-12, "{}", k.cl);
        assert!(k.c_pitch.abs() < 1e-12, "{}", k.c_pitch);
    }

    #[test]
    fn from_behind_the_elevator_pitches_the_other_way() {
        let p = params();
        let up = Controls::new(-0.2, 0.0, 0.0, 0.0);
        let none = Controls::new(0.0, 0.0, 0.0, 0.0);
        let cm =
            |a: f64, c: &Controls| coefficients(&p, &air(a, 0.0), &Vector3::zeros(), c).c_pitch;
        assert!(cm(0.05, &up) > cm(0.05, &none), "nose up from the front");
        assert!(cm(3.1, &up) < cm(3.1, &none), "nose down from behind");
    }

    #[test]
    fn a_flow_from_the_side_rolls_the_aircraft_by_its_side_velocity_times_its_forward() {
        // Dihedral: the upwind wing's extra angle of attack is v Gamma / u on a dynamic
        // pressure of u^2, so the moment goes as u v, none in a flow from the side.
        let p = params();
        let c = Controls::new(0.0, 0.0, 0.0, 0.0);
        let roll = |beta: f64| coefficients(&p, &air(0.0, beta), &Vector3::zeros(), &c).c_roll;
        let b = 80.0_f64.to_radians();
        let expected = p.aero.roll.Cl_beta * b.sin() * b.cos();
        assert!((roll(b) - expected).abs() < 1e-12);
        assert!(roll(std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        // The wing's ailerons, like its lift, have no chordwise flow to work with either.
        let full = Controls::new(0.0, 25.0_f64.to_radians(), 0.0, 0.0);
        let k = coefficients(
            &p,
            &air(0.0, std::f64::consts::FRAC_PI_2),
            &Vector3::zeros(),
            &full,
        );
        assert!(k.c_roll.abs() < 1e-12);
    }

    /// With no angle of attack the wing lifts nothing, so air from ahead and the side can
    /// only hold the aircraft back: the force along the nose is never forward, and with the
    /// flow wholly from the side it is none. The side force taken across the wind at every
    /// sideslip, as the linear model takes it, had pushed a rolling aircraft forward from 17
    /// deg (2.8 N at 32 deg and 13.7 m/s, 0.15 g): it sailed along the runway at 10 m/s in a
    /// 7.5 m/s crosswind with the throttle closed.
    #[test]
    fn air_from_ahead_and_the_side_never_pushes_the_aircraft_forward() {
        let p = params();
        let c = Controls::new(0.0, 0.0, 0.0, 0.0);
        for deg in -90..=90 {
            let a = air(0.0, f64::from(deg).to_radians());
            let (force, _) = forces_and_moments(&p, &a, &Vector3::zeros(), &c, 1.225);
            assert!(force.x <= 1e-9, "{deg} deg: {force:?}");
        }
        let side = air(0.0, std::f64::consts::FRAC_PI_2);
        let (force, _) = forces_and_moments(&p, &side, &Vector3::zeros(), &c, 1.225);
        assert!(force.x.abs() < 1e-9, "{force:?}");
    }
}
