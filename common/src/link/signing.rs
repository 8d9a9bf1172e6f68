//! MAVLink 2 message signing, on the bytes of a frame (the MAVLink guide's "Message signing"):
//! a signed frame carries, after its checksum, a link id, a 48-bit timestamp (10 us units
//! since 2015-01-01 00:00:00 UTC) and the first 6 bytes of SHA-256 over the 32-byte secret key,
//! the frame from its start marker to its checksum, the link id and the timestamp.
//!
//! The `mavlink` crate's own signing needs `std`; this works on the MCU too (`sha2` without
//! its default features). What a receiver accepts (which frames must be signed, replays)
//! is the ground link's policy (`gcs::signing`).

use crate::crc::crc16_mcrf4xx;
use sha2::{Digest, Sha256};

/// Length of the secret key, bytes.
pub const KEY_LEN: usize = 32;
/// Bytes a signature adds to a frame: link id, timestamp, signature.
pub const SIGNATURE_LEN: usize = 13;
/// The `incompat_flags` bit of a signed frame.
pub const IFLAG_SIGNED: u8 = 0x01;
/// Start marker, header and checksum of a MAVLink 2 frame, bytes.
const OVERHEAD: usize = 1 + 9 + 2;
/// Largest frame: start marker, header, 255 bytes of payload, checksum, signature.
pub const MAX_SIGNED_FRAME: usize = OVERHEAD + 255 + SIGNATURE_LEN;

/// A secret key.
pub type Key = [u8; KEY_LEN];

/// What a signed frame says of itself, checked against a key.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Signed {
    /// The sender's link id.
    pub link_id: u8,
    /// The sender's timestamp, 10 us units since 2015-01-01.
    pub timestamp: u64,
    /// The signature matches the key.
    pub valid: bool,
}

/// The 48-bit signature of `frame` (start marker to checksum) for this link id and timestamp.
pub fn signature(key: &Key, frame: &[u8], link_id: u8, timestamp: u64) -> [u8; 6] {
    let mut h = Sha256::new();
    h.update(key);
    h.update(frame);
    h.update([link_id]);
    h.update(timestamp_bytes(timestamp));
    let d = h.finalize();
    let mut s = [0u8; 6];
    for (o, b) in s.iter_mut().zip(d.iter()) {
        *o = *b;
    }
    s
}

fn timestamp_bytes(t: u64) -> [u8; 6] {
    let b = t.to_le_bytes();
    [b[0], b[1], b[2], b[3], b[4], b[5]]
}

/// The length of a MAVLink 2 frame up to its checksum, from its length byte.
fn unsigned_len(frame: &[u8]) -> Option<usize> {
    frame
        .get(1)
        .map(|&n| OVERHEAD.saturating_add(usize::from(n)))
}

/// Reads the signature block of a whole, signed MAVLink 2 `frame` and checks it against
/// `key`; `None` if the frame is not a signed MAVLink 2 frame.
pub fn check(frame: &[u8], key: &Key) -> Option<Signed> {
    if frame.first() != Some(&0xFD) || frame.get(2)? & IFLAG_SIGNED == 0 {
        return None;
    }
    let n = unsigned_len(frame)?;
    let body = frame.get(..n)?;
    let block = frame.get(n..n.checked_add(SIGNATURE_LEN)?)?;
    let (&link_id, rest) = block.split_first()?;
    let (ts, sig) = rest.split_at_checked(6)?;
    let mut t = [0u8; 8];
    for (o, b) in t.iter_mut().zip(ts) {
        *o = *b;
    }
    let timestamp = u64::from_le_bytes(t);
    let valid = signature(key, body, link_id, timestamp) == sig;
    Some(Signed {
        link_id,
        timestamp,
        valid,
    })
}

/// Signs an encoded, unsigned MAVLink 2 `frame`: sets the signed flag, recomputes the
/// checksum (it covers the flags) and appends link id, timestamp and signature. `None` for a
/// frame that is not a whole MAVLink 2 frame.
///
/// The checksum is updated, not recomputed, so signing needs no dialect (no `CRC_EXTRA` of
/// the message): see `crc_change_of_signed_flag`.
pub fn sign(
    frame: &[u8],
    key: &Key,
    link_id: u8,
    timestamp: u64,
) -> Option<heapless::Vec<u8, MAX_SIGNED_FRAME>> {
    if frame.first() != Some(&0xFD) {
        return None;
    }
    let n = unsigned_len(frame)?;
    let mut out: heapless::Vec<u8, MAX_SIGNED_FRAME> =
        heapless::Vec::from_slice(frame.get(..n)?).ok()?;
    let flags = out.get_mut(2)?;
    let was_signed = *flags & IFLAG_SIGNED != 0;
    *flags |= IFLAG_SIGNED;
    let crc_at = n.checked_sub(2)?;
    if !was_signed {
        let &[lo, hi] = out.get(crc_at..n)? else {
            return None;
        };
        // The checksum covers the frame from its length byte to its payload's end, then
        // CRC_EXTRA: after the flags byte (index 2) come crc_at - 3 bytes of the frame and
        // CRC_EXTRA.
        let after_flags = crc_at.checked_sub(2)?;
        let crc = u16::from_le_bytes([lo, hi]) ^ crc_change_of_signed_flag(after_flags);
        out.get_mut(crc_at..n)?.copy_from_slice(&crc.to_le_bytes());
    }
    let sig = signature(key, &out, link_id, timestamp);
    out.push(link_id).ok()?;
    out.extend_from_slice(&timestamp_bytes(timestamp)).ok()?;
    out.extend_from_slice(&sig).ok()?;
    Some(out)
}

/// What setting the signed flag does to a frame's checksum, with `after` bytes covered after
/// the flags byte.
///
/// MAVLink's checksum (CRC-16/MCRF4XX) is affine in the bytes it covers: for two messages of
/// the same length, `crc(a) ^ crc(b)` depends on `a ^ b` alone. So flipping one bit changes the
/// checksum by `crc(flip) ^ crc(zeros)`, whatever the frame, its message or its `CRC_EXTRA`.
fn crc_change_of_signed_flag(after: usize) -> u16 {
    const ZEROS: [u8; 32] = [0; 32];
    let mut flipped = crc16_mcrf4xx(0xFFFF, &[IFLAG_SIGNED]);
    let mut zero = crc16_mcrf4xx(0xFFFF, &[0]);
    let mut left = after;
    while left > 0 {
        let k = left.min(ZEROS.len());
        let z = ZEROS.get(..k).unwrap_or(&[]);
        flipped = crc16_mcrf4xx(flipped, z);
        zero = crc16_mcrf4xx(zero, z);
        left = left.saturating_sub(k);
    }
    flipped ^ zero
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::link::framing::{FrameParser, Sender};
    use mavlink::dialects::common::{
        MavMessage, HEARTBEAT_DATA, PARAM_VALUE_DATA, STATUSTEXT_DATA,
    };
    use mavlink::Message;

    extern crate std;

    #[test]
    fn the_signed_checksum_is_the_one_computed_afresh_with_the_message_s_crc_extra() {
        // Payloads of 1 (trailing zeros cut) to 54 bytes: the updated checksum against the
        // MAVLink guide's recipe, a fresh CRC over the signed header and payload with CRC_EXTRA.
        let text = STATUSTEXT_DATA {
            text: "a longer text, so the payload runs to fifty bytes".into(),
            ..Default::default()
        };
        let value = PARAM_VALUE_DATA {
            param_value: 1.5,
            param_count: 300,
            ..Default::default()
        };
        let msgs = [
            MavMessage::HEARTBEAT(HEARTBEAT_DATA::default()),
            MavMessage::PARAM_VALUE(value),
            MavMessage::STATUSTEXT(text),
        ];
        let mut s = Sender::new(1, 1);
        for m in &msgs {
            let frame = s.encode(m);
            let signed = sign(frame.raw_bytes(), &[3; KEY_LEN], 1, 99).unwrap();
            let n = signed.len() - SIGNATURE_LEN;
            let want =
                mavlink::calculate_crc(&signed[1..n - 2], MavMessage::extra_crc(m.message_id()));
            assert_eq!(signed[n - 2..n], want.to_le_bytes(), "{}", m.message_name());
        }
    }

    #[test]
    fn the_signature_of_a_known_frame_is_the_known_one() {
        // A signed HEARTBEAT (seq 239, system 1, component 2) with its key, link 0 and the
        // largest timestamp, as the mavlink crate's and pymavlink's tests sign it: 2718b168ccf5
        // (SHA-256 checked independently; it covers the 0xFD start marker).
        let key: Key = [
            0x00, 0x01, 0xf2, 0xe3, 0xd4, 0xc5, 0xb6, 0xa7, 0x98, 0x00, 0x70, 0x76, 0x34, 0x32,
            0x00, 0x16, 0x22, 0x42, 0x00, 0xcc, 0xff, 0x7a, 0x00, 0x52, 0x75, 0x73, 0x74, 0x00,
            0x4d, 0x41, 0x56, 0xb3,
        ];
        let frame = [
            0xfd, 0x09, 0x01, 0x00, 0xef, 0x01, 0x02, 0x00, 0x00, 0x00, 0x05, 0x00, 0x00, 0x00,
            0x02, 0x03, 0x59, 0x03, 0x03, 0xc9, 0x8b,
        ];
        let sig = signature(&key, &frame, 0, 0xffff_ffff_ffff);
        assert_eq!(sig, [0x27, 0x18, 0xb1, 0x68, 0xcc, 0xf5]);
        let mut whole = std::vec::Vec::from(frame);
        whole.push(0);
        whole.extend([0xff; 6]);
        whole.extend(sig);
        let c = check(&whole, &key).unwrap();
        assert_eq!(
            (c.link_id, c.timestamp, c.valid),
            (0, 0xffff_ffff_ffff, true)
        );
    }

    #[test]
    fn a_frame_signed_here_verifies_and_any_changed_byte_breaks_it() {
        let key: Key = core::array::from_fn(|i| i as u8);
        let mut s = Sender::new(1, 1);
        let frame = s.encode(&MavMessage::HEARTBEAT(HEARTBEAT_DATA::default()));
        let signed = sign(frame.raw_bytes(), &key, 3, 0x0000_1234_5678).unwrap();
        assert_eq!(signed.len(), frame.raw_bytes().len() + SIGNATURE_LEN);
        let c = check(&signed, &key).unwrap();
        assert_eq!(
            (c.link_id, c.timestamp, c.valid),
            (3, 0x0000_1234_5678, true)
        );
        let mut other = key;
        other[0] ^= 1;
        assert!(!check(&signed, &other).unwrap().valid);
        for i in [4usize, 12, signed.len() - 8, signed.len() - 1] {
            let mut bad = signed.clone();
            bad[i] ^= 0x40;
            assert!(check(&bad, &key).is_none_or(|c| !c.valid), "byte {i}");
        }
    }

    #[test]
    fn a_signed_frame_still_decodes_with_its_new_checksum() {
        let key = [7u8; KEY_LEN];
        let mut s = Sender::new(1, 1);
        let frame = s.encode(&MavMessage::HEARTBEAT(HEARTBEAT_DATA::default()));
        let signed = sign(frame.raw_bytes(), &key, 0, 1).unwrap();
        let mut p = FrameParser::new();
        let mut n = 0;
        p.push(&signed, |_| n += 1);
        assert_eq!(n, 1);
        assert_eq!(p.stats().crc_errors, 0);
    }
}
