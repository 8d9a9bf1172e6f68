//! Strikes: a point of the airframe other than its wheels (nose, propeller, wing tips,
//! fuselage, tail) below the ground while armed, read from a flight's log with the aircraft's
//! ground-contact geometry. The one definition of a strike: the flight summary reports them
//! as events and fails on one, and a campaign's `no_strike` criterion reads the same.

use super::record::Sample;
use crate::aircraft::Aircraft;
use common::math::Euler;
use nalgebra::Vector3;
use serde::Serialize;

/// A non-wheel point of the airframe, from the CG in body axes, named for the report.
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    /// What it is, and where the aircraft file has it.
    pub name: String,
    /// From the CG, body axes, m.
    pub body: Vector3<f64>,
    /// Extra reach below the point whatever the attitude's roll (the propeller disc's radius,
    /// in the body y-z plane).
    pub disc_radius: f64,
}

/// The points that must never touch: every belly point of the aircraft file and the lowest
/// point of the propeller disc, whose hub is at `propeller_hub_m` from the CG.
pub fn strike_points(a: &Aircraft, propeller_hub_m: [f64; 3]) -> Vec<Point> {
    let half_span = 0.5 * a.geometry.b_m;
    let mut v: Vec<Point> = a
        .ground
        .belly_points_m
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let what = if p[1].abs() > 0.5 * half_span {
                if p[1] < 0.0 {
                    "left wing tip"
                } else {
                    "right wing tip"
                }
            } else if p[0] > 0.15 {
                "nose"
            } else if p[0] < -0.2 {
                "tail"
            } else {
                "fuselage"
            };
            Point {
                name: format!("{what} (belly_points_m[{i}])"),
                body: Vector3::from(*p),
                disc_radius: 0.0,
            }
        })
        .collect();
    v.push(Point {
        name: "propeller".into(),
        body: Vector3::from(propeller_hub_m),
        disc_radius: a.propulsion.prop_radius_m,
    });
    v
}

/// What a point is, without where the aircraft file has it (`"nose"`, `"propeller"`).
pub fn kind(point: &str) -> &str {
    point.split(" (").next().unwrap_or(point)
}

/// Where the propeller's hub is, from the CG in body axes, m. The aircraft file's
/// `prop_arm_from_cg_m` is the UMN model's: only its z acts (the thrust is along x), and its x
/// is the difference of the UMN station coordinates, which grow aft. The Ultra Stick is a
/// tractor, so the hub is that far ahead of the CG; a shift `cg_shift_m` of the CG moves it
/// back by as much.
pub fn propeller_hub_m(nominal: &Aircraft, cg_shift_m: [f64; 3]) -> [f64; 3] {
    let p = nominal.geometry.prop_arm_from_cg_m;
    [
        p[0].abs() - cg_shift_m[0],
        p[1] - cg_shift_m[1],
        p[2] - cg_shift_m[2],
    ]
}

/// Height of a point above the ground at a sample (the ground is home's altitude).
pub fn clearance(s: &Sample, home_alt: f64, p: &Point) -> f64 {
    let r = Euler::new(s.roll, s.pitch, s.yaw).body_to_ned();
    let down = (r * p.body).z;
    // The disc spans the body y-z plane: its lowest point reaches R * sqrt(r_zy^2 + r_zz^2)
    // further down.
    let disc = p.disc_radius * r[(2, 1)].hypot(r[(2, 2)]);
    (s.alt - home_alt) - down - disc
}

/// A clearance that is a strike: the point is below the ground.
fn touches(clearance_m: f64) -> bool {
    clearance_m < 0.0
}

/// The strike criterion on the smallest clearance of a flight while armed: met when it was
/// measured (the flight was armed) and nothing touched.
pub fn strike_free(min_clearance_m: Option<f64>) -> bool {
    min_clearance_m.is_some_and(|c| !touches(c))
}

/// The navigator's phase by its index in the log, in words.
pub fn phase_name(index: u8) -> String {
    use common::navigation::Phase as P;
    let known = [
        (P::Idle, "idle (armed, mission not started)"),
        (P::TakeoffRoll, "take-off roll"),
        (P::TakeoffClimb, "take-off climb"),
        (P::Waypoint, "waypoint"),
        (P::Loiter, "loiter"),
        (P::Return, "return"),
        (P::ReturnLoiter, "return loiter"),
        (P::Approach, "approach"),
        (P::Flare, "flare"),
        (P::Landed, "roll-out"),
        (P::Hold, "hold"),
        (P::Complete, "complete"),
        (P::GoAround, "go-around"),
        (P::TakeoffAbort, "aborted take-off"),
    ];
    known
        .iter()
        .find(|(p, _)| *p as u8 == index)
        .map_or_else(|| format!("phase {index}"), |(_, n)| n.to_string())
}

/// One strike: a point going below the ground, and how deep it went before it came clear.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StrikeEvent {
    /// When it touched, s of simulated time.
    pub t_s: f64,
    /// Which point.
    pub point: String,
    /// The navigator's phase then.
    pub phase: String,
    /// The lowest it went below the ground in this contact, m (positive).
    pub depth_m: f64,
}

/// The closest call of a flight: the smallest clearance of any non-wheel point while armed.
#[derive(Clone, Debug, PartialEq)]
pub struct ClosestCall {
    /// Clearance, m (negative: it touched).
    pub clearance_m: f64,
    /// Which point.
    pub point: String,
    /// When, s.
    pub t_s: f64,
    /// The navigator's phase then.
    pub phase: String,
}

/// The clearances of a flight's armed samples: the closest call and every strike.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Survey {
    /// The smallest clearance (`None`: never armed).
    pub closest: Option<ClosestCall>,
    /// Each contact of a point with the ground, in order of time.
    pub strikes: Vec<StrikeEvent>,
}

impl Survey {
    /// The strike criterion ([`strike_free`]) on this flight.
    pub fn strike_free(&self) -> bool {
        strike_free(self.closest.as_ref().map(|c| c.clearance_m))
    }
}

/// Surveys `points` over the armed samples: a strike starts when a point goes below the
/// ground and lasts while it stays there (one event per contact, not per frame).
pub fn survey(samples: &[Sample], points: &[Point], home_alt: f64) -> Survey {
    let mut out = Survey::default();
    // Index into `out.strikes` of each point's contact in progress.
    let mut open: Vec<Option<usize>> = vec![None; points.len()];
    for s in samples.iter().filter(|s| s.armed) {
        for (i, p) in points.iter().enumerate() {
            let c = clearance(s, home_alt, p);
            if out.closest.as_ref().is_none_or(|m| c < m.clearance_m) {
                out.closest = Some(ClosestCall {
                    clearance_m: c,
                    point: p.name.clone(),
                    t_s: s.t,
                    phase: phase_name(s.nav_phase),
                });
            }
            if !touches(c) {
                open[i] = None;
                continue;
            }
            match open[i] {
                Some(k) => out.strikes[k].depth_m = out.strikes[k].depth_m.max(-c),
                None => {
                    open[i] = Some(out.strikes.len());
                    out.strikes.push(StrikeEvent {
                        t_s: s.t,
                        point: p.name.clone(),
                        phase: phase_name(s.nav_phase),
                        depth_m: -c,
                    });
                }
            }
        }
    }
    out
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::plant::ground::rest_state;
    use crate::plant::ModelParams;

    /// A log sample of the aircraft at rest on its wheels at home, armed.
    pub(crate) fn at_rest(a: &Aircraft) -> Sample {
        let (state, _) = rest_state(&ModelParams::new(a), 0.0, 0.0, 0.0);
        let e = Euler::from_quaternion(&state.attitude);
        Sample {
            alt: a.environment.home_alt_msl_m - state.pos_ned.z,
            roll: e.phi,
            pitch: e.theta,
            yaw: e.psi,
            armed: true,
            ..Sample::default()
        }
    }

    #[test]
    fn at_rest_every_non_wheel_point_clears_the_runway_and_a_20_degree_roll_puts_a_tip_on_it() {
        let a = Aircraft::ultrastick25e().unwrap();
        let points = strike_points(&a, propeller_hub_m(&a, [0.0; 3]));
        let home = a.environment.home_alt_msl_m;
        let rest = at_rest(&a);
        for p in &points {
            let c = clearance(&rest, home, p);
            // The tail skid sits 5 cm up in the three-point attitude; the propeller more.
            assert!(c > 0.04, "{}: {c}", p.name);
        }
        // The tips are 0.635 m out and 0.16 m up: the ground is reached at asin(0.16/0.635),
        // about 14.6 degrees.
        let rolled = Sample {
            roll: 20f64.to_radians(),
            ..rest
        };
        let tip = points
            .iter()
            .find(|p| p.name.starts_with("right wing tip"))
            .unwrap();
        assert!(clearance(&rolled, home, tip) < 0.0);
    }

    #[test]
    fn the_propeller_disc_reaches_its_radius_below_the_hub_whatever_the_roll() {
        let a = Aircraft::ultrastick25e().unwrap();
        let hub = propeller_hub_m(&a, [0.0; 3]);
        assert!(
            hub[0] > 0.25,
            "a tractor's propeller is ahead of the CG: {hub:?}"
        );
        let p = Point {
            name: "propeller".into(),
            body: Vector3::from(hub),
            disc_radius: 0.1524,
        };
        let level = Sample {
            alt: 1.0,
            ..Sample::default()
        };
        let rolled = Sample { roll: 0.7, ..level };
        let expect = 1.0 - hub[2] - 0.1524;
        assert!((clearance(&level, 0.0, &p) - expect).abs() < 1e-12);
        assert!((clearance(&rolled, 0.0, &p) - clearance(&level, 0.0, &p)).abs() < 0.05);
    }

    #[test]
    fn a_wing_rocked_onto_the_runway_twice_is_two_strikes_of_that_tip_and_fails_the_criterion() {
        // Rolled right 20 deg from the rest attitude the right tip is below the runway (it
        // reaches it at 14.6 deg); back level it is clear. Rocking right, level, right again
        // while armed is two contacts of the right tip, the deeper one at the larger roll;
        // disarmed, the same rocking is no strike.
        let a = Aircraft::ultrastick25e().unwrap();
        let points = strike_points(&a, propeller_hub_m(&a, [0.0; 3]));
        let home = a.environment.home_alt_msl_m;
        let rest = at_rest(&a);
        let rolls: [f64; 6] = [0.0, 20.0, 22.0, 0.0, 18.0, 0.0];
        let log: Vec<Sample> = rolls
            .iter()
            .enumerate()
            .map(|(k, r)| Sample {
                t: k as f64,
                roll: r.to_radians(),
                ..rest
            })
            .collect();
        let s = survey(&log, &points, home);
        assert_eq!(s.strikes.len(), 2, "{:?}", s.strikes);
        assert!(s
            .strikes
            .iter()
            .all(|e| e.point.starts_with("right wing tip")));
        assert_eq!((s.strikes[0].t_s, s.strikes[1].t_s), (1.0, 4.0));
        let deep = |roll: f64| {
            let tip = points.iter().find(|p| p.name.starts_with("right wing tip"));
            let x = Sample {
                roll: roll.to_radians(),
                ..rest
            };
            -clearance(&x, home, tip.unwrap())
        };
        assert_eq!(s.strikes[0].depth_m, deep(22.0));
        assert_eq!(s.strikes[1].depth_m, deep(18.0));
        assert!(!s.strike_free());
        assert_eq!(s.closest.as_ref().map(|c| c.t_s), Some(2.0));

        let level = survey(&log[..1], &points, home);
        assert!(level.strikes.is_empty() && level.strike_free());
        let disarmed: Vec<Sample> = log.iter().map(|x| Sample { armed: false, ..*x }).collect();
        let d = survey(&disarmed, &points, home);
        assert!(d.strikes.is_empty() && d.closest.is_none() && !d.strike_free());
    }
}
