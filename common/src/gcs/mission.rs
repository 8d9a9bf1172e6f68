//! The MAVLink mission protocol (`*_INT` only) for mission, geofence and rally-point lists.
//! The lists themselves are the vehicle's plan ([`MissionStore`]); the protocol reads and
//! replaces them.
//!
//! One transfer runs at a time, as in PX4. An upload lands in a staging list and replaces the
//! stored list only when its last item has arrived, so a failed or cancelled upload keeps the
//! old plan. Home is not item 0: item 0 is the first thing to fly.

use super::peer::Peer;
use super::texts::{Line, TEXT_MAX};
use crate::link::mav_cmd::mav_cmd;
use crate::navigation::fence::validate_fence;
use crate::navigation::plan::{MissionItem, MissionStore, PlanKind, MISSION_CAPACITY};
use crate::navigation::validate::{validate_mission, PlanRules, ValidationWarning};
use heapless::Vec;
use mavlink::dialects::common::{
    MavCmd, MavFrame, MavMessage, MavMissionResult, MavMissionType, MISSION_ACK_DATA,
    MISSION_COUNT_DATA, MISSION_ITEM_INT_DATA, MISSION_REQUEST_INT_DATA,
};
use num_traits::FromPrimitive;

/// Time without an answer after which an item is requested again, µs.
pub const UPLOAD_RETRY_US: u64 = 500_000;
/// Requests of the same item before the upload is given up with `MAV_MISSION_ERROR`.
pub const UPLOAD_MAX_RETRIES: u8 = 5;
/// Time without a request after which a download is considered over, µs.
pub const DOWNLOAD_TIMEOUT_US: u64 = 5_000_000;

/// The list a `mission_type` names (`None` for ALL or unknown).
pub fn plan_kind(t: MavMissionType) -> Option<PlanKind> {
    match t {
        MavMissionType::MAV_MISSION_TYPE_MISSION => Some(PlanKind::Mission),
        MavMissionType::MAV_MISSION_TYPE_FENCE => Some(PlanKind::Fence),
        MavMissionType::MAV_MISSION_TYPE_RALLY => Some(PlanKind::Rally),
        _ => None,
    }
}

/// The `mission_type` of a list.
pub fn mission_type(kind: PlanKind) -> MavMissionType {
    match kind {
        PlanKind::Mission => MavMissionType::MAV_MISSION_TYPE_MISSION,
        PlanKind::Fence => MavMissionType::MAV_MISSION_TYPE_FENCE,
        PlanKind::Rally => MavMissionType::MAV_MISSION_TYPE_RALLY,
    }
}

/// Takes an item off the link, checking what this autopilot can store for `kind`.
// The *_INT frame numbers are deprecated synonyms, yet QGC and older tools still send them.
#[allow(deprecated)]
pub fn item_from_mav(
    d: &MISSION_ITEM_INT_DATA,
    kind: PlanKind,
) -> Result<MissionItem, MavMissionResult> {
    let command =
        u16::try_from(d.command as u32).map_err(|_| MavMissionResult::MAV_MISSION_UNSUPPORTED)?;
    let frame = d.frame as u32 as u8;
    let cmd_ok = match kind {
        PlanKind::Mission => !(5000..5200).contains(&command),
        PlanKind::Fence => (5000..=5004).contains(&command),
        PlanKind::Rally => command == MavCmd::MAV_CMD_NAV_RALLY_POINT as u32 as u16,
    };
    if !cmd_ok {
        return Err(MavMissionResult::MAV_MISSION_UNSUPPORTED);
    }
    let global = matches!(
        d.frame,
        MavFrame::MAV_FRAME_GLOBAL
            | MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT
            | MavFrame::MAV_FRAME_GLOBAL_INT
            | MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT_INT
    );
    // No terrain database and no local frame: only global positions and frame-less
    // (MISSION) items can be flown.
    if !global && d.frame != MavFrame::MAV_FRAME_MISSION {
        return Err(MavMissionResult::MAV_MISSION_UNSUPPORTED_FRAME);
    }
    if global {
        // x/y of 0 mean "current position" for several commands, so only the range is
        // checked.
        if !(-900_000_000..=900_000_000).contains(&d.x) {
            return Err(MavMissionResult::MAV_MISSION_INVALID_PARAM5_X);
        }
        if !(-1_800_000_000..=1_800_000_000).contains(&d.y) {
            return Err(MavMissionResult::MAV_MISSION_INVALID_PARAM6_Y);
        }
    }
    Ok(MissionItem {
        params: [
            d.param1.to_bits(),
            d.param2.to_bits(),
            d.param3.to_bits(),
            d.param4.to_bits(),
        ],
        x: d.x,
        y: d.y,
        z: d.z.to_bits(),
        command,
        frame,
        autocontinue: d.autocontinue != 0,
    })
}

/// The item as `MISSION_ITEM_INT`; `None` if the stored command or frame is not one the
/// MAVLink dialect knows (cannot happen for items that came over the link).
pub fn item_to_mav(
    item: &MissionItem,
    seq: u16,
    kind: PlanKind,
    current: bool,
    target: (u8, u8),
) -> Option<MISSION_ITEM_INT_DATA> {
    Some(MISSION_ITEM_INT_DATA {
        param1: item.param(0),
        param2: item.param(1),
        param3: item.param(2),
        param4: item.param(3),
        x: item.x,
        y: item.y,
        z: item.z_m(),
        seq,
        command: mav_cmd(u32::from(item.command))?,
        target_system: target.0,
        target_component: target.1,
        frame: MavFrame::from_u32(u32::from(item.frame))?,
        current: u8::from(current),
        autocontinue: u8::from(item.autocontinue),
        mission_type: mission_type(kind),
    })
}

/// The transfer in progress.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Transfer {
    Idle,
    Upload {
        kind: PlanKind,
        count: u16,
        next: u16,
        partner: Peer,
        last_us: u64,
        retries: u8,
    },
    Download {
        kind: PlanKind,
        partner: Peer,
        last_us: u64,
    },
}

/// What the link sends back for a mission message.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum MissionReply {
    /// `MISSION_ACK` with this result.
    Ack(MavMissionType, MavMissionResult),
    /// `MISSION_REQUEST_INT` for this item.
    Request(PlanKind, u16),
    /// `MISSION_COUNT` of a list.
    Count(PlanKind),
    /// `MISSION_ITEM_INT` of this item.
    Item(PlanKind, u16),
}

/// The protocol's state: the transfer in progress and the upload being received.
#[derive(Clone, Debug)]
pub struct MissionManager {
    staging: Vec<MissionItem, MISSION_CAPACITY>,
    transfer: Transfer,
    /// Last upload that completed, so a repeated last item is answered with the same ACK.
    last_done: Option<(PlanKind, u16, Peer)>,
    warnings: Vec<ValidationWarning, 8>,
}

impl Default for MissionManager {
    fn default() -> Self {
        Self::new()
    }
}

impl MissionManager {
    /// Empty lists, no transfer.
    pub fn new() -> Self {
        Self {
            staging: Vec::new(),
            transfer: Transfer::Idle,
            last_done: None,
            warnings: Vec::new(),
        }
    }

    /// Whether a transfer is running.
    pub fn busy(&self) -> bool {
        self.transfer != Transfer::Idle
    }

    fn busy_with_other(&self, partner: Peer) -> bool {
        match self.transfer {
            Transfer::Idle => false,
            Transfer::Upload { partner: p, .. } => p != partner,
            Transfer::Download { .. } => true,
        }
    }

    /// `MISSION_COUNT`: start (or restart) an upload.
    pub(crate) fn on_count(
        &mut self,
        store: &mut MissionStore,
        mtype: MavMissionType,
        count: u16,
        partner: Peer,
        now_us: u64,
    ) -> MissionReply {
        let Some(kind) = plan_kind(mtype) else {
            return MissionReply::Ack(mtype, MavMissionResult::MAV_MISSION_UNSUPPORTED);
        };
        // A new count from the same partner restarts its upload (QGC does so after it timed
        // out); anyone else waits.
        if self.busy_with_other(partner) {
            return MissionReply::Ack(mtype, MavMissionResult::MAV_MISSION_DENIED);
        }
        if usize::from(count) > kind.capacity() {
            self.transfer = Transfer::Idle;
            return MissionReply::Ack(mtype, MavMissionResult::MAV_MISSION_NO_SPACE);
        }
        self.staging.clear();
        if count == 0 {
            self.transfer = Transfer::Idle;
            // The list uploaded last is gone: a repeat of its last item is no longer accepted.
            self.last_done = None;
            store.clear(kind);
            return MissionReply::Ack(mtype, MavMissionResult::MAV_MISSION_ACCEPTED);
        }
        self.last_done = None;
        self.transfer = Transfer::Upload {
            kind,
            count,
            next: 0,
            partner,
            last_us: now_us,
            retries: 0,
        };
        MissionReply::Request(kind, 0)
    }

    /// `MISSION_ITEM_INT` during an upload.
    pub(crate) fn on_item(
        &mut self,
        store: &mut MissionStore,
        rules: &PlanRules,
        d: &MISSION_ITEM_INT_DATA,
        partner: Peer,
        now_us: u64,
    ) -> Option<MissionReply> {
        let Transfer::Upload {
            kind,
            count,
            next,
            partner: p,
            ..
        } = self.transfer
        else {
            // The ACK of a finished upload was lost and the sender repeats its last item.
            if let Some((k, c, p)) = self.last_done {
                if p == partner && mission_type(k) == d.mission_type && d.seq.wrapping_add(1) == c {
                    return Some(MissionReply::Ack(
                        d.mission_type,
                        MavMissionResult::MAV_MISSION_ACCEPTED,
                    ));
                }
            }
            return None;
        };
        if p != partner || mission_type(kind) != d.mission_type {
            return None;
        }
        if d.seq != next {
            if d.seq < next {
                // A repeat of an item we have: our request crossed it; ask again.
                self.touch(now_us);
                return Some(MissionReply::Request(kind, next));
            }
            self.abort();
            return Some(MissionReply::Ack(
                d.mission_type,
                MavMissionResult::MAV_MISSION_INVALID_SEQUENCE,
            ));
        }
        let item = match item_from_mav(d, kind) {
            Ok(i) => i,
            Err(e) => {
                self.abort();
                return Some(MissionReply::Ack(d.mission_type, e));
            }
        };
        if self.staging.push(item).is_err() {
            self.abort();
            return Some(MissionReply::Ack(
                d.mission_type,
                MavMissionResult::MAV_MISSION_NO_SPACE,
            ));
        }
        let next = next.saturating_add(1);
        if next >= count {
            let result = if let Err(r) = self.check(kind, rules) {
                r
            } else if store.replace(kind, &self.staging).is_ok() {
                self.last_done = Some((kind, count, partner));
                MavMissionResult::MAV_MISSION_ACCEPTED
            } else {
                MavMissionResult::MAV_MISSION_NO_SPACE
            };
            self.abort();
            return Some(MissionReply::Ack(d.mission_type, result));
        }
        if let Transfer::Upload {
            next: n,
            retries,
            last_us,
            ..
        } = &mut self.transfer
        {
            *n = next;
            *retries = 0;
            *last_us = now_us;
        }
        Some(MissionReply::Request(kind, next))
    }

    fn touch(&mut self, now_us: u64) {
        match &mut self.transfer {
            Transfer::Upload { last_us, .. } | Transfer::Download { last_us, .. } => {
                *last_us = now_us
            }
            Transfer::Idle => {}
        }
    }

    fn abort(&mut self) {
        self.transfer = Transfer::Idle;
        self.staging.clear();
    }

    /// `MISSION_REQUEST_LIST`: start a download.
    pub(crate) fn on_request_list(
        &mut self,
        store: &MissionStore,
        mtype: MavMissionType,
        partner: Peer,
        now_us: u64,
    ) -> MissionReply {
        let Some(kind) = plan_kind(mtype) else {
            return MissionReply::Ack(mtype, MavMissionResult::MAV_MISSION_UNSUPPORTED);
        };
        if matches!(self.transfer, Transfer::Upload { .. }) {
            return MissionReply::Ack(mtype, MavMissionResult::MAV_MISSION_DENIED);
        }
        self.transfer = if store.items(kind).is_empty() {
            // Nothing to request: the GCS answers the count of 0 with an ACK.
            Transfer::Idle
        } else {
            Transfer::Download {
                kind,
                partner,
                last_us: now_us,
            }
        };
        MissionReply::Count(kind)
    }

    /// `MISSION_REQUEST_INT` (or the legacy `MISSION_REQUEST`, answered the same way).
    pub(crate) fn on_request(
        &mut self,
        store: &MissionStore,
        mtype: MavMissionType,
        seq: u16,
        partner: Peer,
        now_us: u64,
    ) -> MissionReply {
        let Some(kind) = plan_kind(mtype) else {
            return MissionReply::Ack(mtype, MavMissionResult::MAV_MISSION_UNSUPPORTED);
        };
        if matches!(self.transfer, Transfer::Upload { .. }) {
            return MissionReply::Ack(mtype, MavMissionResult::MAV_MISSION_DENIED);
        }
        if usize::from(seq) >= store.items(kind).len() {
            return MissionReply::Ack(mtype, MavMissionResult::MAV_MISSION_INVALID_SEQUENCE);
        }
        if let Transfer::Download {
            partner: p,
            last_us,
            ..
        } = &mut self.transfer
        {
            if *p == partner {
                *last_us = now_us;
            }
        }
        MissionReply::Item(kind, seq)
    }

    /// The warnings of the last accepted mission upload (each returned once).
    pub fn take_warnings(&mut self) -> Vec<ValidationWarning, 8> {
        core::mem::take(&mut self.warnings)
    }

    /// The status text of a warning: what its `Display` writes, by pieces without `core::fmt`
    /// (the MCU image formats nothing with it; `a_warnings_text_is_what_its_display_writes`).
    pub fn warning_text(w: &ValidationWarning) -> Line<TEXT_MAX> {
        let mut line = Line::new();
        match *w {
            ValidationWarning::NoLanding => line.str("Mission has no landing: it ends circling"),
            ValidationWarning::WillSkip { seq, command } => line
                .str("Item ")
                .uint(u64::from(seq))
                .str(": command ")
                .uint(u64::from(command))
                .str(" unsupported, skipped"),
            ValidationWarning::ApproachTooShort { seq } => line
                .str("Item ")
                .uint(u64::from(seq))
                .str(": approach too short, arrives high"),
        };
        line
    }

    /// Checks a complete upload: the mission as the navigator will fly it, the fence as the
    /// geofence reads it. Rally points are stored as they come.
    fn check(&mut self, kind: PlanKind, r: &PlanRules) -> Result<(), MavMissionResult> {
        match kind {
            PlanKind::Mission => {
                let v = validate_mission(&self.staging, r.home.as_ref(), &r.limits, &r.nav);
                v.result.map_err(|e| e.result)?;
                self.warnings = v.warnings;
                Ok(())
            }
            PlanKind::Fence => validate_fence(&self.staging).map_err(|(_, e)| e),
            PlanKind::Rally => Ok(()),
        }
    }

    /// `MISSION_ACK` from the ground station: ends a download, or cancels an upload.
    pub(crate) fn on_ack(&mut self, mtype: MavMissionType, partner: Peer) {
        match self.transfer {
            Transfer::Download {
                kind, partner: p, ..
            } if p == partner && mission_type(kind) == mtype => self.transfer = Transfer::Idle,
            Transfer::Upload {
                kind, partner: p, ..
            } if p == partner && mission_type(kind) == mtype => self.abort(),
            _ => {}
        }
    }

    /// `MISSION_CLEAR_ALL`.
    pub(crate) fn on_clear(
        &mut self,
        store: &mut MissionStore,
        mtype: MavMissionType,
    ) -> MissionReply {
        if self.busy() {
            return MissionReply::Ack(mtype, MavMissionResult::MAV_MISSION_DENIED);
        }
        self.last_done = None;
        match mtype {
            MavMissionType::MAV_MISSION_TYPE_ALL => {
                store.clear(PlanKind::Mission);
                store.clear(PlanKind::Fence);
                store.clear(PlanKind::Rally);
            }
            t => match plan_kind(t) {
                Some(k) => store.clear(k),
                None => return MissionReply::Ack(mtype, MavMissionResult::MAV_MISSION_UNSUPPORTED),
            },
        }
        MissionReply::Ack(mtype, MavMissionResult::MAV_MISSION_ACCEPTED)
    }

    /// Timers: re-request a lost item, give up after [`UPLOAD_MAX_RETRIES`], forget a
    /// download nobody finishes. Returns what to send and to whom.
    pub(crate) fn poll(&mut self, now_us: u64) -> Option<(MissionReply, Peer)> {
        match &mut self.transfer {
            Transfer::Idle => None,
            Transfer::Upload {
                kind,
                next,
                partner,
                last_us,
                retries,
                ..
            } => {
                if now_us.saturating_sub(*last_us) < UPLOAD_RETRY_US {
                    return None;
                }
                let (kind, next, partner) = (*kind, *next, *partner);
                if *retries >= UPLOAD_MAX_RETRIES {
                    self.abort();
                    return Some((
                        MissionReply::Ack(mission_type(kind), MavMissionResult::MAV_MISSION_ERROR),
                        partner,
                    ));
                }
                *retries = retries.saturating_add(1);
                *last_us = now_us;
                Some((MissionReply::Request(kind, next), partner))
            }
            Transfer::Download { last_us, .. } => {
                if now_us.saturating_sub(*last_us) >= DOWNLOAD_TIMEOUT_US {
                    self.transfer = Transfer::Idle;
                }
                None
            }
        }
    }
}

/// The message that carries a reply.
pub(crate) fn mission_message(
    reply: MissionReply,
    to: (u8, u8),
    store: &MissionStore,
    current_seq: u16,
) -> Option<MavMessage> {
    Some(match reply {
        MissionReply::Ack(mission_type, result) => MavMessage::MISSION_ACK(MISSION_ACK_DATA {
            target_system: to.0,
            target_component: to.1,
            mavtype: result,
            mission_type,
            opaque_id: if result == MavMissionResult::MAV_MISSION_ACCEPTED {
                plan_kind(mission_type).map_or(0, |k| store.opaque_id(k))
            } else {
                0
            },
        }),
        MissionReply::Request(kind, seq) => {
            MavMessage::MISSION_REQUEST_INT(MISSION_REQUEST_INT_DATA {
                seq,
                target_system: to.0,
                target_component: to.1,
                mission_type: mission_type(kind),
            })
        }
        MissionReply::Count(kind) => MavMessage::MISSION_COUNT(MISSION_COUNT_DATA {
            count: store.items(kind).len() as u16,
            target_system: to.0,
            target_component: to.1,
            mission_type: mission_type(kind),
            opaque_id: store.opaque_id(kind),
        }),
        MissionReply::Item(kind, seq) => {
            let item = store.items(kind).get(usize::from(seq))?;
            let current = kind == PlanKind::Mission && seq == current_seq;
            MavMessage::MISSION_ITEM_INT(item_to_mav(item, seq, kind, current, to)?)
        }
    })
}
