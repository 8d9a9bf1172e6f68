//! The geofence: inclusion and exclusion polygons and circles from the fence list, plus a
//! maximum height above home.
//!
//! Polygons are runs of `NAV_FENCE_POLYGON_VERTEX_*` items whose `param1` is the run's vertex
//! count (the MAVLink fence protocol). The aircraft is inside the fence when it is inside at
//! least one inclusion zone (if there is any) and inside no exclusion zone. The test is the
//! even-odd ray crossing in the local NED frame about home (flat earth, the frame of every other
//! position here). A malformed run (count under 3, or fewer items than it says) is skipped by
//! [`breached`] and refused by [`validate_fence`] at upload.

use super::items::{FENCE_POLYGON_EXCLUSION, FENCE_POLYGON_INCLUSION};
use super::plan::MissionItem;
use crate::estimator::Home;
use crate::math::geodetic::{flight_ned_offset, GeoPoint};
use crate::param;
use crate::params::{independent, Group, ParamDef};
use mavlink::dialects::common::{MavCmd, MavMissionResult};
use nalgebra::Vector3;

const CIRCLE_INCLUSION: u16 = MavCmd::MAV_CMD_NAV_FENCE_CIRCLE_INCLUSION as u16;
const CIRCLE_EXCLUSION: u16 = MavCmd::MAV_CMD_NAV_FENCE_CIRCLE_EXCLUSION as u16;

/// Parameters of the geofence.
pub const PARAMS: Group<FenceParams> = Group {
    name: "Geofence",
    params: &[param!(
        ParamDef::real(
            "GF_MAX_ALT_M",
            0.0,
            0.0,
            10000.0,
            "m",
            "Highest height above home inside the fence (0, the default as in PX4: no altitude limit)",
        ),
        FenceParams => max_alt
    )],
    base: || FenceParams { max_alt: 0.0 },
    check: independent,
};

/// The geofence's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FenceParams {
    /// Highest height above home, m; 0 for none.
    pub max_alt: f32,
}

impl Default for FenceParams {
    fn default() -> Self {
        PARAMS.defaults()
    }
}

/// Which rule of the fence is broken.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Breach {
    /// Above the maximum height.
    Altitude,
    /// Outside every inclusion zone.
    Outside,
    /// Inside an exclusion zone.
    Excluded,
}

/// One zone of the fence list.
enum Zone<'a> {
    Polygon(&'a [MissionItem], bool),
    Circle(&'a MissionItem, bool),
}

/// The zones of `fence` in order; malformed polygon runs as `Err(seq)`.
fn zones(fence: &[MissionItem]) -> impl Iterator<Item = Result<Zone<'_>, usize>> {
    let mut i = 0;
    core::iter::from_fn(move || loop {
        let it = fence.get(i)?;
        let seq = i;
        match it.command {
            FENCE_POLYGON_INCLUSION | FENCE_POLYGON_EXCLUSION => {
                let c = it.param(0);
                let count = if c.is_finite() && c >= 3.0 && libm::truncf(c) == c {
                    c as usize
                } else {
                    0
                };
                let run = fence.get(i..i.saturating_add(count)).filter(|r| {
                    count >= 3 && r.iter().all(|v| v.command == it.command && v.param(0) == c)
                });
                return Some(match run {
                    Some(r) => {
                        i += count;
                        Ok(Zone::Polygon(r, it.command == FENCE_POLYGON_INCLUSION))
                    }
                    None => {
                        // Skip the rest of this run of vertices.
                        i += 1;
                        while fence.get(i).is_some_and(|v| v.command == it.command) {
                            i += 1;
                        }
                        Err(seq)
                    }
                });
            }
            CIRCLE_INCLUSION | CIRCLE_EXCLUSION => {
                i += 1;
                return Some(Ok(Zone::Circle(it, it.command == CIRCLE_INCLUSION)));
            }
            _ => i += 1,
        }
    })
}

fn vertex(home: &Home, it: &MissionItem) -> (f32, f32) {
    flight_ned_offset(
        home.point,
        GeoPoint {
            lat_e7: it.x,
            lon_e7: it.y,
        },
    )
}

fn inside_polygon(home: &Home, vertices: &[MissionItem], n: f32, e: f32) -> bool {
    let mut inside = false;
    let mut prev = match vertices.last() {
        Some(v) => vertex(home, v),
        None => return false,
    };
    for v in vertices {
        let cur = vertex(home, v);
        let ((n1, e1), (n2, e2)) = (prev, cur);
        if (n1 > n) != (n2 > n) {
            let e_cross = e1 + (n - n1) / (n2 - n1) * (e2 - e1);
            if e < e_cross {
                inside = !inside;
            }
        }
        prev = cur;
    }
    inside
}

/// The first broken rule at `pos_ned` (NED from `home`), if any: altitude first, then the zones.
pub fn breached(
    fence: &[MissionItem],
    home: &Home,
    pos_ned: &Vector3<f32>,
    params: &FenceParams,
) -> Option<Breach> {
    if params.max_alt > 0.0 && -pos_ned.z > params.max_alt {
        return Some(Breach::Altitude);
    }
    let (n, e) = (pos_ned.x, pos_ned.y);
    let mut any_inclusion = false;
    let mut included = false;
    for zone in zones(fence).flatten() {
        let (inside, inclusion) = match zone {
            Zone::Polygon(v, inc) => (inside_polygon(home, v, n, e), inc),
            Zone::Circle(c, inc) => {
                let (cn, ce) = vertex(home, c);
                (
                    crate::math::elementary::hypot(n - cn, e - ce) <= c.param(0),
                    inc,
                )
            }
        };
        if inclusion {
            any_inclusion = true;
            included |= inside;
        } else if inside {
            return Some(Breach::Excluded);
        }
    }
    (any_inclusion && !included).then_some(Breach::Outside)
}

/// Checks a fence list at upload: the first malformed polygon run (`INVALID_PARAM1`: a vertex
/// count under 3 or more than the run holds), circle radius (`INVALID_PARAM1`) or vertex
/// position (`INVALID_PARAM5_X` / `INVALID_PARAM6_Y`), with its sequence number.
pub fn validate_fence(fence: &[MissionItem]) -> Result<(), (u16, MavMissionResult)> {
    let seq16 = |s: usize| u16::try_from(s).unwrap_or(u16::MAX);
    for (s, it) in fence.iter().enumerate() {
        if it.x.unsigned_abs() > 900_000_000 {
            return Err((seq16(s), MavMissionResult::MAV_MISSION_INVALID_PARAM5_X));
        }
        if it.y.unsigned_abs() > 1_800_000_000 {
            return Err((seq16(s), MavMissionResult::MAV_MISSION_INVALID_PARAM6_Y));
        }
        if matches!(it.command, CIRCLE_INCLUSION | CIRCLE_EXCLUSION)
            && !(it.param(0).is_finite() && it.param(0) > 0.0)
        {
            return Err((seq16(s), MavMissionResult::MAV_MISSION_INVALID_PARAM1));
        }
    }
    match zones(fence).find_map(Result::err) {
        Some(s) => Err((seq16(s), MavMissionResult::MAV_MISSION_INVALID_PARAM1)),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::geodetic::offset_point;
    use crate::params::validate_defs;

    use crate::navigation::tests::home;

    fn vertex_item(command: u16, count: f32, n: f32, e: f32) -> MissionItem {
        let p = offset_point(home().point, n, e);
        MissionItem {
            params: [count, 0.0, 0.0, 0.0].map(f32::to_bits),
            x: p.lat_e7,
            y: p.lon_e7,
            command,
            frame: 0,
            ..MissionItem::default()
        }
    }

    /// An L-shaped (concave) inclusion polygon: 0..400 north, 0..400 east, minus the corner
    /// north of 200 and east of 200.
    fn l_shape() -> [MissionItem; 6] {
        let v = |n, e| vertex_item(FENCE_POLYGON_INCLUSION, 6.0, n, e);
        [
            v(0.0, 0.0),
            v(400.0, 0.0),
            v(400.0, 200.0),
            v(200.0, 200.0),
            v(200.0, 400.0),
            v(0.0, 400.0),
        ]
    }

    fn at(n: f32, e: f32, h: f32) -> Vector3<f32> {
        Vector3::new(n, e, -h)
    }

    #[test]
    fn concave_polygon_and_altitude() {
        assert_eq!(validate_defs(PARAMS.defs()), Ok(()));
        let f = l_shape();
        assert_eq!(FenceParams::default().max_alt, 0.0);
        let p = FenceParams { max_alt: 120.0 };
        let h = home();
        assert_eq!(validate_fence(&f), Ok(()));
        assert_eq!(breached(&f, &h, &at(100.0, 100.0, 50.0), &p), None);
        assert_eq!(breached(&f, &h, &at(300.0, 100.0, 50.0), &p), None);
        assert_eq!(breached(&f, &h, &at(100.0, 300.0, 50.0), &p), None);
        // The missing corner, and beyond each side.
        assert_eq!(
            breached(&f, &h, &at(300.0, 300.0, 50.0), &p),
            Some(Breach::Outside)
        );
        assert_eq!(
            breached(&f, &h, &at(-5.0, 100.0, 50.0), &p),
            Some(Breach::Outside)
        );
        assert_eq!(
            breached(&f, &h, &at(100.0, 405.0, 50.0), &p),
            Some(Breach::Outside)
        );
        assert_eq!(
            breached(&f, &h, &at(100.0, 100.0, 121.0), &p),
            Some(Breach::Altitude)
        );
        let off = FenceParams { max_alt: 0.0 };
        assert_eq!(breached(&f, &h, &at(100.0, 100.0, 5000.0), &off), None);
        // No fence: only the altitude.
        assert_eq!(breached(&[], &h, &at(1e5, 1e5, 50.0), &p), None);
    }

    #[test]
    fn exclusion_zones_and_circles() {
        let h = home();
        let p = FenceParams::default();
        let x = |n, e| vertex_item(FENCE_POLYGON_EXCLUSION, 4.0, n, e);
        let mut f: heapless::Vec<MissionItem, 16> = heapless::Vec::new();
        f.extend_from_slice(&[
            x(50.0, 50.0),
            x(50.0, 100.0),
            x(100.0, 100.0),
            x(100.0, 50.0),
        ])
        .unwrap();
        f.push(vertex_item(CIRCLE_INCLUSION, 300.0, 0.0, 0.0))
            .unwrap();
        assert_eq!(validate_fence(&f), Ok(()));
        assert_eq!(breached(&f, &h, &at(0.0, 0.0, 50.0), &p), None);
        assert_eq!(
            breached(&f, &h, &at(75.0, 75.0, 50.0), &p),
            Some(Breach::Excluded)
        );
        assert_eq!(
            breached(&f, &h, &at(250.0, 200.0, 50.0), &p),
            Some(Breach::Outside)
        );
    }

    #[test]
    fn malformed_runs_are_refused_at_upload() {
        let f = l_shape();
        // The count says 6, only 5 vertices arrived.
        assert_eq!(
            validate_fence(&f[..5]),
            Err((0, MavMissionResult::MAV_MISSION_INVALID_PARAM1))
        );
        let two = [
            vertex_item(FENCE_POLYGON_INCLUSION, 2.0, 0.0, 0.0),
            vertex_item(FENCE_POLYGON_INCLUSION, 2.0, 10.0, 0.0),
        ];
        assert_eq!(
            validate_fence(&two),
            Err((0, MavMissionResult::MAV_MISSION_INVALID_PARAM1))
        );
        // Skipped in flight: no inclusion zone left, so no breach.
        assert_eq!(
            breached(
                &two,
                &home(),
                &at(500.0, 0.0, 10.0),
                &FenceParams::default()
            ),
            None
        );
        let mut bad = l_shape();
        bad[2].x = -900_000_001;
        assert_eq!(
            validate_fence(&bad),
            Err((2, MavMissionResult::MAV_MISSION_INVALID_PARAM5_X))
        );
    }
}
