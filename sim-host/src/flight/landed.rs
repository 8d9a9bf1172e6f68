//! Whether the landed state a ground station read (`EXTENDED_SYS_STATE`) told the truth about
//! a landing, judged against the plant's touchdown and the air over the wings after it.

use super::record::Sample;
use common::vehicle::land_detector::LandParams;

/// Longest time from the first contact to the station's `ON_GROUND`, s. A landing that bounces
/// along the runway in gusts (seven times on the pitot-failure flight of
/// `sim-host/tests/failsafe.rs`, its synthetic airspeed 1.7 m/s RMS off) is at rest on its
/// wheels 11.6-12.5 s after it; a clean one takes 7.3-7.6 s (the roll-out slowing under
/// `LND_VXY_MAX`, then `LND_TRIG_S`).
pub const ON_GROUND_WITHIN_S: f64 = 15.0;

/// Longest time from the moment a roll-out can no longer fly (see [`slow_from`]) to the
/// station's `ON_GROUND`, s: the detector's `LND_TRIG_S` (1.5 s), its filters' lag and the
/// estimated airspeed's error. It matters only after a roll-out that kept flying speed through
/// the air for longer than [`ON_GROUND_WITHIN_S`] allows: in a crosswind the aircraft
/// weathervanes against its steered tail wheel and sails along the runway with 10-13.5 m/s of
/// air over its wings, where the three-point attitude could lift it off, and LANDING is the
/// honest word until the air has slowed.
pub const ON_GROUND_AFTER_SLOW_S: f64 = 5.0;

/// When a roll-out can no longer fly: the first time from the touchdown at `touchdown_s` that
/// the true airspeed stays under the land detector's `LND_ASPD_MAX` for its `LND_TRIG_S` (the
/// firmware's defaults). `None` when it never does.
pub fn slow_from(samples: &[Sample], touchdown_s: f64) -> Option<f64> {
    let p = LandParams::default();
    let (max, hold) = (f64::from(p.airspeed_max), f64::from(p.trigger_s));
    let mut since: Option<f64> = None;
    for s in samples.iter().filter(|s| s.t >= touchdown_s) {
        if s.airspeed < max {
            let t0 = *since.get_or_insert(s.t);
            if s.t - t0 >= hold {
                return Some(t0);
            }
        } else {
            since = None;
        }
    }
    None
}

/// The landed states `states` (time, name as the station read it, on each change) against the
/// plant's touchdown at `touchdown_s` and the flight's `samples`: `TAKEOFF` and `IN_AIR` after
/// arming, never `ON_GROUND` from the first `IN_AIR` until the touchdown, `LANDING` on the way
/// down (or still `IN_AIR`) at the touchdown, and `ON_GROUND` for good within
/// [`ON_GROUND_WITHIN_S`] of it, or within [`ON_GROUND_AFTER_SLOW_S`] of the roll-out's
/// slowing under flying speed when that is later ([`slow_from`]). `Err` names the first rule
/// broken.
pub fn landed_state_honest(
    states: &[(f64, String)],
    touchdown_s: f64,
    samples: &[Sample],
) -> Result<(), String> {
    let has = |name: &str| states.iter().any(|(_, s)| s == name);
    for name in ["TAKEOFF", "LANDING"] {
        if !has(name) {
            return Err(format!("{name} never reported: {states:?}"));
        }
    }
    let first_air = states
        .iter()
        .find(|(_, s)| s == "IN_AIR")
        .map(|&(t, _)| t)
        .ok_or_else(|| format!("IN_AIR never reported: {states:?}"))?;
    if let Some((t, _)) = states
        .iter()
        .find(|(t, s)| *t > first_air && *t < touchdown_s && s == "ON_GROUND")
    {
        return Err(format!(
            "ON_GROUND at {t:.1} s, before the touchdown at {touchdown_s:.1} s"
        ));
    }
    let at_touchdown = states
        .iter()
        .rev()
        .find(|(t, _)| *t <= touchdown_s)
        .map(|(_, s)| s.as_str());
    if !matches!(at_touchdown, Some("LANDING" | "IN_AIR")) {
        return Err(format!("{at_touchdown:?} at the touchdown"));
    }
    let Some((t_ground, last)) = states.last() else {
        return Err("no landed state read".into());
    };
    if last != "ON_GROUND" {
        return Err(format!("{last} at the end: {states:?}"));
    }
    let on_ground_at = states
        .iter()
        .find(|(t, s)| *t >= touchdown_s && s == "ON_GROUND")
        .map_or(*t_ground, |&(t, _)| t);
    if on_ground_at != *t_ground {
        return Err(format!(
            "ON_GROUND at {on_ground_at:.1} s did not hold: {states:?}"
        ));
    }
    let slow = slow_from(samples, touchdown_s);
    let due = slow.map_or(touchdown_s + ON_GROUND_WITHIN_S, |t| {
        (touchdown_s + ON_GROUND_WITHIN_S).max(t + ON_GROUND_AFTER_SLOW_S)
    });
    if on_ground_at >= due {
        let slowed = slow.map_or("the air never slowed under flying speed".to_string(), |t| {
            format!("{:.1} s after the air slowed", on_ground_at - t)
        });
        return Err(format!(
            "ON_GROUND {:.1} s after the touchdown ({slowed})",
            on_ground_at - touchdown_s
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn states(list: &[(f64, &str)]) -> Vec<(f64, String)> {
        list.iter().map(|&(t, s)| (t, s.to_string())).collect()
    }

    /// The sequence of an honest landing passes; each lie, alone, is named.
    #[test]
    fn each_dishonest_landed_state_is_named() {
        let honest = [
            (0.0, "ON_GROUND"),
            (10.0, "TAKEOFF"),
            (20.0, "IN_AIR"),
            (300.0, "LANDING"),
            (340.0, "ON_GROUND"),
        ];
        assert_eq!(landed_state_honest(&states(&honest), 333.0, &[]), Ok(()));
        let early = [
            (0.0, "ON_GROUND"),
            (10.0, "TAKEOFF"),
            (20.0, "IN_AIR"),
            (300.0, "LANDING"),
            (330.0, "ON_GROUND"),
        ];
        let e = landed_state_honest(&states(&early), 333.0, &[]).unwrap_err();
        assert!(e.contains("before the touchdown"), "{e}");
        let late = landed_state_honest(&states(&honest), 324.0, &[]).unwrap_err();
        assert!(late.contains("after the touchdown"), "{late}");
        let no_landing = [(10.0, "TAKEOFF"), (20.0, "IN_AIR"), (340.0, "ON_GROUND")];
        let e = landed_state_honest(&states(&no_landing), 333.0, &[]).unwrap_err();
        assert!(e.contains("LANDING never"), "{e}");
        let flying = [(10.0, "TAKEOFF"), (20.0, "IN_AIR"), (300.0, "LANDING")];
        let e = landed_state_honest(&states(&flying), 333.0, &[]).unwrap_err();
        assert!(e.contains("at the end"), "{e}");
    }

    /// A roll-out that keeps flying speed through the air (11 m/s until 340 s, then 8 m/s)
    /// may read LANDING until 5 s after the air has slowed, past the 15 s from the touchdown;
    /// one that slows at once is held to the 15 s.
    #[test]
    fn a_roll_out_at_flying_airspeed_may_read_landing_until_the_air_has_slowed() {
        let rollout = |fast_until: f64| -> Vec<Sample> {
            (0..2000)
                .map(|k| {
                    let t = 320.0 + 0.02 * f64::from(k);
                    Sample {
                        t,
                        airspeed: if t < fast_until { 11.0 } else { 8.0 },
                        ..Sample::default()
                    }
                })
                .collect()
        };
        let sailing = rollout(340.0);
        assert_eq!(slow_from(&sailing, 324.0), Some(340.0));
        assert_eq!(slow_from(&rollout(400.0), 324.0), None);
        let late = [
            (0.0, "ON_GROUND"),
            (10.0, "TAKEOFF"),
            (20.0, "IN_AIR"),
            (300.0, "LANDING"),
            (342.0, "ON_GROUND"),
        ];
        // 18 s after the touchdown, 2 s after the air slowed.
        assert_eq!(landed_state_honest(&states(&late), 324.0, &sailing), Ok(()));
        // The same 18 s after a roll-out slow from the touchdown on.
        let e = landed_state_honest(&states(&late), 324.0, &rollout(0.0)).unwrap_err();
        assert!(
            e.contains("18.0 s after the touchdown (18.0 s after the air slowed)"),
            "{e}"
        );
        // Still at flying speed to the end: held to the 15 s.
        let e = landed_state_honest(&states(&late), 324.0, &rollout(400.0)).unwrap_err();
        assert!(e.contains("never slowed"), "{e}");
        // Slowed, but ON_GROUND 6 s after it.
        let e = landed_state_honest(&states(&late), 324.0, &rollout(336.0)).unwrap_err();
        assert!(e.contains("6.0 s after the air slowed"), "{e}");
    }
}
