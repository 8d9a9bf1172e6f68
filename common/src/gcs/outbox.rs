//! What the link has to send: answers waiting for the next poll, and the status texts beside
//! them.

use super::mission::MissionReply;
use super::peer::{Dest, Peer};
use super::streams::Stream;
use super::texts::{Line, TextQueue, TEXT_MAX};
use crate::vehicle::modes::FlightMode;
use heapless::Deque;
use mavlink::dialects::common::{
    MavCmd, MavMessage, MavParamError, MavResult, MavSeverity, COMMAND_ACK_DATA, COMMAND_INT_DATA,
    COMMAND_LONG_DATA,
};
use mavlink::{MavlinkVersion, MessageData};

const PENDING_CAPACITY: usize = 32;

/// Something to send at the next poll.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Pending {
    Ack {
        command: MavCmd,
        result: MavResult,
        /// How far a command `IN_PROGRESS` is, percent (0 otherwise).
        progress: u8,
        to: Peer,
    },
    /// `COMMAND_ACK` for a command id the dialect does not know.
    Unsupported {
        command: u16,
        to: Peer,
    },
    ParamValue(u16),
    /// `PARAM_ERROR` for a name or an index, to the asker.
    ParamError {
        index: i16,
        name: [u8; 16],
        error: MavParamError,
        to: Peer,
    },
    ProtocolVersion,
    /// `COMPONENT_METADATA`: where the general metadata file is.
    ComponentMetadata,
    Mission(MissionReply, Peer),
    MissionCurrent(Option<u16>),
    ItemReached(u16),
    AutopilotVersion,
    AvailableMode(u8),
    CurrentMode,
    Heartbeat,
    Stream(Stream),
    MessageInterval {
        id: u16,
        interval_us: i32,
    },
}

/// Messages that follow a COMMAND_ACK (at most one per mode for AVAILABLE_MODES).
pub(crate) type After = heapless::Vec<Pending, { FlightMode::ALL.len() }>;

/// A command from `COMMAND_LONG` or `COMMAND_INT`, params 5 and 6 as floats.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Command {
    pub cmd: MavCmd,
    pub p: [f32; 7],
}

/// Answers and status texts waiting for the next poll: what every service writes and the
/// link's poll sends.
#[derive(Clone, Debug, Default)]
pub(crate) struct Outbox {
    pending: Deque<(Pending, Dest), PENDING_CAPACITY>,
    texts: TextQueue,
    dropped: u32,
}

impl Outbox {
    /// Queues a message for every station.
    pub fn push(&mut self, p: Pending) {
        self.push_to(p, Dest::All);
    }

    /// Queues a message for `dest`; dropped (and counted) when the queue is full.
    pub fn push_to(&mut self, p: Pending, dest: Dest) {
        if self.pending.push_back((p, dest)).is_err() {
            self.dropped = self.dropped.wrapping_add(1);
        }
    }

    /// Queues a `COMMAND_ACK` to the station that sent the command.
    pub fn ack(&mut self, command: MavCmd, result: MavResult, to: Peer) {
        self.ack_progress(command, result, 0, to);
    }

    /// Queues a `COMMAND_ACK` with its progress, percent.
    pub fn ack_progress(&mut self, command: MavCmd, result: MavResult, progress: u8, to: Peer) {
        self.push_to(
            Pending::Ack {
                command,
                result,
                progress,
                to,
            },
            to.dest(),
        );
    }

    /// Queues a status text built by pieces ([`Line`]) for every station.
    pub fn text(&mut self, severity: MavSeverity, line: &Line<TEXT_MAX>) {
        self.texts.push_line(severity, line.clone());
    }

    /// The status-text queue.
    pub fn texts_mut(&mut self) -> &mut TextQueue {
        &mut self.texts
    }

    /// The oldest answer waiting, with where it goes.
    pub fn pop(&mut self) -> Option<(Pending, Dest)> {
        self.pending.pop_front()
    }

    /// Answers and texts dropped because their queue was full.
    pub fn dropped(&self) -> u32 {
        self.dropped.wrapping_add(self.texts.dropped())
    }
}

/// What the link hands its owner to send (for the moment it takes to encode it: the size of
/// a message is no burden).
#[derive(Clone, Debug, PartialEq)]
#[allow(clippy::large_enum_variant)]
pub enum Outgoing {
    /// A message of the dialect.
    Message(MavMessage),
    /// A `COMMAND_ACK` for a command id the dialect's `MAV_CMD` does not name (so
    /// `COMMAND_ACK_DATA` cannot carry it).
    Ack(CommandAck),
}

/// `COMMAND_ACK` with the command as a number: the answer MAVLink's command protocol asks for
/// to a command this autopilot does not know (`MAV_RESULT_UNSUPPORTED`), whatever its id.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CommandAck {
    /// The command id, as received.
    pub command: u16,
    /// The result.
    pub result: MavResult,
    /// Who asked (system, component).
    pub target: (u8, u8),
}

impl MessageData for CommandAck {
    type Message = MavMessage;
    const ID: u32 = COMMAND_ACK_DATA::ID;
    const NAME: &'static str = COMMAND_ACK_DATA::NAME;
    const EXTRA_CRC: u8 = COMMAND_ACK_DATA::EXTRA_CRC;
    const ENCODED_LEN: usize = COMMAND_ACK_DATA::ENCODED_LEN;

    fn ser(&self, version: MavlinkVersion, payload: &mut [u8]) -> usize {
        // The dialect's own layout with a placeholder command, then the real id in the
        // command's two bytes (first in the payload: the largest field of the base).
        let n = COMMAND_ACK_DATA {
            command: MavCmd::MAV_CMD_NAV_WAYPOINT,
            result: self.result,
            progress: 0,
            result_param2: 0,
            target_system: self.target.0,
            target_component: self.target.1,
        }
        .ser(version, payload);
        if let Some(c) = payload.get_mut(..2) {
            c.copy_from_slice(&self.command.to_le_bytes());
        }
        n
    }

    fn deser(version: MavlinkVersion, payload: &[u8]) -> Result<Self, mavlink::error::ParserError> {
        let mut full = [0u8; COMMAND_ACK_DATA::ENCODED_LEN];
        for (d, s) in full.iter_mut().zip(payload) {
            *d = *s;
        }
        let command = u16::from_le_bytes([full[0], full[1]]);
        let placeholder = (MavCmd::MAV_CMD_NAV_WAYPOINT as u16).to_le_bytes();
        (full[0], full[1]) = (placeholder[0], placeholder[1]);
        let d = COMMAND_ACK_DATA::deser(version, &full)?;
        Ok(Self {
            command,
            result: d.result,
            target: (d.target_system, d.target_component),
        })
    }
}

/// The command id and target of a `COMMAND_LONG` or `COMMAND_INT` frame that did not decode
/// (its command id is not in the dialect): `(command, target system, target component)`.
pub fn undecoded_command(id: u32, payload: &[u8]) -> Option<(u16, u8, u8)> {
    if id != COMMAND_LONG_DATA::ID && id != COMMAND_INT_DATA::ID {
        return None;
    }
    // Both put the command (u16) at byte 28 and the targets at 30 and 31; MAVLink 2 may have
    // cut trailing zero bytes.
    let byte = |i: usize| payload.get(i).copied().unwrap_or(0);
    Some((u16::from_le_bytes([byte(28), byte(29)]), byte(30), byte(31)))
}
