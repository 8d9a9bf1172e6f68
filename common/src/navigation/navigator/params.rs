//! The navigator's parameters: their declarations (names, defaults, bounds, units) and the
//! rule that keeps the airspeeds in order.

use crate::math::DEG;
use crate::param;
use crate::params::{Group, ParamDef};

/// Parameters of the navigator and its behaviours.
pub const PARAMS: Group<NavParams> = Group {
    name: "Navigator",
    params: &[
        param!(
            ParamDef::real(
                "NAV_ACC_RAD",
                15.0,
                1.0,
                200.0,
                "m",
                "Waypoint acceptance radius when an item gives none",
            ),
            NavParams => accept_radius
        ),
        param!(
            ParamDef::real(
                "NAV_LOIT_RAD",
                60.0,
                10.0,
                1000.0,
                "m",
                "Loiter radius when an item gives none",
            ),
            NavParams => loiter_radius
        ),
        param!(
            ParamDef::real(
                "NAV_ALT_ACC",
                5.0,
                0.5,
                50.0,
                "m",
                "Altitude counted as reached (take-off, loiter to altitude, return)",
            ),
            NavParams => alt_accept
        ),
        param!(
            ParamDef::real(
                "NAV_ASPD",
                17.0,
                8.0,
                40.0,
                "m/s",
                "Cruise airspeed (the thesis's trim I)",
            ),
            NavParams => airspeed
        ),
        param!(
            ParamDef::real(
                "NAV_ASPD_MIN",
                13.0,
                8.0,
                40.0,
                "m/s",
                "Lowest airspeed DO_CHANGE_SPEED may set",
            ),
            NavParams => airspeed_min
        ),
        param!(
            ParamDef::real(
                "NAV_ASPD_MAX",
                23.0,
                8.0,
                40.0,
                "m/s",
                "Highest airspeed DO_CHANGE_SPEED may set (level flight at full throttle ends at 23.6)",
            ),
            NavParams => airspeed_max
        ),
        param!(
            ParamDef::real(
                "NAV_RTL_ALT",
                60.0,
                10.0,
                1000.0,
                "m",
                "Return altitude above home",
            ),
            NavParams => rtl_alt
        ),
        param!(
            ParamDef::boolean(
                "NAV_RTL_LAND",
                false,
                "Return mode lands at home after the return (on) or circles there (off)",
            ),
            NavParams => rtl_land, flag
        ),
        param!(
            ParamDef::real(
                "NAV_TKO_VR",
                13.0,
                5.0,
                30.0,
                "m/s",
                "Take-off rotation airspeed",
            ),
            NavParams => takeoff_vr
        ),
        param!(
            ParamDef::real(
                "NAV_TKO_ASPD",
                17.0,
                8.0,
                40.0,
                "m/s",
                "Airspeed of the take-off climb (the cruise airspeed when that is lower)",
            ),
            NavParams => takeoff_airspeed
        ),
        param!(
            ParamDef::real(
                "NAV_TKO_CLR_M",
                10.0,
                1.0,
                100.0,
                "m",
                "Take-off regime (fixed pitch, full throttle) ends at this height; the bank allowed in its climb (take-off, go-around) widens to 90 deg over it; a failsafe past the rotation waits, wings level, until the climb reaches it",
            ),
            NavParams => takeoff_clear
        ),
        param!(
            ParamDef::real(
                "NAV_TKO_RAMP_S",
                2.0,
                0.0,
                10.0,
                "s",
                "Take-off roll: the throttle rises from idle to full over this time (0: at once)",
            ),
            NavParams => takeoff_ramp
        ),
        param!(
            ParamDef::real(
                "NAV_TKO_ROLL_S",
                20.0,
                0.0,
                120.0,
                "s",
                "Take-off roll given up (throttle closed, rolled out to a stop, disarmed) when the rotation airspeed is not reached in this time (0: never)",
            ),
            NavParams => takeoff_roll_max
        ),
        param!(
            ParamDef::real(
                "NAV_TKO_HDG_DEG",
                0.0,
                0.0,
                180.0,
                "deg",
                "Take-off roll given up (throttle closed, rolled out to a stop, disarmed) when the heading swings off the runway's line by more than this beyond where it stood at the roll's start, a ground loop (0: never; off by default, docs/NAVIGATION.md)",
            ),
            NavParams => takeoff_heading_max, unit DEG
        ),
        param!(
            ParamDef::real(
                "NAV_LND_SLP_DEG",
                5.0,
                1.0,
                20.0,
                "deg",
                "Landing glide slope",
            ),
            NavParams => glide_slope, unit DEG
        ),
        param!(
            ParamDef::real(
                "NAV_LND_ASPD",
                15.0,
                8.0,
                30.0,
                "m/s",
                "Landing approach airspeed",
            ),
            NavParams => land_airspeed
        ),
        param!(
            ParamDef::real(
                "NAV_LND_WIND_K",
                0.0,
                0.0,
                2.0,
                "",
                "Approach airspeed added per m/s of the estimated wind (PX4's FW_WIND_ARSP_SC), up to NAV_ASPD",
            ),
            NavParams => land_wind_k
        ),
        param!(
            ParamDef::real(
                "NAV_LND_GUST_K",
                1.0,
                0.0,
                3.0,
                "",
                "Approach airspeed added per m/s of the gusts (the airspeed's standard deviation about its 2 s mean, over 10 s), up to NAV_ASPD",
            ),
            NavParams => land_gust_k
        ),
        param!(
            ParamDef::real(
                "NAV_FLR_ALT",
                1.5,
                0.5,
                20.0,
                "m",
                "Flare below this height above the land point",
            ),
            NavParams => flare_alt
        ),
        param!(
            ParamDef::real(
                "NAV_FLR_TIME",
                1.0,
                0.0,
                5.0,
                "s",
                "Flare also where the ground is this close in time at the glide slope's sink rate at the present ground speed (PX4's FW_LND_FL_TIME; 0: on height alone)",
            ),
            NavParams => flare_time
        ),
        param!(
            ParamDef::real(
                "NAV_FLR_PTCH_DEG",
                3.0,
                -5.0,
                15.0,
                "deg",
                "Flare pitch at the touchdown sink rate",
            ),
            NavParams => flare_pitch, unit DEG
        ),
        param!(
            ParamDef::real(
                "NAV_FLR_PMAX_DEG",
                15.0,
                0.0,
                30.0,
                "deg",
                "Largest flare pitch (under the stall's and a tail strike's)",
            ),
            NavParams => flare_pitch_max, unit DEG
        ),
        param!(
            ParamDef::real(
                "NAV_FLR_SINK",
                0.4,
                0.05,
                3.0,
                "m/s",
                "Sink rate aimed for at touchdown",
            ),
            NavParams => flare_sink
        ),
        param!(
            ParamDef::real(
                "NAV_FLR_K",
                0.35,
                0.0,
                1.0,
                "rad s/m",
                "Flare pitch per m/s of sink rate above the aim",
            ),
            NavParams => flare_k
        ),
        param!(
            ParamDef::real(
                "NAV_FLR_PAST_K",
                0.05,
                0.0,
                1.0,
                "1/s",
                "Flare past the land point: sink rate aimed for rises this much per metre past it (0: no steering)",
            ),
            NavParams => flare_past_k
        ),
        param!(
            ParamDef::real(
                "NAV_LND_TD_M",
                0.5,
                0.05,
                5.0,
                "m",
                "Touchdown: height above the land point under this for 1 s (or rolling slower than 5 m/s)",
            ),
            NavParams => touchdown_alt
        ),
        param!(
            ParamDef::real(
                "NAV_LND_ABORT_M",
                20.0,
                0.0,
                500.0,
                "m",
                "Go around when the flare is still in the air, at NAV_LIFTOFF_ASPD or more, this far past the land point (0: never)",
            ),
            NavParams => land_abort
        ),
        param!(
            ParamDef::boolean(
                "NAV_LND_USE_RNG",
                true,
                "Flare on the rangefinder's height above ground while it passes its gates (PX4's FW_LND_USETER), else on the height above home",
            ),
            NavParams => land_use_rng,
            flag
        ),
        param!(
            ParamDef::real(
                "NAV_LND_DISARM_S",
                30.0,
                5.0,
                600.0,
                "s",
                "Landed: disarmed once slower than 3 m/s over ground, or this long after the touchdown",
            ),
            NavParams => land_disarm_s
        ),
        param!(
            ParamDef::real(
                "NAV_FLR_THR",
                0.0,
                0.0,
                1.0,
                "",
                "Throttle at the start of the flare, faded to zero at touchdown height (keeps the energy a gusty flare needs)",
            ),
            NavParams => flare_throttle
        ),
        param!(
            ParamDef::real(
                "NAV_APP_DIVE_M",
                1.0,
                0.1,
                50.0,
                "m",
                "Approach: the altitude command lies at most this far below the present height (above the slope the aircraft closes it gently instead of diving)",
            ),
            NavParams => approach_dive
        ),
        param!(
            ParamDef::real(
                "NAV_APP_I",
                0.1,
                0.0,
                1.0,
                "1/s",
                "Approach: integral gain on the height error below or above the glide slope (removes the proportional altitude loop's steady offset there)",
            ),
            NavParams => approach_i
        ),
        param!(
            ParamDef::real(
                "NAV_STEER_K",
                1.5,
                0.0,
                10.0,
                "rad/rad",
                "Ground steering: rudder (tail wheel) per radian of course error on the runway",
            ),
            NavParams => steer_k
        ),
        param!(
            ParamDef::real(
                "NAV_STEER_D",
                0.3,
                0.0,
                2.0,
                "s",
                "Ground steering: rudder (tail wheel) per rad/s of yaw rate, against it (damps the taildragger's swing on the runway)",
            ),
            NavParams => steer_d
        ),
        param!(
            ParamDef::boolean(
                "NAV_TKO_TO_ITEM",
                false,
                "Take-off along the line to the take-off item's position; off: along the heading the aircraft stands on when the roll starts (its runway)",
            ),
            NavParams => takeoff_to_item, flag
        ),
        param!(
            ParamDef::real(
                "NAV_GND_RLL_DEG",
                5.0,
                0.0,
                45.0,
                "deg",
                "Largest bank at the ground in take-off, approach and flare; it widens linearly with height to 90 deg at NAV_GND_RLL_M (LIM_ROLL_DEG governs once it is the smaller)",
            ),
            NavParams => ground_roll_max, unit DEG
        ),
        param!(
            ParamDef::real(
                "NAV_GND_RLL_M",
                3.0,
                0.5,
                50.0,
                "m",
                "Height at which the bank allowed near the ground has widened from NAV_GND_RLL_DEG to 90 deg (NAV_TKO_CLR_M in the take-off's and the go-around's climb, 10 m in the flare, when higher)",
            ),
            NavParams => ground_roll_height
        ),
        param!(
            ParamDef::real(
                "NAV_SPAN_M",
                1.27,
                0.2,
                20.0,
                "m",
                "Wing span: with NAV_TIP_GND_DEG, how high the wheels must be for a bank near the ground (the wing tips keep half their clearance)",
            ),
            NavParams => wing_span
        ),
        param!(
            ParamDef::real(
                "NAV_TIP_GND_DEG",
                17.0,
                1.0,
                45.0,
                "deg",
                "Bank at which a wing tip touches the ground with the wheels on it (measured on the aircraft at rest)",
            ),
            NavParams => tip_ground_bank, unit DEG
        ),
        param!(
            ParamDef::real(
                "NAV_GND_PTCH_DEG",
                10.0,
                -10.0,
                30.0,
                "deg",
                "Roll-out pitch once slow (a taildragger: its three-point attitude or above)",
            ),
            NavParams => ground_pitch, unit DEG
        ),
        param!(
            ParamDef::real(
                "NAV_LIFTOFF_ASPD",
                11.0,
                3.0,
                40.0,
                "m/s",
                "Airspeed at which the wing at NAV_GND_PTCH_DEG lifts the weight",
            ),
            NavParams => liftoff_airspeed
        ),
    ],
    base: || ZERO,
    check: consistent,
};

/// The navigator's parameters in SI units.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct NavParams {
    /// Default acceptance radius, m.
    pub accept_radius: f32,
    /// Default loiter radius, m.
    pub loiter_radius: f32,
    /// Altitude acceptance, m.
    pub alt_accept: f32,
    /// Cruise airspeed, m/s.
    pub airspeed: f32,
    /// Lowest settable airspeed, m/s.
    pub airspeed_min: f32,
    /// Highest settable airspeed, m/s.
    pub airspeed_max: f32,
    /// Return altitude above home, m.
    pub rtl_alt: f32,
    /// Return mode lands.
    pub rtl_land: bool,
    /// Rotation airspeed, m/s.
    pub takeoff_vr: f32,
    /// Airspeed of the take-off climb, m/s: at full throttle the climb regime holds it by
    /// pitch, so a fast cruise airspeed would make the climb a long shallow one (at 23 m/s
    /// the aircraft crossed 2 km before reaching 60 m).
    pub takeoff_airspeed: f32,
    /// Take-off regime clear height, m; a failsafe after the rotation is flown from there.
    pub takeoff_clear: f32,
    /// `NAV_LND_DISARM_S`: longest roll-out before the disarm, s.
    pub land_disarm_s: f32,
    /// `NAV_LND_ABORT_M`: distance past the land point at which a flare still in the air goes
    /// around, m (0: never).
    pub land_abort: f32,
    /// `NAV_LND_USE_RNG`: the flare's height is the rangefinder's while it is valid.
    pub land_use_rng: bool,
    /// `NAV_TKO_RAMP_S`: time of the take-off roll's throttle ramp, s.
    pub takeoff_ramp: f32,
    /// `NAV_TKO_ROLL_S`: longest take-off roll before the rotation airspeed, s (0: no limit).
    pub takeoff_roll_max: f32,
    /// `NAV_TKO_HDG_DEG`: largest heading off the runway's line on the take-off roll, rad (0:
    /// no limit).
    pub takeoff_heading_max: f32,
    /// Glide slope, rad.
    pub glide_slope: f32,
    /// Approach airspeed, m/s.
    pub land_airspeed: f32,
    /// Flare height, m.
    pub flare_alt: f32,
    /// Flare time to touchdown, s (0: height alone).
    pub flare_time: f32,
    /// Approach airspeed added per m/s of wind.
    pub land_wind_k: f32,
    /// Approach airspeed added per m/s of gust level.
    pub land_gust_k: f32,
    /// Flare pitch, rad.
    pub flare_pitch: f32,
    /// `NAV_FLR_PMAX_DEG`: largest pitch the flare commands, rad: below the stall's angle of
    /// attack, and on a tricycle gear below the pitch at which the tail strikes the runway
    /// with the main wheels on it.
    pub flare_pitch_max: f32,
    /// Touchdown sink rate, m/s.
    pub flare_sink: f32,
    /// Flare pitch gain, rad per m/s.
    pub flare_k: f32,
    /// Touchdown height, m.
    pub touchdown_alt: f32,
    /// Ground steering gain, rad of rudder per rad of course error.
    pub steer_k: f32,
    /// Ground steering yaw-rate damping, rad of rudder per rad/s.
    pub steer_d: f32,
    /// Take off along the line to the item's position rather than the standing heading.
    pub takeoff_to_item: bool,
    /// Largest bank at the ground, rad.
    pub ground_roll_max: f32,
    /// Height at which the bank allowed near the ground has widened to 90 deg, m.
    pub ground_roll_height: f32,
    /// Wing span, m.
    pub wing_span: f32,
    /// Bank at which a wing tip touches the ground on the wheels, rad.
    pub tip_ground_bank: f32,
    /// `NAV_GND_PTCH_DEG`: pitch the roll-out holds once slow, rad. Above a taildragger's
    /// three-point attitude (8.7 deg on the Ultra Stick) the elevator holds the tail wheel down
    /// for steering; the roll-out brings the pitch to it from the wheel landing's 0 between 6/11
    /// and 9/11 of [`NavParams::liftoff_airspeed`].
    pub ground_pitch: f32,
    /// `NAV_LIFTOFF_ASPD`: airspeed at which the wing at [`NavParams::ground_pitch`] lifts the
    /// weight, m/s: `sqrt(2 m g / (rho S C_L))` with the lift coefficient at that attitude
    /// (the Ultra Stick's 0.80 at its 8.7 deg: 11.2 m/s). The landing's thresholds are fractions
    /// of it, where that attitude lifts a known share of the weight: a go-around from it up
    /// (the wing carries the weight), the disarm while rolling below 10/11 of it (83 % of the
    /// weight), the tail held down below 9/11 (67 %) and fully below 6/11 (30 %).
    pub liftoff_airspeed: f32,
    /// Approach integral gain on the height error, 1/s.
    pub approach_i: f32,
    /// Largest height the approach's command lies below the present height, m.
    pub approach_dive: f32,
    /// Flare's sink aim per metre past the land point, 1/s.
    pub flare_past_k: f32,
    /// Flare throttle at the flare height, 0..1.
    pub flare_throttle: f32,
}

const ZERO: NavParams = NavParams {
    accept_radius: 0.0,
    loiter_radius: 0.0,
    alt_accept: 0.0,
    airspeed: 0.0,
    airspeed_min: 0.0,
    airspeed_max: 0.0,
    rtl_alt: 0.0,
    rtl_land: false,
    takeoff_vr: 0.0,
    takeoff_airspeed: 0.0,
    takeoff_clear: 0.0,
    takeoff_ramp: 0.0,
    takeoff_roll_max: 0.0,
    takeoff_heading_max: 0.0,
    land_disarm_s: 0.0,
    land_abort: 0.0,
    land_use_rng: false,
    glide_slope: 0.0,
    land_airspeed: 0.0,
    flare_alt: 0.0,
    flare_time: 0.0,
    land_wind_k: 0.0,
    land_gust_k: 0.0,
    flare_pitch: 0.0,
    flare_pitch_max: 0.0,
    flare_sink: 0.0,
    flare_k: 0.0,
    touchdown_alt: 0.0,
    steer_k: 0.0,
    steer_d: 0.0,
    takeoff_to_item: false,
    ground_roll_max: 0.0,
    ground_roll_height: 0.0,
    wing_span: 0.0,
    tip_ground_bank: 0.0,
    ground_pitch: 0.0,
    liftoff_airspeed: 0.0,
    approach_i: 0.0,
    approach_dive: 0.0,
    flare_past_k: 0.0,
    flare_throttle: 0.0,
};

impl Default for NavParams {
    fn default() -> Self {
        PARAMS.defaults()
    }
}

impl NavParams {
    /// The bank allowed at `height` (m) above the ground, rad: `NAV_GND_RLL_DEG` on it,
    /// widening linearly to 90 deg at `widen_m` (m; `NAV_GND_RLL_M` near the ground, more in
    /// the flare). `None` from there up, where the roll limit alone governs, and for an
    /// unknown height.
    ///
    /// No wider either than the bank that leaves a wing tip half the clearance it has wings
    /// level ([`NavParams::bank_for_tip_clearance`]): the span, not a tuned height, bounds a
    /// large aircraft's bank.
    pub fn bank_near_ground(&self, height: f32, widen_m: f32) -> Option<f32> {
        let frac = if widen_m > 0.0 && height.is_finite() {
            (height / widen_m).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let linear = (frac < 1.0)
            .then_some(self.ground_roll_max + (90.0 * DEG - self.ground_roll_max) * frac);
        match (linear, self.bank_for_tip_clearance(height)) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    /// The bank at `height` (m, the wheels above the ground) that leaves the lower wing tip
    /// half the clearance it has wings level, rad; `None` where that is no limit (or the
    /// height is unknown). Wings level with the wheels on the ground the tip is
    /// `b/2 sin(phi_0)` up (`NAV_SPAN_M` = b, `NAV_TIP_GND_DEG` = phi_0); at height `h` it is
    /// `h + b/2 sin(phi_0)` up and a bank `phi` lowers it by `b/2 sin(phi)`, so the bank
    /// allowed is `asin((sin(phi_0) + 2h/b) / 2)`.
    pub fn bank_for_tip_clearance(&self, height: f32) -> Option<f32> {
        let half_span = 0.5 * self.wing_span;
        if !(height.is_finite() && half_span > 0.0) {
            return None;
        }
        let sin = 0.5
            * (crate::math::elementary::sin(self.tip_ground_bank) + height.max(0.0) / half_span);
        (sin < 1.0).then(|| crate::math::elementary::asin(sin))
    }
}

/// Airspeeds in order: cruise and approach inside the settable range; the flare's pitch at
/// the touchdown sink within its largest.
fn consistent(p: &NavParams) -> Result<(), &'static str> {
    if p.flare_pitch > p.flare_pitch_max {
        return Err("NAV_FLR_PMAX_DEG");
    }
    if p.airspeed_min >= p.airspeed_max {
        return Err("NAV_ASPD_MIN");
    }
    if !(p.airspeed_min..=p.airspeed_max).contains(&p.airspeed) {
        return Err("NAV_ASPD");
    }
    if !(p.airspeed_min..=p.airspeed_max).contains(&p.land_airspeed) {
        return Err("NAV_LND_ASPD");
    }
    Ok(())
}
