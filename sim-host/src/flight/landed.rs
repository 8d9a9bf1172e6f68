//! Whether the landed state a ground station read (`EXTENDED_SYS_STATE`) told the truth about
//! a landing, judged against the plant's touchdown.

/// Longest time from the first contact to the station's `ON_GROUND`, s. A landing that bounces
/// along the runway in gusts (seven times on the pitot-failure flight of
/// `sim-host/tests/failsafe.rs`, its synthetic airspeed 1.7 m/s RMS off) is at rest on its
/// wheels 11.6-12.5 s after it; a clean one takes 7.3-7.6 s (the roll-out slowing under
/// `LND_VXY_MAX`, then `LND_TRIG_S`).
pub const ON_GROUND_WITHIN_S: f64 = 15.0;

/// The landed states `states` (time, name as the station read it, on each change) against the
/// plant's touchdown at `touchdown_s`: `TAKEOFF` and `IN_AIR` after arming, never `ON_GROUND`
/// from the first `IN_AIR` until the touchdown, `LANDING` on the way down (or still `IN_AIR`)
/// at the touchdown, and `ON_GROUND` for good within [`ON_GROUND_WITHIN_S`] of it. `Err`
/// names the first rule broken.
pub fn landed_state_honest(states: &[(f64, String)], touchdown_s: f64) -> Result<(), String> {
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
    if on_ground_at - touchdown_s >= ON_GROUND_WITHIN_S {
        return Err(format!(
            "ON_GROUND {:.1} s after the touchdown",
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
        assert_eq!(landed_state_honest(&states(&honest), 333.0), Ok(()));
        let early = [
            (0.0, "ON_GROUND"),
            (10.0, "TAKEOFF"),
            (20.0, "IN_AIR"),
            (300.0, "LANDING"),
            (330.0, "ON_GROUND"),
        ];
        let e = landed_state_honest(&states(&early), 333.0).unwrap_err();
        assert!(e.contains("before the touchdown"), "{e}");
        let late = landed_state_honest(&states(&honest), 324.0).unwrap_err();
        assert!(late.contains("after the touchdown"), "{late}");
        let no_landing = [(10.0, "TAKEOFF"), (20.0, "IN_AIR"), (340.0, "ON_GROUND")];
        let e = landed_state_honest(&states(&no_landing), 333.0).unwrap_err();
        assert!(e.contains("LANDING never"), "{e}");
        let flying = [(10.0, "TAKEOFF"), (20.0, "IN_AIR"), (300.0, "LANDING")];
        let e = landed_state_honest(&states(&flying), 333.0).unwrap_err();
        assert!(e.contains("at the end"), "{e}");
    }
}
