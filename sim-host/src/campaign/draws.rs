//! One flight's draws: every dispersed quantity, from the campaign seed and the flight's index
//! alone, applied to a copy of the aircraft and to the flight's configuration.
//!
//! The stream is ChaCha8 (as the sensor noise and the turbulence use: its output is fixed
//! across releases of `rand_chacha`), seeded with the campaign seed, on the stream numbered by
//! the flight's index: flights are independent of each other and of how a campaign is split.
//! Every quantity takes exactly one uniform number in a fixed order, whatever its spread (a
//! zero spread takes its number and ignores it), so changing one key of the campaign file
//! leaves every other quantity's draw as it was.

use super::spec::CampaignSpec;
use crate::aircraft::{Aero, Aircraft};
use crate::environment::wind::{along_runway, Turbulence};
use rand::{Rng, RngCore, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::de::{MapAccess, Visitor};
use serde::ser::SerializeMap;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::f64::consts::TAU;

/// Named quantities in the order they were drawn (a JSON object in that order).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Quantities(pub Vec<(String, f64)>);

impl Quantities {
    /// The value of `name`, if drawn.
    pub fn get(&self, name: &str) -> Option<f64> {
        self.0.iter().find(|(n, _)| n == name).map(|(_, v)| *v)
    }

    fn push(&mut self, name: impl Into<String>, v: f64) {
        self.0.push((name.into(), v));
    }
}

impl Serialize for Quantities {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(Some(self.0.len()))?;
        for (k, v) in &self.0 {
            m.serialize_entry(k, v)?;
        }
        m.end()
    }
}

impl<'de> Deserialize<'de> for Quantities {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Quantities;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an object of numbers")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut a: A) -> Result<Quantities, A::Error> {
                let mut q = Quantities::default();
                while let Some((k, v)) = a.next_entry::<String, f64>()? {
                    q.0.push((k, v));
                }
                Ok(q)
            }
        }
        d.deserialize_map(V)
    }
}

/// The uniform numbers of one flight, each recorded under the quantity's name.
pub struct Sampler {
    rng: ChaCha8Rng,
    /// What was drawn.
    pub drawn: Quantities,
}

impl Sampler {
    /// The stream of flight `index` of the campaign seeded `seed`.
    pub fn new(seed: u64, index: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(index);
        Self {
            rng,
            drawn: Quantities::default(),
        }
    }

    /// A raw 64-bit number (seeds).
    pub fn seed(&mut self) -> u64 {
        self.rng.next_u64()
    }

    fn unit(&mut self) -> f64 {
        self.rng.random::<f64>()
    }

    /// `1 + U(-s, s)`, recorded.
    pub fn factor(&mut self, name: &str, s: f64) -> f64 {
        let v = 1.0 + s * (2.0 * self.unit() - 1.0);
        self.drawn.push(name, v);
        v
    }

    /// `U(-d, d)`, recorded.
    pub fn symmetric(&mut self, name: &str, d: f64) -> f64 {
        let v = d * (2.0 * self.unit() - 1.0);
        self.drawn.push(name, v);
        v
    }

    /// `U(lo, hi)`, recorded.
    pub fn range(&mut self, name: &str, r: [f64; 2]) -> f64 {
        let v = r[0] + (r[1] - r[0]) * self.unit();
        self.drawn.push(name, v);
        v
    }

    /// One of `n` choices, equally likely, recorded as its index.
    pub fn choice(&mut self, name: &str, n: usize) -> usize {
        let k = ((self.unit() * n as f64) as usize).min(n.saturating_sub(1));
        self.drawn.push(name, k as f64);
        k
    }

    /// A uniform number in `[0, 1)`, not recorded: a draw that a mission kind does not use
    /// still takes its place in the stream.
    pub fn unit_silent(&mut self) -> f64 {
        self.unit()
    }

    /// Records a quantity drawn with [`Self::unit_silent`].
    pub fn record(&mut self, name: &str, v: f64) {
        self.drawn.push(name, v);
    }
}

/// Every coefficient of the aerodynamic model, named by its key in the aircraft file.
fn aero_coefficients(a: &mut Aero) -> Vec<(&'static str, &mut f64)> {
    let (l, d, s) = (&mut a.lift, &mut a.drag, &mut a.side);
    let (r, p, y) = (&mut a.roll, &mut a.pitch, &mut a.yaw);
    vec![
        ("lift.CL0", &mut l.CL0),
        ("lift.CL_alpha", &mut l.CL_alpha),
        ("lift.CL_q", &mut l.CL_q),
        ("lift.CL_de", &mut l.CL_de),
        ("lift.CL_da", &mut l.CL_da),
        ("lift.CL_df", &mut l.CL_df),
        ("drag.CD_min", &mut d.CD_min),
        ("drag.CL_at_CD_min", &mut d.CL_at_CD_min),
        ("drag.oswald_e", &mut d.oswald_e),
        ("drag.CD_de", &mut d.CD_de),
        ("drag.CD_da", &mut d.CD_da),
        ("drag.CD_dr", &mut d.CD_dr),
        ("drag.CD_df", &mut d.CD_df),
        ("side.CY_beta", &mut s.CY_beta),
        ("side.CY_p", &mut s.CY_p),
        ("side.CY_r", &mut s.CY_r),
        ("side.CY_dr", &mut s.CY_dr),
        ("side.CY_da", &mut s.CY_da),
        ("roll.Cl_beta", &mut r.Cl_beta),
        ("roll.Cl_p", &mut r.Cl_p),
        ("roll.Cl_r", &mut r.Cl_r),
        ("roll.Cl_da", &mut r.Cl_da),
        ("roll.Cl_dr", &mut r.Cl_dr),
        ("roll.Cl_df", &mut r.Cl_df),
        ("pitch.Cm0", &mut p.Cm0),
        ("pitch.Cm_alpha", &mut p.Cm_alpha),
        ("pitch.Cm_q", &mut p.Cm_q),
        ("pitch.Cm_de", &mut p.Cm_de),
        ("pitch.Cm_da", &mut p.Cm_da),
        ("pitch.Cm_df", &mut p.Cm_df),
        ("yaw.Cn_beta", &mut y.Cn_beta),
        ("yaw.Cn_p", &mut y.Cn_p),
        ("yaw.Cn_r", &mut y.Cn_r),
        ("yaw.Cn_da", &mut y.Cn_da),
        ("yaw.Cn_dr", &mut y.Cn_dr),
        ("yaw.Cn_df", &mut y.Cn_df),
    ]
}

/// The day's conditions: wind, turbulence and the runway.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Day {
    /// Steady wind, NED, m/s (towards).
    pub wind_ned: [f64; 3],
    /// Turbulence severity.
    pub turbulence: Turbulence,
    /// Runway heading, rad from north.
    pub runway_heading_rad: f64,
}

/// Applies the aircraft's draws to a copy of `nominal`: aerodynamics, mass, inertia, centre
/// of gravity, thrust, servos and sensors. The draws are recorded in `s`.
pub fn disperse_aircraft(s: &mut Sampler, spec: &CampaignSpec, nominal: &Aircraft) -> Aircraft {
    let mut a = nominal.clone();
    for (name, c) in aero_coefficients(&mut a.aero) {
        *c *= s.factor(&format!("aero.{name}"), spec.aero.coefficient_spread);
    }
    let m = &spec.mass;
    a.mass.mass_kg *= s.factor("mass.mass_kg", m.mass_spread);
    a.mass.Jx_kgm2 *= s.factor("mass.Jx_kgm2", m.inertia_spread);
    a.mass.Jy_kgm2 *= s.factor("mass.Jy_kgm2", m.inertia_spread);
    a.mass.Jz_kgm2 *= s.factor("mass.Jz_kgm2", m.inertia_spread);
    a.mass.Jxz_kgm2 *= s.factor("mass.Jxz_kgm2", m.inertia_spread);
    let cg = [
        s.symmetric("mass.cg_x_m", m.cg_shift_m[0]),
        s.symmetric("mass.cg_y_m", m.cg_shift_m[1]),
        s.symmetric("mass.cg_z_m", m.cg_shift_m[2]),
    ];
    shift_cg(&mut a, cg);
    let k = s.factor("propulsion.thrust", spec.propulsion.thrust_spread);
    for c in &mut a.propulsion.CT_poly_J {
        *c *= k;
    }
    a.actuators.bandwidth_Hz *= s.factor("servos.bandwidth", spec.servos.bandwidth_spread);
    a.actuators.rate_limit_radps *= s.factor("servos.rate_limit", spec.servos.rate_limit_spread);

    let ss = &spec.sensors;
    let sc = &mut a.sensors;
    for (i, axis) in ["x", "y", "z"].iter().enumerate() {
        sc.gyro_bias_radps[i] = s.symmetric(
            &format!("sensors.gyro_bias_{axis}_radps"),
            ss.gyro_bias_radps,
        );
    }
    for (i, axis) in ["x", "y", "z"].iter().enumerate() {
        sc.accel_bias_mps2[i] = s.symmetric(
            &format!("sensors.accel_bias_{axis}_mps2"),
            ss.accel_bias_mps2,
        );
    }
    for (i, axis) in ["x", "y", "z"].iter().enumerate() {
        sc.calibration.mag_offset_gauss[i] = s.symmetric(
            &format!("sensors.mag_offset_{axis}_gauss"),
            ss.mag_offset_gauss,
        );
    }
    for (i, axis) in ["x", "y", "z"].iter().enumerate() {
        sc.calibration.gyro_scale[i] *=
            s.factor(&format!("sensors.gyro_scale_{axis}"), ss.gyro_scale_spread);
    }
    for (i, axis) in ["x", "y", "z"].iter().enumerate() {
        sc.calibration.accel_scale[i] *= s.factor(
            &format!("sensors.accel_scale_{axis}"),
            ss.accel_scale_spread,
        );
    }
    sc.calibration.pitot_scale *= s.factor("sensors.pitot_scale", ss.pitot_scale_spread);
    sc.calibration.pitot_offset_pa = s.symmetric("sensors.pitot_offset_Pa", ss.pitot_offset_pa);
    // Noise powers are variances per hertz: a standard deviation k times larger is k^2.
    let k = s.range("sensors.noise_imu", ss.noise_factor);
    sc.gyro_noise_power = sc.gyro_noise_power.map(|p| p * k * k);
    sc.accel_noise_power = sc.accel_noise_power.map(|p| p * k * k);
    let k = s.range("sensors.noise_mag", ss.noise_factor);
    sc.mag_noise_power_nt = sc.mag_noise_power_nt.map(|p| p * k * k);
    let k = s.range("sensors.noise_baro", ss.noise_factor);
    sc.ps_noise_power_kpa *= k * k;
    let k = s.range("sensors.noise_pitot", ss.noise_factor);
    sc.pd_noise_power_kpa *= k * k;
    let k = s.range("sensors.noise_gps", ss.noise_factor);
    sc.gps.horiz_m *= k;
    sc.gps.vert_m *= k;
    sc.gps.vel_mps *= k;
    sc.gps.latency_s = s.range("sensors.gps_latency_s", ss.gps_latency_s);

    let e = &spec.estimator;
    let h = s.range(
        "estimator.gps_startup_horizontal_m",
        e.gps_startup_horizontal_m,
    );
    let dir = s
        .range("estimator.gps_startup_direction_deg", [0.0, 360.0])
        .to_radians();
    let v = s.symmetric("estimator.gps_startup_down_m", e.gps_startup_vertical_m);
    sc.gps.startup_offset_m = [h * dir.cos(), h * dir.sin(), v];
    sc.gps.startup_tau_s = s.range("estimator.gps_startup_tau_s", e.gps_startup_tau_s);
    a
}

/// Moves the centre of gravity by `d` (body axes, m): every point the file gives from the CG
/// (where the aerodynamic force and the thrust act, the wheels, the belly points) moves by
/// `-d`. The aerodynamic moment coefficients are about the CG in the model, so the shift acts
/// through the force's arm, as moving a battery does.
pub fn shift_cg(a: &mut Aircraft, d: [f64; 3]) {
    let mv = |p: &mut [f64; 3]| {
        for i in 0..3 {
            p[i] -= d[i];
        }
    };
    mv(&mut a.geometry.aero_arm_from_cg_m);
    mv(&mut a.geometry.prop_arm_from_cg_m);
    a.ground.translate([-d[0], -d[1], -d[2]]);
}

/// The wind, its turbulence and the runway, recorded in `s`.
pub fn draw_day(s: &mut Sampler, spec: &CampaignSpec) -> Day {
    let speed = s.range("wind.speed_mps", spec.wind.speed_mps);
    let from = s.range("wind.from_deg", [0.0, 360.0]).to_radians();
    let names = &spec.wind.turbulence;
    let k = s.choice("wind.turbulence_index", names.len());
    // Checked when the campaign file was read.
    let turbulence = names
        .get(k)
        .and_then(|n| crate::flight::parse_turbulence(n).ok())
        .unwrap_or(Turbulence::None);
    let mut runway = s
        .range("runway.heading_deg", spec.runway.heading_deg)
        .to_radians();
    // Blowing from `from`: towards the opposite direction.
    let wind_ned = [-speed * from.cos(), -speed * from.sin(), 0.0];
    // A tailwind along the drawn heading: the pilot uses the runway's other end.
    let tailwind = along_runway(wind_ned, runway).0 > 0.0;
    let reversed = spec.runway.into_wind && tailwind;
    if reversed {
        runway += std::f64::consts::PI;
    }
    s.record("runway.reversed_into_wind", f64::from(u8::from(reversed)));
    Day {
        wind_ned,
        turbulence,
        runway_heading_rad: runway.rem_euclid(TAU),
    }
}
