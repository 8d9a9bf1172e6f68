//! Rotations between the NED, body and wind frames, air-data angles and Euler kinematics.

use super::elementary::Elementary;
use nalgebra::{Matrix3, Quaternion, RealField, UnitQuaternion, Vector3};

/// 3-2-1 Euler angles in radians: roll `phi`, pitch `theta`, yaw `psi`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Euler<T> {
    /// Roll, positive right wing down.
    pub phi: T,
    /// Pitch, positive nose up.
    pub theta: T,
    /// Yaw (heading of the body x axis), positive clockwise seen from above, from north.
    pub psi: T,
}

impl<T: Elementary> Euler<T> {
    /// Builds the angles from roll, pitch and yaw.
    pub fn new(phi: T, theta: T, psi: T) -> Self {
        Self { phi, theta, psi }
    }

    /// The unit quaternion that rotates body vectors into NED.
    pub fn to_quaternion(self) -> UnitQuaternion<T> {
        // Rz(yaw) * Ry(pitch) * Rx(roll), the 3-2-1 sequence, as nalgebra's
        // `from_euler_angles` composes it (term for term, so the plant's `f64` is unchanged),
        // with the half angles' sines and cosines of `Elementary`.
        let half = T::one() / (T::one() + T::one());
        let (sr, cr) = (self.phi * half).sin_cos_el();
        let (sp, cp) = (self.theta * half).sin_cos_el();
        let (sy, cy) = (self.psi * half).sin_cos_el();
        UnitQuaternion::new_unchecked(Quaternion::new(
            cr * cp * cy + sr * sp * sy,
            sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
        ))
    }

    /// The angles of a body-to-NED quaternion (pitch in [-pi/2, pi/2], roll and yaw in (-pi, pi]).
    ///
    /// nalgebra's `euler_angles` divides both arguments of the roll and yaw `atan2` by the
    /// cosine of the pitch: the same angles while that cosine is positive, for a cosine and
    /// four divisions (a cosine that, as `libm`'s `f32` `cosf`, had cost the MCU about 1,100
    /// instructions of software `f64`). They are taken from the matrix directly; the poles (where the
    /// 3-2-1 sequence is singular) are nalgebra's: yaw zero, roll from the first row.
    pub fn from_quaternion(q: &UnitQuaternion<T>) -> Self {
        let r = q.to_rotation_matrix();
        let m = r.matrix();
        if m.m31.abs() < T::one() {
            Self {
                phi: m.m32.atan2(m.m33),
                theta: -m.m31.asin_el(),
                psi: m.m21.atan2(m.m11),
            }
        } else if m.m31 <= -T::one() {
            Self::new(m.m12.atan2(m.m13), T::frac_pi_2(), T::zero())
        } else {
            Self::new(-m.m12.atan2(-m.m13), -T::frac_pi_2(), T::zero())
        }
    }

    /// The direction cosine matrix that rotates body vectors into NED.
    pub fn body_to_ned(self) -> Matrix3<T> {
        let (sf, cf) = self.phi.sin_cos_el();
        let (st, ct) = self.theta.sin_cos_el();
        let (sp, cp) = self.psi.sin_cos_el();
        Matrix3::new(
            ct * cp,
            sf * st * cp - cf * sp,
            cf * st * cp + sf * sp,
            ct * sp,
            sf * st * sp + cf * cp,
            cf * st * sp - sf * cp,
            -st,
            sf * ct,
            cf * ct,
        )
    }

    /// Euler angle rates from body rates `(p, q, r)`.
    ///
    /// Singular at pitch +-90 deg, where the 3-2-1 sequence loses a degree of freedom; the plant
    /// integrates a quaternion for that reason and uses this only for reporting.
    pub fn rates_from_body(self, omega: &Vector3<T>) -> Vector3<T> {
        let (sf, cf) = self.phi.sin_cos_el();
        let tt = self.theta.tan_el();
        let ct = self.theta.sin_cos_el().1;
        let (p, q, r) = (omega.x, omega.y, omega.z);
        Vector3::new(
            p + (q * sf + r * cf) * tt,
            q * cf - r * sf,
            (q * sf + r * cf) / ct,
        )
    }
}

/// Rotates a body-frame vector into NED.
pub fn body_to_ned<T: RealField + Copy>(q: &UnitQuaternion<T>, v_body: &Vector3<T>) -> Vector3<T> {
    q.transform_vector(v_body)
}

/// Rotates a NED vector into the body frame.
pub fn ned_to_body<T: RealField + Copy>(q: &UnitQuaternion<T>, v_ned: &Vector3<T>) -> Vector3<T> {
    q.inverse_transform_vector(v_ned)
}

/// The matrix that rotates wind-frame vectors into the body frame, `C_bw(alpha, beta)`.
///
/// Wind axes: x along the air-relative velocity. Lift and drag are defined there, so the plant
/// forms its aerodynamic force as `C_bw * q S [-CD, CY, -CL]`.
pub fn wind_to_body<T: Elementary>(alpha: T, beta: T) -> Matrix3<T> {
    let (sa, ca) = alpha.sin_cos_el();
    let (sb, cb) = beta.sin_cos_el();
    Matrix3::new(
        ca * cb,
        -ca * sb,
        -sa,
        sb,
        cb,
        T::zero(),
        sa * cb,
        -sa * sb,
        ca,
    )
}

/// Airspeed, angle of attack and sideslip of an air-relative body velocity.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AirData<T> {
    /// True airspeed, m/s.
    pub va: T,
    /// Angle of attack `atan2(w, u)`, rad.
    pub alpha: T,
    /// Sideslip `asin(v / Va)`, rad.
    pub beta: T,
}

impl<T: Elementary> AirData<T> {
    /// Air data of the body-frame velocity relative to the air mass.
    ///
    /// At zero airspeed the angles are zero rather than undefined.
    pub fn from_body_velocity(v_rel: &Vector3<T>) -> Self {
        let va = v_rel.norm();
        if va <= T::default_epsilon() {
            return Self {
                va,
                alpha: T::zero(),
                beta: T::zero(),
            };
        }
        let alpha = v_rel.z.atan2(v_rel.x);
        let ratio = (v_rel.y / va).clamp(-T::one(), T::one());
        Self {
            va,
            alpha,
            beta: ratio.asin_el(),
        }
    }

    /// The air-relative body velocity these angles and speed describe.
    pub fn body_velocity(&self) -> Vector3<T> {
        wind_to_body(self.alpha, self.beta) * Vector3::new(self.va, T::zero(), T::zero())
    }
}

/// Wraps an angle into (-pi, pi].
// Not inlined: its remainder and two compares were copied into some twenty callers (1 KB of
// the MCU image).
#[inline(never)]
pub fn wrap_pi<T: RealField + Copy>(angle: T) -> T {
    let two_pi = T::two_pi();
    let mut a = angle % two_pi;
    if a > T::pi() {
        a -= two_pi;
    } else if a <= -T::pi() {
        a += two_pi;
    }
    a
}

/// Wraps an angle into [0, 2 pi).
pub fn wrap_two_pi<T: RealField + Copy>(angle: T) -> T {
    let two_pi = T::two_pi();
    let a = angle % two_pi;
    if a < T::zero() {
        a + two_pi
    } else {
        a
    }
}

/// Ground speed above which the course over ground is trusted, m/s: slower, GPS velocity
/// noise of a few dm/s swings the course by tens of degrees, and the heading stands in for it.
pub const MIN_COURSE_SPEED_MPS: f32 = 3.0;

/// Course over ground and ground speed from a NED velocity (course in (-pi, pi]).
pub fn course_and_speed<T: RealField + Copy>(v_ned: &Vector3<T>) -> (T, T) {
    let vg = (v_ned.x * v_ned.x + v_ned.y * v_ned.y).sqrt();
    (v_ned.y.atan2(v_ned.x), vg)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// Over a grid of attitudes, pitch up to 89.9 deg, the angles agree with nalgebra's
    /// `euler_angles` to float rounding, and rebuild the quaternion they came from.
    #[test]
    fn euler_angles_agree_with_nalgebras_over_all_attitudes() {
        let mut worst = 0.0_f32;
        for i in -6..=6 {
            for j in -6..=6 {
                for k in -6..=6 {
                    let roll = i as f32 * 0.52;
                    let pitch = j as f32 * 0.2616;
                    let yaw = k as f32 * 0.52;
                    let q = UnitQuaternion::from_euler_angles(roll, pitch, yaw);
                    let (phi, theta, psi) = q.euler_angles();
                    let e = Euler::from_quaternion(&q);
                    let wrap = |a: f32| crate::math::wrap_pi(a).abs();
                    worst = worst
                        .max(wrap(e.phi - phi))
                        .max(wrap(e.theta - theta))
                        .max(wrap(e.psi - psi));
                    assert!(q.angle_to(&e.to_quaternion()) < 2e-3, "{e:?} from {q:?}");
                }
            }
        }
        assert!(worst < 1e-5, "worst difference {worst} rad");
        for p in [f32::to_radians(89.9), -f32::to_radians(89.9)] {
            let q = UnitQuaternion::from_euler_angles(0.4, p, -1.2);
            let e = Euler::from_quaternion(&q);
            assert!((e.theta - p).abs() < 1e-3, "{e:?}");
        }
    }

    #[test]
    fn dcm_matches_quaternion() {
        let e = Euler::new(0.3_f64, -0.2, 2.5);
        let m = e.to_quaternion().to_rotation_matrix().into_inner();
        assert_relative_eq!(m, e.body_to_ned(), epsilon = 1e-12);
        let back = Euler::from_quaternion(&e.to_quaternion());
        assert_relative_eq!(back.phi, 0.3, epsilon = 1e-12);
        assert_relative_eq!(back.theta, -0.2, epsilon = 1e-12);
        assert_relative_eq!(back.psi, 2.5, epsilon = 1e-12);
    }

    #[test]
    fn nose_up_pitch_points_body_x_up() {
        // 30 deg nose up, heading north: body x is north and up (negative down).
        let q = Euler::new(0.0_f64, 30f64.to_radians(), 0.0).to_quaternion();
        let x_ned = body_to_ned(&q, &Vector3::x());
        assert_relative_eq!(x_ned.x, 30f64.to_radians().cos(), epsilon = 1e-12);
        assert_relative_eq!(x_ned.z, -(30f64.to_radians().sin()), epsilon = 1e-12);
        // Heading east (psi = 90 deg) turns body x to east.
        let q = Euler::new(0.0_f64, 0.0, core::f64::consts::FRAC_PI_2).to_quaternion();
        assert_relative_eq!(body_to_ned(&q, &Vector3::x()).y, 1.0, epsilon = 1e-12);
        // Right wing down: body y points down.
        let q = Euler::new(core::f64::consts::FRAC_PI_2, 0.0, 0.0).to_quaternion();
        assert_relative_eq!(body_to_ned(&q, &Vector3::y()).z, 1.0, epsilon = 1e-12);
        let v = Vector3::new(1.0, 2.0, 3.0);
        assert_relative_eq!(ned_to_body(&q, &body_to_ned(&q, &v)), v, epsilon = 1e-12);
    }

    #[test]
    fn air_data_round_trip() {
        let v = Vector3::new(16.974236_f64, 0.3, 0.935579);
        let ad = AirData::from_body_velocity(&v);
        assert_relative_eq!(ad.alpha, (0.935579_f64).atan2(16.974236), epsilon = 1e-12);
        assert_relative_eq!(ad.body_velocity(), v, epsilon = 1e-12);
        // Drag (along -x_wind) opposes the air-relative velocity.
        let drag_body = wind_to_body(ad.alpha, ad.beta) * Vector3::new(-1.0, 0.0, 0.0);
        assert_relative_eq!(drag_body.dot(&v) / v.norm(), -1.0, epsilon = 1e-12);
        let still = AirData::from_body_velocity(&Vector3::<f32>::zeros());
        assert_eq!(still.alpha, 0.0);
    }

    #[test]
    fn euler_rates_level_and_banked() {
        let e = Euler::new(0.0_f64, 0.0, 0.0);
        assert_relative_eq!(
            e.rates_from_body(&Vector3::new(0.1, 0.2, 0.3)),
            Vector3::new(0.1, 0.2, 0.3),
            epsilon = 1e-12
        );
        // A coordinated level turn banked phi: psi_dot = (q sin phi + r cos phi) / cos theta.
        let phi = 0.544_f64;
        let e = Euler::new(phi, 0.0, 0.0);
        let psi_dot = 20f64.to_radians();
        let omega = Vector3::new(0.0, psi_dot * phi.sin(), psi_dot * phi.cos());
        assert_relative_eq!(e.rates_from_body(&omega).z, psi_dot, epsilon = 1e-12);
    }

    #[test]
    fn wrapping() {
        assert_relative_eq!(wrap_pi(3.5_f64), 3.5 - 2.0 * core::f64::consts::PI);
        assert_relative_eq!(wrap_pi(-3.5_f64), -3.5 + 2.0 * core::f64::consts::PI);
        assert_relative_eq!(wrap_pi(core::f32::consts::PI), core::f32::consts::PI);
        assert_relative_eq!(wrap_two_pi(-0.5_f64), 2.0 * core::f64::consts::PI - 0.5);
        let (chi, vg) = course_and_speed(&Vector3::new(0.0_f64, -3.0, 1.0));
        assert_relative_eq!(chi, -core::f64::consts::FRAC_PI_2);
        assert_relative_eq!(vg, 3.0);
    }
}
