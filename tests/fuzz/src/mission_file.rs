//! The mission-file readers (`sim_host::mission_file`): any text, and `.plan` and `QGC WPL
//! 110` files built by the fuzzer with the right shape and any values in it (huge numbers,
//! nulls, jumps anywhere, polygons and circles, rally points).
//!
//! Asserted: reading never panics and reads the same text the same way twice; what it accepts
//! is what the mission protocol can carry: items numbered 0.. in each list, each list's
//! `mission_type`, addressed to the autopilot; global positions within range; `DO_JUMP`
//! targets whole numbers naming an item of the mission; the home position finite and within
//! range; and from a `.plan`, whose JSON cannot hold an infinity, no infinite value (a number
//! too large for the item's field is refused, not turned into one).

use std::path::Path;

use arbitrary::{Arbitrary, Unstructured};
use mavlink::dialects::common::{MavCmd, MavMissionType, MISSION_ITEM_INT_DATA};
use serde_json::{json, Value};
use sim_host::mission_file::item::is_global;
use sim_host::mission_file::{parse_mission_text, MissionFile};

/// A number as a file may write it.
#[derive(Arbitrary, Clone, Copy, Debug)]
pub enum Num {
    Small(i8),
    Int(i32),
    Deg(i32),
    Huge(i16),
    Bits(u64),
    Null,
}

impl Num {
    fn value(self) -> Value {
        match self {
            Num::Small(v) => json!(v),
            Num::Int(v) => json!(v),
            Num::Deg(v) => json!(f64::from(v) * 1e-7),
            Num::Huge(e) => json!(10f64.powi(i32::from(e % 400))),
            Num::Bits(b) => {
                serde_json::Number::from_f64(f64::from_bits(b)).map_or(Value::Null, Value::Number)
            }
            Num::Null => Value::Null,
        }
    }

    fn text(self) -> String {
        match self.value() {
            Value::Null => "nan".into(),
            v => v.to_string(),
        }
    }
}

#[derive(Arbitrary, Clone, Debug)]
pub struct PlanItem {
    command: u8,
    frame: u8,
    params: [Num; 7],
    jump_id: Option<u8>,
    autocontinue: bool,
    complex: bool,
}

const COMMANDS: [u32; 12] = [16, 17, 18, 19, 20, 21, 22, 31, 177, 178, 179, 183];

#[derive(Arbitrary, Clone, Debug)]
pub enum Built {
    Text(String),
    Plan {
        home: Option<[Num; 3]>,
        items: Vec<PlanItem>,
        polygons: Vec<(bool, Vec<[Num; 2]>)>,
        circles: Vec<(bool, [Num; 2], Num)>,
        rally: Vec<[Num; 3]>,
    },
    Wpl {
        home: [Num; 3],
        items: Vec<PlanItem>,
        spaces: bool,
    },
}

impl Built {
    fn text(&self) -> String {
        match self {
            Built::Text(t) => t.clone(),
            Built::Plan {
                home,
                items,
                polygons,
                circles,
                rally,
            } => {
                let items: Vec<Value> = items
                    .iter()
                    .map(|it| {
                        let mut v = json!({
                            "type": if it.complex { "ComplexItem" } else { "SimpleItem" },
                            "command": COMMANDS[usize::from(it.command) % COMMANDS.len()],
                            "frame": it.frame % 12,
                            "autoContinue": it.autocontinue,
                            "params": it.params.iter().map(|p| p.value()).collect::<Vec<_>>(),
                        });
                        if let Some(id) = it.jump_id {
                            v["doJumpId"] = json!(id);
                        }
                        v
                    })
                    .collect();
                let pos = |p: &[Num]| p.iter().map(|n| n.value()).collect::<Vec<_>>();
                json!({
                    "fileType": "Plan",
                    "version": 1,
                    "mission": {
                        "version": 2,
                        "plannedHomePosition": home.as_ref().map(|h| pos(h)),
                        "items": items,
                    },
                    "geoFence": {
                        "version": 2,
                        "polygons": polygons.iter().map(|(inc, v)| json!({
                            "inclusion": inc,
                            "polygon": v.iter().map(|p| pos(p)).collect::<Vec<_>>(),
                        })).collect::<Vec<_>>(),
                        "circles": circles.iter().map(|(inc, c, r)| json!({
                            "inclusion": inc,
                            "circle": { "center": pos(c), "radius": r.value() },
                        })).collect::<Vec<_>>(),
                    },
                    "rallyPoints": {
                        "version": 2,
                        "points": rally.iter().map(|p| pos(p)).collect::<Vec<_>>(),
                    },
                })
                .to_string()
            }
            Built::Wpl {
                home,
                items,
                spaces,
            } => {
                let sep = if *spaces { " " } else { "\t" };
                let mut t = String::from("QGC WPL 110\n");
                let line = |i: usize, frame: u8, cmd: u32, p: [Num; 7], ac: bool| {
                    let mut cols = vec![
                        i.to_string(),
                        "0".into(),
                        (frame % 12).to_string(),
                        cmd.to_string(),
                    ];
                    cols.extend(p[..4].iter().map(|n| n.text()));
                    cols.extend(p[4..].iter().map(|n| n.text()));
                    cols.push(if ac { "1" } else { "0" }.into());
                    cols.join(sep)
                };
                let [a, b, c] = *home;
                let zero = Num::Small(0);
                t += &line(0, 0, 16, [zero, zero, zero, zero, a, b, c], true);
                t.push('\n');
                for (i, it) in items.iter().enumerate() {
                    let cmd = COMMANDS[usize::from(it.command) % COMMANDS.len()];
                    t += &line(i + 1, it.frame, cmd, it.params, it.autocontinue);
                    t.push('\n');
                }
                t
            }
        }
    }
}

fn check_list(items: &[MISSION_ITEM_INT_DATA], kind: MavMissionType, plan: bool, len: usize) {
    for (i, it) in items.iter().enumerate() {
        assert_eq!(usize::from(it.seq), i, "items numbered 0..");
        assert_eq!(it.mission_type, kind);
        assert_eq!(
            (it.target_system, it.target_component, it.current),
            (1, 1, 0)
        );
        if is_global(it.frame) {
            assert!(it.x.unsigned_abs() <= 900_000_000, "latitude {}", it.x);
            assert!(it.y.unsigned_abs() <= 1_800_000_000, "longitude {}", it.y);
        }
        if plan {
            for v in [it.param1, it.param2, it.param3, it.param4, it.z] {
                assert!(
                    !v.is_infinite(),
                    "item {i}: an infinite value from a .plan: {it:?}"
                );
            }
        }
        if it.command == MavCmd::MAV_CMD_DO_JUMP && kind == MavMissionType::MAV_MISSION_TYPE_MISSION
        {
            let t = it.param1;
            assert!(
                t.fract() == 0.0 && t >= 0.0 && (t as usize) < len,
                "item {i}: DO_JUMP to {t} of {len} items"
            );
        }
    }
}

fn check(f: &MissionFile, plan: bool) {
    let len = f.mission.len();
    check_list(
        &f.mission,
        MavMissionType::MAV_MISSION_TYPE_MISSION,
        plan,
        len,
    );
    check_list(&f.fence, MavMissionType::MAV_MISSION_TYPE_FENCE, plan, len);
    check_list(&f.rally, MavMissionType::MAV_MISSION_TYPE_RALLY, plan, len);
    if let Some((lat, lon, alt)) = f.home {
        assert!(lat.abs() <= 90.0 && lon.abs() <= 180.0, "home {lat} {lon}");
        // A WPL file may write `nan` for it; a .plan cannot.
        assert!(!plan || alt.is_finite(), "home altitude {alt}");
    }
}

/// Runs one input.
pub fn run(data: &[u8]) {
    let Ok(built) = Built::arbitrary_take_rest(Unstructured::new(data)) else {
        return;
    };
    let text = built.text();
    if crate::trace() {
        eprintln!("{text}");
    }
    let path = Path::new("fuzz.plan");
    let first = parse_mission_text(&text, path);
    let again = parse_mission_text(&text, path);
    // Compared as text: NaN fields are not equal to themselves.
    assert_eq!(
        format!("{:?}", first.as_ref().ok()),
        format!("{:?}", again.as_ref().ok()),
        "the same text reads the same"
    );
    if let Ok(f) = &first {
        let wpl = text
            .strip_prefix('\u{feff}')
            .unwrap_or(&text)
            .trim_start()
            .starts_with("QGC WPL");
        check(f, !wpl);
    }
}
