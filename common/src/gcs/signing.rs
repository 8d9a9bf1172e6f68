//! The ground link's signing policy (MAVLink 2 message signing).
//!
//! With no key, nothing changes. With a key (set by `SETUP_SIGNING`, kept with the
//! parameters), every frame that could change the vehicle (commands, modes, parameter writes,
//! mission uploads, sticks, a ground station's heartbeat, a new key) must be signed with it,
//! and its timestamp must be newer than the last one of its stream (system, component, link
//! id) or, for a new stream, less than a minute behind the vehicle's signing clock: anything
//! else is dropped and counted. Reading stays open to all: parameters and missions can be
//! downloaded unsigned, and telemetry goes to every station. Every frame the vehicle sends is
//! signed, with a timestamp that only grows.
//!
//! The vehicle has no calendar: its signing clock starts at the timestamp a key was set up
//! with (or was last saved at), moves on with the vehicle's own clock, and jumps forward to
//! any newer timestamp of a correctly signed frame (never of a badly signed one).

use crate::link::signing::{Key, Signed, KEY_LEN};
use mavlink::dialects::common::{MavMessage, SETUP_SIGNING_DATA};

/// How far behind the signing clock a new stream's first timestamp may be, in 10 us units
/// (one minute, as the MAVLink guide asks).
pub const NEW_STREAM_WINDOW: u64 = 6_000_000;
/// The largest timestamp a signature can carry (48 bits, 10 us units: 2104).
pub const MAX_TIMESTAMP: u64 = 0xFFFF_FFFF_FFFF;
/// Streams whose last timestamp is remembered; the oldest is forgotten for a new one.
pub const STREAMS: usize = 8;

/// One sender's last accepted timestamp.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Stream {
    system: u8,
    component: u8,
    link_id: u8,
    timestamp: u64,
}

/// Why a frame was dropped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Refusal {
    /// Not signed, or its signature does not match the key.
    Unsigned,
    /// Its timestamp is not newer than its stream's last, or a new stream's is too old.
    Replay,
}

impl core::fmt::Display for Refusal {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Refusal::Unsigned => "not signed with the key",
            Refusal::Replay => "signature timestamp too old (a replay)",
        })
    }
}

impl core::error::Error for Refusal {}

/// The signing state of a ground link.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Signing {
    key: Option<Key>,
    /// The signing clock at `at_us` of the vehicle's clock, 10 us units since 2015.
    base: u64,
    at_us: u64,
    now_us: u64,
    last_sent: u64,
    streams: heapless::Vec<Stream, STREAMS>,
    refused: u32,
    changes: u32,
}

/// Whether a message may change the vehicle, and so must be signed once a key is set.
pub fn needs_signature(msg: &MavMessage) -> bool {
    !matches!(
        msg,
        MavMessage::PARAM_REQUEST_LIST(_)
            | MavMessage::PARAM_REQUEST_READ(_)
            | MavMessage::MISSION_REQUEST_LIST(_)
            | MavMessage::MISSION_REQUEST_INT(_)
    ) && !is_legacy_request(msg)
}

#[allow(deprecated)] // MISSION_REQUEST is deprecated, still sent by older ground stations.
fn is_legacy_request(msg: &MavMessage) -> bool {
    matches!(msg, MavMessage::MISSION_REQUEST(_))
}

impl Signing {
    /// The key, when signing is on.
    pub fn key(&self) -> Option<&Key> {
        self.key.as_ref()
    }

    /// Frames dropped by the policy.
    pub fn refused(&self) -> u32 {
        self.refused
    }

    /// Counts changes of the key, so a board knows when to persist it.
    pub fn change_count(&self) -> u32 {
        self.changes
    }

    /// The signing clock now, 10 us units since 2015-01-01 (never beyond what a signature
    /// can carry).
    pub fn timestamp(&self) -> u64 {
        self.base
            .saturating_add(self.now_us.saturating_sub(self.at_us) / 10)
            .min(MAX_TIMESTAMP)
    }

    /// Loads a persisted key and the timestamp it was saved at (at start-up); a timestamp
    /// beyond 48 bits is not taken.
    pub fn load(&mut self, key: Option<Key>, timestamp: u64) {
        self.key = key.filter(|k| k.iter().any(|&b| b != 0));
        if timestamp <= MAX_TIMESTAMP {
            self.set_clock(timestamp);
        }
        self.streams.clear();
    }

    /// The vehicle's clock moved on.
    pub fn tick(&mut self, now_us: u64) {
        self.now_us = self.now_us.max(now_us);
    }

    fn set_clock(&mut self, timestamp: u64) {
        if timestamp > self.timestamp() {
            self.base = timestamp;
            self.at_us = self.now_us;
        }
    }

    /// The timestamp of the next frame sent: the clock, and always newer than the last (until
    /// the 48 bits run out, in 2104).
    pub fn next_timestamp(&mut self) -> u64 {
        let t = self
            .timestamp()
            .max(self.last_sent.saturating_add(1))
            .min(MAX_TIMESTAMP);
        self.last_sent = t;
        t
    }

    /// Decides on one received frame of `system`/`component` carrying `msg`.
    pub fn admit(
        &mut self,
        system: u8,
        component: u8,
        msg: &MavMessage,
        signed: Option<Signed>,
    ) -> Result<(), Refusal> {
        if self.key.is_none() {
            return Ok(());
        }
        let r = match signed {
            Some(s) if s.valid => self.fresh(system, component, s),
            _ if !needs_signature(msg) => Ok(()),
            _ => Err(Refusal::Unsigned),
        };
        if r.is_err() {
            self.refused = self.refused.saturating_add(1);
        }
        r
    }

    fn fresh(&mut self, system: u8, component: u8, s: Signed) -> Result<(), Refusal> {
        let same =
            |t: &Stream| t.system == system && t.component == component && t.link_id == s.link_id;
        match self.streams.iter_mut().find(|t| same(t)) {
            Some(t) if s.timestamp <= t.timestamp => return Err(Refusal::Replay),
            Some(t) => t.timestamp = s.timestamp,
            None => {
                if s.timestamp.saturating_add(NEW_STREAM_WINDOW) < self.timestamp() {
                    return Err(Refusal::Replay);
                }
                if self.streams.is_full() {
                    // The stream heard from longest ago (the oldest timestamp) makes room.
                    if let Some(i) = (0..self.streams.len())
                        .min_by_key(|&i| self.streams.get(i).map_or(0, |t| t.timestamp))
                    {
                        // `swap_remove` without its panic path (heapless's bounds assertion,
                        // inlined here in the size-optimised MCU image): the last stream
                        // takes the place of the one removed.
                        if let Some(Stream {
                            system,
                            component,
                            link_id,
                            timestamp,
                        }) = self.streams.pop()
                        {
                            if let Some(slot) = self.streams.get_mut(i) {
                                slot.system = system;
                                slot.component = component;
                                slot.link_id = link_id;
                                slot.timestamp = timestamp;
                            }
                        }
                    }
                }
                let _ = self.streams.push(Stream {
                    system,
                    component,
                    link_id: s.link_id,
                    timestamp: s.timestamp,
                });
            }
        }
        self.set_clock(s.timestamp);
        Ok(())
    }

    /// `SETUP_SIGNING`: takes the key (all zero with a zero timestamp turns signing off). With
    /// signing on, only a correctly signed setup is taken (`signed_ok`), so nobody without the
    /// key can replace it. An initial timestamp no signature can carry (beyond 48 bits) is
    /// refused: the clock would pass every timestamp a station can send, and every signed
    /// frame, a new setup included, would be refused as a replay. Returns whether it was taken.
    pub fn setup(&mut self, d: &SETUP_SIGNING_DATA, signed_ok: bool) -> bool {
        if (self.key.is_some() && !signed_ok) || d.initial_timestamp > MAX_TIMESTAMP {
            return false;
        }
        let off = d.secret_key.iter().all(|&b| b == 0) && d.initial_timestamp == 0;
        let mut key = [0u8; KEY_LEN];
        for (k, b) in key.iter_mut().zip(d.secret_key.iter()) {
            *k = *b;
        }
        self.key = if off { None } else { Some(key) };
        self.set_clock(d.initial_timestamp);
        self.streams.clear();
        self.changes = self.changes.wrapping_add(1);
        true
    }

    /// `SETUP_SIGNING` as a station sent it (`signed`: its signature block, if it had one):
    /// the setup taken or refused as [`Signing::setup`] does, and the status text that tells
    /// the station which.
    pub fn on_setup(&mut self, d: &SETUP_SIGNING_DATA, signed: Option<Signed>) -> &'static str {
        let with_key = signed.is_some_and(|s| s.valid);
        if !self.setup(d, with_key) {
            "Signing setup refused: not signed with the key"
        } else if self.key.is_some() {
            "Signing on: unsigned writes are refused"
        } else {
            "Signing off"
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mavlink::dialects::common::{HEARTBEAT_DATA, PARAM_REQUEST_LIST_DATA, PARAM_SET_DATA};

    fn on(key: u8, ts: u64) -> Signing {
        let mut s = Signing::default();
        let d = SETUP_SIGNING_DATA {
            initial_timestamp: ts,
            target_system: 1,
            target_component: 1,
            secret_key: [key; 32],
        };
        assert!(s.setup(&d, false));
        s
    }

    fn signed(link_id: u8, timestamp: u64) -> Option<Signed> {
        Some(Signed {
            link_id,
            timestamp,
            valid: true,
        })
    }

    fn write() -> MavMessage {
        MavMessage::PARAM_SET(PARAM_SET_DATA::default())
    }

    #[test]
    fn without_a_key_everything_passes() {
        let mut s = Signing::default();
        assert_eq!(s.admit(255, 190, &write(), None), Ok(()));
    }

    #[test]
    fn with_a_key_writes_need_a_signature_and_reads_do_not() {
        let mut s = on(7, 1_000_000_000);
        assert_eq!(s.admit(255, 190, &write(), None), Err(Refusal::Unsigned));
        let bad = Some(Signed {
            link_id: 0,
            timestamp: 1_000_000_001,
            valid: false,
        });
        assert_eq!(s.admit(255, 190, &write(), bad), Err(Refusal::Unsigned));
        let list = MavMessage::PARAM_REQUEST_LIST(PARAM_REQUEST_LIST_DATA::default());
        assert_eq!(s.admit(255, 190, &list, None), Ok(()));
        // A ground station's heartbeat keeps the link-loss failsafe quiet: signed only.
        let hb = MavMessage::HEARTBEAT(HEARTBEAT_DATA::default());
        assert_eq!(s.admit(255, 190, &hb, None), Err(Refusal::Unsigned));
        assert_eq!(s.refused(), 3);
    }

    #[test]
    fn a_replayed_frame_is_refused_and_each_stream_counts_its_own_time() {
        let t0 = 1_000_000_000;
        let mut s = on(7, t0);
        assert_eq!(s.admit(255, 190, &write(), signed(0, t0 + 5)), Ok(()));
        assert_eq!(
            s.admit(255, 190, &write(), signed(0, t0 + 5)),
            Err(Refusal::Replay)
        );
        assert_eq!(s.admit(255, 190, &write(), signed(0, t0 + 6)), Ok(()));
        // Another link of the same station is another stream.
        assert_eq!(s.admit(255, 190, &write(), signed(1, t0 + 1)), Ok(()));
        // A new stream more than a minute behind the clock is a replay of an old recording.
        assert_eq!(
            s.admit(250, 1, &write(), signed(0, t0 - NEW_STREAM_WINDOW - 10)),
            Err(Refusal::Replay)
        );
    }

    #[test]
    fn the_clock_follows_the_vehicle_and_newer_signed_time_and_never_goes_back() {
        let t0 = 1_000_000_000;
        let mut s = on(7, t0);
        s.tick(1_000_000);
        assert_eq!(s.timestamp(), t0 + 100_000);
        assert_eq!(s.admit(255, 190, &write(), signed(0, t0 + 500_000)), Ok(()));
        assert_eq!(s.timestamp(), t0 + 500_000);
        let a = s.next_timestamp();
        let b = s.next_timestamp();
        assert!(b > a && a >= t0 + 500_000);
    }

    #[test]
    fn only_a_signed_setup_replaces_a_key_and_zeros_turn_signing_off() {
        let mut s = on(7, 1);
        let other = SETUP_SIGNING_DATA {
            initial_timestamp: 2,
            target_system: 1,
            target_component: 1,
            secret_key: [9; 32],
        };
        assert!(!s.setup(&other, false));
        assert_eq!(s.key(), Some(&[7; 32]));
        let off = SETUP_SIGNING_DATA {
            initial_timestamp: 0,
            target_system: 1,
            target_component: 1,
            secret_key: [0; 32],
        };
        assert!(s.setup(&off, true));
        assert_eq!(s.key(), None);
    }

    #[test]
    fn a_setup_time_no_signature_can_carry_is_refused() {
        // Taken, the clock would pass every 48-bit timestamp: each signed frame, a new
        // setup included, would then be refused as a replay.
        let mut s = Signing::default();
        let far = SETUP_SIGNING_DATA {
            initial_timestamp: MAX_TIMESTAMP + 1,
            target_system: 1,
            target_component: 1,
            secret_key: [7; 32],
        };
        assert!(!s.setup(&far, false));
        assert_eq!(s.key(), None);
        let mut s = on(7, 1_000);
        assert!(!s.setup(&far, true));
        s.load(Some([7; 32]), u64::MAX);
        assert!(s.timestamp() <= MAX_TIMESTAMP);
        assert_eq!(s.admit(255, 190, &write(), signed(0, 2_000)), Ok(()));
        // At the end of the 48 bits, the clock stops there instead of wrapping to 0.
        let mut s = on(7, MAX_TIMESTAMP);
        s.tick(10_000_000);
        assert_eq!(s.timestamp(), MAX_TIMESTAMP);
        assert_eq!(s.next_timestamp(), MAX_TIMESTAMP);
    }

    #[test]
    fn refusals_read_as_a_plain_reason_and_are_errors() {
        extern crate std;
        use std::string::ToString;
        assert_eq!(Refusal::Unsigned.to_string(), "not signed with the key");
        assert_eq!(
            Refusal::Replay.to_string(),
            "signature timestamp too old (a replay)"
        );
        let e: &dyn core::error::Error = &Refusal::Replay;
        assert!(e.source().is_none());
    }
}
