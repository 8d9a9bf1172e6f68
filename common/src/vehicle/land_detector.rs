//! The land detector: whether the aircraft is on the ground, told from the estimate (there is
//! no weight-on-wheels switch), after PX4's fixed-wing land detector.
//!
//! Landed needs every sign of rest at once, held for `LND_TRIG_S`: horizontal speed over
//! ground under `LND_VXY_MAX`, vertical speed under `LND_VZ_MAX`, airspeed under
//! `LND_ASPD_MAX` and a specific force within `LND_ACC_TOL` of 1 g (no manoeuvre, no
//! climb-out). Each input is low-passed first (time constant [`FILTER_TAU_S`]), so a short
//! gust or bump neither lands nor launches it. Any sign of flight ends "landed" at once: a
//! ground speed or vertical speed over its threshold, or an airspeed over `LND_ASPD_TO`
//! (higher than `LND_ASPD_MAX`, so the wind over an aircraft stopped on the runway, gusts
//! and all, does not launch it). Disarmed, the airspeed is not
//! evidence (wind over a parked aircraft) and the aircraft is on the ground as soon as it is
//! at rest over the ground: a disarmed airframe with its motor stopped does not hover.
//!
//! Ground speed is no evidence of flight in the navigator's roll-out, armed or disarmed after
//! it: the navigator has seen the wheels on the runway (a bounce back into the air returns it
//! to the flare, and vertical speed still lifts the aircraft); nor, once it reads landed there,
//! is an airspeed over `LND_ASPD_TO` (a crosswind's gusts over a rolling aircraft). A tailwind
//! carries a landed aircraft along at 13 m/s over the ground with 8 m/s of air over its wings,
//! far under any speed it could fly at; without this it read "landing" for the 20 s its wheels
//! took to slow it under `LND_VXY_MAX`.
//!
//! The height over home is no input: an aircraft started in the air below home's altitude is
//! flying, and one at 4 m on its final approach is too.
//!
//! [`LandDetector::update`] is a pure step: explicit inputs and time step, no clock.

use super::snapshot::LandedState;
use crate::navigation::navigator::io::Phase;
use crate::param;
use crate::params::{Group, ParamDef};

/// The landed state reported (`EXTENDED_SYS_STATE`) from the detector's `landed` and the
/// navigator's `phase` while it flies the armed aircraft (`None` otherwise): taking off in the
/// take-off roll or climb; landing when airborne on an approach or flare, or rolling out fast
/// enough to count as moving (after a landing or a take-off given up); in the air when
/// airborne otherwise; on the ground when landed, outside a take-off.
pub fn reported_state(landed: bool, phase: Option<Phase>) -> LandedState {
    let takeoff = matches!(phase, Some(Phase::TakeoffRoll | Phase::TakeoffClimb));
    let landing = matches!(
        phase,
        Some(Phase::Approach | Phase::Flare | Phase::Landed | Phase::TakeoffAbort)
    );
    match (landed, takeoff, landing) {
        (_, true, _) => LandedState::Takeoff,
        (true, false, _) => LandedState::OnGround,
        (false, false, true) => LandedState::Landing,
        (false, false, false) => LandedState::InAir,
    }
}

/// Time constant of the low-pass filters on the detector's inputs, s.
pub const FILTER_TAU_S: f32 = 0.3;

/// Standard gravity, m/s^2: the specific force at rest.
const G: f32 = crate::math::GRAVITY;

/// Parameters of the land detector.
pub const PARAMS: Group<LandParams> = Group {
    name: "Land detector",
    params: &[
        param!(
            ParamDef::real(
                "LND_VXY_MAX",
                8.0,
                0.5,
                20.0,
                "m/s",
                "Landed only under this horizontal speed over ground (more is flight at once)",
            ),
            LandParams => vel_xy_max
        ),
        param!(
            ParamDef::real(
                "LND_VZ_MAX",
                1.0,
                0.1,
                10.0,
                "m/s",
                "Landed only under this vertical speed, up or down (more is flight at once)",
            ),
            LandParams => vel_z_max
        ),
        param!(
            ParamDef::real(
                "LND_ASPD_MAX",
                10.0,
                2.0,
                30.0,
                "m/s",
                "Landed only under this airspeed while armed (more in flight: still flying)",
            ),
            LandParams => airspeed_max
        ),
        param!(
            ParamDef::real(
                "LND_ASPD_TO",
                12.0,
                2.0,
                40.0,
                "m/s",
                "Armed on the ground, an airspeed over this is a take-off (not LND_ASPD_MAX: gusts)",
            ),
            LandParams => airspeed_takeoff
        ),
        param!(
            ParamDef::real(
                "LND_ACC_TOL",
                3.0,
                0.5,
                20.0,
                "m/s^2",
                "Landed only with the specific force within this of 1 g",
            ),
            LandParams => accel_tol
        ),
        param!(
            ParamDef::real(
                "LND_TRIG_S",
                1.5,
                0.1,
                10.0,
                "s",
                "Time every sign of rest must hold before the aircraft counts as landed",
            ),
            LandParams => trigger_s
        ),
    ],
    base: || LandParams {
        vel_xy_max: 0.0,
        vel_z_max: 0.0,
        airspeed_max: 0.0,
        airspeed_takeoff: 0.0,
        accel_tol: 0.0,
        trigger_s: 0.0,
    },
    check: crate::params::independent,
};

/// The land detector's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LandParams {
    /// `LND_VXY_MAX`: horizontal speed at rest, m/s.
    pub vel_xy_max: f32,
    /// `LND_VZ_MAX`: vertical speed at rest, m/s.
    pub vel_z_max: f32,
    /// `LND_ASPD_MAX`: airspeed at rest (armed), m/s.
    pub airspeed_max: f32,
    /// `LND_ASPD_TO`: airspeed that, landed and armed, shows a take-off, m/s.
    pub airspeed_takeoff: f32,
    /// `LND_ACC_TOL`: specific force's tolerance around 1 g at rest, m/s^2.
    pub accel_tol: f32,
    /// `LND_TRIG_S`: time at rest that makes a landing, s.
    pub trigger_s: f32,
}

impl Default for LandParams {
    fn default() -> Self {
        PARAMS.defaults()
    }
}

/// What the detector needs each step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LandInputs {
    /// Armed (motor live).
    pub armed: bool,
    /// Horizontal speed over ground, m/s.
    pub ground_speed: f32,
    /// Vertical speed, down positive, m/s.
    pub vel_down: f32,
    /// Airspeed, m/s.
    pub airspeed: f32,
    /// Magnitude of the accelerometer's specific force, m/s^2 (`None`: no sample yet).
    pub specific_force: Option<f32>,
    /// In the navigator's roll-out, or disarmed at its end: the wheels have been seen on the
    /// runway.
    pub rolling_out: bool,
}

/// Low-passed inputs.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Filtered {
    ground_speed: f32,
    vel_down: f32,
    airspeed: f32,
    /// |specific force| - g, m/s^2.
    accel_dev: f32,
}

impl Filtered {
    /// Moving as a flight or a take-off run moves: over the ground faster than `LND_VXY_MAX`
    /// (but in the navigator's roll-out, `rolling_out`), or up or down faster than
    /// `LND_VZ_MAX`.
    fn moving(&self, p: &LandParams, rolling_out: bool) -> bool {
        (self.ground_speed > p.vel_xy_max && !rolling_out)
            || libm::fabsf(self.vel_down) > p.vel_z_max
    }
}

/// The land detector's state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LandDetector {
    landed: bool,
    /// Time every sign of rest has held, s.
    at_rest_s: f32,
    filtered: Option<Filtered>,
}

impl Default for LandDetector {
    fn default() -> Self {
        Self::new()
    }
}

impl LandDetector {
    /// On the ground (a vehicle boots on the ground; flight evidence ends that at once).
    pub const fn new() -> Self {
        Self {
            landed: true,
            at_rest_s: 0.0,
            filtered: None,
        }
    }

    /// On the ground.
    pub fn landed(&self) -> bool {
        self.landed
    }

    /// The aircraft has just been disarmed: the disarmed rule (at rest over the ground with
    /// the motor stopped, on the ground) on the inputs as last filtered, at once rather than at
    /// the next step, so that the tick that disarms does not report a disarmed aircraft in the
    /// air (a roll-out into a gusty headwind disarms at a walking pace over the ground with more
    /// air over the wings than `LND_ASPD_MAX`: the campaign's flights ending on that tick read
    /// "in air"). `rolling_out` as in [`LandInputs`]. Returns [`LandDetector::landed`].
    pub fn disarmed(&mut self, p: &LandParams, rolling_out: bool) -> bool {
        if let Some(f) = self.filtered {
            if !f.moving(p, rolling_out) {
                self.landed = true;
                self.at_rest_s = p.trigger_s;
            }
        }
        self.landed
    }

    /// One step of `dt` seconds. Non-finite inputs (an estimator not yet converged) leave the
    /// state as it was. Returns [`LandDetector::landed`].
    pub fn update(&mut self, p: &LandParams, i: &LandInputs, dt: f32) -> bool {
        let accel_dev = i.specific_force.map_or(0.0, |f| f - G);
        let raw = Filtered {
            ground_speed: i.ground_speed,
            vel_down: i.vel_down,
            airspeed: i.airspeed,
            accel_dev,
        };
        let finite = raw.ground_speed.is_finite()
            && raw.vel_down.is_finite()
            && raw.airspeed.is_finite()
            && raw.accel_dev.is_finite();
        if !(finite && dt.is_finite() && dt > 0.0) {
            return self.landed;
        }
        let k = dt / (FILTER_TAU_S + dt);
        let f = match self.filtered {
            None => raw,
            Some(f) => Filtered {
                ground_speed: f.ground_speed + k * (raw.ground_speed - f.ground_speed),
                vel_down: f.vel_down + k * (raw.vel_down - f.vel_down),
                airspeed: f.airspeed + k * (raw.airspeed - f.airspeed),
                accel_dev: f.accel_dev + k * (raw.accel_dev - f.accel_dev),
            },
        };
        self.filtered = Some(f);
        let moving = f.moving(p, i.rolling_out);
        // Landed, only an airspeed near flying speed is a take-off: wind and its gusts over
        // the stopped aircraft are not (hysteresis between the two thresholds).
        let airspeed_max = if self.landed {
            p.airspeed_takeoff.max(p.airspeed_max)
        } else {
            p.airspeed_max
        };
        // Landed in the roll-out, a gust over the take-off airspeed is no take-off either: the
        // navigator goes back to the flare if the wheels leave the runway, ending the roll-out.
        let flying_air = i.armed && f.airspeed > airspeed_max && !(i.rolling_out && self.landed);
        if moving || flying_air {
            // Evidence of flight (or of a take-off run): not landed, at once.
            self.landed = false;
            self.at_rest_s = 0.0;
            return false;
        }
        let quiet = libm::fabsf(f.accel_dev) <= p.accel_tol;
        if !i.armed {
            // At rest over the ground with the motor stopped: on the ground.
            self.landed = true;
            self.at_rest_s = p.trigger_s;
            return true;
        }
        if quiet {
            self.at_rest_s = (self.at_rest_s + dt).min(p.trigger_s);
            if self.at_rest_s >= p.trigger_s {
                self.landed = true;
            }
        } else {
            self.at_rest_s = 0.0;
        }
        self.landed
    }
}

#[cfg(test)]
mod tests {
    //! Expectations from what an aircraft does (at rest, rolling, flying, flaring), written as
    //! inputs, not taken from the detector's code.
    use super::*;

    const DT: f32 = 0.02;

    fn at_rest(armed: bool) -> LandInputs {
        LandInputs {
            armed,
            ground_speed: 0.0,
            vel_down: 0.0,
            airspeed: 0.0,
            specific_force: Some(G),
            rolling_out: false,
        }
    }

    /// Armed and flying at 15 m/s.
    fn cruising() -> LandInputs {
        LandInputs {
            ground_speed: 15.0,
            airspeed: 15.0,
            ..at_rest(true)
        }
    }

    /// Steps `d` for `seconds` and returns whether it was landed after each step.
    fn run(d: &mut LandDetector, i: &LandInputs, seconds: f32) -> std::vec::Vec<bool> {
        extern crate std;
        let p = LandParams::default();
        let n = (seconds / DT).round() as usize;
        (0..n).map(|_| d.update(&p, i, DT)).collect()
    }

    extern crate std;

    #[test]
    fn parameters_are_well_formed_and_named_within_16_characters() {
        let p = LandParams::default();
        assert_eq!(p.vel_xy_max, 8.0);
        assert_eq!(p.trigger_s, 1.5);
        for d in PARAMS.params {
            assert!(d.def.name.len() <= 16, "{}", d.def.name);
        }
    }

    #[test]
    fn standing_still_on_the_ground_it_is_landed_armed_or_not() {
        let mut d = LandDetector::new();
        assert!(d.landed());
        assert!(run(&mut d, &at_rest(false), 5.0).iter().all(|&l| l));
        assert!(run(&mut d, &at_rest(true), 5.0).iter().all(|&l| l));
    }

    #[test]
    fn the_take_off_run_ends_landed_at_once_and_flight_keeps_it_ended() {
        let mut d = LandDetector::new();
        run(&mut d, &at_rest(true), 2.0);
        // Full throttle on the runway: 2 m/s^2 forward, accelerating from rest.
        let p = LandParams::default();
        let mut t = 0.0f32;
        let mut left_ground_at = None;
        while t < 8.0 {
            let v = 2.0 * t;
            let i = LandInputs {
                ground_speed: v,
                airspeed: v,
                specific_force: Some(libm::hypotf(G, 2.0)),
                ..at_rest(true)
            };
            if !d.update(&p, &i, DT) && left_ground_at.is_none() {
                left_ground_at = Some(v);
            }
            t += DT;
        }
        // Not landed from just over LND_VXY_MAX (8 m/s, the filter's lag behind it), before
        // the rotation at 13 m/s.
        let v = left_ground_at.expect("never left the landed state");
        assert!((8.0..11.0).contains(&v), "{v}");
        // Climbing out at 17 m/s, 2 m/s up, pulling 1.2 g: flying all along.
        let climb = LandInputs {
            ground_speed: 17.0,
            vel_down: -2.0,
            airspeed: 17.0,
            specific_force: Some(1.2 * G),
            ..at_rest(true)
        };
        assert!(run(&mut d, &climb, 10.0).iter().all(|&l| !l));
    }

    #[test]
    fn slow_flight_into_a_headwind_is_flight_by_its_airspeed() {
        // 14 m/s of air, 10 m/s of wind on the nose: 4 m/s over the ground, level.
        let mut d = LandDetector::new();
        let i = LandInputs {
            ground_speed: 4.0,
            airspeed: 14.0,
            ..at_rest(true)
        };
        assert!(run(&mut d, &i, 10.0).iter().all(|&l| !l));
    }

    #[test]
    fn an_air_start_at_cruise_speed_is_flight_from_the_first_step() {
        let mut d = LandDetector::new();
        let i = LandInputs {
            ground_speed: 17.0,
            airspeed: 17.0,
            vel_down: 0.5,
            ..at_rest(false)
        };
        // Disarmed as well as armed: the ground speed says it.
        assert!(!d.update(&LandParams::default(), &i, DT));
        let armed = LandInputs { armed: true, ..i };
        assert!(run(&mut d, &armed, 5.0).iter().all(|&l| !l));
    }

    #[test]
    fn on_final_approach_it_flies_and_lands_only_once_the_wheels_are_down_and_slow() {
        let mut d = LandDetector::new();
        let p = LandParams::default();
        // Final approach and flare: 14 m/s, sinking 1.5 m/s, then 0.5 m/s in the flare.
        let approach = LandInputs {
            ground_speed: 14.0,
            airspeed: 14.0,
            vel_down: 1.5,
            ..at_rest(true)
        };
        assert!(run(&mut d, &approach, 3.0).iter().all(|&l| !l));
        let flare = LandInputs {
            vel_down: 0.5,
            ground_speed: 12.0,
            airspeed: 12.0,
            ..approach
        };
        assert!(run(&mut d, &flare, 2.0).iter().all(|&l| !l));
        // Touchdown at 12 m/s, rolling out at 1.5 m/s^2 of deceleration.
        let mut t = 0.0f32;
        let mut landed_at = None;
        while t < 12.0 {
            let v = (12.0 - 1.5 * t).max(0.0);
            let i = LandInputs {
                ground_speed: v,
                airspeed: v,
                vel_down: 0.0,
                specific_force: Some(libm::hypotf(G, 1.5)),
                ..at_rest(true)
            };
            if d.update(&p, &i, DT) && landed_at.is_none() {
                landed_at = Some((t, v));
            }
            t += DT;
        }
        let (t, v) = landed_at.expect("never landed");
        // Not while rolling fast: under LND_VXY_MAX, and LND_TRIG_S after it got there
        // (12 - 8 = 4 m/s at 1.5 m/s^2: 2.7 s).
        assert!(v < 8.0, "{v}");
        assert!(t >= 2.7 + 1.5 - 0.1, "{t}");
        assert!(t < 2.7 + 1.5 + 1.0, "{t}");
    }

    #[test]
    fn a_bounce_or_a_bump_on_the_ground_does_not_land_it_early() {
        let mut d = LandDetector::new();
        let p = LandParams::default();
        run(&mut d, &cruising(), 1.0);
        let slow = LandInputs {
            ground_speed: 3.0,
            airspeed: 3.0,
            ..at_rest(true)
        };
        // Rolling slowly for 1 s, then a bump (2 g for 0.3 s) restarts the wait.
        run(&mut d, &slow, 1.0);
        let bump = LandInputs {
            specific_force: Some(2.0 * G),
            ..slow
        };
        assert!(run(&mut d, &bump, 0.3).iter().all(|&l| !l));
        let after = run(&mut d, &slow, 3.0);
        let first = after.iter().position(|&l| l).expect("never landed");
        // The filter lets the bump decay, then the full LND_TRIG_S.
        assert!(first as f32 * DT >= p.trigger_s, "{first}");
        // Once landed, it stays so while at rest.
        assert!(after[first..].iter().all(|&l| l));
    }

    #[test]
    fn disarmed_at_rest_over_the_ground_in_a_wind_it_is_landed_at_once() {
        let mut d = LandDetector::new();
        run(&mut d, &cruising(), 1.0);
        // Stopped on the runway, 11 m/s of wind over the wings: armed, the airspeed keeps it
        // "flying"; disarmed, the wind is no evidence.
        let windy = LandInputs {
            airspeed: 11.0,
            ..at_rest(true)
        };
        assert!(run(&mut d, &windy, 3.0).iter().all(|&l| !l));
        let p = LandParams::default();
        assert!(d.update(
            &p,
            &LandInputs {
                armed: false,
                ..windy
            },
            DT
        ));
    }

    /// The tick that disarms reads the aircraft as disarmed, before the next step: stopped
    /// over the ground with 11 m/s of headwind over the wings (armed, "flying" by its airspeed
    /// over `LND_ASPD_MAX`) it is on the ground at once; still sinking at 3 m/s (over
    /// `LND_VZ_MAX`) it is not.
    #[test]
    fn the_tick_that_disarms_a_stopped_aircraft_reads_it_on_the_ground() {
        let p = LandParams::default();
        let mut d = LandDetector::new();
        run(&mut d, &cruising(), 1.0);
        let headwind = LandInputs {
            ground_speed: 1.5,
            airspeed: 11.0,
            ..at_rest(true)
        };
        assert!(run(&mut d, &headwind, 3.0).iter().all(|&l| !l));
        assert!(d.disarmed(&p, true));
        let mut d = LandDetector::new();
        run(&mut d, &cruising(), 1.0);
        let sinking = LandInputs {
            vel_down: 3.0,
            ..headwind
        };
        run(&mut d, &sinking, 3.0);
        assert!(!d.disarmed(&p, true));
        // Before any input, as booted: on the ground.
        assert!(LandDetector::new().disarmed(&p, false));
    }

    #[test]
    fn landed_and_armed_a_gusty_wind_under_the_take_off_airspeed_does_not_launch_it() {
        let mut d = LandDetector::new();
        let p = LandParams::default();
        // Stopped, armed, the wind gusting between 6 and 11.5 m/s every second.
        for k in 0..500 {
            let gust = if (k / 50) % 2 == 0 { 6.0 } else { 11.5 };
            let i = LandInputs {
                airspeed: gust,
                ..at_rest(true)
            };
            assert!(d.update(&p, &i, DT), "launched at step {k}");
        }
        // The take-off run's airspeed over LND_ASPD_TO is a take-off.
        let run_up = LandInputs {
            airspeed: 13.0,
            ground_speed: 6.0,
            ..at_rest(true)
        };
        assert!(run(&mut d, &run_up, 1.0).iter().any(|&l| !l));
    }

    #[test]
    fn rolling_out_in_a_tailwind_it_is_landed_by_its_airspeed_not_its_ground_speed() {
        let p = LandParams::default();
        // Touched down at 13 m/s of air with 5 m/s of tailwind: 18 m/s over the ground, the
        // wheels slowing it at 0.5 m/s^2 (mu_roll g), the air over the wings 5 m/s less.
        let landed_at = |rolling_out: bool| {
            let mut d = LandDetector::new();
            run(
                &mut d,
                &LandInputs {
                    ground_speed: 18.0,
                    airspeed: 13.0,
                    ..at_rest(true)
                },
                1.0,
            );
            let mut t = 0.0f32;
            while t < 40.0 {
                let v = (18.0 - 0.5 * t).max(0.0);
                let i = LandInputs {
                    ground_speed: v,
                    airspeed: (v - 5.0).abs(),
                    rolling_out,
                    ..at_rest(true)
                };
                if d.update(&p, &i, DT) {
                    return t;
                }
                t += DT;
            }
            f32::INFINITY
        };
        // In the roll-out: once the air is under LND_ASPD_MAX (13 - 10 = 3 m/s at 0.5 m/s^2:
        // 6 s), then LND_TRIG_S. Without the navigator's word: once the ground speed is under
        // LND_VXY_MAX (20 s), then LND_TRIG_S.
        let rolling = landed_at(true);
        assert!((6.0 + 1.5..6.0 + 1.5 + 1.0).contains(&rolling), "{rolling}");
        let unknown = landed_at(false);
        assert!(
            (20.0 + 1.5..20.0 + 1.5 + 1.0).contains(&unknown),
            "{unknown}"
        );
    }

    #[test]
    fn landed_in_the_roll_out_a_crosswind_gust_over_the_take_off_airspeed_does_not_launch_it() {
        // Rolling at 8 m/s with 5 m/s of wind across: 9.4 m/s of air, landed after
        // LND_TRIG_S; then a gust takes the air to 13.5 m/s (over LND_ASPD_TO) for 2 s.
        let rolling = LandInputs {
            ground_speed: 8.0,
            airspeed: 9.4,
            rolling_out: true,
            ..at_rest(true)
        };
        let gust = LandInputs {
            airspeed: 13.5,
            ..rolling
        };
        // Coming in from the flare, flying.
        let flying = LandInputs {
            rolling_out: false,
            ground_speed: 13.0,
            airspeed: 13.5,
            ..rolling
        };
        let mut d = LandDetector::new();
        run(&mut d, &flying, 1.0);
        assert!(!d.landed());
        assert!(run(&mut d, &rolling, 3.0).last() == Some(&true));
        assert!(run(&mut d, &gust, 2.0).iter().all(|&l| l));
        // Outside the roll-out (the navigator back in the flare), the same gust is flight.
        let flare = LandInputs {
            rolling_out: false,
            ground_speed: 0.0,
            ..gust
        };
        assert!(run(&mut d, &flare, 2.0).iter().any(|&l| !l));
        // Not yet landed in the roll-out, the airspeed over LND_ASPD_MAX still keeps it
        // "flying": the wheels are down, the wings could still lift it off.
        let mut d = LandDetector::new();
        run(&mut d, &flying, 1.0);
        assert!(run(
            &mut d,
            &LandInputs {
                airspeed: 11.0,
                ..rolling
            },
            5.0
        )
        .iter()
        .all(|&l| !l));
    }

    #[test]
    fn disarmed_on_the_runway_still_rolling_it_stays_landed_and_a_climb_still_lifts_it() {
        let mut d = LandDetector::new();
        let rolling = LandInputs {
            ground_speed: 12.0,
            airspeed: 4.0,
            rolling_out: true,
            ..at_rest(true)
        };
        assert!(run(&mut d, &rolling, 3.0).last() == Some(&true));
        // Disarmed at 12 m/s over the ground (the navigator's roll-out time is up).
        let disarmed = LandInputs {
            armed: false,
            ..rolling
        };
        assert!(run(&mut d, &disarmed, 3.0).iter().all(|&l| l));
        // Lifted 2 m/s by a gust: not on the ground.
        let lifted = LandInputs {
            vel_down: -2.0,
            ..disarmed
        };
        assert!(run(&mut d, &lifted, 1.0).iter().any(|&l| !l));
        // A flight that ends disarmed (forced in the air) is not landed by it: the ground
        // speed still says flight.
        let mut d = LandDetector::new();
        let fly = LandInputs {
            ground_speed: 17.0,
            airspeed: 17.0,
            ..at_rest(true)
        };
        run(&mut d, &fly, 1.0);
        let forced = LandInputs {
            armed: false,
            ..fly
        };
        assert!(run(&mut d, &forced, 3.0).iter().all(|&l| !l));
    }

    #[test]
    fn non_finite_inputs_leave_the_state_as_it_was() {
        let mut d = LandDetector::new();
        let p = LandParams::default();
        let nan = LandInputs {
            ground_speed: f32::NAN,
            ..at_rest(true)
        };
        assert!(d.update(&p, &nan, DT));
        let fly = cruising();
        assert!(!d.update(&p, &fly, DT));
        assert!(!d.update(&p, &nan, DT));
        assert!(!d.update(&p, &at_rest(true), f32::NAN));
    }
}
