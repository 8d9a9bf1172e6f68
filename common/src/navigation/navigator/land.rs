//! Landing: approach, flare, touchdown and roll-out onto a point, and the go-around.
//!
//! Landing flies the line from the previous waypoint (or from where the item began) to the
//! land point, level until it meets the glide slope, then down it (`LonMode::Glide`: the
//! slope's flight-path angle fed forward, a slow integral of the height error, no diving
//! back onto the slope). The slope aims short of the point by the flare's own length, so
//! the wheels, not the slope, meet the ground at the point. Below the flare height the
//! throttle is closed and the pitch follows a sink rate that shrinks with height (past the
//! point a faster one, so that a gust's extra speed does not float the aircraft far down
//! the runway; short of it a nose that may come down to level at the flare's top, so that
//! an updraft there does not either); once the wheels have touched (low and rising again)
//! the pitch goes to 0, as in a wheel landing, so the ground's kick on the main wheels does
//! not bounce the aircraft back into the air, unless it sinks again (then it was an
//! updraft, and the flare goes on); a second on the ground (height under `NAV_LND_TD_M`, sinking slower
//! than 0.5 m/s) is the touchdown: [`NavOutput::landed`] for the firmware to disarm once
//! stopped.
//!
//! The height the flare is triggered on and flown by is the rangefinder's height above ground
//! while it passes the estimator's gates (`estimator::hagl`) and `NAV_LND_USE_RNG` is set, else
//! the height above the land point, as without a rangefinder. The flare begins at `NAV_FLR_ALT`,
//! or earlier where the sink rate brings the ground within `NAV_FLR_TIME`; the approach is
//! flown at `NAV_LND_ASPD`, faster in wind and gusts (`NAV_LND_WIND_K`, `NAV_LND_GUST_K`:
//! the gust meter of `gust.rs`).
//!
//! A flare still in the air `NAV_LND_ABORT_M` past the point (floated, or bounced off the
//! runway) or lifted out of itself by a gust goes around, as a pilot does after a bounce:
//! full throttle in the take-off regime on the runway's line up to the approach's start
//! height, a leg back parallel to the runway two loiter radii to its left (a left-hand
//! circuit), and a new approach from far enough out to meet the glide slope from that
//! height. A ground station asks for the same with `MAV_CMD_DO_GO_AROUND`. After
//! `GO_AROUNDS_MAX` go-arounds the landing lands whatever its flare brings.

use super::guide::{climb_from_runway, course_near_runway, follow, horizontal_dist, Flight};
use super::gust::approach_airspeed;
use super::io::{NavOutput, Phase};
use super::params::NavParams;
use crate::control::autopilot::Commands;
use crate::control::lateral::{RollMode, RUDDER};
use crate::control::longitudinal::LonMode;
use crate::guidance::Path;
use crate::math::clamp;
use nalgebra::Vector3;

/// Largest height the approach's integral may add to or take off the glide slope, m, and the
/// largest height error it integrates: it is there for the metre the proportional loop
/// leaves on the slope, not for a gust's (winding up on those flew the aircraft under the
/// slope once it was back on it).
const SLOPE_TRIM_MAX_M: f32 = 1.5;

/// Ground speed under which a flaring aircraft counts as rolling on the runway, m/s: the
/// estimated height alone carries the barometer's and GPS's offsets (tenths of a metre).
const ROLLING_SPEED: f32 = 5.0;
/// Ground speed under which a landed aircraft may be disarmed, m/s: until then it is steered,
/// since a taildragger rolling free swings round (a ground loop), harmless at a walking pace.
/// Waiting for a full stop (1 m/s) kept aircraft armed for minutes in a crosswind, where a
/// loaded tail wheel steered against the drift sails the aircraft along (PX4 disarms a
/// landed fixed wing under 5 m/s).
const STOPPED_SPEED: f32 = 3.0;

/// Airspeed under which a landed aircraft still rolling may be disarmed, as a fraction of
/// `NAV_LIFTOFF_ASPD`: there the wing at its attitude on the wheels lifts (10/11)^2, 83 %, of
/// the weight, so the aircraft cannot fly off with its surfaces at rest (10 m/s on the Ultra
/// Stick). Disarmed at 14.6 m/s, it rotated past the three-point attitude and hopped a metre
/// into the air.
const DISARM_LIFTOFF: f32 = 10.0 / 11.0;

/// Time on the ground that makes a touchdown, s.
const TOUCHDOWN_S: f32 = 1.0;
/// Sink rate under which the aircraft counts as on the ground, m/s.
const TOUCHDOWN_SINK: f32 = 0.5;
/// Fastest sink a flare that has floated past the land point aims for, m/s: two thirds of the
/// 1.5 m/s a small aircraft's landing gear is held to.
const PAST_SINK_MAX: f32 = 1.0;
/// Climb rate that, below the touchdown height, shows the wheels have touched and kicked the
/// aircraft up, m/s.
const BOUNCE_CLIMB: f32 = 0.3;
/// Sink rate that, after a touch, shows the aircraft is still (or again) in the air and
/// falling, m/s: the flare takes over again. An updraft half a metre up looks like the
/// wheels' kick to an estimated height that is tenths of a metre off, and the wheel
/// landing's level pitch then met the next downdraft at up to 2 m/s (2 of 200 light
/// turbulence landings, `docs/NAVIGATION.md`).
const REFLARE_SINK: f32 = 0.6;

/// Airspeeds between which the roll-out's pitch goes from `NAV_GND_PTCH_DEG` to the wheel
/// landing's 0, as fractions of `NAV_LIFTOFF_ASPD`: there the wing at the attitude on the
/// wheels lifts (6/11)^2 and (9/11)^2 of the weight, 30 % and 67 % (6 and 9 m/s on the Ultra
/// Stick). Faster, the low attitude keeps the wing's lift under the weight (at 13 m/s the
/// Ultra Stick's three-point attitude lifts 29 N against its 19 N).
const TAIL_DOWN_LIFTOFF: (f32, f32) = (6.0 / 11.0, 9.0 / 11.0);

/// The roll-out's pitch at `airspeed` (m/s): `NAV_GND_PTCH_DEG` once slow, so that the
/// elevator holds the steered wheel on the ground (the taildragger's tail wheel, held down
/// as a pilot holds the stick back; pitch 0 there, the wheel landing's attitude, has the pitch
/// loop wind up against the tail wheel in a headwind and, once the tail lifts, put the nose
/// onto the propeller); that pitch also when the airspeed is unknown, as the aircraft has
/// stopped flying.
fn rollout_pitch(p: &NavParams, airspeed: f32) -> f32 {
    let (slow, fast) = TAIL_DOWN_LIFTOFF;
    let (slow, fast) = (slow * p.liftoff_airspeed, fast * p.liftoff_airspeed);
    if !airspeed.is_finite() {
        return p.ground_pitch;
    }
    p.ground_pitch * ((fast - airspeed) / (fast - slow)).clamp(0.0, 1.0)
}

/// Height at which the bank the flare allows has widened to 90 deg, m (`NAV_GND_RLL_M` when
/// larger): 17.75 deg at the 1.5 m flare's top, 7.5 deg at 0.3 m. The approach's bank widening
/// to 90 deg at 3 m let the course loop answer a gust's 9 deg of course with 25 deg of bank at
/// 0.85 m, and the wing tip met the runway (58 of 1000 dispersed flights in moderate
/// turbulence, `docs/RESULTS-MONTECARLO.md`); widening to 10 m on the approach as well held
/// its crosswind corrections too long (`docs/NAVIGATION.md`).
const FLARE_BANK_M: f32 = 10.0;

/// Time constant over which the approach takes up the difference between the estimate's
/// height and the rangefinder's, s: a few of the rangefinder's 20 Hz readings after its median,
/// and short against the 10 to 20 s of an approach within the rangefinder's 40 m.
const RANGE_EXCESS_TAU_S: f32 = 1.0;

/// Most go-arounds one landing flies; after them it lands whatever the flare brings.
const GO_AROUNDS_MAX: u8 = 2;
/// Height a flaring aircraft must climb back to, as a multiple of the flare height, for the
/// flare to count as ballooned (a gust has lifted it out of the flare): it goes around.
const BALLOON_FLARES: f32 = 2.0;
/// Least height above the land point a go-around climbs to, m.
const GO_AROUND_MIN_M: f32 = 15.0;
/// How many times the glide slope's height above the point an approach may begin at; higher,
/// it flies the circuit instead ([`Landing::step`]).
const APPROACH_HIGH: f32 = 2.0;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum LandPhase {
    Approach,
    Flare,
    /// Climbing away on the runway's line after a go-around.
    Climb,
    /// Flying back, offset to the left of the runway, to a new approach.
    Downwind,
    Landed,
}

/// The circuit a go-around flies back to the runway on: up to `height` (above home), along
/// a leg parallel to the approach two loiter radii to its left, and round onto a new
/// approach from `origin`, far enough out to meet the glide slope from that height.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Circuit {
    height: f32,
    downwind: Path,
    origin: Vector3<f32>,
}

/// A landing in progress.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Landing {
    origin: Vector3<f32>,
    point: Vector3<f32>,
    phase: LandPhase,
    ground_time: f32,
    /// The approach's integral of the height error, m (added to the altitude command).
    slope_trim: f32,
    /// The wheels have touched (low and rising again): the flare is over and the pitch
    /// is held at 0 (a taildragger's main wheels, ahead of the centre of gravity, pitch it up
    /// as they touch; holding the flare's attitude there lifts it off again).
    touched: bool,
    /// Time since the touchdown, s.
    rollout_s: f32,
    /// Go-arounds flown.
    go_arounds: u8,
    /// How far the estimate's height above the land point reads over the rangefinder's, m,
    /// low-passed over [`RANGE_EXCESS_TAU_S`] and held when the rangefinder is not used: the
    /// approach flies its slope that much higher in the estimate's frame, so that the slope
    /// meets the ground the rangefinder sees, where the flare starts (PX4's `FW_LND_USETER` 2).
    range_excess: f32,
    /// Height the flare began at, m: `NAV_FLR_ALT`, or higher when the sink rate brought the
    /// ground within `NAV_FLR_TIME` first (0 before a flare).
    flare_top: f32,
    /// The approach's start has been judged ([`APPROACH_HIGH`]).
    judged: bool,
}

/// How far past the point where the glide slope meets the flare height the flare carries
/// the aircraft at `ground_speed` (m/s) along the approach, m. The flare's sink rate falls
/// linearly with height from the slope's `s_a` to the touchdown's `s_t` over the flare
/// height `h_f` ([`flare_height`] at the slope's sink): height decays as `e^(-t/tau)` towards `-s_t tau` with `tau = h_f /
/// (s_a - s_t)`, reaching the ground after `tau ln(s_a / s_t)`.
fn flare_overrun(p: &NavParams, ground_speed: f32) -> f32 {
    let tan_slope = crate::math::elementary::tan(p.glide_slope);
    let s_a = ground_speed * tan_slope;
    let s_t = p.flare_sink;
    let h_f = flare_height(p, s_a);
    if !(s_a > s_t && s_t > 0.0 && tan_slope > 0.0 && h_f > 0.0) {
        return 0.0;
    }
    let tau = h_f / (s_a - s_t);
    let flare_m = ground_speed * tau * libm::logf(s_a / s_t);
    let overrun = flare_m - h_f / tan_slope;
    if overrun.is_finite() {
        overrun.max(0.0)
    } else {
        0.0
    }
}

/// Height the flare begins at, m: `NAV_FLR_ALT`, or where the ground is `NAV_FLR_TIME` away
/// at the sink rate `sink` (m/s, down positive) when that is higher (PX4's `FW_LND_FL_TIME`,
/// ArduPlane's `LAND_FLARE_SEC`): a faster or steeper approach flares higher, so that the
/// flare has the time it needs to arrest the sink.
fn flare_height(p: &NavParams, sink: f32) -> f32 {
    let by_time = p.flare_time * sink;
    if by_time.is_finite() {
        p.flare_alt.max(by_time)
    } else {
        p.flare_alt
    }
}

impl Landing {
    /// An approach from `origin` to the touchdown `point` (both NED from home).
    pub fn new(origin: Vector3<f32>, point: Vector3<f32>) -> Self {
        Self {
            origin,
            point,
            phase: LandPhase::Approach,
            ground_time: 0.0,
            slope_trim: 0.0,
            touched: false,
            rollout_s: 0.0,
            go_arounds: 0,
            range_excess: 0.0,
            flare_top: 0.0,
            judged: false,
        }
    }

    /// Gives up this approach: climb away on the runway's line and fly a circuit to a new one.
    /// Ignored once on the ground, or after [`GO_AROUNDS_MAX`] go-arounds; returns whether the
    /// aircraft goes around.
    pub fn go_around(&mut self) -> bool {
        let can = matches!(self.phase, LandPhase::Approach | LandPhase::Flare)
            && self.go_arounds < GO_AROUNDS_MAX;
        if can {
            self.go_arounds += 1;
            self.phase = LandPhase::Climb;
            self.touched = false;
            self.ground_time = 0.0;
            self.slope_trim = 0.0;
        }
        can
    }

    /// The circuit after a go-around, flown at `airspeed` (m/s).
    fn circuit(&self, p: &NavParams, airspeed: f32) -> Circuit {
        let d = Vector3::new(
            self.point.x - self.origin.x,
            self.point.y - self.origin.y,
            0.0,
        );
        let d = if d.norm() > 0.01 {
            d.normalize()
        } else {
            Vector3::x()
        };
        let left = Vector3::new(d.y, -d.x, 0.0);
        let ground = -self.point.z;
        let height = (-self.origin.z).max(ground + GO_AROUND_MIN_M);
        let tan_slope = crate::math::elementary::tan(p.glide_slope).max(0.01);
        let turn = 2.0 * p.loiter_radius;
        let length =
            horizontal_dist(&self.origin, &self.point).max((height - ground) / tan_slope + turn);
        let mut origin = self.point - d * length;
        origin.z = -height;
        let mut from = self.point + left * turn;
        from.z = -height;
        let downwind = Path::Line {
            origin: from,
            direction: -d,
            airspeed,
        };
        Circuit {
            height,
            downwind,
            origin,
        }
    }

    /// One step of the go-around's climb or its circuit back to a new approach.
    fn step_circuit(&mut self, f: &Flight, line: &Path, out: &mut NavOutput) {
        let p = f.params;
        let state = f.state;
        let c = self.circuit(p, f.cruise);
        out.phase = Phase::GoAround;
        out.target = Some(c.origin);
        if self.phase == LandPhase::Climb {
            let g = f.guidance.step(line, &state.pos_ned, state.ground_speed());
            out.guidance = Some(g);
            let hagl = state.height() + self.point.z;
            // Put back on the runway by a gust below the lift-off airspeed, the aircraft cannot
            // climb away: full throttle on the wheels at the climb's pitch rolled two of 2000
            // campaign aircraft on their noses and round the field for minutes (seed 1's
            // flight 971, seed 2's 150). After `TOUCHDOWN_S` so, the landing is finished on the
            // ground instead: throttle closed, the roll-out.
            if hagl < p.touchdown_alt && state.airspeed < p.liftoff_airspeed {
                self.ground_time += f.dt;
            } else {
                self.ground_time = 0.0;
            }
            if self.ground_time >= TOUCHDOWN_S {
                self.phase = LandPhase::Landed;
                out.phase = Phase::Landed;
                roll_out(f, g.path_course, &mut self.rollout_s, out);
                return;
            }
            out.commands = Some(Commands {
                roll: climb_from_runway(g.course, hagl, p),
                yaw: RUDDER,
                lon: LonMode::TakeOff {
                    altitude: c.height,
                    airspeed: f.cruise.min(p.takeoff_airspeed),
                    clear_altitude: -self.point.z + p.takeoff_clear,
                },
            });
            if state.height() >= c.height - p.alt_accept {
                self.phase = LandPhase::Downwind;
            }
            return;
        }
        f.emit(&c.downwind, Some(c.origin), Phase::GoAround, out);
        // Abeam the new approach's start: turn onto it.
        let back = self.origin - self.point;
        if (state.pos_ned - c.origin).dot(&Vector3::new(back.x, back.y, 0.0)) >= 0.0 {
            *self = Self {
                go_arounds: self.go_arounds,
                range_excess: self.range_excess,
                ..Self::new(c.origin, self.point)
            };
        }
    }

    /// A mission's landing on `point`, from `origin` (the previous waypoint, or where the
    /// item began) unless that lies within 10 m of the point, then from `pos` (the present
    /// position).
    pub fn item(origin: Vector3<f32>, point: Vector3<f32>, pos: Vector3<f32>) -> Self {
        let origin = if horizontal_dist(&origin, &point) > 10.0 {
            origin
        } else {
            pos
        };
        Self::new(origin, point)
    }

    /// The touchdown has been made: the aircraft is on the ground.
    pub fn landed(&self) -> bool {
        self.phase == LandPhase::Landed
    }

    /// One step of the landing: its commands, guidance and phase into `out`.
    pub fn step(&mut self, f: &Flight, out: &mut NavOutput) {
        let p = f.params;
        let state = f.state;
        let dt = f.dt;
        let pos = state.pos_ned;
        let hagl = match (state.oracle, state.range_hagl) {
            (Some(o), _) => o.height_m + self.point.z,
            // The land point is on the ground the rangefinder sees (flat, at its height).
            (None, Some(h)) if p.land_use_rng && h.is_finite() => h,
            _ => state.height() + self.point.z,
        };
        let sink_now = state.oracle.map_or(state.vel_ned.z, |o| o.vel_down_mps);
        // The oracle measures the flare alone: the approach stays on the estimate with it.
        if let (None, Some(h)) = (state.oracle, state.range_hagl) {
            let excess = state.height() + self.point.z - h;
            let k = (dt / RANGE_EXCESS_TAU_S).clamp(0.0, 1.0);
            if p.land_use_rng && excess.is_finite() && k.is_finite() {
                self.range_excess += (excess - self.range_excess) * k;
            }
        }
        let airspeed = approach_airspeed(p, state.wind_speed, f.gust);
        let line = Path::line_between(&self.origin, &self.point, airspeed).unwrap_or(Path::Line {
            origin: self.point,
            direction: Vector3::x(),
            airspeed,
        });
        if matches!(self.phase, LandPhase::Climb | LandPhase::Downwind) {
            self.step_circuit(f, &line, out);
            return;
        }
        let mut g = f.guidance.step(&line, &pos, state.ground_speed());
        // Level at the approach's start height until the glide slope, then down it, the
        // command moving at the slope's rate over the ground so the autopilot can fly the
        // flight-path angle that rate asks for.
        let (signed_to_go, along_speed) = match line {
            Path::Line { direction, .. } => {
                let d = Vector3::new(direction.x, direction.y, 0.0);
                let n = d.norm();
                if n > 0.0 {
                    ((self.point - pos).dot(&d) / n, state.vel_ned.dot(&d) / n)
                } else {
                    (0.0, 0.0)
                }
            }
            Path::Orbit { .. } => (0.0, 0.0),
        };
        let to_go = signed_to_go.max(0.0);
        let start_h = -self.origin.z;
        let tan_slope = crate::math::elementary::tan(p.glide_slope);
        // The slope aims short of the point by as far as the flare carries past where the
        // slope meets the flare height, so that the wheels touch at the point.
        let along = if along_speed.is_finite() {
            along_speed.max(0.0)
        } else {
            0.0
        };
        let ahead = (to_go - flare_overrun(p, along)).max(0.0);
        let on_slope = -self.point.z + tan_slope * ahead;
        let top = start_h.max(-self.point.z);
        g.altitude = on_slope.min(top);
        let climb_rate = if ahead > 0.0 && on_slope < top {
            -tan_slope * along
        } else {
            0.0
        };
        // An approach that begins more than `APPROACH_HIGH` times the slope's height above the
        // point is not dived onto the slope (the dive feeds on the altitude filter's lag:
        // docs/NAVIGATION.md) but flown again from the circuit, whose final is long enough:
        // a final laid out for an aircraft that turns tighter, its last corner's wider fillet
        // cut short (an Aerosonde 25 m above its slope 230 m out, which dived to the ground at
        // 6 m/s), as ArduPlane aborts a landing whose slope steepens past `LAND_ABORT_DEG`.
        if !self.judged {
            self.judged = true;
            let above = state.height() + self.point.z;
            let slope_above = (on_slope + self.point.z).max(p.flare_alt);
            if self.phase == LandPhase::Approach
                && above > APPROACH_HIGH * slope_above
                && self.go_around()
            {
                self.step_circuit(f, &line, out);
                return;
            }
        }
        out.guidance = Some(g);
        out.target = Some(self.point);
        // On the slope's sink at the present ground speed, not the measured sink: a 0.2 s
        // downdraft's sink on short final flared aircraft at 2-3 m in moderate turbulence,
        // and they touched down harder (hard landings 44 -> 67 of 300, docs/NAVIGATION.md).
        let flare_h = flare_height(p, along * tan_slope);
        if self.phase == LandPhase::Approach && hagl < flare_h {
            self.phase = LandPhase::Flare;
            self.flare_top = flare_h;
        }
        let flare_top = self.flare_top.max(p.flare_alt);
        // Lifted off the runway by a gust after the touchdown, the aircraft is flying again:
        // the flare, not the roll-out's level pitch, brings it back down.
        if self.phase == LandPhase::Landed && hagl > p.touchdown_alt && sink_now < -BOUNCE_CLIMB {
            self.phase = LandPhase::Flare;
            self.touched = false;
            self.ground_time = 0.0;
        }
        // Floated or bounced past the point by more than the landing may be long, or lifted
        // by a gust out of the flare: go around. Still on the approach, above the flare's
        // height, that far past the point, the runway left is too short for a flare from
        // there (a glide pulled up from under the slope has floated an aircraft 230 m down
        // the runway at 3-5 m): go around as well.
        let long = p.land_abort > 0.0 && -signed_to_go > p.land_abort;
        let mut abort = self.phase == LandPhase::Approach && long;
        if self.phase == LandPhase::Flare {
            let sink = sink_now;
            let on_ground = hagl < p.touchdown_alt || state.ground_speed() < ROLLING_SPEED;
            // Rising again this close to the ground is the wheels' kick (or a gust about to
            // balloon the aircraft): from then on the flare's pitch-up is over.
            if hagl < p.touchdown_alt && sink < -BOUNCE_CLIMB {
                self.touched = true;
            } else if sink > REFLARE_SINK {
                self.touched = false;
            }
            if on_ground && sink < TOUCHDOWN_SINK {
                self.ground_time += dt;
            } else {
                self.ground_time = 0.0;
            }
            if self.ground_time >= TOUCHDOWN_S {
                self.phase = LandPhase::Landed;
            }
            let airborne = hagl > p.touchdown_alt;
            // From `NAV_LIFTOFF_ASPD` up the wing lifts the weight even at the attitude on
            // the wheels, so the aircraft can climb away; slower, it is rolling (an estimated
            // height tenths of a metre off may say otherwise), and full throttle there put one
            // aircraft of 1000 on its nose.
            let flying = state.airspeed >= p.liftoff_airspeed;
            abort = flying
                && self.rollout_s == 0.0
                && (long && airborne || hagl > BALLOON_FLARES * flare_top);
        }
        if abort && self.go_around() {
            self.step_circuit(f, &line, out);
            return;
        }
        match self.phase {
            LandPhase::Approach => {
                out.phase = Phase::Approach;
                // The altitude loop is proportional: on the slope it settles below it by what
                // its gain needs to make the pitch the slower approach flies at (a metre on
                // the Ultra Stick). A slow integral of the height error takes that out.
                let slope = g.altitude + self.range_excess;
                let err = slope - state.height();
                if climb_rate != 0.0 && libm::fabsf(err) < SLOPE_TRIM_MAX_M {
                    self.slope_trim = (self.slope_trim + p.approach_i * err * dt)
                        .clamp(-SLOPE_TRIM_MAX_M, SLOPE_TRIM_MAX_M);
                }
                // Caught high by a gust near the ground, the aircraft is not dived back onto
                // the slope (that arrives at the flare sinking fast): the command stays within
                // `NAV_APP_DIVE_M` below the present height, and the landing is long instead.
                let cmd = (slope + self.slope_trim).max(state.height() - p.approach_dive);
                out.commands = Some(Commands {
                    roll: course_near_runway(g.course, hagl, p.ground_roll_height, p),
                    lon: LonMode::Glide {
                        altitude: cmd,
                        airspeed: g.airspeed,
                        climb_rate,
                    },
                    ..follow(&g)
                });
            }
            LandPhase::Flare => {
                out.phase = Phase::Flare;
                // The sink rate aimed for shrinks from the glide's to the touchdown's with
                // height; pitch up as the aircraft sinks faster than that.
                let approach_sink = along * tan_slope;
                let frac = (hagl / flare_top).clamp(0.0, 1.0);
                let aim = p.flare_sink + (approach_sink - p.flare_sink).max(0.0) * frac;
                // Floating past the point (a gust's extra speed at the flare), the flare gives
                // up on the gentlest touchdown for a nearer one: a faster sink aimed for the
                // farther past, up to `PAST_SINK_MAX`, and the nose may come down to level.
                let past = -signed_to_go;
                // Short of the point the nose is held no lower than the flare's pitch at the
                // ground, level at the flare's top: a gust that lifts the aircraft there is
                // flown down again at the glide's attitude rather than floated on (a floor
                // of the touchdown pitch all the way up carried two of 200 landings 22-25 m
                // long).
                let (aim, floor) = if past > 0.0 && p.flare_past_k > 0.0 {
                    (
                        (aim + p.flare_past_k * past).min(PAST_SINK_MAX.max(aim)),
                        0.0,
                    )
                } else {
                    (aim, p.flare_pitch * (1.0 - frac))
                };
                let sink = sink_now;
                let pitch = if self.touched {
                    0.0
                } else if sink.is_finite() {
                    clamp(
                        p.flare_pitch + p.flare_k * (sink - aim),
                        floor,
                        p.flare_pitch_max,
                    )
                } else {
                    p.flare_pitch
                };
                // The rudder steers the tail wheel once the wheels are about to touch; in the
                // air it stays the yaw damper, so the aircraft keeps its crab in a crosswind
                // (lining the nose up with the runway there would let it drift downwind).
                let yaw = if hagl < p.touchdown_alt {
                    f.steer(g.course)
                } else {
                    RUDDER
                };
                out.commands = Some(Commands {
                    roll: course_near_runway(
                        g.course,
                        hagl,
                        p.ground_roll_height.max(FLARE_BANK_M),
                        p,
                    ),
                    yaw,
                    lon: LonMode::Pitch {
                        pitch,
                        throttle: p.flare_throttle * frac,
                    },
                });
            }
            LandPhase::Climb | LandPhase::Downwind => {}
            LandPhase::Landed => {
                out.phase = Phase::Landed;
                roll_out(f, g.path_course, &mut self.rollout_s, out);
            }
        }
    }

    /// In the flare or on the runway after it: a failsafe lets the landing finish.
    pub fn touching_down(&self) -> bool {
        matches!(self.phase, LandPhase::Flare | LandPhase::Landed)
    }
}

/// One step of a roll-out on the runway (after a touchdown, or a take-off given up), steered
/// along `course` (rad): throttle closed, wings level, the nose as [`rollout_pitch`] holds it;
/// `rollout_s` is the time rolled so far (s), and [`NavOutput::landed`] says when the
/// aircraft may be disarmed.
pub(super) fn roll_out(f: &Flight, course: f32, rollout_s: &mut f32, out: &mut NavOutput) {
    let state = f.state;
    // Slow enough to be left to itself, or rolling for longer than any roll-out that slows
    // down takes (ArduPilot's LAND_DISARMDELAY): in a strong crosswind the tail wheel steered
    // against the drift is a keel, and the aircraft sails along the runway at 10 m/s for
    // minutes; disarmed, it weathervanes and stops.
    *rollout_s += f.dt;
    out.landed = state.ground_speed() < STOPPED_SPEED
        || (*rollout_s >= f.params.land_disarm_s
            && state.airspeed < DISARM_LIFTOFF * f.params.liftoff_airspeed);
    out.commands = Some(Commands {
        roll: RollMode::Roll(0.0),
        yaw: f.steer(course),
        lon: LonMode::Pitch {
            pitch: rollout_pitch(f.params, state.airspeed),
            throttle: 0.0,
        },
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::DEG;

    /// At the Ultra Stick's `NAV_LIFTOFF_ASPD` (11 m/s) the fractions give the airspeeds the
    /// landing was flown with, bit for bit: the disarm under 10 m/s, the tail held down from
    /// 9 m/s and fully under 6 m/s (at `NAV_GND_PTCH_DEG`, 10 deg). An aircraft lifting off at
    /// 22 m/s holds its tail down under 12 and 18 m/s.
    #[test]
    fn the_landing_s_airspeeds_are_fractions_of_the_lift_off_airspeed() {
        let p = NavParams::default();
        assert_eq!(p.liftoff_airspeed, 11.0);
        assert_eq!(DISARM_LIFTOFF * p.liftoff_airspeed, 10.0);
        let (slow, fast) = TAIL_DOWN_LIFTOFF;
        assert_eq!(
            (slow * p.liftoff_airspeed, fast * p.liftoff_airspeed),
            (6.0, 9.0)
        );
        assert_eq!(p.ground_pitch, 10.0 * DEG);
        assert_eq!(rollout_pitch(&p, 5.0), 10.0 * DEG);
        assert_eq!(rollout_pitch(&p, f32::NAN), 10.0 * DEG);
        assert_eq!(rollout_pitch(&p, 9.5), 0.0);
        assert!((rollout_pitch(&p, 7.5) - 5.0 * DEG).abs() < 1e-6);
        let big = NavParams {
            liftoff_airspeed: 22.0,
            ground_pitch: 2.0 * DEG,
            ..p
        };
        assert!((rollout_pitch(&big, 12.0) - 2.0 * DEG).abs() < 1e-6);
        assert!((rollout_pitch(&big, 15.0) - 1.0 * DEG).abs() < 1e-6);
        assert_eq!(rollout_pitch(&big, 18.0), 0.0);
    }
}
