//! The mission protocol as a state machine (`GroundLink::handle` with the stores): uploads,
//! downloads, cancels, clears and timeouts from three stations at once (two of them with
//! the same MAVLink address on different channels), items good and bad, home known or not.
//!
//! Asserted, after every message and every poll:
//! - a stored list changes only to a complete upload of one station: the items that station
//!   sent, in order, after its last `MISSION_COUNT`, as many as it announced; and only on that
//!   station's last item (or emptied by a clear or a count of 0);
//! - a stored mission passed the navigator's checks with the rules of that moment, a stored
//!   fence the geofence's;
//! - a `MISSION_ACK` of `ACCEPTED` after an item tells its station the truth: the list stored
//!   is the one it uploaded;
//! - what a download sends is what is stored: the count, and every item bit for bit.

use std::collections::BTreeMap;

use arbitrary::Arbitrary;
use common::estimator::Home;
use common::gcs::mission::{item_from_mav, mission_type, plan_kind};
use common::gcs::{GroundLink, Outgoing, Peer, Stores};
use common::navigation::plan::{MissionItem, MissionStore, PlanKind};
use common::navigation::validate::PlanRules;
use common::navigation::{navigator, validate, validate_fence, validate_mission};
use common::params::ParamStore;
use common::vehicle::params::REGISTRY;
use common::vehicle::snapshot::VehicleSnapshot;
use common::vehicle::Vehicle;
use mavlink::dialects::common::*;
use mavlink::{MavHeader, Message};

use crate::frames::{HOME, HOME_ALT_M};
use crate::gcs::{Float, Item, Kind};

const PEERS: [Peer; 3] = [
    Peer {
        system: 255,
        component: 190,
        channel: 0,
    },
    Peer {
        system: 255,
        component: 190,
        channel: 1,
    },
    Peer {
        system: 246,
        component: 1,
        channel: 2,
    },
];

/// A message of the mission protocol, or time passing.
#[derive(Arbitrary, Clone, Debug)]
pub enum MissionAction {
    Count {
        peer: u8,
        kind: Kind,
        count: u8,
    },
    /// Items `seq`.. of an upload, as a station sends them on request.
    Items {
        peer: u8,
        kind: Kind,
        seq: u8,
        items: Vec<Item>,
    },
    RequestList {
        peer: u8,
        kind: Kind,
    },
    Request {
        peer: u8,
        kind: Kind,
        seq: u8,
    },
    Ack {
        peer: u8,
        kind: Kind,
        cancel: bool,
    },
    Clear {
        peer: u8,
        kind: Kind,
    },
    Float {
        peer: u8,
        kind: Kind,
    },
    SetCurrent {
        peer: u8,
        seq: u16,
    },
    /// Time passes (timeouts, retries).
    Wait {
        ms: u16,
    },
    /// Home is set (or moves), or is not known yet.
    Home {
        set: bool,
        north: i8,
        alt: i8,
    },
    /// A mission altitude limit changes.
    Limit {
        max: Float,
    },
}

/// What one station has uploaded since its last count.
#[derive(Clone, Debug)]
struct Upload {
    kind: PlanKind,
    count: usize,
    items: Vec<MissionItem>,
}

struct Harness {
    link: GroundLink,
    params: ParamStore,
    plan: MissionStore,
    home: Option<Home>,
    snapshot: VehicleSnapshot,
    now_us: u64,
    uploads: BTreeMap<usize, Upload>,
}

impl Harness {
    fn rules(&self) -> PlanRules {
        PlanRules {
            home: self.home,
            limits: self.params.load(&validate::PARAMS),
            nav: self.params.load(&navigator::params::PARAMS),
        }
    }

    /// Hands one message to the link from station `p`, then polls it; returns what it sent.
    fn send(&mut self, p: usize, msg: &MavMessage) -> Vec<(common::gcs::Dest, MavMessage)> {
        let peer = PEERS[p];
        let header = MavHeader {
            system_id: u32::from(peer.system),
            component_id: peer.component,
            sequence: 0,
        };
        let lists = [PlanKind::Mission, PlanKind::Fence, PlanKind::Rally]
            .map(|k| self.plan.items(k).to_vec());
        let rules = self.rules();
        let mut stores = Stores {
            params: &mut self.params,
            plan: &mut self.plan,
            rules,
        };
        self.link.handle(
            &header,
            msg,
            self.now_us,
            &self.snapshot,
            &mut stores,
            common::gcs::Origin {
                channel: peer.channel,
                signed: None,
            },
        );
        self.model_item(p, msg);
        // A list replaced by an equal one (or an empty one cleared) changes nothing to check.
        for (i, k) in [PlanKind::Mission, PlanKind::Fence, PlanKind::Rally]
            .into_iter()
            .enumerate()
        {
            if self.plan.items(k) != lists[i] {
                self.check_change(p, msg, k, &rules);
            }
        }
        let sent = self.poll();
        for (dest, m) in &sent {
            let to_p = *dest == peer.dest()
                && m.target_system_id() == Some(peer.system)
                && m.target_component_id() == Some(peer.component);
            if !to_p {
                continue;
            }
            match (m, msg) {
                // The station's upload starts (or restarts) when the link asks for item 0.
                (MavMessage::MISSION_REQUEST_INT(r), MavMessage::MISSION_COUNT(c))
                    if r.seq == 0 =>
                {
                    if let Some(kind) = plan_kind(c.mission_type) {
                        self.uploads.insert(
                            p,
                            Upload {
                                kind,
                                count: usize::from(c.count),
                                items: Vec::new(),
                            },
                        );
                    }
                }
                (MavMessage::MISSION_ACK(a), MavMessage::MISSION_ITEM_INT(_))
                    if a.mavtype == MavMissionResult::MAV_MISSION_ACCEPTED =>
                {
                    let kind = plan_kind(a.mission_type).expect("an ACK for a list");
                    let up = self.uploads.get(&p).expect("the station uploaded");
                    assert_eq!(
                        self.plan.items(kind),
                        &up.items[..],
                        "ACCEPTED, yet the {kind:?} stored is not the one station {p} uploaded"
                    );
                }
                _ => {}
            }
        }
        sent
    }

    /// An item the station sent, as the protocol would take it.
    fn model_item(&mut self, p: usize, msg: &MavMessage) {
        let MavMessage::MISSION_ITEM_INT(d) = msg else {
            return;
        };
        if let Some(up) = self.uploads.get_mut(&p) {
            if mission_type(up.kind) == d.mission_type
                && usize::from(d.seq) == up.items.len()
                && up.items.len() < up.count
            {
                match item_from_mav(d, up.kind) {
                    Ok(item) => up.items.push(item),
                    // The protocol ends this upload: nothing more of it can be stored.
                    Err(_) => up.count = usize::MAX,
                }
            }
        }
    }

    /// A stored list changed on `msg` from station `p`.
    fn check_change(&self, p: usize, msg: &MavMessage, kind: PlanKind, rules: &PlanRules) {
        let now = self.plan.items(kind);
        if now.is_empty() {
            let cleared = match msg {
                MavMessage::MISSION_CLEAR_ALL(d) => {
                    d.mission_type == MavMissionType::MAV_MISSION_TYPE_ALL
                        || plan_kind(d.mission_type) == Some(kind)
                }
                MavMessage::MISSION_COUNT(d) => {
                    d.count == 0 && plan_kind(d.mission_type) == Some(kind)
                }
                _ => false,
            };
            assert!(cleared, "the {kind:?} emptied by {msg:?}");
            return;
        }
        assert!(
            matches!(msg, MavMessage::MISSION_ITEM_INT(_)),
            "the {kind:?} changed on {msg:?}"
        );
        let up = self
            .uploads
            .get(&p)
            .unwrap_or_else(|| panic!("the {kind:?} changed with no upload from station {p}"));
        assert_eq!(
            up.kind, kind,
            "the {kind:?} replaced by a {:?} upload",
            up.kind
        );
        assert_eq!(up.items.len(), up.count, "an incomplete upload stored");
        assert_eq!(
            now,
            &up.items[..],
            "the {kind:?} stored is not what station {p} sent"
        );
        match kind {
            PlanKind::Mission => {
                let v = validate_mission(now, rules.home.as_ref(), &rules.limits, &rules.nav);
                assert!(
                    v.result.is_ok(),
                    "a mission stored that fails its checks: {v:?}"
                );
            }
            PlanKind::Fence => {
                assert_eq!(
                    validate_fence(now),
                    Ok(()),
                    "a fence stored that fails its checks"
                )
            }
            PlanKind::Rally => {}
        }
    }

    fn poll(&mut self) -> Vec<(common::gcs::Dest, MavMessage)> {
        let mut sent = Vec::new();
        let stores = Stores {
            params: &mut self.params,
            plan: &mut self.plan,
            rules: PlanRules {
                home: self.home,
                limits: Default::default(),
                nav: Default::default(),
            },
        };
        self.link
            .poll(self.now_us, &self.snapshot, &stores, |dest, out| {
                if let Outgoing::Message(m) = out {
                    sent.push((dest, m));
                }
            });
        for (_, m) in &sent {
            match m {
                MavMessage::MISSION_COUNT(c) => {
                    let kind = plan_kind(c.mission_type).expect("a count of a list");
                    assert_eq!(usize::from(c.count), self.plan.items(kind).len(), "count");
                    assert_eq!(c.opaque_id, self.plan.opaque_id(kind), "opaque id");
                }
                MavMessage::MISSION_ITEM_INT(d) => {
                    let kind = plan_kind(d.mission_type).expect("an item of a list");
                    let stored = self.plan.items(kind).get(usize::from(d.seq));
                    let stored = stored.expect("a download of an item that is stored");
                    assert_eq!(
                        item_from_mav(d, kind).ok().as_ref(),
                        Some(stored),
                        "a download sends the stored item bit for bit"
                    );
                }
                _ => {}
            }
        }
        sent
    }

    fn step(&mut self, a: &MissionAction) {
        let peer = |p: u8| usize::from(p) % PEERS.len();
        let to = |kind: Kind| kind.get();
        match a {
            MissionAction::Count {
                peer: p,
                kind,
                count,
            } => {
                let m = MavMessage::MISSION_COUNT(MISSION_COUNT_DATA {
                    count: u16::from(*count),
                    target_system: 1,
                    target_component: 1,
                    mission_type: to(*kind),
                    opaque_id: 0,
                });
                self.send(peer(*p), &m);
            }
            MissionAction::Items {
                peer: p,
                kind,
                seq,
                items,
            } => {
                for (i, it) in items.iter().take(40).enumerate() {
                    let seq = u16::from(*seq) + i as u16;
                    if let Some(d) = it.data(seq, to(*kind)) {
                        self.send(peer(*p), &MavMessage::MISSION_ITEM_INT(d));
                    }
                }
            }
            MissionAction::RequestList { peer: p, kind } => {
                let m = MavMessage::MISSION_REQUEST_LIST(MISSION_REQUEST_LIST_DATA {
                    target_system: 1,
                    target_component: 1,
                    mission_type: to(*kind),
                });
                self.send(peer(*p), &m);
            }
            MissionAction::Request { peer: p, kind, seq } => {
                let m = MavMessage::MISSION_REQUEST_INT(MISSION_REQUEST_INT_DATA {
                    seq: u16::from(*seq),
                    target_system: 1,
                    target_component: 1,
                    mission_type: to(*kind),
                });
                self.send(peer(*p), &m);
            }
            MissionAction::Ack {
                peer: p,
                kind,
                cancel,
            } => {
                let m = MavMessage::MISSION_ACK(MISSION_ACK_DATA {
                    target_system: 1,
                    target_component: 1,
                    mavtype: if *cancel {
                        MavMissionResult::MAV_MISSION_OPERATION_CANCELLED
                    } else {
                        MavMissionResult::MAV_MISSION_ACCEPTED
                    },
                    mission_type: to(*kind),
                    opaque_id: 0,
                });
                self.send(peer(*p), &m);
            }
            MissionAction::Clear { peer: p, kind } => {
                let m = MavMessage::MISSION_CLEAR_ALL(MISSION_CLEAR_ALL_DATA {
                    target_system: 1,
                    target_component: 1,
                    mission_type: to(*kind),
                });
                self.send(peer(*p), &m);
            }
            MissionAction::Float { peer: p, kind } => {
                let m = MavMessage::MISSION_ITEM(MISSION_ITEM_DATA {
                    target_system: 1,
                    target_component: 1,
                    mission_type: to(*kind),
                    ..MISSION_ITEM_DATA::DEFAULT
                });
                self.send(peer(*p), &m);
            }
            MissionAction::SetCurrent { peer: p, seq } => {
                let m = MavMessage::MISSION_SET_CURRENT(MISSION_SET_CURRENT_DATA {
                    seq: *seq,
                    target_system: 1,
                    target_component: 1,
                });
                self.send(peer(*p), &m);
            }
            MissionAction::Wait { ms } => {
                self.now_us += u64::from(*ms) * 1000;
                self.poll();
            }
            MissionAction::Home { set, north, alt } => {
                self.home = set.then(|| Home {
                    point: common::math::geodetic::GeoPoint {
                        lat_e7: HOME.lat_e7 + i32::from(*north) * 1000,
                        lon_e7: HOME.lon_e7,
                    },
                    alt_amsl_m: HOME_ALT_M + f32::from(*alt),
                });
            }
            MissionAction::Limit { max } => {
                if let Some(i) = self.params.index_of("MIS_ALT_MAX") {
                    let _ = self.params.set_index(i, max.get());
                }
            }
        }
    }
}

/// Runs one input.
pub fn run(data: &[u8]) {
    let mut h = Harness {
        link: GroundLink::default(),
        params: ParamStore::new(REGISTRY),
        plan: MissionStore::default(),
        home: None,
        snapshot: Vehicle::new().snapshot(),
        now_us: 0,
        uploads: BTreeMap::new(),
    };
    crate::each_action(data, 300, |a: &MissionAction| h.step(a));
}
