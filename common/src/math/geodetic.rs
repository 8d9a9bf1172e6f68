//! Geodetic positions and their local NED offsets.
//!
//! Positions travel as MAVLink does, in integer 1e-7 degrees, because an `f32` latitude in
//! radians resolves only ~0.4 m. Offsets from a reference point are formed in integers first
//! and only then scaled, on the WGS-84 ellipsoid's local radii of curvature at the reference:
//! the flat-earth frame of the plant, with north along the meridian. Distances within 1 km of
//! the reference agree with a full ECEF conversion to better than 1 cm, far below GPS noise;
//! the simulator and the firmware both use these two functions, so they agree exactly.

use nalgebra::RealField;
use simba::scalar::SupersetOf;

/// WGS-84 semi-major axis, m.
pub const WGS84_A_M: f64 = 6_378_137.0;
/// WGS-84 first eccentricity squared.
pub const WGS84_E2: f64 = 6.694_379_990_14e-3;

const E7_PER_DEG: f64 = 1e7;
const DEG_E7_FULL_TURN: i64 = 3_600_000_000;

/// A latitude/longitude pair in 1e-7 degrees (MAVLink's `lat`/`lon` fields).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GeoPoint {
    /// Latitude, 1e-7 deg, positive north.
    pub lat_e7: i32,
    /// Longitude, 1e-7 deg, positive east.
    pub lon_e7: i32,
}

impl GeoPoint {
    /// From degrees (rounded to the nearest 1e-7 deg).
    pub fn from_deg(lat_deg: f64, lon_deg: f64) -> Self {
        Self {
            lat_e7: round_e7(lat_deg * E7_PER_DEG),
            lon_e7: round_e7(lon_deg * E7_PER_DEG),
        }
    }

    /// Latitude in degrees.
    pub fn lat_deg(&self) -> f64 {
        deg_of_e7(self.lat_e7)
    }

    /// Longitude in degrees.
    pub fn lon_deg(&self) -> f64 {
        deg_of_e7(self.lon_e7)
    }

    /// True when latitude is within +-90 deg and longitude within +-180 deg.
    pub fn is_valid(&self) -> bool {
        self.lat_e7.unsigned_abs() <= 900_000_000 && self.lon_e7.unsigned_abs() <= 1_800_000_000
    }
}

/// `e7 / 1e7`, rounded to the nearest `f64` (ties to even) as IEEE 754's division rounds it,
/// in integers: the board's FPU has no `f64`, and a flight log's latitudes and longitudes are
/// `f64` degrees (PX4's `vehicle_global_position`), which soft-float arithmetic would cost
/// a kilobyte of flash for.
pub fn deg_of_e7(e7: i32) -> f64 {
    const D: u64 = 10_000_000;
    let sign = u64::from(e7 < 0) << 63;
    let x = u64::from(e7.unsigned_abs());
    if x == 0 {
        return f64::from_bits(sign);
    }
    // x scaled into [2^30, 2^31) (i32::MIN's 2^31 halves exactly), so that x / D lies in
    // [107, 215) and floor(x 2^64 / D) has 71 or 72 bits: its top 53, a rounding bit and
    // whether anything below is non-zero fix the result.
    let up = 31 - i64::from(64 - x.leading_zeros());
    let x = if up >= 0 { x << up } else { x >> 1 };
    let q1 = (x << 32) / D;
    let r1 = (x << 32) % D;
    let q2 = (r1 << 32) / D;
    let exact_below = (r1 << 32).is_multiple_of(D);
    // floor(x 2^64 / D) >> 18, and the 18 bits shifted out.
    let top = (q1 << 14) | (q2 >> 18);
    let low = q2 & ((1 << 18) - 1);
    let (mant, cut, round, rest_zero) = if top >> 53 != 0 {
        (top >> 1, 19, top & 1 == 1, low == 0 && exact_below)
    } else {
        (
            top,
            18,
            low >> 17 == 1,
            low & ((1 << 17) - 1) == 0 && exact_below,
        )
    };
    let mut mant = mant;
    let mut exp = 1023 + 52 + cut - 64 - up;
    if round && (!rest_zero || mant & 1 == 1) {
        mant += 1;
        if mant >> 53 != 0 {
            mant >>= 1;
            exp += 1;
        }
    }
    f64::from_bits(sign | ((exp as u64) << 52) | (mant & ((1 << 52) - 1)))
}

fn round_e7(x: f64) -> i32 {
    let r = if x >= 0.0 { x + 0.5 } else { x - 0.5 };
    // Saturating cast: out-of-range input is caught by `is_valid`, never wrapped.
    r as i32
}

// The `f64` conversions serve the plant and the host's tools; the board's flight code takes
// [`LocalFrame`], in `f32`.
use libm::{cos as lat_cos, sin as lat_sin};

use super::elementary::BOARD_ARITHMETIC;

/// Meridian and prime-vertical radii of curvature (m) at a latitude.
fn radii(lat_rad: f64) -> (f64, f64) {
    let s = lat_sin(lat_rad);
    let w2 = 1.0 - WGS84_E2 * s * s;
    let w = libm::sqrt(w2);
    (WGS84_A_M * (1.0 - WGS84_E2) / (w2 * w), WGS84_A_M / w)
}

fn deg_e7_to_rad(d: i64) -> f64 {
    d as f64 / E7_PER_DEG * core::f64::consts::PI / 180.0
}

/// A longitude, or a difference of two, in 1e-7 deg brought within half a turn of zero (the
/// short way across the antimeridian).
fn wrap_lon_e7(d: i64) -> i64 {
    if d > DEG_E7_FULL_TURN / 2 {
        d - DEG_E7_FULL_TURN
    } else if d < -DEG_E7_FULL_TURN / 2 {
        d + DEG_E7_FULL_TURN
    } else {
        d
    }
}

/// North and east offsets (m) of `p` from `origin`.
pub fn ned_offset<T: RealField + Copy>(origin: GeoPoint, p: GeoPoint) -> (T, T) {
    let dlat = i64::from(p.lat_e7) - i64::from(origin.lat_e7);
    // Take the short way across the antimeridian.
    let dlon = wrap_lon_e7(i64::from(p.lon_e7) - i64::from(origin.lon_e7));
    // Radii at the middle latitude: the parallel shrinks with latitude, and scaling east by
    // the reference's cosine alone costs 3 cm at 1 km on the diagonal.
    let lat_mid = deg_e7_to_rad(i64::from(origin.lat_e7)) + 0.5 * deg_e7_to_rad(dlat);
    let (m, n) = radii(lat_mid);
    let north = deg_e7_to_rad(dlat) * m;
    let east = deg_e7_to_rad(dlon) * n * lat_cos(lat_mid);
    (T::from_subset(&north), T::from_subset(&east))
}

/// The point at `north`, `east` metres from `origin` (the inverse of [`ned_offset`]).
///
/// Non-finite offsets return the origin rather than a garbage position.
pub fn offset_point<T: RealField + Copy>(origin: GeoPoint, north: T, east: T) -> GeoPoint {
    let (Some(north), Some(east)) = (
        SupersetOf::<f64>::to_subset(&north),
        SupersetOf::<f64>::to_subset(&east),
    ) else {
        return origin;
    };
    if !north.is_finite() || !east.is_finite() {
        return origin;
    }
    let lat0 = deg_e7_to_rad(i64::from(origin.lat_e7));
    let to_e7 = 180.0 / core::f64::consts::PI * E7_PER_DEG;
    // The latitude comes first and fixes the middle latitude, so this inverts `ned_offset`
    // without iteration (the meridian radius hardly changes over the step).
    let (m0, _) = radii(lat0);
    let (m, _) = radii(lat0 + 0.5 * north / m0);
    let dlat_rad = north / m;
    let lat_mid = lat0 + 0.5 * dlat_rad;
    let (_, n) = radii(lat_mid);
    let dlat = dlat_rad * to_e7;
    let dlon = east / (n * lat_cos(lat_mid)) * to_e7;
    let lat = f64::from(origin.lat_e7) + dlat;
    let mut lon = f64::from(origin.lon_e7) + dlon;
    if lon > 1.8e9 {
        lon -= 3.6e9;
    } else if lon < -1.8e9 {
        lon += 3.6e9;
    }
    GeoPoint {
        lat_e7: round_e7(lat),
        lon_e7: round_e7(lon),
    }
}

/// North and east (m) of `p` from `origin` as the flight code takes them: on the board through
/// a [`LocalFrame`] in `f32` (no software `f64`); on the host build the generic `f64`
/// [`ned_offset`] unless `bounded-trig` (the two agree within 5 mm within 10 km of the origin:
/// test below), as its flights and campaigns were computed.
pub fn flight_ned_offset(origin: GeoPoint, p: GeoPoint) -> (f32, f32) {
    if BOARD_ARITHMETIC {
        LocalFrame::new(origin).ned_offset(p)
    } else {
        ned_offset(origin, p)
    }
}

/// The point `north`, `east` metres from `origin` as the flight code takes it (as
/// [`flight_ned_offset`]: the board's [`LocalFrame`], the host's [`offset_point`]).
pub fn flight_offset_point(origin: GeoPoint, north: f32, east: f32) -> GeoPoint {
    if BOARD_ARITHMETIC {
        LocalFrame::new(origin).offset_point(north, east)
    } else {
        offset_point(origin, north, east)
    }
}

/// Radians per 1e-7 degree.
const RAD_PER_E7: f64 = core::f64::consts::PI / 180.0 / E7_PER_DEG;

/// The local NED frame about one origin, for the flight code's `f32` arithmetic: the radii of
/// curvature are worked out once, when the origin is set, as second-order expansions in the
/// latitude offset, so an offset or a point costs a dozen `f32` operations and no
/// trigonometry (the generic functions above take three sines, a cosine and three square
/// roots in `f64` per point, which the Cortex-M4F's single-precision FPU does in software).
/// Within 10 km of the origin at latitudes up to 80 deg the two agree to a few millimetres
/// (test below); the offsets are formed in integers first, as above.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalFrame {
    origin: GeoPoint,
    /// Meridian radius at the origin's latitude plus `x`: `m[0] + m[1] x + m[2] x^2`, m.
    m: [f32; 3],
    /// Radius of the parallel (prime-vertical radius times the cosine) likewise, m.
    c: [f32; 3],
}

impl LocalFrame {
    /// The frame about `origin`: on the board [`Self::with_f32_radii`], on the host
    /// [`Self::with_f64_radii`] (unless `bounded-trig`), which agree within millimetres.
    pub fn new(origin: GeoPoint) -> Self {
        if BOARD_ARITHMETIC {
            Self::with_f32_radii(origin)
        } else {
            Self::with_f64_radii(origin)
        }
    }

    /// The frame about `origin` with the radii and their first two derivatives in the
    /// latitude worked out in `f32` (the meridian radius `M = a (1 - e^2) / W^3` with `W^2 =
    /// 1 - e^2 sin^2`, so `M' = 3 e^2 M sin cos / W^2`; the parallel's radius `P = a cos / W`,
    /// whose derivative is `-M sin`): the board's, which has no `f64` in hardware.
    pub fn with_f32_radii(origin: GeoPoint) -> Self {
        let lat0 = origin.lat_e7 as f32 * RAD_PER_E7 as f32;
        let (s, c) = super::elementary::sin_cos(lat0);
        let (a, e2) = (WGS84_A_M as f32, WGS84_E2 as f32);
        let w2 = 1.0 - e2 * s * s;
        let w = libm::sqrtf(w2);
        let m = a * (1.0 - e2) / (w2 * w);
        // M' = 3 e^2 M g with g = sin cos / W^2, g' = (cos^2 - sin^2) / W^2 + 2 e^2 g^2.
        let g = s * c / w2;
        let dm = 3.0 * e2 * m * g;
        let dg = (c * c - s * s) / w2 + 2.0 * e2 * g * g;
        let ddm = 3.0 * e2 * (dm * g + m * dg);
        let p = a * c / w;
        let dp = -m * s;
        let ddp = -(dm * s + m * c);
        Self {
            origin,
            m: [m, dm, 0.5 * ddm],
            c: [p, dp, 0.5 * ddp],
        }
    }

    /// The frame about `origin` with the radii's expansion from central differences of the
    /// `f64` radii over 1 mrad (the third-order terms they leave are far below `f32`'s
    /// resolution of the radii): the host build's, as its flights were first computed.
    pub fn with_f64_radii(origin: GeoPoint) -> Self {
        let lat0 = f64::from(origin.lat_e7) * RAD_PER_E7;
        let h = 1e-3;
        let parallel = |lat: f64| {
            let (_, n) = radii(lat);
            n * lat_cos(lat)
        };
        let meridian = |lat: f64| radii(lat).0;
        let expand = |f: &dyn Fn(f64) -> f64| {
            let (lo, mid, hi) = (f(lat0 - h), f(lat0), f(lat0 + h));
            [
                mid as f32,
                ((hi - lo) / (2.0 * h)) as f32,
                ((hi - 2.0 * mid + lo) / (2.0 * h * h)) as f32,
            ]
        };
        Self {
            origin,
            m: expand(&meridian),
            c: expand(&parallel),
        }
    }

    /// The origin.
    pub fn origin(&self) -> GeoPoint {
        self.origin
    }

    fn at(k: &[f32; 3], x: f32) -> f32 {
        k[0] + x * (k[1] + x * k[2])
    }

    /// North and east offsets (m) of `p` from the origin (as [`ned_offset`]).
    pub fn ned_offset(&self, p: GeoPoint) -> (f32, f32) {
        let dlat = i64::from(p.lat_e7) - i64::from(self.origin.lat_e7);
        let dlon = wrap_lon_e7(i64::from(p.lon_e7) - i64::from(self.origin.lon_e7));
        let k = RAD_PER_E7 as f32;
        let (dlat, dlon) = (dlat as f32 * k, dlon as f32 * k);
        let mid = 0.5 * dlat;
        (dlat * Self::at(&self.m, mid), dlon * Self::at(&self.c, mid))
    }

    /// The point at `north`, `east` metres from the origin (as [`offset_point`]); non-finite
    /// offsets return the origin.
    pub fn offset_point(&self, north: f32, east: f32) -> GeoPoint {
        if !north.is_finite() || !east.is_finite() {
            return self.origin;
        }
        // The latitude first, at the meridian radius of the middle latitude (one refinement
        // from the origin's: the radius hardly changes over the step).
        let first = north / self.m[0];
        let dlat = north / Self::at(&self.m, 0.5 * first);
        let dlon = east / Self::at(&self.c, 0.5 * dlat);
        let k = RAD_PER_E7 as f32;
        let round = |x: f32| -> i64 {
            let r = if x >= 0.0 { x + 0.5 } else { x - 0.5 };
            // Saturating: a step beyond the globe is caught by `is_valid`, never wrapped.
            r as i64
        };
        let lat = i64::from(self.origin.lat_e7).saturating_add(round(dlat / k));
        let lon = wrap_lon_e7(i64::from(self.origin.lon_e7).saturating_add(round(dlon / k)));
        let to_i32 = |x: i64| x.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32;
        GeoPoint {
            lat_e7: to_i32(lat),
            lon_e7: to_i32(lon),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn ecef(lat: f64, lon: f64) -> [f64; 3] {
        let (s, c) = (lat.sin(), lat.cos());
        let n = WGS84_A_M / libm::sqrt(1.0 - WGS84_E2 * s * s);
        [
            n * c * lon.cos(),
            n * c * lon.sin(),
            n * (1.0 - WGS84_E2) * s,
        ]
    }

    #[test]
    fn distances_match_ecef_within_a_centimetre_at_1km() {
        // The thesis's home point (UMN), and points ~1 km away in several directions.
        let home = GeoPoint::from_deg(44.7258357, -93.07501316);
        let a = ecef(home.lat_deg().to_radians(), home.lon_deg().to_radians());
        for (dlat, dlon) in [
            (0.0072, 0.0100),
            (-0.009, 0.0),
            (0.0, -0.0127),
            (0.005, -0.004),
        ] {
            let p = GeoPoint::from_deg(home.lat_deg() + dlat, home.lon_deg() + dlon);
            let (n, e): (f64, f64) = ned_offset(home, p);
            let b = ecef(p.lat_deg().to_radians(), p.lon_deg().to_radians());
            let chord =
                ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2)).sqrt();
            let d = (n * n + e * e).sqrt();
            assert!(
                (d - chord).abs() < 0.01,
                "distance {d} vs ECEF chord {chord}"
            );
        }
    }

    #[test]
    fn round_trip_in_f32() {
        let home = GeoPoint::from_deg(44.7258357, -93.07501316);
        let p = offset_point(home, 1234.5_f32, -678.9_f32);
        let (n, e): (f32, f32) = ned_offset(home, p);
        // One 1e-7 deg step is ~1.1 cm of latitude.
        assert_relative_eq!(n, 1234.5, epsilon = 0.02);
        assert_relative_eq!(e, -678.9, epsilon = 0.02);
    }

    #[test]
    fn antimeridian_and_bad_input() {
        let a = GeoPoint::from_deg(0.0, 179.9999);
        let b = GeoPoint::from_deg(0.0, -179.9999);
        let (_, e): (f64, f64) = ned_offset(a, b);
        assert!(e > 0.0 && e < 30.0, "east {e}");
        assert_eq!(offset_point(a, f32::NAN, 1.0), a);
        assert!(!GeoPoint {
            lat_e7: 910_000_000,
            lon_e7: 0
        }
        .is_valid());
    }

    /// Every 1e-7 degree from -180 to 180 deg in steps of 7,919 (a prime, so every last digit
    /// is met), the ends and i32's extremes: bit for bit `f64`'s correctly rounded quotient.
    #[test]
    fn degrees_of_1e7_units_are_the_correctly_rounded_quotient_bit_for_bit() {
        let check = |e7: i32| {
            let want = f64::from(e7) / 1e7;
            assert_eq!(deg_of_e7(e7).to_bits(), want.to_bits(), "{e7}: {want}");
        };
        let mut e7 = -1_800_000_000;
        while e7 <= 1_800_000_000 {
            check(e7);
            e7 += 7_919;
        }
        for e7 in [
            0,
            1,
            -1,
            5,
            10_000_000,
            447_258_357,
            -930_750_131,
            i32::MAX,
            i32::MIN,
        ] {
            check(e7);
        }
        assert!(deg_of_e7(0).to_bits() == 0 && deg_of_e7(-1) < 0.0);
    }

    #[test]
    fn the_local_frame_agrees_with_the_generic_conversions_within_millimetres() {
        for (lat, lon) in [
            (44.7258357, -93.07501316),
            (0.0, 179.99),
            (-33.9, 18.4),
            (80.0, 5.0),
        ] {
            let home = GeoPoint::from_deg(lat, lon);
            for frame in [
                LocalFrame::with_f32_radii(home),
                LocalFrame::with_f64_radii(home),
            ] {
                for (n, e) in [
                    (1234.5_f64, -678.9_f64),
                    (-9000.0, 4000.0),
                    (7000.0, 7000.0),
                    (-300.0, -9900.0),
                    (0.0, 0.0),
                ] {
                    let p = offset_point(home, n, e);
                    let q = frame.offset_point(n as f32, e as f32);
                    // One 1e-7 deg step is ~1.1 cm: the points may differ by one rounding.
                    assert!(
                        (p.lat_e7 - q.lat_e7).abs() <= 1 && (p.lon_e7 - q.lon_e7).abs() <= 1,
                        "{lat} {n} {e}: {p:?} vs {q:?}"
                    );
                    let (gn, ge): (f64, f64) = ned_offset(home, p);
                    let (fn_, fe) = frame.ned_offset(p);
                    assert!(
                        (f64::from(fn_) - gn).abs() < 5e-3 && (f64::from(fe) - ge).abs() < 5e-3,
                        "{lat} {n} {e}: ({gn}, {ge}) vs ({fn_}, {fe})"
                    );
                }
                assert_eq!(frame.offset_point(f32::NAN, 1.0), home);
            }
        }
    }
}
