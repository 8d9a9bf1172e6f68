//! MAVLink byte-stream framing with counted rejections.
//!
//! The `mavlink` crate's own reader skips corrupt frames silently; an autopilot must count
//! them (bad CRC, unknown message, undecodable payload) and report them, so this parser does
//! the frame synchronisation itself and the checksum (MAVLink's CRC-16, [`crate::crc`]), and
//! leaves the payload to the dialect's decoders. It takes bytes in whatever chunks a UART, a socket or a pipe
//! delivers them, never allocates and never panics.
//!
//! The parser and the [`Sender`] are generic over the [`Dialect`] they speak: the whole common
//! set ([`Common`], the default, for the host's tools) or the autopilot's own ([`Autopilot`]),
//! whose image then holds the code of its own messages only.

use super::dialect::{Autopilot, Common, Dialect};
use super::signing::{self, Key, Signed};
use crate::crc::crc16_mcrf4xx;
use core::marker::PhantomData;
use mavlink::dialects::common::MavMessage;
use mavlink::{MAVLinkV1MessageRaw, MAVLinkV2MessageRaw, MavHeader, MavlinkVersion};

const STX_V1: u8 = 0xFE;
const STX_V2: u8 = 0xFD;
const V1_HEADER: usize = 5;
const V2_HEADER: usize = 9;
const V2_IFLAG_SIGNED: u8 = 0x01;
const V2_SIGNATURE: usize = 13;
const CHECKSUM: usize = 2;
const MAX_FRAME: usize = 1 + V2_HEADER + 255 + CHECKSUM + V2_SIGNATURE;

/// Counters of everything the parser saw.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LinkStats {
    /// Frames decoded and delivered.
    pub frames_ok: u32,
    /// Frames whose checksum did not match.
    pub crc_errors: u32,
    /// Frames of a message id this dialect does not know.
    pub unknown_ids: u32,
    /// Frames with a valid checksum whose payload did not decode (bad enum value, ...).
    pub parse_errors: u32,
    /// Frames with incompatibility flags this parser does not support.
    pub unsupported: u32,
    /// Bytes skipped while looking for a start-of-frame marker.
    pub bytes_skipped: u32,
    /// Lost frames, from gaps in each sender's sequence numbers.
    pub seq_gaps: u32,
    /// Frames cut short: still waiting for bytes when their datagram ended.
    pub cut_short: u32,
}

impl core::ops::Add for LinkStats {
    type Output = Self;
    /// The counts of two parsers together (wrapping, as each counter does).
    fn add(self, o: Self) -> Self {
        Self {
            frames_ok: self.frames_ok.wrapping_add(o.frames_ok),
            crc_errors: self.crc_errors.wrapping_add(o.crc_errors),
            unknown_ids: self.unknown_ids.wrapping_add(o.unknown_ids),
            parse_errors: self.parse_errors.wrapping_add(o.parse_errors),
            unsupported: self.unsupported.wrapping_add(o.unsupported),
            bytes_skipped: self.bytes_skipped.wrapping_add(o.bytes_skipped),
            seq_gaps: self.seq_gaps.wrapping_add(o.seq_gaps),
            cut_short: self.cut_short.wrapping_add(o.cut_short),
        }
    }
}

/// A frame whose checksum matched but whose payload this dialect could not decode (an enum
/// value it does not know): what a protocol may still answer (an unknown command gets
/// `MAV_RESULT_UNSUPPORTED`).
#[derive(Clone, Copy, Debug)]
pub struct Undecoded<'a> {
    /// Sender, sequence and component.
    pub header: MavHeader,
    /// Message id.
    pub id: u32,
    /// The payload as received (MAVLink 2 may have cut its trailing zeros).
    pub payload: &'a [u8],
}

/// A decoded frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Sender, sequence and component.
    pub header: MavHeader,
    /// Protocol version the frame arrived in.
    pub version: MavlinkVersion,
    /// The message.
    pub message: MavMessage,
    /// For a signed MAVLink 2 frame read with a key installed: its signature block and
    /// whether it matches the key (`None`: unsigned, or no key to check against).
    pub signed: Option<Signed>,
}

/// Incremental MAVLink 1 and 2 frame parser of the messages of dialect `D`.
pub struct FrameParser<D = Common> {
    buf: [u8; MAX_FRAME],
    len: usize,
    stats: LinkStats,
    last_seq: Option<(u32, u8)>,
    key: Option<Key>,
    dialect: PhantomData<D>,
}

impl<D: Dialect> Default for FrameParser<D> {
    fn default() -> Self {
        Self::for_dialect()
    }
}

// Lives for one check on the stack; boxing is not available without a heap.
#[allow(clippy::large_enum_variant)]
enum Check {
    NeedMore,
    Bad,
    /// Skip a whole frame (its CRC matched but its payload did not decode): its header, id,
    /// where its payload lies and its whole length.
    Skip(MavHeader, u32, core::ops::Range<usize>, usize),
    Done(Frame, usize),
}

impl FrameParser<Common> {
    /// An empty parser of the whole common dialect.
    pub const fn new() -> Self {
        Self::for_dialect()
    }
}

impl FrameParser<Autopilot> {
    /// An empty parser of the autopilot's dialect.
    pub const fn autopilot() -> Self {
        Self::for_dialect()
    }
}

impl<D: Dialect> FrameParser<D> {
    /// An empty parser of dialect `D`.
    pub const fn for_dialect() -> Self {
        Self {
            buf: [0; MAX_FRAME],
            len: 0,
            stats: LinkStats {
                frames_ok: 0,
                crc_errors: 0,
                unknown_ids: 0,
                parse_errors: 0,
                unsupported: 0,
                bytes_skipped: 0,
                seq_gaps: 0,
                cut_short: 0,
            },
            last_seq: None,
            key: None,
            dialect: PhantomData,
        }
    }

    /// The key signed frames are checked against (MAVLink 2 signing); `None`: not checked.
    pub fn set_key(&mut self, key: Option<Key>) {
        self.key = key;
    }

    /// The bytes held, waiting to form a frame.
    fn held(&self) -> &[u8] {
        self.buf.get(..self.len).unwrap_or(&[])
    }

    /// Bytes still missing before the candidate frame held can be checked: those up to its
    /// first three bytes (marker, length, flags), then those up to its whole length (no frame
    /// is shorter than either). A reader that hands the parser bytes only once that many have arrived
    /// calls it once or twice a frame instead of once a byte; the frames found, and when, are
    /// the same, since a candidate is checked only once it is whole.
    pub fn bytes_wanted(&self) -> usize {
        let held = self.len;
        if held < 3 {
            return 3usize.saturating_sub(held);
        }
        let (Some(&stx), Some(&payload_len), Some(&flags)) =
            (self.buf.first(), self.buf.get(1), self.buf.get(2))
        else {
            return 1;
        };
        let payload_len = usize::from(payload_len);
        // At most 1 + 9 + 255 + 2 + 13: no overflow.
        #[allow(clippy::arithmetic_side_effects)]
        let total = if stx == STX_V2 {
            let sig = if flags & V2_IFLAG_SIGNED != 0 {
                V2_SIGNATURE
            } else {
                0
            };
            1 + V2_HEADER + payload_len + CHECKSUM + sig
        } else {
            1 + V1_HEADER + payload_len + CHECKSUM
        };
        total.saturating_sub(held).max(1)
    }

    /// What the parser has counted so far.
    pub fn stats(&self) -> LinkStats {
        self.stats
    }

    /// Feeds bytes; calls `on_frame` for every complete, valid frame in order.
    pub fn push(&mut self, bytes: &[u8], on_frame: impl FnMut(Frame)) {
        self.push_with(bytes, on_frame, |_| {});
    }

    /// As [`FrameParser::push`], and calls `on_undecoded` for every frame whose checksum
    /// matched but whose payload did not decode.
    pub fn push_with(
        &mut self,
        bytes: &[u8],
        mut on_frame: impl FnMut(Frame),
        mut on_undecoded: impl FnMut(Undecoded<'_>),
    ) {
        self.push_dyn(bytes, &mut on_frame, &mut on_undecoded);
    }

    /// [`FrameParser::push_with`] with its callbacks called through their vtables: one copy
    /// of the framing for all its callers (the MCU image's two links had a copy each, with
    /// their handlers inlined into it, 1.5 KB), and a function of its own in the image's
    /// profile (one call per chunk of bytes).
    #[inline(never)]
    fn push_dyn(
        &mut self,
        bytes: &[u8],
        on_frame: &mut dyn FnMut(Frame),
        on_undecoded: &mut dyn FnMut(Undecoded<'_>),
    ) {
        let mut rest = bytes;
        while let Some((&b, tail)) = rest.split_first() {
            if self.len == 0 && b != STX_V1 && b != STX_V2 {
                self.stats.bytes_skipped = self.stats.bytes_skipped.wrapping_add(1);
                rest = tail;
                continue;
            }
            // Every byte short of the candidate's header, then of its whole length, would
            // only be answered "more" (a header the parser cannot take is answered as soon
            // as it is whole): they go in together and are checked once, not once a byte
            // (tens of instructions a byte on the MCU, whose budget is per period).
            let n = self.bytes_wanted().min(rest.len());
            let (take, after) = (rest.get(..n).unwrap_or(&[]), rest.get(n..).unwrap_or(&[]));
            let room = self.buf.get_mut(self.len..).unwrap_or(&mut []);
            let kept = take.len().min(room.len());
            for (slot, &b) in room.iter_mut().zip(take) {
                *slot = b;
            }
            self.len = self.len.saturating_add(kept);
            rest = after;
            self.drain(on_frame, on_undecoded);
        }
    }

    /// The transport says a datagram ended. On a datagram link (MAVLink over UDP) a frame never
    /// spans two datagrams, so a candidate still waiting for bytes is not a frame (a corrupt
    /// length byte, a truncated send): it is dropped and the frames behind it in the same
    /// datagram are delivered now, not when later datagrams have filled the length it claimed.
    pub fn end_of_datagram(&mut self, mut on_frame: impl FnMut(Frame)) {
        self.end_of_datagram_with(&mut on_frame, &mut |_| {});
    }

    /// As [`FrameParser::end_of_datagram`], with [`FrameParser::push_with`]'s callbacks.
    pub fn end_of_datagram_with(
        &mut self,
        on_frame: &mut impl FnMut(Frame),
        on_undecoded: &mut impl FnMut(Undecoded<'_>),
    ) {
        self.end_of_datagram_dyn(on_frame, on_undecoded);
    }

    /// [`FrameParser::end_of_datagram_with`] through the callbacks' vtables, as
    /// [`FrameParser::push_dyn`].
    fn end_of_datagram_dyn(
        &mut self,
        on_frame: &mut dyn FnMut(Frame),
        on_undecoded: &mut dyn FnMut(Undecoded<'_>),
    ) {
        while self.len > 0 {
            self.stats.cut_short = self.stats.cut_short.wrapping_add(1);
            self.resync();
            self.drain(on_frame, on_undecoded);
        }
    }

    /// Checks the buffer until it needs more bytes.
    fn drain(
        &mut self,
        on_frame: &mut dyn FnMut(Frame),
        on_undecoded: &mut dyn FnMut(Undecoded<'_>),
    ) {
        loop {
            match self.check() {
                Check::NeedMore => return,
                Check::Done(frame, n) => {
                    self.note_sequence(&frame.header);
                    self.stats.frames_ok = self.stats.frames_ok.wrapping_add(1);
                    on_frame(frame);
                    self.consume(n);
                }
                Check::Skip(header, id, payload, n) => {
                    let payload = self.buf.get(payload).unwrap_or(&[]);
                    on_undecoded(Undecoded {
                        header,
                        id,
                        payload,
                    });
                    self.consume(n)
                }
                // A corrupt candidate: the real frame may start inside it, so resynchronise
                // on the next marker after its first byte.
                Check::Bad => self.resync(),
            }
            if self.len == 0 {
                return;
            }
        }
    }

    fn consume(&mut self, n: usize) {
        self.drop_front(n);
        self.skip_to_marker(0);
    }

    /// Forgets the first `n` bytes held (all of them when fewer are held).
    fn drop_front(&mut self, n: usize) {
        let len = self.len.min(self.buf.len());
        let n = n.min(len);
        // Byte by byte from the front (the bytes kept move towards it, so none is overwritten
        // before it is read): `copy_within` would be the image's only use of `memmove`.
        for i in n..len {
            let b = self.buf.get(i).copied().unwrap_or(0);
            if let Some(d) = self.buf.get_mut(i.saturating_sub(n)) {
                *d = b;
            }
        }
        self.len = len.saturating_sub(n);
    }

    fn resync(&mut self) {
        self.skip_to_marker(1);
    }

    fn skip_to_marker(&mut self, from: usize) {
        let start = self
            .held()
            .iter()
            .enumerate()
            .skip(from)
            .find(|(_, &b)| b == STX_V1 || b == STX_V2)
            .map_or(self.len, |(i, _)| i);
        self.stats.bytes_skipped = self.stats.bytes_skipped.wrapping_add(start as u32);
        self.drop_front(start);
    }

    fn note_sequence(&mut self, h: &MavHeader) {
        if let Some((sys, seq)) = self.last_seq {
            if sys == h.system_id {
                let gap = h.sequence.wrapping_sub(seq).wrapping_sub(1);
                // A large jump is a restarted sender, not 200 lost frames.
                if gap > 0 && gap < 128 {
                    self.stats.seq_gaps = self.stats.seq_gaps.wrapping_add(u32::from(gap));
                }
            }
        }
        self.last_seq = Some((h.system_id, h.sequence));
    }

    fn check(&mut self) -> Check {
        let Some(&stx) = self.buf.first().filter(|_| self.len > 0) else {
            return Check::NeedMore;
        };
        if self.len < 3 {
            return Check::NeedMore;
        }

        let payload_len = usize::from(self.buf[1]);
        if stx == STX_V2 {
            let iflags = self.buf[2];
            if iflags & !V2_IFLAG_SIGNED != 0 {
                self.stats.unsupported = self.stats.unsupported.wrapping_add(1);
                return Check::Bad;
            }
            let sig = if iflags & V2_IFLAG_SIGNED != 0 {
                V2_SIGNATURE
            } else {
                0
            };
            // At most 1 + 9 + 255 + 2 + 13: no overflow.
            #[allow(clippy::arithmetic_side_effects)]
            let total = 1 + V2_HEADER + payload_len + CHECKSUM + sig;
            if self.len < total {
                return Check::NeedMore;
            }
            let mut raw = MAVLinkV2MessageRaw::new();
            if !copy_into(raw.as_mut_slice(), self.held(), total) {
                return Check::Bad;
            }
            let id = raw.message_id();
            // At most 1 + 9 + 255: no overflow.
            #[allow(clippy::arithmetic_side_effects)]
            let end = 1 + V2_HEADER + payload_len;
            if let Some(bad) = self.check_crc(id, |x| checksum_matches(raw.as_slice(), end, x)) {
                return bad;
            }
            let header = MavHeader {
                system_id: raw.system_id(),
                component_id: raw.component_id(),
                sequence: raw.sequence(),
            };
            let signed = match (&self.key, self.held().get(..total)) {
                (Some(k), Some(frame)) => signing::check(frame, k),
                _ => None,
            };
            let start = 1 + V2_HEADER;
            let check = self.finish(header, MavlinkVersion::V2, id, raw.payload(), start, total);
            match check {
                Check::Done(mut f, n) => {
                    f.signed = signed;
                    Check::Done(f, n)
                }
                other => other,
            }
        } else {
            #[allow(clippy::arithmetic_side_effects)]
            let total = 1 + V1_HEADER + payload_len + CHECKSUM;
            if self.len < total {
                return Check::NeedMore;
            }
            let mut raw = MAVLinkV1MessageRaw::new();
            if !copy_into(raw.as_mut_slice(), self.held(), total) {
                return Check::Bad;
            }
            let id = u32::from(raw.message_id());
            // At most 1 + 9 + 255: no overflow.
            #[allow(clippy::arithmetic_side_effects)]
            let end = 1 + V1_HEADER + payload_len;
            if let Some(bad) = self.check_crc(id, |x| checksum_matches(raw.as_slice(), end, x)) {
                return bad;
            }
            let header = MavHeader {
                system_id: u32::from(raw.system_id()),
                component_id: raw.component_id(),
                sequence: raw.sequence(),
            };
            let start = 1 + V1_HEADER;
            self.finish(header, MavlinkVersion::V1, id, raw.payload(), start, total)
        }
    }

    /// `None` when the checksum of a frame of message `id` matches; else the candidate is
    /// bad, counted as an unknown id or a checksum error.
    fn check_crc(&mut self, id: u32, valid: impl FnOnce(u8) -> bool) -> Option<Check> {
        match D::extra_crc(id) {
            // Its checksum cannot be checked, so its length cannot be trusted either: a
            // corrupt start marker with a garbage id must not swallow the real frame behind
            // it. Resynchronise as after any bad candidate.
            None => {
                self.stats.unknown_ids = self.stats.unknown_ids.wrapping_add(1);
                Some(Check::Bad)
            }
            Some(extra) if !valid(extra) => {
                self.stats.crc_errors = self.stats.crc_errors.wrapping_add(1);
                Some(Check::Bad)
            }
            Some(_) => None,
        }
    }

    fn finish(
        &mut self,
        header: MavHeader,
        version: MavlinkVersion,
        id: u32,
        payload: &[u8],
        payload_start: usize,
        total: usize,
    ) -> Check {
        match D::decode(version, id, payload) {
            Ok(message) => Check::Done(
                Frame {
                    header,
                    version,
                    message,
                    signed: None,
                },
                total,
            ),
            Err(_) => {
                self.stats.parse_errors = self.stats.parse_errors.wrapping_add(1);
                let range = payload_start..payload_start.saturating_add(payload.len());
                Check::Skip(header, id, range, total)
            }
        }
    }
}

/// Copies the first `n` bytes of `src` into `dst`; false when either is shorter.
fn copy_into(dst: &mut [u8], src: &[u8], n: usize) -> bool {
    match (dst.get_mut(..n), src.get(..n)) {
        (Some(d), Some(s)) => {
            d.copy_from_slice(s);
            true
        }
        _ => false,
    }
}

/// Whether the checksum behind the first `end` bytes of `frame` (start marker, header and
/// payload) is MAVLink's of them and `extra_crc` (`common::crc`'s CRC-16, which the frames
/// the autopilot writes carry).
fn checksum_matches(frame: &[u8], end: usize, extra_crc: u8) -> bool {
    match (frame.get(1..end), frame.get(end..end.saturating_add(2))) {
        (Some(covered), Some(&[lo, hi])) => {
            crc16_mcrf4xx(crc16_mcrf4xx(0xFFFF, covered), &[extra_crc])
                == u16::from_le_bytes([lo, hi])
        }
        _ => false,
    }
}

/// Encodes one MAVLink 2 frame of the whole common dialect; returns the buffer holding it
/// (`raw_bytes()` is the frame).
pub fn encode_v2(header: MavHeader, message: &MavMessage) -> MAVLinkV2MessageRaw {
    let mut raw = MAVLinkV2MessageRaw::new();
    raw.serialize_message(header, message);
    raw
}

/// Hands out the sequence numbers of one sender on one link, which writes the messages of
/// dialect `D`.
#[derive(Clone, Copy, Debug)]
pub struct Sender<D = Common> {
    system_id: u8,
    component_id: u8,
    sequence: u8,
    dialect: PhantomData<D>,
}

impl Sender<Common> {
    /// A sender of the whole common dialect with the given identity.
    pub const fn new(system_id: u8, component_id: u8) -> Self {
        Self::for_dialect(system_id, component_id)
    }

    /// Encodes `message` as the next MAVLink 2 frame of this sender.
    pub fn encode(&mut self, message: &MavMessage) -> MAVLinkV2MessageRaw {
        encode_v2(self.next_header(), message)
    }
}

impl Sender<Autopilot> {
    /// A sender of the autopilot's dialect with the given identity.
    pub const fn autopilot(system_id: u8, component_id: u8) -> Self {
        Self::for_dialect(system_id, component_id)
    }
}

impl<D: Dialect> Sender<D> {
    /// A sender of dialect `D` with the given identity.
    pub const fn for_dialect(system_id: u8, component_id: u8) -> Self {
        Self {
            system_id,
            component_id,
            sequence: 0,
            dialect: PhantomData,
        }
    }

    fn header(&self) -> MavHeader {
        MavHeader {
            system_id: u32::from(self.system_id),
            component_id: self.component_id,
            sequence: self.sequence,
        }
    }

    /// The header for the next frame.
    pub fn next_header(&mut self) -> MavHeader {
        let h = self.header();
        self.sequence = self.sequence.wrapping_add(1);
        h
    }

    /// Encodes `message` as the next MAVLink 2 frame of this sender; `None` (and no sequence
    /// number spent) for a message its dialect does not write.
    pub fn try_encode(&mut self, message: &MavMessage) -> Option<MAVLinkV2MessageRaw> {
        let mut raw = MAVLinkV2MessageRaw::new();
        self.try_encode_into(message, &mut raw)?;
        Some(raw)
    }

    /// [`Sender::try_encode`] into `raw` (a fresh buffer): no frame copied on its way out.
    pub fn try_encode_into(
        &mut self,
        message: &MavMessage,
        raw: &mut MAVLinkV2MessageRaw,
    ) -> Option<()> {
        D::encode_into(self.header(), message, raw)?;
        self.sequence = self.sequence.wrapping_add(1);
        Some(())
    }

    /// Encodes one message's data (a type of the dialect's, or one written for a case the
    /// dialect's types cannot express) as the next MAVLink 2 frame of this sender.
    pub fn encode_data<M: mavlink::MessageData>(&mut self, data: &M) -> MAVLinkV2MessageRaw {
        let mut raw = MAVLinkV2MessageRaw::new();
        self.encode_data_into(data, &mut raw);
        raw
    }

    /// [`Sender::encode_data`] into `raw` (a fresh buffer).
    pub fn encode_data_into<M: mavlink::MessageData>(
        &mut self,
        data: &M,
        raw: &mut MAVLinkV2MessageRaw,
    ) {
        let header = self.next_header();
        // The dialect's writer, not the crate's `serialize_message_data`, whose bounds checks
        // inlined into the board's code would be panic sites of ours (its system id is a u8:
        // the writer never refuses it).
        if let Some(p) = super::dialect::write_payload(raw, data) {
            let _ = super::dialect::finish_v2(raw, header, p);
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use mavlink::dialects::common::{HEARTBEAT_DATA, PARAM_VALUE_DATA};
    use std::vec::Vec;

    fn frames(bytes: &[u8], chunk: usize) -> (Vec<Frame>, LinkStats) {
        let mut p = FrameParser::new();
        let mut out = Vec::new();
        for c in bytes.chunks(chunk.max(1)) {
            p.push(c, |f| out.push(f));
        }
        (out, p.stats())
    }

    fn heartbeat(seq: u8) -> Vec<u8> {
        let h = MavHeader {
            system_id: 1,
            component_id: 1,
            sequence: seq,
        };
        encode_v2(h, &MavMessage::HEARTBEAT(HEARTBEAT_DATA::default()))
            .raw_bytes()
            .to_vec()
    }

    #[test]
    fn decodes_frames_in_any_chunking() {
        let mut s = Vec::new();
        for i in 0..5 {
            s.extend(heartbeat(i));
        }
        for chunk in [1, 3, 7, 1000] {
            let (f, st) = frames(&s, chunk);
            assert_eq!(f.len(), 5);
            assert_eq!(st.crc_errors + st.bytes_skipped + st.seq_gaps, 0);
            assert_eq!(f[4].header.sequence, 4);
        }
    }

    #[test]
    fn counts_and_survives_garbage_bad_crc_truncation_and_unknown_ids() {
        let mut s = Vec::new();
        s.extend(b"\x00garbage\x01\x02");
        let mut bad = heartbeat(0);
        let n = bad.len();
        bad[n - 1] ^= 0xFF; // corrupt checksum
        s.extend(&bad);
        let trunc = heartbeat(1);
        s.extend(&trunc[..trunc.len() - 4]); // truncated: swallowed by the next frame's bytes
                                             // An unknown message id 0xABCDE with a plausible header.
        s.extend([STX_V2, 2, 0, 0, 9, 1, 1, 0xDE, 0xBC, 0x0A, 1, 2, 0x55, 0x66]);
        s.extend(heartbeat(2));
        s.extend(heartbeat(3));
        let (f, st) = frames(&s, 5);
        // Both heartbeats after the debris still arrive.
        assert!(f.len() >= 2, "{st:?}");
        assert_eq!(f.last().map(|f| f.header.sequence), Some(3));
        assert!(st.crc_errors >= 1, "{st:?}");
        assert!(st.bytes_skipped >= 10, "{st:?}");
    }

    #[test]
    fn an_unknown_id_is_counted_and_the_next_frame_still_arrives() {
        let mut s = Vec::new();
        s.extend([STX_V2, 2, 0, 0, 9, 1, 1, 0xDE, 0xBC, 0x0A, 1, 2, 0x55, 0x66]);
        s.extend(heartbeat(7));
        let (f, st) = frames(&s, 64);
        assert_eq!(f.len(), 1);
        assert_eq!(st.unknown_ids, 1);
    }

    #[test]
    fn mavlink1_frames_decode_and_sequence_gaps_count() {
        let h = MavHeader {
            system_id: 255,
            component_id: 190,
            sequence: 10,
        };
        let mut v1 = MAVLinkV1MessageRaw::new();
        let msg = MavMessage::PARAM_VALUE(PARAM_VALUE_DATA::default());
        v1.serialize_message(h, &msg);
        let mut s = v1.raw_bytes().to_vec();
        let h2 = MavHeader { sequence: 13, ..h };
        s.extend(encode_v2(h2, &msg).raw_bytes());
        let (f, st) = frames(&s, 2);
        assert_eq!(f.len(), 2);
        assert_eq!(f[0].version, MavlinkVersion::V1);
        assert_eq!(st.seq_gaps, 2);
    }

    #[test]
    fn a_corrupt_length_does_not_hold_the_frames_behind_it_in_its_datagram() {
        // A heartbeat whose length byte was hit (9 became 200), then two good ones, in one
        // datagram: they arrive when the datagram ends, not after 200 more bytes.
        let mut bad = heartbeat(0);
        bad[1] = 200;
        let mut s = bad;
        s.extend(heartbeat(1));
        s.extend(heartbeat(2));
        let mut p = FrameParser::new();
        let mut got = Vec::new();
        p.push(&s, |f| got.push(f.header.sequence));
        assert!(
            got.is_empty(),
            "held behind the corrupt length until the datagram ends"
        );
        p.end_of_datagram(|f| got.push(f.header.sequence));
        assert_eq!(got, [1, 2]);
        assert_eq!(p.stats().cut_short, 1);
        // The next datagram starts clean.
        p.push(&heartbeat(3), |f| got.push(f.header.sequence));
        assert_eq!(got, [1, 2, 3]);
    }

    #[test]
    fn a_frame_whose_payload_holds_a_whole_mavlink1_frame_still_arrives_byte_by_byte() {
        use mavlink::dialects::common::{MavSeverity, STATUSTEXT_DATA};
        // A MAVLink 1 heartbeat (17 bytes) inside a status text: while the text arrives, a
        // complete, valid frame lies in the buffer behind its start.
        let h = MavHeader {
            system_id: 1,
            component_id: 1,
            sequence: 0,
        };
        let mut v1 = mavlink::MAVLinkV1MessageRaw::new();
        v1.serialize_message(h, &MavMessage::HEARTBEAT(HEARTBEAT_DATA::default()));
        let mut text = [b'x'; 50];
        text[10..10 + v1.raw_bytes().len()].copy_from_slice(v1.raw_bytes());
        let msg = MavMessage::STATUSTEXT(STATUSTEXT_DATA {
            severity: MavSeverity::MAV_SEVERITY_INFO,
            text: text.into(),
            id: 0,
            chunk_seq: 0,
        });
        let s = encode_v2(h, &msg).raw_bytes().to_vec();
        let (f, _) = frames(&s, 1);
        assert!(
            matches!(
                f.as_slice(),
                [Frame {
                    message: MavMessage::STATUSTEXT(_),
                    ..
                }]
            ),
            "{f:?}"
        );
    }

    /// Frames found, each with the number of bytes that had arrived when it was, and the
    /// counters: the parser handed every byte as it arrives, or, as the MCU's loop does, the
    /// bytes waiting once there are `bytes_wanted` of them.
    fn arrivals(bytes: &[u8], wait: bool) -> (Vec<(u8, usize)>, LinkStats, usize) {
        let mut p = FrameParser::new();
        let (mut found, mut waiting, mut calls) = (Vec::new(), Vec::new(), 0);
        for (i, &b) in bytes.iter().enumerate() {
            waiting.push(b);
            if wait && waiting.len() < p.bytes_wanted() {
                continue;
            }
            calls += 1;
            p.push(&waiting, |f| found.push((f.header.sequence, i + 1)));
            waiting.clear();
        }
        (found, p.stats(), calls)
    }

    /// Three clean frames (the first `frames_only` bytes returned), then debris among frames:
    /// garbage, a bad checksum, a truncated frame, an unknown id, unsupported flags, MAVLink 1,
    /// and noise with markers and a heartbeat now and then.
    fn debris_stream() -> (Vec<u8>, usize) {
        let mut s = Vec::new();
        for i in 0..3 {
            s.extend(heartbeat(i));
        }
        let frames_only = s.len();
        s.extend(b"\x00garbage\x01\x02");
        let mut bad = heartbeat(3);
        let n = bad.len();
        bad[n - 1] ^= 0xFF;
        s.extend(&bad);
        let trunc = heartbeat(4);
        s.extend(&trunc[..trunc.len() - 4]);
        s.extend([STX_V2, 2, 0, 0, 9, 1, 1, 0xDE, 0xBC, 0x0A, 1, 2, 0x55, 0x66]);
        s.extend([STX_V2, 9, 0x80]);
        s.extend(heartbeat(5));
        let mut v1 = MAVLinkV1MessageRaw::new();
        let h = MavHeader {
            system_id: 1,
            component_id: 1,
            sequence: 6,
        };
        v1.serialize_message(h, &MavMessage::HEARTBEAT(HEARTBEAT_DATA::default()));
        s.extend(v1.raw_bytes());
        // Noise with markers among it, and a heartbeat now and then.
        let mut x: u32 = 0x8765_4321;
        for k in 0..5_000u32 {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            s.push(if x & 7 == 0 { STX_V2 } else { (x >> 8) as u8 });
            if k % 500 == 0 {
                s.extend(heartbeat((k / 500) as u8 + 7));
            }
        }
        (s, frames_only)
    }

    #[test]
    fn bytes_handed_over_once_the_parser_wants_them_give_the_same_frames_at_the_same_bytes() {
        let (s, frames_only) = debris_stream();
        let (byte_by_byte, stats, _) = arrivals(&s, false);
        let (waited, waited_stats, _) = arrivals(&s, true);
        assert!(byte_by_byte.len() >= 10, "{byte_by_byte:?}");
        assert_eq!(waited, byte_by_byte);
        assert_eq!(waited_stats, stats);
        // Clean frames: two calls each (the first three bytes, then the rest).
        let (_, _, calls) = arrivals(&s[..frames_only], true);
        assert_eq!(calls, 6);
    }

    /// The bytes of a chunk go into the candidate together, up to what it still lacks: the
    /// same frames and the same counts as one byte a call, however the stream is cut.
    #[test]
    fn a_chunk_taken_in_at_once_gives_what_its_bytes_one_by_one_give() {
        let (mut s, _) = debris_stream();
        // Unsupported flags under a length that claims most of a frame: answered as soon as
        // the header is whole, so the short frame behind it is not held back.
        s.extend([STX_V2, 250, 0x80]);
        s.extend(heartbeat(40));
        s.extend(heartbeat(41));
        // Each frame with the chunk it came out of.
        let found = |chunk: usize| {
            let mut p = FrameParser::new();
            let mut out = Vec::new();
            for (k, c) in s.chunks(chunk).enumerate() {
                p.push(c, |f| {
                    let id = mavlink::Message::message_id(&f.message);
                    out.push((f.header.sequence, id, k));
                });
            }
            (out, p.stats())
        };
        let (one_by_one, stats) = found(1);
        assert!(one_by_one.len() >= 12, "{one_by_one:?}");
        for chunk in [2, 3, 5, 13, 64, 97, 280, 281, s.len()] {
            let expected: Vec<_> = one_by_one
                .iter()
                .map(|&(seq, id, byte)| (seq, id, byte / chunk))
                .collect();
            assert_eq!(found(chunk), (expected, stats), "chunks of {chunk}");
        }
    }

    #[test]
    fn random_bytes_never_panic() {
        // xorshift: deterministic noise, including many 0xFD/0xFE markers.
        let mut x: u32 = 0x1234_5678;
        let mut s = Vec::new();
        for _ in 0..200_000 {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            let b = (x & 0xFF) as u8;
            s.push(if b < 16 { STX_V2 } else { b });
        }
        // A garbage marker just before the end can claim up to 280 bytes as its frame, so
        // enough real frames must follow for the parser to resynchronise.
        for i in 0..15 {
            s.extend(heartbeat(i));
        }
        let (f, _) = frames(&s, 97);
        assert!(matches!(
            f.last().map(|f| &f.message),
            Some(MavMessage::HEARTBEAT(_))
        ));
    }
}
