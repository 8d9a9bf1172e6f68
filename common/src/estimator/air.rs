//! Air data: true airspeed from the pitot-static pair, and the horizontal wind.
//!
//! Airspeed: `Va = sqrt(2 dp / rho)` with `rho = p / (R T)` from the barometer (ideal gas),
//! then a first-order low-pass.
//!
//! Wind: a two-state EKF on `(w_n, w_e)` (vertical wind taken as zero), random-walk process,
//! with two measurements per airspeed sample, both written on the air-relative velocity
//! `v_air = v_ground - w`:
//! - airspeed: `Va = |v_air|`;
//! - zero sideslip: the component of `v_air` along the body y axis is 0 (a coordinated
//!   aircraft flies with `beta ~ 0`).
//!
//! Neither assumes that the air velocity points along the body x axis, so the angle of attack
//! does not bias the wind in turns; together they make the wind observable in straight flight
//! too (the pair fixes both the along-track and the cross-track component).

use super::kalman::{scalar_update, Refused};
use crate::math::atmosphere::R_AIR;
use nalgebra::{Matrix2, Vector2, Vector3};

/// Air density (kg/m^3) from static pressure (Pa) and temperature (deg C), ideal gas law.
/// `None` when the pair is not physical.
pub fn air_density(pressure_pa: f32, temperature_c: f32) -> Option<f32> {
    let t_k = temperature_c + 273.15;
    if !(pressure_pa.is_finite() && t_k.is_finite()) || pressure_pa <= 0.0 || t_k <= 0.0 {
        return None;
    }
    Some(pressure_pa / (R_AIR as f32 * t_k))
}

/// True airspeed (m/s) from a differential pressure (Pa) and density; negative pressures
/// (sensor noise at rest) read as zero.
pub fn true_airspeed(diff_pressure_pa: f32, density: f32) -> f32 {
    if density <= 0.0 || !density.is_finite() || !diff_pressure_pa.is_finite() {
        return 0.0;
    }
    libm::sqrtf(2.0 * diff_pressure_pa.max(0.0) / density)
}

/// First-order low-pass of the airspeed, and a low-passed rate of change of it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AirspeedFilter {
    value: f32,
    rate: f32,
    primed: bool,
}

impl AirspeedFilter {
    /// Feeds one airspeed over `dt` with time constant `tau` (0: no filtering) and returns the
    /// filtered value. The rate of change is the difference of the filtered value, low-passed
    /// again with `rate_tau`.
    pub fn update(&mut self, va: f32, dt: f32, tau: f32, rate_tau: f32) -> f32 {
        if !self.primed {
            self.value = va;
            self.rate = 0.0;
            self.primed = true;
        } else if dt > 0.0 {
            let a = if tau > 0.0 { dt / (tau + dt) } else { 1.0 };
            let before = self.value;
            self.value += a.clamp(0.0, 1.0) * (va - self.value);
            let raw_rate = (self.value - before) / dt;
            let b = if rate_tau > 0.0 {
                dt / (rate_tau + dt)
            } else {
                1.0
            };
            self.rate += b.clamp(0.0, 1.0) * (raw_rate - self.rate);
        }
        self.value
    }

    /// Rate of change of the airspeed, m/s^2.
    pub fn rate(&self) -> f32 {
        self.rate
    }

    /// The filtered airspeed, m/s.
    pub fn value(&self) -> f32 {
        self.value
    }
}

/// Noise settings of the wind filter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WindNoise {
    /// Random walk of each component, m/s/sqrt(s).
    pub process: f32,
    /// Airspeed, m/s.
    pub airspeed: f32,
    /// Lateral air velocity allowed by the zero-sideslip assumption, m/s.
    pub lateral: f32,
}

/// The horizontal-wind EKF.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WindFilter {
    w: Vector2<f32>,
    p: Matrix2<f32>,
    initialized: bool,
}

/// Initial 1-sigma wind uncertainty per component, m/s.
const INIT_SIGMA: f32 = 3.0;

impl WindFilter {
    /// True once the first airspeed has been fused.
    pub fn is_initialized(&self) -> bool {
        self.initialized
    }

    /// Wind NED (the air mass's velocity over the ground), m/s; down is zero.
    pub fn wind(&self) -> Vector3<f32> {
        Vector3::new(self.w.x, self.w.y, 0.0)
    }

    /// 1-sigma uncertainty of the larger component, m/s.
    pub fn sigma(&self) -> f32 {
        libm::sqrtf(self.p.m11.max(self.p.m22))
    }

    /// Grows the uncertainty over `dt`.
    pub fn predict(&mut self, dt: f32, noise: &WindNoise) {
        if self.initialized {
            let q = noise.process * noise.process * dt;
            let p = self.p + Matrix2::identity() * q;
            if p.iter().all(|x| x.is_finite()) {
                self.p = p;
            }
        }
    }

    /// Fuses airspeed `va` with the ground velocity `v_ned` and the body y axis in NED
    /// (`body_y_ned`). Returns the number of components gated.
    pub fn update(
        &mut self,
        va: f32,
        v_ned: &Vector3<f32>,
        body_x_ned: &Vector3<f32>,
        body_y_ned: &Vector3<f32>,
        noise: &WindNoise,
        gate_sigma: f32,
    ) -> u8 {
        if !self.initialized {
            // Start from the no-sideslip, no-incidence triangle.
            let w = v_ned - body_x_ned * va;
            if !w.iter().all(|c| c.is_finite()) {
                return 0;
            }
            self.w = Vector2::new(w.x, w.y);
            self.p = Matrix2::identity() * (INIT_SIGMA * INIT_SIGMA);
            self.initialized = true;
            return 0;
        }
        let mut gated = 0;
        // Airspeed magnitude.
        let air = Vector3::new(v_ned.x - self.w.x, v_ned.y - self.w.y, v_ned.z);
        let norm = air.norm();
        if norm > 1.0 {
            let h = Vector2::new(-air.x / norm, -air.y / norm);
            let innov = va - norm;
            let r = noise.airspeed * noise.airspeed;
            match scalar_update(&mut self.p, &h, innov, r, gate_sigma) {
                Ok(f) => self.w += f.dx,
                Err(Refused::Gated) => gated += 1,
                Err(Refused::Degenerate) => {}
            }
        }
        // Zero sideslip: body_y . (v - w) = 0.
        let air = Vector3::new(v_ned.x - self.w.x, v_ned.y - self.w.y, v_ned.z);
        let h = Vector2::new(-body_y_ned.x, -body_y_ned.y);
        let innov = -body_y_ned.dot(&air);
        let r = noise.lateral * noise.lateral;
        match scalar_update(&mut self.p, &h, innov, r, gate_sigma) {
            Ok(f) => self.w += f.dx,
            Err(Refused::Gated) => gated += 1,
            Err(Refused::Degenerate) => {}
        }
        gated
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::atmosphere::standard_atmosphere;

    #[test]
    fn density_and_airspeed_invert_the_pitot_equation() {
        let a = standard_atmosphere(100.0_f32);
        let rho = air_density(a.pressure_pa, a.temperature_k - 273.15).unwrap();
        // US1976 at 100 m, the density that reproduces the UMN trim.
        assert!((rho - 1.21328).abs() < 2e-4, "rho {rho}");
        let dp = 0.5 * rho * 17.0 * 17.0;
        assert!((true_airspeed(dp, rho) - 17.0).abs() < 1e-4);
        assert_eq!(true_airspeed(-3.0, rho), 0.0);
        assert!(air_density(-1.0, 15.0).is_none());
        assert!(air_density(101_325.0, -300.0).is_none());
    }

    #[test]
    fn wind_is_found_in_straight_flight_with_incidence() {
        // Flying north at 17 m/s airspeed with 3 deg angle of attack (air velocity below the
        // body x axis), 5 m/s wind from the west (blowing east).
        let wind = Vector3::new(0.0, 5.0, 0.0);
        let alpha = 0.055_f32;
        let theta = alpha; // level flight
        let body_x = Vector3::new(libm::cosf(theta), 0.0, -libm::sinf(theta));
        let body_y = Vector3::new(0.0, 1.0, 0.0);
        let v_air = Vector3::new(17.0, 0.0, 0.0);
        let v = v_air + wind;
        let noise = WindNoise {
            process: 0.1,
            airspeed: 0.5,
            lateral: 1.0,
        };
        let mut f = WindFilter::default();
        for _ in 0..500 {
            f.predict(0.02, &noise);
            f.update(17.0, &v, &body_x, &body_y, &noise, 5.0);
        }
        assert!((f.wind() - wind).norm() < 0.05, "wind {:?}", f.wind());
    }
}
