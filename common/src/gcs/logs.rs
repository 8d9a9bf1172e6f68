//! MAVLink's log protocol (the MAVLink guide's "Onboard Log Download"): the flight logs the
//! board keeps, listed and downloaded as QGroundControl's Log Download page and MAVProxy's
//! `log` module ask for them.
//!
//! - `LOG_REQUEST_LIST` (first and last id; 0 and 0xffff for all) is answered with one
//!   `LOG_ENTRY` per log in that range, oldest first; with no log at all, one entry with id 0
//!   and `num_logs` 0, as the protocol says. Ids run from 1 (the oldest kept) to `num_logs`.
//! - `LOG_REQUEST_DATA` (id, offset, count; count 0xffffffff for the rest of the log) is
//!   answered with `LOG_DATA` packets of 90 bytes from the offset on; the last one is shorter,
//!   or, when the log's end falls on a packet's end, a packet of 0 bytes at the log's size
//!   follows, so the client always sees the end. A new request replaces the one in progress:
//!   that is how a client asks again for what it lost. A request past the end gets one packet
//!   of 0 bytes at the log's size.
//! - `LOG_REQUEST_END` stops a transfer; `LOG_ERASE` erases every log but the one being
//!   written, refused in the air with a status text.
//!
//! The link never reaches the board's storage by itself: requests wait here, and the board
//! serves them when it calls `GroundLink::serve_logs` with its [`LogStore`] and the room it
//! gives log data: what its output has left after the telemetry (less [`LOG_RESERVE_BYTES`]
//! on a board whose output buffer is larger than a poll's telemetry), and in the air at most
//! [`ARMED_PACKETS_PER_CALL`] packets a call, so a download never starves the streams.

use super::outbox::Outbox;
use super::peer::{Dest, Peer};
use mavlink::dialects::common::{
    MavMessage, MavSeverity, LOG_DATA_DATA, LOG_ENTRY_DATA, LOG_REQUEST_DATA_DATA,
    LOG_REQUEST_LIST_DATA,
};

/// One log the board keeps.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LogEntryInfo {
    /// Bytes in it (of the log being written: so far).
    pub size_bytes: u32,
    /// When it started, seconds since 1970 (UTC); 0 when the board does not know.
    pub time_utc_s: u32,
}

/// What the log protocol needs of the board's flight logs (files in SITL, a flash region on
/// the MCU). Logs are numbered by age, 0 the oldest kept.
pub trait LogStore {
    /// Looks again at what is kept (a station asked for the list): what
    /// [`LogStore::count`] and [`LogStore::entry`] answer until the next call.
    fn refresh(&mut self);
    /// Logs kept (at most 65,535 are listed).
    fn count(&self) -> u16;
    /// Log `index`, 0 the oldest.
    fn entry(&self, index: u16) -> Option<LogEntryInfo>;
    /// Reads bytes of log `index` from byte `offset` into `buf`: how many (0 at the end), or
    /// `None` when the log cannot be read.
    fn read(&mut self, index: u16, offset: u32, buf: &mut [u8]) -> Option<usize>;
    /// Erases every log but the one being written; whether it did.
    fn erase_all(&mut self) -> bool;
}

/// A board that keeps no logs: every list is empty.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoLogs;

impl LogStore for NoLogs {
    fn refresh(&mut self) {}
    fn count(&self) -> u16 {
        0
    }
    fn entry(&self, _: u16) -> Option<LogEntryInfo> {
        None
    }
    fn read(&mut self, _: u16, _: u32, _: &mut [u8]) -> Option<usize> {
        None
    }
    fn erase_all(&mut self) -> bool {
        true
    }
}

/// Bytes of file data in one `LOG_DATA`.
pub const DATA_LEN: usize = 90;
/// Bytes of a `LOG_DATA` frame at most: MAVLink 2 header (10), payload (97), checksum (2),
/// signature (13).
pub const LOG_DATA_FRAME: usize = 10 + 97 + 2 + 13;
/// Bytes of a `FILE_TRANSFER_PROTOCOL` frame at most (a log read over MAVLink FTP).
pub const FTP_FRAME: usize = 10 + 254 + 2 + 13;
/// Bytes of a `LOG_ENTRY` frame at most.
pub const LOG_ENTRY_FRAME: usize = 10 + 14 + 2 + 13;
/// Room of a board's output buffer that log transfer leaves to the telemetry and answers of
/// the next poll, bytes (a board that hands its output to a UART as it goes gives log data
/// only what the UART can take now instead).
pub const LOG_RESERVE_BYTES: usize = 1024;
/// `LOG_DATA` packets a call at most while armed (on the ground: as many as there is room
/// for).
pub const ARMED_PACKETS_PER_CALL: usize = 2;

/// What one call of the board may send of log transfers (the log protocol's and the log
/// files' over FTP together): bytes of its output, and packets of data (in the air
/// [`ARMED_PACKETS_PER_CALL`], on the ground as many as there is room for).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pace {
    room: usize,
    packets: usize,
}

impl Pace {
    /// `room` bytes, and the packets of data the vehicle's state allows.
    pub fn new(room: usize, armed: bool) -> Self {
        Self {
            room,
            packets: if armed {
                ARMED_PACKETS_PER_CALL
            } else {
                usize::MAX
            },
        }
    }

    /// Whether a frame of `len` bytes fits.
    pub fn fits(&self, len: usize) -> bool {
        self.room >= len
    }

    /// Whether a packet of data in a frame of `len` bytes may go.
    pub fn data_fits(&self, len: usize) -> bool {
        self.packets > 0 && self.fits(len)
    }

    /// A frame of `len` bytes went.
    pub fn spend(&mut self, len: usize) {
        self.room = self.room.saturating_sub(len);
    }

    /// A packet of data in a frame of `len` bytes went.
    pub fn spend_data(&mut self, len: usize) {
        self.spend(len);
        self.packets = self.packets.saturating_sub(1);
    }

    /// The packets of data left, for a service that counts its own.
    pub fn packets_mut(&mut self) -> &mut usize {
        &mut self.packets
    }
}

/// `LOG_REQUEST_LIST`'s and `LOG_REQUEST_DATA`'s "to the end".
const ALL_IDS: u16 = 0xffff;
const ALL_BYTES: u32 = 0xffff_ffff;

/// A list being sent.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Listing {
    /// The next id to send (1-based), and the last.
    next: u16,
    last: u16,
    to: Peer,
}

/// A download being sent.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Download {
    /// 1-based, as on the wire.
    id: u16,
    /// The next byte to send.
    ofs: u32,
    /// One past the last byte asked for (saturated).
    end: u32,
    to: Peer,
}

/// The log protocol's state: what was asked and not yet answered.
#[derive(Clone, Debug, Default)]
pub struct LogService {
    listing: Option<Listing>,
    download: Option<Download>,
    refresh: bool,
    erase: bool,
}

impl LogService {
    /// Nothing asked.
    pub fn new() -> Self {
        Self::default()
    }

    /// Whether anything waits for the board's store (`GroundLink::serve_logs`).
    pub fn busy(&self) -> bool {
        self.listing.is_some() || self.download.is_some() || self.refresh || self.erase
    }

    /// `LOG_REQUEST_LIST` from `from`.
    pub fn on_request_list(&mut self, d: &LOG_REQUEST_LIST_DATA, from: Peer) {
        self.refresh = true;
        self.listing = Some(Listing {
            // Id 0 is "the first", as is 1.
            next: d.start.max(1),
            last: d.end,
            to: from,
        });
    }

    /// `LOG_REQUEST_DATA` from `from`: replaces the transfer in progress.
    pub fn on_request_data(&mut self, d: &LOG_REQUEST_DATA_DATA, from: Peer) {
        let end = if d.count == ALL_BYTES {
            u32::MAX
        } else {
            d.ofs.saturating_add(d.count)
        };
        self.download = Some(Download {
            id: d.id,
            ofs: d.ofs,
            end,
            to: from,
        });
    }

    /// `LOG_REQUEST_END`: the transfer stops.
    pub fn on_request_end(&mut self) {
        self.download = None;
        self.listing = None;
    }

    /// `LOG_ERASE`: done at the next [`LogService::serve`] on the ground, refused in the air.
    pub(crate) fn on_erase(&mut self, armed: bool, out: &mut Outbox) {
        if armed {
            out.texts_mut().push_str(
                MavSeverity::MAV_SEVERITY_WARNING,
                "Log erase refused: armed",
            );
            return;
        }
        self.erase = true;
        self.download = None;
        self.listing = None;
    }

    /// Serves what was asked from `store`, as far as `pace` allows. Status texts (an erase
    /// done or failed) go to `outbox`.
    pub(crate) fn serve<F: FnMut(Dest, MavMessage)>(
        &mut self,
        store: &mut dyn LogStore,
        pace: &mut Pace,
        outbox: &mut Outbox,
        mut send: F,
    ) {
        if core::mem::take(&mut self.erase) {
            if store.erase_all() {
                outbox
                    .texts_mut()
                    .push_str(MavSeverity::MAV_SEVERITY_INFO, "Logs erased");
            } else {
                outbox
                    .texts_mut()
                    .push_str(MavSeverity::MAV_SEVERITY_WARNING, "Log erase failed");
            }
            self.refresh = true;
        }
        if core::mem::take(&mut self.refresh) {
            store.refresh();
        }
        self.send_list(store, pace, &mut send);
        while pace.data_fits(LOG_DATA_FRAME) {
            let Some(m) = self.next_data(store) else {
                break;
            };
            if let Some(d) = self.download.map(|d| d.to) {
                send(d.dest(), m);
            }
            pace.spend_data(LOG_DATA_FRAME);
            if self.download.is_some_and(|d| d.ofs >= d.end) {
                self.download = None;
            }
        }
    }

    fn send_list<F: FnMut(Dest, MavMessage)>(
        &mut self,
        store: &mut dyn LogStore,
        pace: &mut Pace,
        send: &mut F,
    ) {
        let Some(l) = self.listing else { return };
        let num_logs = store.count();
        if num_logs == 0 {
            if pace.fits(LOG_ENTRY_FRAME) {
                send(l.to.dest(), entry(0, 0, LogEntryInfo::default()));
                pace.spend(LOG_ENTRY_FRAME);
                self.listing = None;
            }
            return;
        }
        let last = if l.last == ALL_IDS {
            num_logs
        } else {
            l.last.min(num_logs)
        };
        let mut next = l.next;
        while next <= last && pace.fits(LOG_ENTRY_FRAME) {
            let info = store.entry(next.saturating_sub(1)).unwrap_or_default();
            send(l.to.dest(), entry(next, num_logs, info));
            pace.spend(LOG_ENTRY_FRAME);
            next = next.saturating_add(1);
            if next == 0 {
                break;
            }
        }
        self.listing = (next <= last && next != 0).then_some(Listing { next, ..l });
    }

    /// The next `LOG_DATA` of the download, advancing it.
    fn next_data(&mut self, store: &mut dyn LogStore) -> Option<MavMessage> {
        let d = self.download.as_mut()?;
        let index = d.id.checked_sub(1);
        let size = index.and_then(|i| store.entry(i)).map(|e| e.size_bytes);
        let Some((index, size)) = index.zip(size) else {
            // No such log: nothing to send (PX4 and ArduPilot stay silent too).
            self.download = None;
            return None;
        };
        let mut data = [0u8; DATA_LEN];
        let ofs = d.ofs;
        let want = (d.end.min(size).saturating_sub(ofs) as usize).min(DATA_LEN);
        let n = if want == 0 {
            0
        } else {
            match store.read(index, ofs, data.get_mut(..want).unwrap_or(&mut [])) {
                Some(n) => n.min(want),
                None => {
                    self.download = None;
                    return None;
                }
            }
        };
        // A short (or empty) packet marks the end for the client. After a full packet that
        // reaches the log's end, one more (of 0 bytes) says so; a request that ends inside
        // the log ends with its last byte.
        let next = ofs.saturating_add(n as u32);
        let end_seen = n == 0 || (next >= size && n < DATA_LEN);
        d.ofs = if end_seen || next >= d.end {
            d.end
        } else {
            next
        };
        let id = d.id;
        Some(MavMessage::LOG_DATA(LOG_DATA_DATA {
            ofs: if n == 0 { size.min(ofs) } else { ofs },
            id,
            count: n as u8,
            data,
        }))
    }
}

fn entry(id: u16, num_logs: u16, info: LogEntryInfo) -> MavMessage {
    MavMessage::LOG_ENTRY(LOG_ENTRY_DATA {
        time_utc: info.time_utc_s,
        size: info.size_bytes,
        id,
        num_logs,
        last_log_num: num_logs,
    })
}

#[cfg(test)]
mod tests;
