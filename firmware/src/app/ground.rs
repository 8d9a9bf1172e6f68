//! The ground-station port: bytes from the ground stations framed (one parser per channel, so
//! two stations never mix their bytes) and handed to the [`GroundLink`] with the vehicle's
//! snapshot and stores; the link's answers, telemetry and the vehicle's notices encoded into
//! one outgoing buffer, each frame tagged with where it goes.

use common::gcs::ftp::{self, File};
use common::gcs::logs::LOG_RESERVE_BYTES;
use common::gcs::{
    Dest, GroundLink, LinkConfig, Origin, Outgoing, Stores, COMPONENT_ID, SYSTEM_ID,
};
use common::link::dialect::Autopilot;
use common::link::framing::{FrameParser, LinkStats, Sender};
use common::link::signing;
use common::vehicle::commander::Severity;
use common::vehicle::{FromGround, Notice, Vehicle};
use mavlink::dialects::common::{MavMessage, MavSeverity};

/// Bytes waiting for the ground station at most (a full parameter burst and telemetry). The
/// MCU hands them to its USART's ring on every pass of its loop, so a pass's answers and
/// telemetry are all it holds (a burst of four FTP frames is 1 KiB).
#[cfg(target_os = "none")]
pub const GCS_OUT: usize = 4096;
/// Bytes waiting for the ground station at most (a full parameter burst and telemetry).
#[cfg(not(target_os = "none"))]
pub const GCS_OUT: usize = 8192;

/// Channels a board may have: one UART on the MCU; on the host a fixed ground station and up
/// to eight more that spoke first (see `sitl::GcsUdp`).
#[cfg(target_os = "none")]
pub const CHANNELS: usize = 1;
/// Channels a board may have: one UART on the MCU; on the host a fixed ground station and up
/// to eight more that spoke first (see `sitl::GcsUdp`).
#[cfg(not(target_os = "none"))]
pub const CHANNELS: usize = 9;

/// The files served over MAVLink FTP: the component metadata the build script generated from
/// the parameter registry (`build.rs`).
pub static FILES: [File; 2] = [
    File {
        name: ftp::GENERAL,
        bytes: include_bytes!(concat!(env!("OUT_DIR"), "/general.json")),
    },
    File {
        name: "parameters.json.xz",
        bytes: include_bytes!(concat!(env!("OUT_DIR"), "/parameters.json.xz")),
    },
];

/// Tag of a frame for every channel in the output buffer.
const TO_ALL: u8 = 0xFF;

/// The ground link with its framing and output buffer.
pub struct GroundPort {
    parsers: [FrameParser<Autopilot>; CHANNELS],
    tx: Sender<Autopilot>,
    link: GroundLink,
    /// Frames waiting, each as `[destination, length lo, length hi, frame...]`.
    out: heapless::Vec<u8, GCS_OUT>,
    bytes_dropped: u32,
    /// The vehicle's status texts with when they were sent, µs, kept for the flight log (the
    /// oldest dropped when full).
    log_texts: heapless::Deque<(u64, Severity, &'static str), LOG_TEXTS>,
}

/// Status texts kept for the flight log between two sensor frames.
const LOG_TEXTS: usize = 8;

impl Default for GroundPort {
    fn default() -> Self {
        Self::new()
    }
}

fn severity(s: Severity) -> MavSeverity {
    match s {
        Severity::Info => MavSeverity::MAV_SEVERITY_INFO,
        Severity::Warning => MavSeverity::MAV_SEVERITY_WARNING,
        Severity::Critical => MavSeverity::MAV_SEVERITY_CRITICAL,
    }
}

impl GroundPort {
    /// A port with the autopilot's identity and nothing received.
    /// Not inlined: see `App::fresh`.
    #[inline(never)]
    pub fn new() -> Self {
        Self {
            parsers: core::array::from_fn(|_| FrameParser::autopilot()),
            tx: Sender::autopilot(SYSTEM_ID, COMPONENT_ID),
            link: GroundLink::new(LinkConfig {
                files: &FILES,
                ..LinkConfig::default()
            }),
            out: heapless::Vec::new(),
            bytes_dropped: 0,
            log_texts: heapless::Deque::new(),
        }
    }

    /// The ground link's protocol state.
    pub fn link(&self) -> &GroundLink {
        &self.link
    }

    /// The ground link's protocol state, writable.
    pub fn link_mut(&mut self) -> &mut GroundLink {
        &mut self.link
    }

    /// MAVLink 2 signing of the link.
    pub fn signing_mut(&mut self) -> &mut common::gcs::signing::Signing {
        self.link.signing_mut()
    }

    /// Framing counters, every channel together.
    pub fn stats(&self) -> LinkStats {
        self.parsers
            .iter()
            .fold(LinkStats::default(), |a, p| a + p.stats())
    }

    /// Bytes the parser of `channel` needs before it can check its next frame
    /// ([`FrameParser::bytes_wanted`]); 1 for a channel the port does not have.
    pub fn bytes_wanted(&self, channel: u8) -> usize {
        self.parsers
            .get(usize::from(channel))
            .map_or(1, FrameParser::bytes_wanted)
    }

    /// The link's figures for the flight log.
    pub(crate) fn log_figures(&self) -> super::log::GroundFigures {
        super::log::GroundFigures {
            stats: self.stats(),
            tx_dropped: self.bytes_dropped(),
            heard_us: self.link.gcs_last_seen_us(),
        }
    }

    /// The vehicle's status texts since the last call, oldest first, with when they were
    /// sent, for the flight log.
    pub(crate) fn take_log_text(&mut self) -> Option<(u64, Severity, &'static str)> {
        self.log_texts.pop_front()
    }

    /// Forgets the texts kept for the flight log (no log is being recorded).
    pub(crate) fn forget_log_texts(&mut self) {
        self.log_texts.clear();
    }

    /// Bytes dropped because the output buffer was full.
    pub fn bytes_dropped(&self) -> u32 {
        self.bytes_dropped
    }

    /// What the ground link hands the vehicle with a sensor frame.
    pub fn from_ground(&mut self) -> FromGround {
        FromGround {
            requests: self.link.take_requests(),
            heard_us: self.link.gcs_last_seen_us(),
        }
    }

    /// Bytes from the ground stations on `channel` (refused beyond [`CHANNELS`]): every
    /// complete frame to the link, what it accepted to the vehicle, the answers into the
    /// output buffer. `datagram`: the bytes are one whole datagram (MAVLink over UDP), so a
    /// frame still incomplete at its end is not a frame and the ones behind it go through now.
    pub fn on_bytes(&mut self, channel: u8, bytes: &[u8], datagram: bool, vehicle: &mut Vehicle) {
        let Some(parser) = self.parsers.get_mut(usize::from(channel)) else {
            return;
        };
        let before = parser.stats();
        let now = vehicle.time_us().unwrap_or(0);
        // Signed frames are checked against the key in force when they arrive.
        parser.set_key(self.link.signing().key().copied());
        // Both callbacks answer through the link, one frame at a time, in order. The parser
        // never calls one from inside the other, so the borrow is always free: `try_` keeps
        // the image free of the panic path `borrow_mut` would bring. The vehicle's snapshot
        // is formed at the first complete frame, not per call: bytes that complete no frame
        // cost their framing only.
        let shared = core::cell::RefCell::new((&mut self.link, &mut *vehicle, None));
        let frames = core::cell::Cell::new(0u32);
        let mut on_frame = |f: common::link::framing::Frame| {
            if let Ok(mut guard) = shared.try_borrow_mut() {
                let (link, vehicle, snapshot) = &mut *guard;
                let snapshot = snapshot.get_or_insert_with(|| vehicle.snapshot());
                let (params, plan, rules) = vehicle.stores();
                let mut stores = Stores {
                    params,
                    plan,
                    rules,
                };
                let origin = Origin {
                    channel,
                    signed: f.signed,
                };
                frames.set(frames.get().saturating_add(1));
                link.handle(&f.header, &f.message, now, snapshot, &mut stores, origin)
            }
        };
        let mut on_undecoded = |raw: common::link::framing::Undecoded<'_>| {
            if let Ok(mut guard) = shared.try_borrow_mut() {
                frames.set(frames.get().saturating_add(1));
                guard
                    .0
                    .handle_undecoded(&raw.header, raw.id, raw.payload, channel)
            }
        };
        parser.push_with(bytes, &mut on_frame, &mut on_undecoded);
        if datagram {
            parser.end_of_datagram_with(&mut on_frame, &mut on_undecoded);
        }
        let (_, _, snapshot) = shared.into_inner();
        let after = parser.stats();
        let bad = after.crc_errors.wrapping_sub(before.crc_errors)
            + after.parse_errors.wrapping_sub(before.parse_errors);
        for _ in 0..bad.min(64) {
            self.link.note_rx_error();
        }
        // Nothing reached the link: nothing to act on or answer before the next poll.
        if frames.get() == 0 {
            return;
        }
        let requests = self.link.take_requests();
        vehicle.apply(&requests);
        // Nothing the vehicle acted on: the snapshot the frames saw still describes it.
        let unchanged = requests == common::vehicle::requests::VehicleRequests::default();
        self.poll_with(now, vehicle, snapshot.filter(|_| unchanged));
    }

    /// The vehicle's notices to the link, then everything due at `now_us` into the buffer.
    pub fn poll(&mut self, now_us: u64, vehicle: &mut Vehicle) {
        self.poll_with(now_us, vehicle, None);
    }

    /// [`GroundPort::poll`] with the vehicle's snapshot when one was just taken.
    fn poll_with(
        &mut self,
        now_us: u64,
        vehicle: &mut Vehicle,
        snapshot: Option<common::vehicle::snapshot::VehicleSnapshot>,
    ) {
        while let Some(n) = vehicle.next_notice() {
            match n {
                Notice::Text(s, text) => {
                    self.link.send_statustext(severity(s), text);
                    if self.log_texts.is_full() {
                        self.log_texts.pop_front();
                    }
                    let _ = self.log_texts.push_back((now_us, s, text));
                }
                Notice::Mission { current, reached } => {
                    self.link.mission_progress(current, reached)
                }
                Notice::Tune(r) => self.link.send_tune_report(&r),
            }
        }
        let snapshot = snapshot.unwrap_or_else(|| vehicle.snapshot());
        let (params, plan, rules) = vehicle.stores();
        let stores = Stores {
            params,
            plan,
            rules,
        };
        self.link.signing_mut().tick(now_us);
        self.through_link(|link, send| link.poll(now_us, &snapshot, &stores, send));
    }

    /// Lends the link to `f` with a sender that encodes each message the moment the link
    /// hands it over, signed as the link's own, so no list of whole messages (64 of them:
    /// 18 KB) waits on the stack. The link only hands messages over: its signing state is
    /// lent to the encoder meanwhile.
    fn through_link(&mut self, f: impl FnOnce(&mut GroundLink, &mut dyn FnMut(Dest, Outgoing))) {
        let mut signing = core::mem::take(self.link.signing_mut());
        let (tx, out, dropped) = (&mut self.tx, &mut self.out, &mut self.bytes_dropped);
        f(&mut self.link, &mut |dest, msg| {
            queue(tx, out, dropped, &mut signing, dest, &msg)
        });
        *self.link.signing_mut() = signing;
    }

    /// Serves the log protocol's requests from the board's `store`, within `room` bytes and
    /// what the output buffer has left after [`GroundPort::poll`] (telemetry first), less
    /// [`LOG_RESERVE_BYTES`] for the next poll's.
    pub fn serve_logs(
        &mut self,
        store: &mut dyn common::gcs::logs::LogStore,
        armed: bool,
        room: usize,
    ) {
        let left = GCS_OUT
            .saturating_sub(self.out.len())
            .saturating_sub(LOG_RESERVE_BYTES)
            .min(room);
        self.through_link(|link, send| link.serve_logs(store, armed, left, send));
    }

    /// A message of the board's own (its figures of itself) to every station, framed and
    /// signed as the link's own.
    pub fn send(&mut self, msg: &MavMessage) {
        // Encoded from the borrowed message: no copy of it (a clone of `MavMessage` is a match
        // over the whole common dialect in the image).
        let mut raw = mavlink::MAVLinkV2MessageRaw::new();
        if self.tx.try_encode_into(msg, &mut raw).is_some() {
            let (out, dropped) = (&mut self.out, &mut self.bytes_dropped);
            push_frame(out, dropped, self.link.signing_mut(), Dest::All, &raw);
        }
    }

    /// Hands out the frames waiting, one call per frame with where it goes, and empties the
    /// buffer.
    pub fn drain(&mut self, out: &mut impl FnMut(Dest, &[u8])) {
        let mut rest: &[u8] = &self.out;
        while let [tag, lo, hi, tail @ ..] = rest {
            let n = usize::from(u16::from_le_bytes([*lo, *hi]));
            let Some(frame) = tail.get(..n) else {
                break;
            };
            let dest = match *tag {
                TO_ALL => Dest::All,
                c => Dest::Channel(c),
            };
            out(dest, frame);
            rest = tail.get(n..).unwrap_or(&[]);
        }
        self.out.clear();
    }
}

/// Encodes `msg` (signed when `signing` has a key) into the output buffer `buf`, or counts its
/// bytes in `dropped` when the buffer is full.
fn queue(
    tx: &mut Sender<Autopilot>,
    buf: &mut heapless::Vec<u8, GCS_OUT>,
    dropped: &mut u32,
    signing: &mut common::gcs::signing::Signing,
    dest: Dest,
    msg: &Outgoing,
) {
    let mut raw = mavlink::MAVLinkV2MessageRaw::new();
    match msg {
        Outgoing::Message(m) => {
            // Not in the autopilot's dialect: nothing to send.
            if tx.try_encode_into(m, &mut raw).is_none() {
                return;
            }
        }
        Outgoing::Ack(a) => tx.encode_data_into(a, &mut raw),
    }
    push_frame(buf, dropped, signing, dest, &raw);
}

/// Puts an encoded frame (signed when `signing` has a key) into the output buffer `buf`, or
/// counts its bytes in `dropped` when the buffer is full.
fn push_frame(
    buf: &mut heapless::Vec<u8, GCS_OUT>,
    dropped: &mut u32,
    signing: &mut common::gcs::signing::Signing,
    dest: Dest,
    raw: &mavlink::MAVLinkV2MessageRaw,
) {
    // With signing on, every frame is signed; the link id says which channel.
    let link_id = match dest {
        Dest::All => 0,
        Dest::Channel(c) => c,
    };
    let signed = match signing.key().copied() {
        Some(key) => {
            let t = signing.next_timestamp();
            signing::sign(raw.raw_bytes(), &key, link_id, t)
        }
        None => None,
    };
    let frame = signed.as_deref().unwrap_or(raw.raw_bytes());
    let tag = match dest {
        Dest::All => TO_ALL,
        Dest::Channel(c) => c,
    };
    let [lo, hi] = (frame.len() as u16).to_le_bytes();
    let fits = buf.len().saturating_add(3).saturating_add(frame.len()) <= buf.capacity();
    if !fits
        || buf.extend_from_slice(&[tag, lo, hi]).is_err()
        || buf.extend_from_slice(frame).is_err()
    {
        *dropped = dropped.saturating_add(frame.len() as u32);
    }
}
