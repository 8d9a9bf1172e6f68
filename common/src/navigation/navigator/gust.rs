//! The gust level the approach's airspeed is raised by: the measured airspeed's standard
//! deviation about its own slow mean, and the approach airspeed it and the wind ask for.
//!
//! A pilot adds half the wind and the gusts to the approach speed so that a gust's drop in
//! airspeed leaves the wing flying and the controls biting (PX4 raises its lowest airspeed by
//! `FW_WIND_ARSP_SC` times the wind). In gusts of a standard deviation `sigma` the airspeed
//! dips below its mean by `2 sigma` about one second in forty: an approach `NAV_LND_GUST_K`
//! times `sigma` faster keeps that much more of its margin over the stall.

use super::params::NavParams;

/// Time constant of the airspeed's mean the gusts are measured about, s: longer than a gust
/// the Dryden spectrum puts most of its energy in at 15 m/s (a few seconds at most near the
/// ground), shorter than the airspeed changes the navigator commands (a few seconds of
/// deceleration onto the approach).
const MEAN_TAU_S: f32 = 2.0;
/// Time constant over which the gusts' variance is averaged, s: a few dozen gusts.
const VARIANCE_TAU_S: f32 = 10.0;

/// Running gust level of the measured airspeed.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct GustMeter {
    mean: Option<f32>,
    variance: f32,
}

impl GustMeter {
    /// Takes the airspeed `airspeed` (m/s) measured `dt` (s) after the last; a reading that
    /// is not a finite number, or a step that is not a positive time, changes nothing.
    pub fn update(&mut self, airspeed: f32, dt: f32) {
        if !(airspeed.is_finite() && dt.is_finite() && dt > 0.0) {
            return;
        }
        let Some(mean) = self.mean else {
            self.mean = Some(airspeed);
            return;
        };
        let dev = airspeed - mean;
        self.mean = Some(mean + dev * (dt / MEAN_TAU_S).min(1.0));
        let k = (dt / VARIANCE_TAU_S).min(1.0);
        self.variance += (dev * dev - self.variance) * k;
    }

    /// The gusts' standard deviation, m/s (0 before the second reading).
    pub fn sigma(&self) -> f32 {
        libm::sqrtf(self.variance.max(0.0))
    }
}

/// The approach's airspeed, m/s: `NAV_LND_ASPD` plus `NAV_LND_WIND_K` times the wind's speed
/// `wind` (m/s) plus `NAV_LND_GUST_K` times the gust level `gust` (m/s), no faster than the
/// cruise airspeed `NAV_ASPD` (nor slower than `NAV_LND_ASPD`); a wind or gust level that is not
/// a finite number adds nothing.
pub(super) fn approach_airspeed(p: &NavParams, wind: f32, gust: f32) -> f32 {
    let add = |k: f32, x: f32| if x.is_finite() { k * x.max(0.0) } else { 0.0 };
    let v = p.land_airspeed + add(p.land_wind_k, wind) + add(p.land_gust_k, gust);
    v.min(p.airspeed.max(p.land_airspeed))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sine of amplitude `a` has a standard deviation of `a / sqrt(2)`: measured about its
    /// mean, a one-second sine of 2 m/s reads 1.41 m/s (a one-second period lies well inside
    /// the 2 s mean's passband's complement: the mean follows it by 1/(2 pi 2) of its
    /// amplitude, 8 %).
    #[test]
    fn a_sinusoidal_gust_reads_its_standard_deviation() {
        let mut g = GustMeter::default();
        let dt = 0.02;
        for i in 0..5000 {
            let t = i as f32 * dt;
            g.update(15.0 + 2.0 * libm::sinf(2.0 * core::f32::consts::PI * t), dt);
        }
        let expected = 2.0 / libm::sqrtf(2.0);
        assert!(
            (g.sigma() - expected).abs() < 0.1 * expected,
            "{} m/s for {expected}",
            g.sigma()
        );
    }

    #[test]
    fn a_steady_airspeed_reads_no_gusts_and_bad_readings_change_nothing() {
        let mut g = GustMeter::default();
        for _ in 0..1000 {
            g.update(15.0, 0.02);
        }
        assert_eq!(g.sigma(), 0.0);
        let before = g;
        g.update(f32::NAN, 0.02);
        g.update(20.0, f32::NAN);
        g.update(20.0, -1.0);
        assert_eq!(g, before);
    }

    /// 15 m/s approach, half the 6 m/s wind, the 1.5 m/s gust level once: 19.5, held to the
    /// 17 m/s cruise airspeed; in calm air 15.
    #[test]
    fn the_approach_is_flown_faster_in_wind_and_gusts_up_to_the_cruise_airspeed() {
        let p = NavParams {
            land_wind_k: 0.5,
            land_gust_k: 1.0,
            ..NavParams::default()
        };
        assert_eq!(approach_airspeed(&p, 0.0, 0.0), 15.0);
        assert_eq!(approach_airspeed(&p, 2.0, 0.5), 16.5);
        assert_eq!(approach_airspeed(&p, 6.0, 1.5), 17.0);
        assert_eq!(approach_airspeed(&p, f32::NAN, f32::INFINITY), 15.0);
    }
}
