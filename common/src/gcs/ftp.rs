//! A read-only MAVLink FTP server (the MAVLink guide's "File Transfer Protocol") for the
//! files the vehicle serves: the component metadata a ground station downloads
//! (`general.json` and the parameter metadata), and the flight logs the board keeps, as
//! `/logs/log_1.ulg`, `/logs/log_2.ulg`, ... (the ids of the log protocol's `LOG_ENTRY`, 1 the
//! oldest).
//!
//! One session at a time, as PX4's. It answers `ListDirectory` (`/` and `/logs`),
//! `OpenFileRO` (the file's length), `ReadFile`, `BurstReadFile` (the rest of the file
//! streamed a few packets per poll, the last flagged `burst_complete`, then `EOF`),
//! `ResetSessions`, `TerminateSession` and `None`; anything else gets `NAK UnknownCommand`.
//! What touches a log waits for the board's [`LogStore`] ([`Ftp::serve_logs`], called where
//! the log protocol is served). Every reply carries the request's sequence number plus one
//! (a burst counts on from there), which is what QGroundControl checks.

use super::logs::LogStore;
use super::peer::Peer;
use super::texts::Line;
use mavlink::dialects::common::{MavMessage, FILE_TRANSFER_PROTOCOL_DATA};

/// A file the vehicle serves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct File {
    /// Its path, without a leading `/` (`general.json`).
    pub name: &'static str,
    /// Its contents.
    pub bytes: &'static [u8],
}

/// The name of the general metadata file, the one `COMPONENT_METADATA` points to.
pub const GENERAL: &str = "general.json";

/// MAVLink's CRC-32 of a file (component metadata's `file_crc`): the polynomial 0x04C11DB7,
/// reflected, starting from 0 and with no final XOR ([`crate::crc::Crc32::mavlink_ftp`]).
/// Ground stations use it as the key of their metadata cache, so it changes with every change
/// of the file.
pub fn file_crc(bytes: &[u8]) -> u32 {
    let mut crc = crate::crc::Crc32::mavlink_ftp();
    crc.digest(bytes);
    crc.get()
}

/// The `mftp://` URI of a served file (QGroundControl opens `/name`, PX4's form).
pub fn uri(f: &File) -> heapless::String<100> {
    let mut s = heapless::String::new();
    // Names are the firmware's own and short; one too long for 100 bytes is cut.
    for c in "mftp://".chars().chain(f.name.chars()) {
        if s.push(c).is_err() {
            break;
        }
    }
    s
}

/// Bytes of file data in one packet.
pub const DATA_LEN: usize = 239;
/// Burst packets sent per poll: paces a download to leave the link room for telemetry
/// (4 per 20 ms poll is 48 kB/s).
pub const BURST_PER_POLL: usize = 4;

const HEADER: usize = 12;
const OP_NONE: u8 = 0;
const OP_TERMINATE: u8 = 1;
const OP_RESET: u8 = 2;
const OP_LIST: u8 = 3;
const OP_OPEN_RO: u8 = 4;
const OP_READ: u8 = 5;
const OP_BURST: u8 = 15;
const ACK: u8 = 128;
const NAK: u8 = 129;
const ERR_SESSION: u8 = 4;
const ERR_NO_SESSIONS: u8 = 5;
const ERR_EOF: u8 = 6;
const ERR_UNKNOWN: u8 = 7;
const ERR_NOT_FOUND: u8 = 10;
const SESSION: u8 = 0;

/// What to send: a header and where its data comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Reply {
    seq: u16,
    opcode: u8,
    req_opcode: u8,
    burst_complete: bool,
    offset: u32,
    data: Data,
}

// A reply is built and sent within a poll, one at a time (one waits at most): its bytes
// travel with it rather than in a buffer of the server's that every reply would share.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Data {
    None,
    /// A NAK's error code.
    Error(u8),
    /// A file's length (the `OpenFileRO` answer).
    Length(u32),
    /// Bytes of the open file.
    Slice {
        file: usize,
        len: usize,
    },
    /// Bytes read for this reply (a log's, a listing).
    Bytes {
        buf: [u8; DATA_LEN],
        len: u8,
    },
}

/// The file a session has open.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Open {
    /// One of the files given at start.
    Static(usize),
    /// A flight log, by its place in the board's list (0 the oldest).
    Log(u16),
}

/// What a path names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Target {
    File(Open),
    Root,
    Logs,
}

/// A request that waits for the board's logs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Deferred {
    /// `ListDirectory` of `/logs`.
    List,
    /// `OpenFileRO` of a log.
    Open(u16),
    /// `ReadFile` of the open log, this many bytes.
    Read(u16, usize),
}

/// The folder the logs are listed in.
const LOG_DIR: &str = "logs";

/// A burst in progress.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Burst {
    next_seq: u16,
    offset: u32,
    /// Packets left before the burst ends (`burst_complete`).
    left: u16,
    /// Bytes per packet: what the request asked for (QGroundControl asks for a full packet,
    /// pymavlink's client for less), a full packet when it asked for none.
    chunk: usize,
}

impl Burst {
    /// A burst from `offset`, its first packet numbered `seq`, of packets of `size` bytes (a
    /// full packet when the request asked for none).
    fn new(seq: u16, offset: u32, size: usize) -> Self {
        Self {
            next_seq: seq,
            offset,
            left: BURST_PACKETS,
            chunk: if size == 0 {
                DATA_LEN
            } else {
                size.min(DATA_LEN)
            },
        }
    }

    /// The burst's next packet: `data` (`n` bytes) and the burst after it, or, with no data
    /// left, `EOF` and the burst's end.
    fn step(self, data: Option<(Data, usize)>) -> (Reply, Option<Burst>) {
        let Some((data, n)) = data else {
            let eof = Reply {
                seq: self.next_seq,
                opcode: NAK,
                req_opcode: OP_BURST,
                burst_complete: false,
                offset: self.offset,
                data: Data::Error(ERR_EOF),
            };
            return (eof, None);
        };
        let last = self.left <= 1;
        let next = (!last).then_some(Burst {
            next_seq: self.next_seq.wrapping_add(1),
            offset: self.offset.saturating_add(n as u32),
            left: self.left.saturating_sub(1),
            chunk: self.chunk,
        });
        let r = Reply {
            seq: self.next_seq,
            opcode: ACK,
            req_opcode: OP_BURST,
            burst_complete: last,
            offset: self.offset,
            data,
        };
        (r, next)
    }
}

/// The server's state.
#[derive(Clone, Debug, Default)]
pub struct Ftp {
    files: &'static [File],
    /// The open file and the station it is open for.
    session: Option<(Open, Peer)>,
    /// A request that waits for the logs: the reply's head, what it asked, and whose.
    deferred: Option<(Reply, Deferred, Peer)>,
    /// When the session's station last asked something, µs.
    last_request_us: u64,
    reply: Option<(Reply, Peer)>,
    burst: Option<Burst>,
}

/// A session whose station has asked nothing for this long, µs, is given to another station
/// that asks (QGroundControl retries a request after 1 s).
const SESSION_TIMEOUT_US: u64 = 3_000_000;

/// Packets of one burst before `burst_complete` (the whole of a small file; about 35 kB, as
/// PX4, for a larger one).
const BURST_PACKETS: u16 = 150;

impl Ftp {
    /// A server for these files.
    pub fn new(files: &'static [File]) -> Self {
        Self {
            files,
            ..Self::default()
        }
    }

    /// The files served.
    pub fn files(&self) -> &'static [File] {
        self.files
    }

    fn file(&self, i: usize) -> Option<&'static File> {
        let files: &'static [File] = self.files;
        files.get(i)
    }

    /// A request from `from` at `now_us`; its answer waits for [`Ftp::next`].
    pub fn handle(&mut self, d: &FILE_TRANSFER_PROTOCOL_DATA, from: Peer, now_us: u64) {
        let p = &d.payload;
        let seq = u16::from_le_bytes([p[0], p[1]]);
        let (session, opcode, size) = (p[2], p[3], usize::from(p[4]));
        let offset = u32::from_le_bytes([p[8], p[9], p[10], p[11]]);
        let data = p
            .get(HEADER..HEADER.saturating_add(size.min(DATA_LEN)))
            .unwrap_or(&[]);
        let reply_seq = seq.wrapping_add(1);
        let ack = |data| Reply {
            seq: reply_seq,
            opcode: ACK,
            req_opcode: opcode,
            burst_complete: false,
            offset,
            data,
        };
        let nak = |e| Reply {
            opcode: NAK,
            ..ack(Data::Error(e))
        };
        self.burst = None;
        // A station that went away without resetting does not keep the session from others.
        let stale = now_us.saturating_sub(self.last_request_us) > SESSION_TIMEOUT_US;
        if stale && self.session.is_some_and(|(_, p)| p != from) {
            self.session = None;
        }
        let open = self.session.filter(|(_, p)| *p == from).map(|(f, _)| f);
        if open.is_some() || self.session.is_none() {
            self.last_request_us = now_us;
        }
        let r = match opcode {
            OP_NONE => ack(Data::None),
            OP_RESET => {
                self.session = None;
                ack(Data::None)
            }
            OP_TERMINATE => {
                self.session = None;
                ack(Data::None)
            }
            OP_LIST => match self.find(data) {
                Some(Target::Root) => self.root_listing(offset).map_or(nak(ERR_EOF), ack),
                Some(Target::Logs) => {
                    self.deferred = Some((ack(Data::None), Deferred::List, from));
                    self.reply = None;
                    return;
                }
                _ => nak(ERR_NOT_FOUND),
            },
            OP_OPEN_RO if self.session.is_some() && open.is_none() => nak(ERR_NO_SESSIONS),
            OP_OPEN_RO => match self.find(data) {
                Some(Target::File(Open::Static(i))) => {
                    self.session = Some((Open::Static(i), from));
                    let len = self.file(i).map_or(0, |f| f.bytes.len());
                    ack(Data::Length(u32::try_from(len).unwrap_or(u32::MAX)))
                }
                Some(Target::File(Open::Log(i))) => {
                    self.deferred = Some((ack(Data::None), Deferred::Open(i), from));
                    self.reply = None;
                    return;
                }
                _ => nak(ERR_NOT_FOUND),
            },
            OP_READ | OP_BURST if session != SESSION => nak(ERR_SESSION),
            OP_READ | OP_BURST => match open {
                None => nak(ERR_SESSION),
                Some(Open::Log(i)) => {
                    if opcode == OP_READ {
                        let want = size.clamp(1, DATA_LEN);
                        self.deferred = Some((ack(Data::None), Deferred::Read(i, want), from));
                    } else {
                        self.burst = Some(Burst::new(reply_seq, offset, size));
                    }
                    self.reply = None;
                    return;
                }
                Some(Open::Static(f)) => {
                    let len = self.file(f).map_or(0, |f| f.bytes.len());
                    let at = usize::try_from(offset).unwrap_or(usize::MAX);
                    if at >= len {
                        nak(ERR_EOF)
                    } else if opcode == OP_READ {
                        let n = len.saturating_sub(at).min(size.max(1)).min(DATA_LEN);
                        ack(Data::Slice { file: f, len: n })
                    } else {
                        self.burst = Some(Burst::new(reply_seq, offset, size));
                        self.reply = None;
                        return;
                    }
                }
            },
            _ => nak(ERR_UNKNOWN),
        };
        self.reply = Some((r, from));
    }

    /// The general metadata file (`general.json`), when it is served.
    pub fn general(&self) -> Option<&'static File> {
        let files: &'static [File] = self.files;
        files.iter().find(|f| f.name == GENERAL)
    }

    /// What a request's path names (leading and trailing slashes and a trailing NUL
    /// ignored): a served file, a log (`logs/log_N.ulg`, N from 1), or a folder.
    fn find(&self, path: &[u8]) -> Option<Target> {
        let end = path.iter().position(|&b| b == 0).unwrap_or(path.len());
        let mut name = path.get(..end)?;
        while let Some(rest) = name.strip_prefix(b"/") {
            name = rest;
        }
        while let Some(rest) = name.strip_suffix(b"/") {
            name = rest;
        }
        if name.is_empty() {
            return Some(Target::Root);
        }
        if name == LOG_DIR.as_bytes() {
            return Some(Target::Logs);
        }
        if let Some(n) = name
            .strip_prefix(b"logs/log_")
            .and_then(|n| n.strip_suffix(b".ulg"))
        {
            let id = core::str::from_utf8(n).ok()?.parse::<u16>().ok()?;
            return Some(Target::File(Open::Log(id.checked_sub(1)?)));
        }
        self.files
            .iter()
            .position(|f| f.name.as_bytes() == name)
            .map(|i| Target::File(Open::Static(i)))
    }

    /// The root folder's entries from the `from`-th on, as many as a packet holds: the served
    /// files and the log folder; `None` past the last.
    fn root_listing(&self, from: u32) -> Option<Data> {
        let files: &'static [File] = self.files;
        let count = files.len().saturating_add(1);
        listing(from, count, |k, s| match files.get(k) {
            Some(f) => {
                s.str("F").str(f.name).str("\t").uint(f.bytes.len() as u64);
            }
            None => {
                s.str("D").str(LOG_DIR);
            }
        })
    }

    /// Whether a request waits for the board's logs ([`Ftp::serve_logs`]).
    pub fn wants_logs(&self) -> bool {
        self.deferred.is_some()
            || (self.burst.is_some() && matches!(self.session, Some((Open::Log(_), _))))
    }

    /// The next packet that needs the board's logs, and to whom: a deferred answer, else the
    /// next of a burst of a log (at most `budget` burst packets).
    pub fn serve_logs(
        &mut self,
        store: &mut dyn LogStore,
        budget: &mut usize,
    ) -> Option<(MavMessage, Peer)> {
        if let Some((head, what, to)) = self.deferred.take() {
            let nak = |e| Reply {
                opcode: NAK,
                data: Data::Error(e),
                ..head
            };
            let ok = |data| Reply { data, ..head };
            let r = match what {
                Deferred::List => {
                    // What is kept now, as for LOG_REQUEST_LIST.
                    store.refresh();
                    let count = usize::from(store.count());
                    let names = |k: usize, s: &mut Line<48>| {
                        let size = store
                            .entry(u16::try_from(k).unwrap_or(u16::MAX))
                            .map_or(0, |e| e.size_bytes);
                        s.str("Flog_")
                            .uint(k.saturating_add(1) as u64)
                            .str(".ulg\t")
                            .uint(u64::from(size));
                    };
                    listing(head.offset, count, names).map_or(nak(ERR_EOF), ok)
                }
                Deferred::Open(i) => match refreshed_entry(store, i) {
                    Some(e) => {
                        self.session = Some((Open::Log(i), to));
                        ok(Data::Length(e.size_bytes))
                    }
                    None => nak(ERR_NOT_FOUND),
                },
                Deferred::Read(i, want) => {
                    read_log(store, i, head.offset, want).map_or(nak(ERR_EOF), ok)
                }
            };
            return Some((self.message(&r, to), to));
        }
        let b = self.burst?;
        let (Open::Log(i), to) = self.session? else {
            return None;
        };
        if *budget == 0 {
            return None;
        }
        *budget = budget.saturating_sub(1);
        let data = read_log(store, i, b.offset, b.chunk).map(|d| {
            let n = match d {
                Data::Bytes { len, .. } => usize::from(len),
                _ => 0,
            };
            (d, n)
        });
        let (r, next) = b.step(data);
        self.burst = next;
        Some((self.message(&r, to), to))
    }

    /// The next packet to send and to whom: a pending reply, else the next of a burst (at most
    /// `budget` burst packets; the caller counts them per poll).
    pub fn next(&mut self, budget: &mut usize) -> Option<(MavMessage, Peer)> {
        if let Some((r, to)) = self.reply.take() {
            return Some((self.message(&r, to), to));
        }
        let b = self.burst?;
        // A log's burst is served with the logs.
        let (Open::Static(f), to) = self.session? else {
            return None;
        };
        if *budget == 0 {
            return None;
        }
        *budget = budget.saturating_sub(1);
        let len = self.file(f).map_or(0, |f| f.bytes.len());
        let at = usize::try_from(b.offset).unwrap_or(usize::MAX);
        let data = (at < len).then(|| {
            let n = len.saturating_sub(at).min(b.chunk);
            (Data::Slice { file: f, len: n }, n)
        });
        let (r, next) = b.step(data);
        self.burst = next;
        Some((self.message(&r, to), to))
    }

    fn message(&self, r: &Reply, to: Peer) -> MavMessage {
        let mut payload = [0u8; 251];
        let (size, data): (u8, &[u8]) = match r.data {
            Data::None => (0, &[]),
            Data::Error(_) | Data::Length(_) => (0, &[]),
            Data::Slice { file, len } => {
                let at = usize::try_from(r.offset).unwrap_or(usize::MAX);
                let bytes = self
                    .file(file)
                    .and_then(|f| f.bytes.get(at..at.saturating_add(len)))
                    .unwrap_or(&[]);
                (bytes.len() as u8, bytes)
            }
            Data::Bytes { ref buf, len } => (len, buf.get(..usize::from(len)).unwrap_or(&[])),
        };
        let small: [u8; 4];
        let (size, data) = match r.data {
            Data::Error(e) => {
                small = [e, 0, 0, 0];
                (1, &small[..1])
            }
            Data::Length(n) => {
                small = n.to_le_bytes();
                (4, &small[..])
            }
            _ => (size, data),
        };
        let [s0, s1] = r.seq.to_le_bytes();
        let [o0, o1, o2, o3] = r.offset.to_le_bytes();
        let header = [
            s0,
            s1,
            SESSION,
            r.opcode,
            size,
            r.req_opcode,
            u8::from(r.burst_complete),
            0,
            o0,
            o1,
            o2,
            o3,
        ];
        for (d, b) in payload.iter_mut().zip(header.iter().chain(data)) {
            *d = *b;
        }
        MavMessage::FILE_TRANSFER_PROTOCOL(FILE_TRANSFER_PROTOCOL_DATA {
            target_network: 0,
            target_system: to.system,
            target_component: to.component,
            payload,
        })
    }
}

/// Log `index` as the store finds it now.
fn refreshed_entry(store: &mut dyn LogStore, index: u16) -> Option<super::logs::LogEntryInfo> {
    store.refresh();
    store.entry(index)
}

/// Up to `want` bytes of log `index` from `offset`; `None` at or past its end (or unreadable).
fn read_log(store: &mut dyn LogStore, index: u16, offset: u32, want: usize) -> Option<Data> {
    let mut buf = [0u8; DATA_LEN];
    let n = store.read(index, offset, buf.get_mut(..want.min(DATA_LEN))?)?;
    (n > 0).then_some(Data::Bytes {
        buf,
        len: u8::try_from(n).unwrap_or(0),
    })
}

/// A `ListDirectory` answer: entries `from`.. of `count`, each written by `entry` and ended by
/// a NUL, as many as a packet holds; `None` when `from` is past the last.
fn listing(from: u32, count: usize, mut entry: impl FnMut(usize, &mut Line<48>)) -> Option<Data> {
    let first = usize::try_from(from).ok()?;
    if first >= count {
        return None;
    }
    let mut buf = [0u8; DATA_LEN];
    let mut len = 0usize;
    for k in first..count {
        let mut s = Line::<48>::new();
        entry(k, &mut s);
        if s.is_cut() {
            break;
        }
        let s = s.as_str();
        let end = len.saturating_add(s.len()).saturating_add(1);
        let Some(dst) = buf.get_mut(len..end) else {
            break;
        };
        // Byte by byte: no slice operation that could panic (the image keeps none).
        for (d, b) in dst.iter_mut().zip(s.as_bytes().iter().chain([0u8].iter())) {
            *d = *b;
        }
        len = end;
    }
    Some(Data::Bytes {
        buf,
        len: u8::try_from(len).unwrap_or(0),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    extern crate std;
    use std::vec::Vec;

    static TEXT: [u8; 600] = {
        let mut t = [0u8; 600];
        let mut i = 0;
        while i < 600 {
            t[i] = b'a' + (i % 26) as u8;
            i += 1;
        }
        t
    };
    static FILES: [File; 1] = [File {
        name: "params.json",
        bytes: &TEXT,
    }];
    const QGC: Peer = Peer {
        system: 255,
        component: 190,
        channel: 0,
    };

    fn request(seq: u16, opcode: u8, offset: u32, data: &[u8]) -> FILE_TRANSFER_PROTOCOL_DATA {
        let mut payload = [0u8; 251];
        payload[..2].copy_from_slice(&seq.to_le_bytes());
        payload[3] = opcode;
        payload[4] = data.len() as u8;
        payload[8..12].copy_from_slice(&offset.to_le_bytes());
        payload[12..12 + data.len()].copy_from_slice(data);
        FILE_TRANSFER_PROTOCOL_DATA {
            target_network: 0,
            target_system: 1,
            target_component: 1,
            payload,
        }
    }

    /// (seq, opcode, size, req_opcode, burst_complete, offset, data)
    fn fields(m: &MavMessage) -> (u16, u8, u8, u8, u8, u32, Vec<u8>) {
        let MavMessage::FILE_TRANSFER_PROTOCOL(d) = m else {
            panic!("{m:?}")
        };
        let p = &d.payload;
        let size = p[4];
        (
            u16::from_le_bytes([p[0], p[1]]),
            p[3],
            size,
            p[5],
            p[6],
            u32::from_le_bytes([p[8], p[9], p[10], p[11]]),
            p[12..12 + usize::from(size)].to_vec(),
        )
    }

    fn all(f: &mut Ftp) -> Vec<MavMessage> {
        let mut out = Vec::new();
        loop {
            let mut budget = 1000;
            match f.next(&mut budget) {
                Some((m, _)) => out.push(m),
                None => return out,
            }
        }
    }

    #[test]
    fn a_station_downloads_a_file_as_qgroundcontrol_does() {
        let mut f = Ftp::new(&FILES);
        // Open: ACK with size 4 and the length; the sequence number is the request's plus one.
        f.handle(&request(10, OP_OPEN_RO, 0, b"/params.json"), QGC, 0);
        let open = fields(&all(&mut f)[0]);
        assert_eq!((open.0, open.1, open.2), (11, ACK, 4));
        assert_eq!(open.6, 600u32.to_le_bytes());
        // A burst: 239 + 239 + 122 bytes at offsets 0, 239, 478, numbered on from 13, then EOF.
        f.handle(&request(12, OP_BURST, 0, &[]), QGC, 0);
        let burst: Vec<_> = all(&mut f).iter().map(fields).collect();
        let got: Vec<(u16, u32, usize)> = burst.iter().map(|b| (b.0, b.5, b.6.len())).collect();
        assert_eq!(
            got,
            [(13, 0, 239), (14, 239, 239), (15, 478, 122), (16, 600, 1)]
        );
        assert_eq!((burst[3].1, burst[3].6[0]), (NAK, ERR_EOF));
        let bytes: Vec<u8> = burst[..3].iter().flat_map(|b| b.6.clone()).collect();
        assert_eq!(bytes, TEXT);
        // A gap filled with ReadFile, then the sessions reset.
        f.handle(&request(17, OP_READ, 239, &[0; 100]), QGC, 0);
        let read = fields(&all(&mut f)[0]);
        assert_eq!((read.0, read.5, read.6.len()), (18, 239, 100));
        f.handle(&request(19, OP_RESET, 0, &[]), QGC, 0);
        assert_eq!(fields(&all(&mut f)[0]).1, ACK);
    }

    #[test]
    fn unknown_files_commands_and_sessions_are_refused_with_their_codes() {
        let mut f = Ftp::new(&FILES);
        f.handle(&request(0, OP_OPEN_RO, 0, b"nothing.json"), QGC, 0);
        let r = fields(&all(&mut f)[0]);
        assert_eq!((r.1, r.2, r.6[0]), (NAK, 1, ERR_NOT_FOUND));
        f.handle(&request(2, OP_READ, 0, &[]), QGC, 0);
        assert_eq!(fields(&all(&mut f)[0]).6[0], ERR_SESSION);
        // Writing is not served.
        f.handle(&request(4, 6, 0, b"x"), QGC, 0);
        assert_eq!(fields(&all(&mut f)[0]).6[0], ERR_UNKNOWN);
        // A second station cannot open while the first has a session.
        f.handle(&request(6, OP_OPEN_RO, 0, b"params.json"), QGC, 0);
        all(&mut f);
        let other = Peer { channel: 1, ..QGC };
        f.handle(&request(0, OP_OPEN_RO, 0, b"params.json"), other, 1_000_000);
        assert_eq!(fields(&all(&mut f)[0]).6[0], ERR_NO_SESSIONS);
        // ... until the first has been silent for longer than the session timeout.
        f.handle(&request(2, OP_OPEN_RO, 0, b"params.json"), other, 4_100_000);
        assert_eq!(fields(&all(&mut f)[0]).1, ACK);
    }

    #[test]
    fn the_file_crc_is_mavlinks_crc32_as_px4s_build_computes_it() {
        // Check value of the reflected 0x04C11DB7 from 0 without final XOR over "123456789",
        // computed with the table-driven Python of PX4's metadata build (not zlib's CRC-32,
        // 0xCBF43926, which starts from all ones and inverts).
        assert_eq!(file_crc(b"123456789"), 0x2DFD_2D88);
        assert_eq!(uri(&FILES[0]).as_str(), "mftp://params.json");
    }

    /// Two logs, as a board keeps them.
    struct TwoLogs(Vec<Vec<u8>>);

    impl LogStore for TwoLogs {
        fn refresh(&mut self) {}
        fn count(&self) -> u16 {
            self.0.len() as u16
        }
        fn entry(&self, index: u16) -> Option<crate::gcs::logs::LogEntryInfo> {
            self.0
                .get(usize::from(index))
                .map(|l| crate::gcs::logs::LogEntryInfo {
                    size_bytes: l.len() as u32,
                    time_utc_s: 0,
                })
        }
        fn read(&mut self, index: u16, offset: u32, buf: &mut [u8]) -> Option<usize> {
            let l = self.0.get(usize::from(index))?;
            let from = (offset as usize).min(l.len());
            let n = buf.len().min(l.len() - from);
            buf[..n].copy_from_slice(&l[from..from + n]);
            Some(n)
        }
        fn erase_all(&mut self) -> bool {
            false
        }
    }

    fn with_logs(f: &mut Ftp, store: &mut TwoLogs) -> Vec<MavMessage> {
        let mut out = Vec::new();
        loop {
            let mut budget = 1000;
            match f.serve_logs(store, &mut budget) {
                Some((m, _)) => out.push(m),
                None => return out,
            }
        }
    }

    fn entries(data: &[u8]) -> Vec<std::string::String> {
        data.split(|&b| b == 0)
            .filter(|e| !e.is_empty())
            .map(|e| std::string::String::from_utf8(e.to_vec()).unwrap())
            .collect()
    }

    #[test]
    fn the_logs_are_listed_and_downloaded_as_files_under_logs() {
        let log: Vec<u8> = (0..1000u32).map(|k| (k * 7) as u8).collect();
        let mut store = TwoLogs(std::vec![std::vec![1, 2, 3], log.clone()]);
        let mut f = Ftp::new(&FILES);
        // The root: the served file with its size, and the log folder.
        f.handle(&request(0, OP_LIST, 0, b"/"), QGC, 0);
        let root = fields(&all(&mut f)[0]);
        assert_eq!(root.1, ACK);
        assert_eq!(entries(&root.6), ["Fparams.json\t600", "Dlogs"]);
        // The folder waits for the logs: nothing from the poll, the list from the store.
        f.handle(&request(2, OP_LIST, 0, b"/logs"), QGC, 0);
        assert!(all(&mut f).is_empty() && f.wants_logs());
        let list = fields(&with_logs(&mut f, &mut store)[0]);
        assert_eq!((list.0, list.1), (3, ACK));
        assert_eq!(entries(&list.6), ["Flog_1.ulg\t3", "Flog_2.ulg\t1000"]);
        // Past the last entry: EOF, as the listing's end.
        f.handle(&request(4, OP_LIST, 2, b"/logs/"), QGC, 0);
        let end = fields(&with_logs(&mut f, &mut store)[0]);
        assert_eq!((end.1, end.6[0]), (NAK, ERR_EOF));
        // Open log 2: its length; a burst: its bytes, then EOF.
        f.handle(&request(6, OP_OPEN_RO, 0, b"/logs/log_2.ulg"), QGC, 0);
        let open = fields(&with_logs(&mut f, &mut store)[0]);
        assert_eq!(
            (open.0, open.1, open.6.clone()),
            (7, ACK, 1000u32.to_le_bytes().to_vec())
        );
        f.handle(&request(8, OP_BURST, 0, &[]), QGC, 0);
        assert!(all(&mut f).is_empty());
        let burst: Vec<_> = with_logs(&mut f, &mut store).iter().map(fields).collect();
        let got: Vec<u8> = burst
            .iter()
            .filter(|b| b.1 == ACK)
            .flat_map(|b| b.6.clone())
            .collect();
        assert_eq!(got, log);
        let last = burst.last().unwrap();
        assert_eq!((last.1, last.6[0]), (NAK, ERR_EOF));
        // A gap read, and a log that is not there.
        f.handle(&request(20, OP_READ, 500, &[0; 100]), QGC, 0);
        let read = fields(&with_logs(&mut f, &mut store)[0]);
        assert_eq!(
            (read.0, read.5, read.6.as_slice()),
            (21, 500, &log[500..600])
        );
        f.handle(&request(22, OP_TERMINATE, 0, &[]), QGC, 0);
        all(&mut f);
        f.handle(&request(24, OP_OPEN_RO, 0, b"/logs/log_9.ulg"), QGC, 0);
        let none = fields(&with_logs(&mut f, &mut store)[0]);
        assert_eq!((none.1, none.6[0]), (NAK, ERR_NOT_FOUND));
    }
}
