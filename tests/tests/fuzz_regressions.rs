//! The cases the fuzz targets in `tests/fuzz/` found, each kept as a plain test so it stays
//! fixed without the fuzzer (`docs/RELIABILITY.md` tells each story).

use common::gcs::{Dest, GroundLink, Origin, Outgoing, Stores};
use common::navigation::plan::{MissionStore, PlanKind};
use common::navigation::validate::PlanRules;
use common::params::ParamStore;
use common::vehicle::params::REGISTRY;
use common::vehicle::Vehicle;
use mavlink::dialects::common::*;
use mavlink::MavHeader;

/// A ground station talking to a bare ground link with its stores.
struct Station {
    link: GroundLink,
    params: ParamStore,
    plan: MissionStore,
}

impl Station {
    fn new() -> Self {
        Self {
            link: GroundLink::default(),
            params: ParamStore::new(REGISTRY),
            plan: MissionStore::default(),
        }
    }

    /// Sends `msg` from station 255/190 and returns the mission acknowledgements it gets.
    fn send(&mut self, msg: MavMessage) -> Vec<MavMissionResult> {
        let header = MavHeader {
            system_id: 255,
            component_id: 190,
            sequence: 0,
        };
        let snapshot = Vehicle::new().snapshot();
        let mut stores = Stores {
            params: &mut self.params,
            plan: &mut self.plan,
            rules: PlanRules {
                home: None,
                limits: Default::default(),
                nav: Default::default(),
            },
        };
        self.link
            .handle(&header, &msg, 0, &snapshot, &mut stores, Origin::default());
        let mut acks = Vec::new();
        self.link.poll(0, &snapshot, &stores, |_: Dest, out| {
            if let Outgoing::Message(MavMessage::MISSION_ACK(a)) = out {
                acks.push(a.mavtype);
            }
        });
        acks
    }
}

fn count(n: u16) -> MavMessage {
    MavMessage::MISSION_COUNT(MISSION_COUNT_DATA {
        count: n,
        target_system: 1,
        target_component: 1,
        ..MISSION_COUNT_DATA::DEFAULT
    })
}

fn waypoint() -> MavMessage {
    MavMessage::MISSION_ITEM_INT(MISSION_ITEM_INT_DATA {
        x: 473_977_420,
        y: 85_455_940,
        z: 50.0,
        seq: 0,
        command: MavCmd::MAV_CMD_NAV_WAYPOINT,
        target_system: 1,
        target_component: 1,
        frame: MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT,
        autocontinue: 1,
        ..MISSION_ITEM_INT_DATA::DEFAULT
    })
}

#[test]
fn a_repeated_last_item_is_not_accepted_once_its_mission_was_cleared() {
    for clear in [
        count(0),
        MavMessage::MISSION_CLEAR_ALL(MISSION_CLEAR_ALL_DATA {
            target_system: 1,
            target_component: 1,
            ..MISSION_CLEAR_ALL_DATA::DEFAULT
        }),
    ] {
        let mut s = Station::new();
        s.send(count(1));
        let accepted = vec![MavMissionResult::MAV_MISSION_ACCEPTED];
        assert_eq!(s.send(waypoint()), accepted);
        // The ACK was lost: the repeated item gets the same answer.
        assert_eq!(s.send(waypoint()), accepted);
        assert_eq!(s.send(clear.clone()), accepted);
        assert!(s.plan.items(PlanKind::Mission).is_empty());
        // The item arrives once more: the station must not be told its mission is stored.
        assert!(
            !s.send(waypoint())
                .contains(&MavMissionResult::MAV_MISSION_ACCEPTED),
            "after {clear:?}"
        );
    }
}

#[test]
fn a_number_too_large_for_a_float_in_a_mission_file_is_refused_not_made_infinite() {
    use sim_host::mission_file::parse_mission_text;
    use std::path::Path;
    let item = |p1: &str| {
        format!(
            r#"{{"fileType":"Plan","version":1,"mission":{{"version":2,"items":[{{"type":"SimpleItem","command":31,"frame":0,"autoContinue":true,"params":[{p1},0,0,0,0,0,0]}}]}}}}"#
        )
    };
    assert!(parse_mission_text(&item("1e38"), Path::new("a.plan")).is_ok());
    let err = parse_mission_text(&item("1e230"), Path::new("a.plan")).unwrap_err();
    assert!(
        err.to_string().contains("too large for a 32-bit float"),
        "{err}"
    );
    let circle = r#"{"fileType":"Plan","version":1,"mission":{"version":2,"items":[]},"geoFence":{"version":2,"circles":[{"inclusion":true,"circle":{"center":[47,8],"radius":1e39}}]}}"#;
    assert!(parse_mission_text(circle, Path::new("a.plan")).is_err());
    let rally = r#"{"fileType":"Plan","version":1,"mission":{"version":2,"items":[]},"rallyPoints":{"version":2,"points":[[47,8,1e39]]}}"#;
    assert!(parse_mission_text(rally, Path::new("a.plan")).is_err());
    let wpl = "QGC WPL 110\n0\t1\t0\t16\t0\t0\t0\t0\t47\t8\t400\t1\n1\t0\t3\t16\t1e39\t0\t0\t0\t47\t8\t50\t1\n";
    let err = parse_mission_text(wpl, Path::new("a.waypoints")).unwrap_err();
    assert!(
        err.to_string().contains("too large for a 32-bit float"),
        "{err}"
    );
}

#[test]
fn a_power_cut_during_a_save_keeps_the_copy_that_loads_when_the_newest_one_does_not() {
    use common::storage::{load_params, save, save_params, AbRegion, RamFlash, PARAMS_MAGIC};
    const SECTOR: u32 = 16 * 1024;
    const REGION: AbRegion = AbRegion {
        magic: PARAMS_MAGIC,
        slot_a: 0,
        slot_b: SECTOR,
        slot_len: SECTOR,
    };
    let mut scratch = vec![0u8; SECTOR as usize];
    let value = |f: &mut RamFlash<{ 2 * SECTOR as usize }>| {
        let mut store = ParamStore::new(REGISTRY);
        let mut scratch = vec![0u8; SECTOR as usize];
        load_params(f, &REGION, &mut store, &mut scratch)
            .ok()
            .flatten()
            .and_then(|_| store.get("NAV_ACC_RAD"))
    };
    let mut base = RamFlash::<{ 2 * SECTOR as usize }>::new(SECTOR);
    let mut old = ParamStore::new(REGISTRY);
    old.set("NAV_ACC_RAD", 31.0).unwrap();
    save_params(&mut base, &REGION, &mut old, &mut scratch).unwrap();
    // A newer copy, intact but in a format this firmware does not read (an empty record).
    save(&mut base, &REGION, &(), &mut scratch).unwrap();
    assert_eq!(value(&mut base), Some(31.0), "the older copy loads");
    let mut new = ParamStore::new(REGISTRY);
    new.set("NAV_ACC_RAD", 42.0).unwrap();
    let mut probe = base.clone();
    let before = probe.ops();
    save_params(&mut probe, &REGION, &mut new.clone(), &mut scratch).unwrap();
    let total = probe.ops() - before;
    for cut in 0..=total {
        let mut f = base.clone();
        f.cut_after(Some(cut));
        let _ = save_params(&mut f, &REGION, &mut new.clone(), &mut scratch);
        f.cut_after(None);
        let got = value(&mut f);
        assert!(
            got == Some(31.0) || got == Some(42.0),
            "cut at operation {cut} of {total}: {got:?}"
        );
    }
}

#[test]
fn a_saved_parameter_refused_twice_is_counted_once() {
    use common::params::store::{ImportReport, ParamImage, ParamRecord};
    let record = |name: &str, value: f32| ParamRecord {
        name: name.try_into().unwrap(),
        value,
    };
    let mut image = ParamImage::new();
    // A throttle limit below the trim: the longitudinal stage refuses its records...
    image.push(record("THR_MAX", 0.3)).unwrap();
    // ...among them this one, which its definition refused already.
    image.push(record("ALT_KP", f32::NAN)).unwrap();
    image.push(record("NO_SUCH_PARAM", 1.0)).unwrap();
    let report = ParamStore::new(REGISTRY).import(&image);
    assert_eq!(
        report,
        ImportReport {
            loaded: 0,
            unknown: 1,
            rejected: 2,
        }
    );
}
