//! Mission, geofence and rally-point storage and the MAVLink mission protocol (`*_INT` only).
//!
//! One transfer runs at a time, as in PX4. An upload lands in a staging list and replaces the
//! stored list only when its last item has arrived, so a failed or cancelled upload keeps the
//! old plan. Home is not item 0: item 0 is the first thing to fly.

use crate::estimator::Home;
use crate::navigation::{
    validate_fence, validate_mission, MissionLimits, NavParams, ValidationWarning,
};
use heapless::Vec;
use mavlink::dialects::common::{
    MavCmd, MavFrame, MavMissionResult, MavMissionType, MISSION_ITEM_INT_DATA,
};
use num_traits::FromPrimitive;
use serde::{Deserialize, Serialize};

/// Mission items stored (at least 128, QGC plans of a few hundred items are rare on a small
/// fixed wing).
pub const MISSION_CAPACITY: usize = 160;
/// Geofence items stored (polygon vertices, circles, return point).
pub const FENCE_CAPACITY: usize = 64;
/// Rally points stored.
pub const RALLY_CAPACITY: usize = 16;

/// Time without an answer after which an item is requested again, µs.
pub const UPLOAD_RETRY_US: u64 = 500_000;
/// Requests of the same item before the upload is given up with `MAV_MISSION_ERROR`.
pub const UPLOAD_MAX_RETRIES: u8 = 5;
/// Time without a request after which a download is considered over, µs.
pub const DOWNLOAD_TIMEOUT_US: u64 = 5_000_000;

/// Which list an item belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum PlanKind {
    /// Mission items.
    Mission,
    /// Geofence.
    Fence,
    /// Rally points.
    Rally,
}

impl PlanKind {
    /// The list a `mission_type` names (`None` for ALL or unknown).
    pub fn from_mav(t: MavMissionType) -> Option<Self> {
        match t {
            MavMissionType::MAV_MISSION_TYPE_MISSION => Some(PlanKind::Mission),
            MavMissionType::MAV_MISSION_TYPE_FENCE => Some(PlanKind::Fence),
            MavMissionType::MAV_MISSION_TYPE_RALLY => Some(PlanKind::Rally),
            _ => None,
        }
    }

    /// The `mission_type` of this list.
    pub fn to_mav(self) -> MavMissionType {
        match self {
            PlanKind::Mission => MavMissionType::MAV_MISSION_TYPE_MISSION,
            PlanKind::Fence => MavMissionType::MAV_MISSION_TYPE_FENCE,
            PlanKind::Rally => MavMissionType::MAV_MISSION_TYPE_RALLY,
        }
    }

    /// How many items this list can hold.
    pub const fn capacity(self) -> usize {
        match self {
            PlanKind::Mission => MISSION_CAPACITY,
            PlanKind::Fence => FENCE_CAPACITY,
            PlanKind::Rally => RALLY_CAPACITY,
        }
    }
}

/// One stored item. Float fields are kept as their bit patterns so every value, NaN payloads
/// included, comes back exactly as it was sent.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct MissionItem {
    /// `param1..param4` bit patterns.
    pub params: [u32; 4],
    /// `x`: latitude degE7 (global frames) or local x * 1e4.
    pub x: i32,
    /// `y`: longitude degE7 (global frames) or local y * 1e4.
    pub y: i32,
    /// `z` bit pattern: altitude, m (frame-dependent reference).
    pub z: u32,
    /// `MAV_CMD` number.
    pub command: u16,
    /// `MAV_FRAME` number.
    pub frame: u8,
    /// Continue to the next item when this one completes.
    pub autocontinue: bool,
}

impl MissionItem {
    /// `param1..param4` as floats.
    pub fn param(&self, i: usize) -> f32 {
        f32::from_bits(self.params.get(i).copied().unwrap_or(0))
    }

    /// `z` as a float, m.
    pub fn z_m(&self) -> f32 {
        f32::from_bits(self.z)
    }

    /// Takes an item off the link, checking what this autopilot can store for `kind`.
    // The *_INT frame numbers are deprecated synonyms, yet QGC and older tools still send them.
    #[allow(deprecated)]
    pub fn from_mav(d: &MISSION_ITEM_INT_DATA, kind: PlanKind) -> Result<Self, MavMissionResult> {
        let command = u16::try_from(d.command as u32)
            .map_err(|_| MavMissionResult::MAV_MISSION_UNSUPPORTED)?;
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
        Ok(Self {
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
    pub fn to_mav(
        &self,
        seq: u16,
        kind: PlanKind,
        current: bool,
        target: (u8, u8),
    ) -> Option<MISSION_ITEM_INT_DATA> {
        Some(MISSION_ITEM_INT_DATA {
            param1: self.param(0),
            param2: self.param(1),
            param3: self.param(2),
            param4: self.param(3),
            x: self.x,
            y: self.y,
            z: self.z_m(),
            seq,
            command: MavCmd::from_u32(u32::from(self.command))?,
            target_system: target.0,
            target_component: target.1,
            frame: MavFrame::from_u32(u32::from(self.frame))?,
            current: u8::from(current),
            autocontinue: u8::from(self.autocontinue),
            mission_type: kind.to_mav(),
        })
    }
}

/// A list does not fit its storage.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NoSpace;

/// The three stored lists.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MissionStore {
    /// Mission items, item 0 first to fly.
    pub mission: Vec<MissionItem, MISSION_CAPACITY>,
    /// Geofence items.
    pub fence: Vec<MissionItem, FENCE_CAPACITY>,
    /// Rally points.
    pub rally: Vec<MissionItem, RALLY_CAPACITY>,
}

impl MissionStore {
    /// The items of one list.
    pub fn items(&self, kind: PlanKind) -> &[MissionItem] {
        match kind {
            PlanKind::Mission => &self.mission,
            PlanKind::Fence => &self.fence,
            PlanKind::Rally => &self.rally,
        }
    }

    /// Empties one list.
    pub fn clear(&mut self, kind: PlanKind) {
        match kind {
            PlanKind::Mission => self.mission.clear(),
            PlanKind::Fence => self.fence.clear(),
            PlanKind::Rally => self.rally.clear(),
        }
    }

    /// Replaces one list; a list longer than the capacity is refused as a whole.
    pub fn replace(&mut self, kind: PlanKind, items: &[MissionItem]) -> Result<(), NoSpace> {
        fn put<const N: usize>(
            v: &mut Vec<MissionItem, N>,
            items: &[MissionItem],
        ) -> Result<(), NoSpace> {
            let mut n = Vec::new();
            n.extend_from_slice(items).map_err(|_| NoSpace)?;
            *v = n;
            Ok(())
        }
        match kind {
            PlanKind::Mission => put(&mut self.mission, items),
            PlanKind::Fence => put(&mut self.fence, items),
            PlanKind::Rally => put(&mut self.rally, items),
        }
    }

    /// CRC-32 of one list, never 0: the `opaque_id` a ground station may compare to skip a
    /// download. 0 is reserved by MAVLink for "no id".
    pub fn opaque_id(&self, kind: PlanKind) -> u32 {
        let items = self.items(kind);
        if items.is_empty() {
            return 0;
        }
        let mut crc = crc_any::CRCu32::crc32();
        for it in items {
            for p in it.params {
                crc.digest(&p.to_le_bytes());
            }
            crc.digest(&it.x.to_le_bytes());
            crc.digest(&it.y.to_le_bytes());
            crc.digest(&it.z.to_le_bytes());
            crc.digest(&it.command.to_le_bytes());
            crc.digest(&[it.frame, u8::from(it.autocontinue)]);
        }
        crc.get_crc().max(1)
    }
}

/// The transfer in progress.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Transfer {
    Idle,
    Upload {
        kind: PlanKind,
        count: u16,
        next: u16,
        partner: (u8, u8),
        last_us: u64,
        retries: u8,
    },
    Download {
        kind: PlanKind,
        partner: (u8, u8),
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

/// The stored lists plus the protocol state.
#[derive(Clone, Debug)]
pub struct MissionManager {
    store: MissionStore,
    staging: Vec<MissionItem, MISSION_CAPACITY>,
    transfer: Transfer,
    /// Last upload that completed, so a repeated last item is answered with the same ACK.
    last_done: Option<(PlanKind, u16, (u8, u8))>,
    changes: u32,
    rules: PlanRules,
    warnings: Vec<ValidationWarning, 8>,
}

/// What a finished upload is checked against before it replaces the stored list: the
/// navigator's limits and the present home (the vehicle keeps these up to date).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PlanRules {
    /// Home, once known (absolute altitudes are checked against it).
    pub home: Option<Home>,
    /// Altitude range of mission items.
    pub limits: MissionLimits,
    /// The navigator's parameters (approach checks).
    pub nav: NavParams,
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
            store: MissionStore {
                mission: Vec::new(),
                fence: Vec::new(),
                rally: Vec::new(),
            },
            staging: Vec::new(),
            transfer: Transfer::Idle,
            last_done: None,
            changes: 0,
            rules: PlanRules::default(),
            warnings: Vec::new(),
        }
    }

    /// The stored lists.
    pub fn store(&self) -> &MissionStore {
        &self.store
    }

    /// Replaces all lists (loading from flash at start-up).
    pub fn load(&mut self, store: MissionStore) {
        self.store = store;
        self.transfer = Transfer::Idle;
        self.changes = self.changes.wrapping_add(1);
    }

    /// Counts every change of a stored list: the navigator reloads and the firmware persists
    /// when it moves.
    pub fn change_count(&self) -> u32 {
        self.changes
    }

    /// Whether a transfer is running.
    pub fn busy(&self) -> bool {
        self.transfer != Transfer::Idle
    }

    fn busy_with_other(&self, partner: (u8, u8)) -> bool {
        match self.transfer {
            Transfer::Idle => false,
            Transfer::Upload { partner: p, .. } => p != partner,
            Transfer::Download { .. } => true,
        }
    }

    /// `MISSION_COUNT`: start (or restart) an upload.
    pub(crate) fn on_count(
        &mut self,
        mtype: MavMissionType,
        count: u16,
        partner: (u8, u8),
        now_us: u64,
    ) -> MissionReply {
        let Some(kind) = PlanKind::from_mav(mtype) else {
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
            self.store.clear(kind);
            self.changes = self.changes.wrapping_add(1);
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
        d: &MISSION_ITEM_INT_DATA,
        partner: (u8, u8),
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
                if p == partner && k.to_mav() == d.mission_type && d.seq.wrapping_add(1) == c {
                    return Some(MissionReply::Ack(
                        d.mission_type,
                        MavMissionResult::MAV_MISSION_ACCEPTED,
                    ));
                }
            }
            return None;
        };
        if p != partner || kind.to_mav() != d.mission_type {
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
        let item = match MissionItem::from_mav(d, kind) {
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
        let next = next + 1;
        if next >= count {
            let result = if let Err(r) = self.check(kind) {
                r
            } else if self.store.replace(kind, &self.staging).is_ok() {
                self.changes = self.changes.wrapping_add(1);
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
        mtype: MavMissionType,
        partner: (u8, u8),
        now_us: u64,
    ) -> MissionReply {
        let Some(kind) = PlanKind::from_mav(mtype) else {
            return MissionReply::Ack(mtype, MavMissionResult::MAV_MISSION_UNSUPPORTED);
        };
        if matches!(self.transfer, Transfer::Upload { .. }) {
            return MissionReply::Ack(mtype, MavMissionResult::MAV_MISSION_DENIED);
        }
        self.transfer = if self.store.items(kind).is_empty() {
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
        mtype: MavMissionType,
        seq: u16,
        partner: (u8, u8),
        now_us: u64,
    ) -> MissionReply {
        let Some(kind) = PlanKind::from_mav(mtype) else {
            return MissionReply::Ack(mtype, MavMissionResult::MAV_MISSION_UNSUPPORTED);
        };
        if matches!(self.transfer, Transfer::Upload { .. }) {
            return MissionReply::Ack(mtype, MavMissionResult::MAV_MISSION_DENIED);
        }
        if usize::from(seq) >= self.store.items(kind).len() {
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

    /// Sets what finished uploads are checked against.
    pub fn set_rules(&mut self, rules: PlanRules) {
        self.rules = rules;
    }

    /// The warnings of the last accepted mission upload (each returned once).
    pub fn take_warnings(&mut self) -> Vec<ValidationWarning, 8> {
        core::mem::take(&mut self.warnings)
    }

    /// Checks a complete upload: the mission as the navigator will fly it, the fence as the
    /// geofence reads it. Rally points are stored as they come.
    fn check(&mut self, kind: PlanKind) -> Result<(), MavMissionResult> {
        match kind {
            PlanKind::Mission => {
                let r = &self.rules;
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
    pub(crate) fn on_ack(&mut self, mtype: MavMissionType, partner: (u8, u8)) {
        match self.transfer {
            Transfer::Download {
                kind, partner: p, ..
            } if p == partner && kind.to_mav() == mtype => self.transfer = Transfer::Idle,
            Transfer::Upload {
                kind, partner: p, ..
            } if p == partner && kind.to_mav() == mtype => self.abort(),
            _ => {}
        }
    }

    /// `MISSION_CLEAR_ALL`.
    pub(crate) fn on_clear(&mut self, mtype: MavMissionType) -> MissionReply {
        if self.busy() {
            return MissionReply::Ack(mtype, MavMissionResult::MAV_MISSION_DENIED);
        }
        match mtype {
            MavMissionType::MAV_MISSION_TYPE_ALL => {
                self.store.clear(PlanKind::Mission);
                self.store.clear(PlanKind::Fence);
                self.store.clear(PlanKind::Rally);
            }
            t => match PlanKind::from_mav(t) {
                Some(k) => self.store.clear(k),
                None => return MissionReply::Ack(mtype, MavMissionResult::MAV_MISSION_UNSUPPORTED),
            },
        }
        self.changes = self.changes.wrapping_add(1);
        MissionReply::Ack(mtype, MavMissionResult::MAV_MISSION_ACCEPTED)
    }

    /// Timers: re-request a lost item, give up after [`UPLOAD_MAX_RETRIES`], forget a
    /// download nobody finishes. Returns what to send and to whom.
    pub(crate) fn poll(&mut self, now_us: u64) -> Option<(MissionReply, (u8, u8))> {
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
                        MissionReply::Ack(kind.to_mav(), MavMissionResult::MAV_MISSION_ERROR),
                        partner,
                    ));
                }
                *retries += 1;
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
