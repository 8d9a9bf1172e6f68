//! Steady wind plus Dryden turbulence (MIL-F-8785C, low altitude).
//!
//! The turbulence velocities are generated in body axes by the Dryden shaping filters driven
//! by seeded white noise, with the low-altitude scale lengths and intensities of MIL-F-8785C
//! (h in feet below 1000 ft):
//!
//! - `L_w = h`, `L_u = L_v = h / (0.177 + 0.000823 h)^1.2`
//! - `sigma_w = 0.1 W20`, `sigma_u = sigma_v = sigma_w / (0.177 + 0.000823 h)^0.4`
//! - `W20` (wind at 20 ft): light 15 kt, moderate 30 kt, severe 45 kt.
//!
//! Transfer functions (V the airspeed): `H_u = sigma_u sqrt(2 L_u / (pi V)) / (1 + L_u/V s)`;
//! `H_v = sigma_v sqrt(L_v / (pi V)) (1 + sqrt(3) L_v/V s) / (1 + L_v/V s)^2`, and `H_w` alike
//! with `L_w`. Angular turbulence components are not modelled.

use nalgebra::{UnitQuaternion, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

const FT: f64 = 0.3048;
const KT: f64 = 0.514_444;

/// Turbulence severity (MIL-F-8785C).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Turbulence {
    /// No turbulence.
    None,
    /// W20 = 15 kt.
    Light,
    /// W20 = 30 kt.
    Moderate,
    /// W20 = 45 kt.
    Severe,
}

impl Turbulence {
    /// Wind speed at 20 ft, m/s.
    pub fn w20_mps(self) -> f64 {
        KT * match self {
            Turbulence::None => 0.0,
            Turbulence::Light => 15.0,
            Turbulence::Moderate => 30.0,
            Turbulence::Severe => 45.0,
        }
    }
}

/// Scale lengths (m) and intensities (m/s) at an altitude above ground.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DrydenScales {
    /// Longitudinal and lateral scale length, m.
    pub l_uv_m: f64,
    /// Vertical scale length, m.
    pub l_w_m: f64,
    /// Longitudinal and lateral intensity, m/s.
    pub sigma_uv: f64,
    /// Vertical intensity, m/s.
    pub sigma_w: f64,
}

/// MIL-F-8785C low-altitude scales; the altitude is clamped to 10..1000 ft, the model's range.
pub fn dryden_scales(alt_agl_m: f64, severity: Turbulence) -> DrydenScales {
    let h = (alt_agl_m / FT).clamp(10.0, 1000.0);
    let k = 0.177 + 0.000823 * h;
    let sigma_w = 0.1 * severity.w20_mps();
    DrydenScales {
        l_uv_m: h / k.powf(1.2) * FT,
        l_w_m: h * FT,
        sigma_uv: sigma_w / k.powf(0.4),
        sigma_w,
    }
}

/// A first-order Dryden channel (u) or second-order one (v, w), integrated exactly for a
/// zero-order-hold noise input.
#[derive(Clone, Copy, Debug, Default)]
struct Channel {
    x1: f64,
    x2: f64,
}

/// A steady wind (NED, m/s, the direction it blows towards) in a runway's axes, the runway
/// heading `heading_rad`: its part along the runway (positive blowing towards the heading, a
/// tailwind) and across it (positive blowing towards the heading's right, a crosswind from the
/// left). The one definition of that frame change, for the campaign's windsock figures and
/// the navigation tables.
pub fn along_runway(wind_ned: [f64; 3], heading_rad: f64) -> (f64, f64) {
    let (sin, cos) = heading_rad.sin_cos();
    let [n, e, _] = wind_ned;
    (n * cos + e * sin, -n * sin + e * cos)
}

/// The wind model: a steady NED wind plus body-axis turbulence.
pub struct Wind {
    /// Steady wind, NED, m/s (the direction it blows towards).
    pub steady_ned: Vector3<f64>,
    severity: Turbulence,
    rng: ChaCha8Rng,
    u: Channel,
    v: Channel,
    w: Channel,
    gust_body: Vector3<f64>,
}

impl Wind {
    /// A wind blowing towards `steady_ned`, with turbulence of `severity`, seeded.
    pub fn new(steady_ned: Vector3<f64>, severity: Turbulence, seed: u64) -> Self {
        Self {
            steady_ned,
            severity,
            rng: ChaCha8Rng::seed_from_u64(seed ^ 0x00D2_1DE4),
            u: Channel::default(),
            v: Channel::default(),
            w: Channel::default(),
            gust_body: Vector3::zeros(),
        }
    }

    /// Calm air.
    pub fn calm() -> Self {
        Self::new(Vector3::zeros(), Turbulence::None, 0)
    }

    /// The turbulence velocity in body axes, m/s.
    pub fn gust_body(&self) -> Vector3<f64> {
        self.gust_body
    }

    /// Advances the turbulence by `dt` at airspeed `va` and height `alt_agl_m`, and returns the
    /// total wind in NED for attitude `q`.
    pub fn step(
        &mut self,
        dt: f64,
        va: f64,
        alt_agl_m: f64,
        q: &UnitQuaternion<f64>,
    ) -> Vector3<f64> {
        if self.severity != Turbulence::None && dt > 0.0 {
            let s = dryden_scales(alt_agl_m, self.severity);
            let v = va.max(1.0);
            let mut n = || -> f64 { StandardNormal.sample(&mut self.rng) };
            // The MIL spectra integrate to sigma^2 over 0 < omega < inf, which is what these
            // filters give when driven by white noise of (two-sided) density pi; held over dt,
            // such noise has variance pi / dt.
            let (nu, nv, nw) = (n(), n(), n());
            let scale = (std::f64::consts::PI / dt).sqrt();
            let gu = first_order(
                &mut self.u,
                dt,
                s.l_uv_m / v,
                s.sigma_uv * (2.0 * s.l_uv_m / (std::f64::consts::PI * v)).sqrt(),
                nu * scale,
            );
            let gv = second_order(
                &mut self.v,
                dt,
                s.l_uv_m / v,
                s.sigma_uv * (s.l_uv_m / (std::f64::consts::PI * v)).sqrt(),
                nv * scale,
            );
            let gw = second_order(
                &mut self.w,
                dt,
                s.l_w_m / v,
                s.sigma_w * (s.l_w_m / (std::f64::consts::PI * v)).sqrt(),
                nw * scale,
            );
            self.gust_body = Vector3::new(gu, gv, gw);
        }
        self.steady_ned + q.transform_vector(&self.gust_body)
    }
}

/// y = K / (1 + T s) u.
fn first_order(c: &mut Channel, dt: f64, t: f64, k: f64, u: f64) -> f64 {
    let a = (-dt / t).exp();
    c.x1 = a * c.x1 + (1.0 - a) * k * u;
    c.x1
}

/// y = K (1 + sqrt(3) T s) / (1 + T s)^2 u, as two cascaded lags plus the lead.
fn second_order(c: &mut Channel, dt: f64, t: f64, k: f64, u: f64) -> f64 {
    let a = (-dt / t).exp();
    // x1 = K/(1+Ts) u ; x2 = 1/(1+Ts) x1 ; y = x2 + sqrt(3) T dx2/dt = x2 + sqrt(3)(x1 - x2).
    c.x1 = a * c.x1 + (1.0 - a) * k * u;
    c.x2 = a * c.x2 + (1.0 - a) * c.x1;
    c.x2 + 3f64.sqrt() * (c.x1 - c.x2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_wind_towards_the_east_crosses_a_northbound_runway_from_the_left_and_heads_a_westbound_one()
    {
        let (along, across) = along_runway([0.0, 5.0, 0.0], 0.0);
        assert!(along.abs() < 1e-12 && (across - 5.0).abs() < 1e-12);
        // Runway heading west (270 deg): the wind blows against it.
        let (along, across) = along_runway([0.0, 5.0, 0.0], 1.5 * std::f64::consts::PI);
        assert!((along + 5.0).abs() < 1e-12 && across.abs() < 1e-12);
        // Runway heading east: a tailwind of the whole 5 m/s.
        let (along, _) = along_runway([0.0, 5.0, 0.0], 0.5 * std::f64::consts::PI);
        assert!((along - 5.0).abs() < 1e-12);
    }

    #[test]
    fn scales_match_mil_f_8785c_at_100m() {
        // h = 328 ft: L_w = 328 ft, L_u = 328 / 0.447^1.2 = 861 ft; sigma_w = 1.5 kt (light).
        let s = dryden_scales(100.0, Turbulence::Light);
        assert!((s.l_w_m - 100.0).abs() < 0.01);
        assert!((s.l_uv_m / FT - 861.0).abs() < 3.0, "{}", s.l_uv_m / FT);
        assert!((s.sigma_w - 0.1 * 15.0 * KT).abs() < 1e-9);
        assert!((s.sigma_uv / s.sigma_w - 1.0 / 0.447f64.powf(0.4)).abs() < 0.01);
    }

    #[test]
    fn turbulence_has_the_specified_intensity() {
        let mut w = Wind::new(Vector3::zeros(), Turbulence::Moderate, 3);
        let q = UnitQuaternion::identity();
        let dt = 0.01;
        let (mut su, mut sw, mut n) = (0.0, 0.0, 0.0);
        for k in 0..600_000 {
            w.step(dt, 17.0, 100.0, &q);
            if k > 10_000 {
                let g = w.gust_body();
                su += g.x * g.x;
                sw += g.z * g.z;
                n += 1.0;
            }
        }
        let s = dryden_scales(100.0, Turbulence::Moderate);
        let (ru, rw) = ((su / n).sqrt() / s.sigma_uv, (sw / n).sqrt() / s.sigma_w);
        // 100 minutes of simulated air: the RMS is within 15 % of sigma (the long u scale
        // length, 262 m at 17 m/s, leaves few independent samples).
        assert!((ru - 1.0).abs() < 0.15, "u rms / sigma = {ru}");
        assert!((rw - 1.0).abs() < 0.15, "w rms / sigma = {rw}");
    }

    #[test]
    fn calm_air_is_the_steady_wind() {
        let mut w = Wind::new(Vector3::new(0.0, 5.0, 0.0), Turbulence::None, 0);
        let v = w.step(0.01, 17.0, 100.0, &UnitQuaternion::identity());
        assert_eq!(v, Vector3::new(0.0, 5.0, 0.0));
    }
}
