//! What the link has to send: answers waiting for the next poll, and status texts.

use super::mission::MissionReply;
use super::streams::Stream;
use crate::vehicle::modes::FlightMode;
use heapless::String;
use mavlink::dialects::common::{MavCmd, MavResult, MavSeverity};

/// Longest STATUSTEXT text.
pub const STATUSTEXT_LEN: usize = 50;

/// A STATUSTEXT waiting to be sent.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Text {
    pub severity: MavSeverity,
    pub text: String<STATUSTEXT_LEN>,
}

/// Something to send at the next poll.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Pending {
    Ack {
        command: MavCmd,
        result: MavResult,
        to: (u8, u8),
    },
    ParamValue(u16),
    Mission(MissionReply, (u8, u8)),
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
