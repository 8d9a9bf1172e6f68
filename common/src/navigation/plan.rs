//! The plan: mission items, geofence and rally points as the vehicle stores them, and their
//! capacities. The ground link fills it through the mission protocol, storage persists it and
//! the navigator flies it; none of them owns it.
//!
//! Items are kept in MAVLink's own shape (command and frame numbers, `param1..4`, `x`, `y`,
//! `z`) so that every value, NaN payloads included, comes back exactly as it was sent.

use heapless::Vec;
use serde::{Deserialize, Serialize};

/// Mission items stored: a QGroundControl survey of a small fixed wing's field (a few dozen
/// transects, each two waypoints, with its camera items) or a long waypoint route fits; a
/// plan of a few hundred items does not, and is refused whole (`MAV_MISSION_NO_SPACE`). Each
/// item costs 64 bytes of the STM32F405's RAM (stored and staged during an upload).
pub const MISSION_CAPACITY: usize = 140;
/// Geofence items stored (polygon vertices, circles, return point): a 30-vertex inclusion
/// polygon with its return point.
pub const FENCE_CAPACITY: usize = 32;
/// Rally points stored.
pub const RALLY_CAPACITY: usize = 16;

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
}

/// A list does not fit its storage.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NoSpace;

impl core::fmt::Display for NoSpace {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("list too long for its storage")
    }
}

impl core::error::Error for NoSpace {}

/// The three stored lists.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct MissionStore {
    /// Mission items, item 0 first to fly.
    pub mission: Vec<MissionItem, MISSION_CAPACITY>,
    /// Geofence items.
    pub fence: Vec<MissionItem, FENCE_CAPACITY>,
    /// Rally points.
    pub rally: Vec<MissionItem, RALLY_CAPACITY>,
    /// Changes since start-up (not persisted).
    #[serde(skip)]
    changes: u32,
}

impl PartialEq for MissionStore {
    /// The same lists, whatever their history.
    fn eq(&self, other: &Self) -> bool {
        self.mission == other.mission && self.fence == other.fence && self.rally == other.rally
    }
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

    /// Counts every change of a stored list: the navigator reloads and the firmware persists
    /// when it moves.
    pub fn change_count(&self) -> u32 {
        self.changes
    }

    /// Replaces all lists (loading from flash at start-up).
    pub fn load(&mut self, lists: MissionStore) {
        let changes = self.changes.wrapping_add(1);
        *self = lists;
        self.changes = changes;
    }

    /// Empties one list.
    pub fn clear(&mut self, kind: PlanKind) {
        match kind {
            PlanKind::Mission => self.mission.clear(),
            PlanKind::Fence => self.fence.clear(),
            PlanKind::Rally => self.rally.clear(),
        }
        self.changes = self.changes.wrapping_add(1);
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
        }?;
        self.changes = self.changes.wrapping_add(1);
        Ok(())
    }

    /// CRC-32 of one list, never 0: the `opaque_id` a ground station may compare to skip a
    /// download. 0 is reserved by MAVLink for "no id".
    pub fn opaque_id(&self, kind: PlanKind) -> u32 {
        let items = self.items(kind);
        if items.is_empty() {
            return 0;
        }
        let mut crc = crate::crc::Crc32::ieee();
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
        crc.get().max(1)
    }
}
