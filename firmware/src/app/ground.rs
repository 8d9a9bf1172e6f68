//! The ground-station port: bytes from the ground station framed and handed to the
//! [`GroundLink`] with the vehicle's snapshot and stores; the link's answers, telemetry and the
//! vehicle's notices encoded into one outgoing buffer.

use common::gcs::{GroundLink, Stores, COMPONENT_ID, SYSTEM_ID};
use common::link::framing::{FrameParser, LinkStats, Sender};
use common::vehicle::commander::Severity;
use common::vehicle::{FromGround, Notice, Vehicle};
use mavlink::dialects::common::MavSeverity;

/// Bytes waiting for the ground station at most (a full parameter burst and telemetry).
pub const GCS_OUT: usize = 8192;

/// The ground link with its framing and output buffer.
pub struct GroundPort {
    parser: FrameParser,
    tx: Sender,
    link: GroundLink,
    out: heapless::Vec<u8, GCS_OUT>,
    bytes_dropped: u32,
}

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
    pub fn new() -> Self {
        Self {
            parser: FrameParser::new(),
            tx: Sender::new(SYSTEM_ID, COMPONENT_ID),
            link: GroundLink::default(),
            out: heapless::Vec::new(),
            bytes_dropped: 0,
        }
    }

    /// The ground link's protocol state.
    pub fn link(&self) -> &GroundLink {
        &self.link
    }

    /// Framing counters.
    pub fn stats(&self) -> LinkStats {
        self.parser.stats()
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

    /// Bytes from the ground station: every complete frame to the link, what it accepted to
    /// the vehicle, the answers into the output buffer.
    pub fn on_bytes(&mut self, bytes: &[u8], vehicle: &mut Vehicle) {
        let before = self.parser.stats();
        let now = vehicle.time_us().unwrap_or(0);
        let snapshot = vehicle.snapshot();
        let (params, plan, rules) = vehicle.stores();
        let mut stores = Stores {
            params,
            plan,
            rules,
        };
        let link = &mut self.link;
        self.parser.push(bytes, |frame| {
            link.handle(&frame.header, &frame.message, now, &snapshot, &mut stores);
        });
        let after = self.parser.stats();
        let bad = after.crc_errors.wrapping_sub(before.crc_errors)
            + after.parse_errors.wrapping_sub(before.parse_errors);
        for _ in 0..bad.min(64) {
            self.link.note_rx_error();
        }
        vehicle.apply(&self.link.take_requests());
        self.poll(now, vehicle);
    }

    /// The vehicle's notices to the link, then everything due at `now_us` into the buffer.
    pub fn poll(&mut self, now_us: u64, vehicle: &mut Vehicle) {
        while let Some(n) = vehicle.next_notice() {
            match n {
                Notice::Text(s, text) => self.link.send_statustext(severity(s), text),
                Notice::Mission { current, reached } => {
                    self.link.mission_progress(current, reached)
                }
            }
        }
        let snapshot = vehicle.snapshot();
        let (params, plan, rules) = vehicle.stores();
        let stores = Stores {
            params,
            plan,
            rules,
        };
        let (tx, buf, dropped) = (&mut self.tx, &mut self.out, &mut self.bytes_dropped);
        self.link.poll(now_us, &snapshot, &stores, |msg| {
            let raw = tx.encode(&msg);
            if buf.extend_from_slice(raw.raw_bytes()).is_err() {
                *dropped = dropped.saturating_add(raw.raw_bytes().len() as u32);
            }
        });
    }

    /// Hands out the bytes waiting for the ground station.
    pub fn drain(&mut self, out: &mut impl FnMut(&[u8])) {
        if !self.out.is_empty() {
            out(&self.out);
            self.out.clear();
        }
    }
}
