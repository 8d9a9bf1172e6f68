//! Who a message came from and where an answer goes.

use crate::link::signing::Signed;

/// How a frame came in: the board's channel and, for a signed frame read with a key
/// installed, its signature block and whether it matched.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Origin {
    /// The board's channel: 0 for a single link.
    pub channel: u8,
    /// The signature, when there was one to check.
    pub signed: Option<Signed>,
}

/// Where a message came from: the station's MAVLink address and the board's channel it
/// arrived on (which UART, which UDP peer). Two stations that share a system and component
/// id are told apart by their channels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Peer {
    /// MAVLink system id.
    pub system: u8,
    /// MAVLink component id.
    pub component: u8,
    /// The board's channel: 0 for a single link.
    pub channel: u8,
}

impl Peer {
    /// `(system, component)`: the target of an answer.
    pub fn address(self) -> (u8, u8) {
        (self.system, self.component)
    }

    /// Answers to this peer go back on its channel.
    pub fn dest(self) -> Dest {
        Dest::Channel(self.channel)
    }
}

/// Where a message goes: to every station (telemetry, status texts, changes everyone should
/// see), or back on one channel (answers to one station's request).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Dest {
    /// Every station on every channel.
    All,
    /// The stations on this channel.
    Channel(u8),
}

impl Dest {
    /// Whether a station on `channel` is owed the message.
    pub fn reaches(self, channel: u8) -> bool {
        match self {
            Dest::All => true,
            Dest::Channel(c) => c == channel,
        }
    }
}
