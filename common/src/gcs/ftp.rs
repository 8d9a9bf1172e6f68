//! A read-only MAVLink FTP server (the MAVLink guide's "File Transfer Protocol") for the few
//! files the vehicle serves from flash: the component metadata a ground station downloads
//! (`general.json` and the parameter metadata).
//!
//! One session at a time, as PX4's. It answers `OpenFileRO` (the file's length), `ReadFile`,
//! `BurstReadFile` (the rest of the file streamed a few packets per poll, the last flagged
//! `burst_complete`, then `EOF`), `ResetSessions`, `TerminateSession` and `None`; anything
//! else gets `NAK UnknownCommand`. Every reply carries the request's sequence number plus one
//! (a burst counts on from there), which is what QGroundControl checks.

use super::peer::Peer;
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
}

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

/// The server's state.
#[derive(Clone, Debug, Default)]
pub struct Ftp {
    files: &'static [File],
    /// The open file and the station it is open for.
    session: Option<(usize, Peer)>,
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
            OP_OPEN_RO if self.session.is_some() && open.is_none() => nak(ERR_NO_SESSIONS),
            OP_OPEN_RO => match self.find(data) {
                Some(i) => {
                    self.session = Some((i, from));
                    let len = self.file(i).map_or(0, |f| f.bytes.len());
                    ack(Data::Length(u32::try_from(len).unwrap_or(u32::MAX)))
                }
                None => nak(ERR_NOT_FOUND),
            },
            OP_READ | OP_BURST if session != SESSION => nak(ERR_SESSION),
            OP_READ | OP_BURST => match open {
                None => nak(ERR_SESSION),
                Some(f) => {
                    let len = self.file(f).map_or(0, |f| f.bytes.len());
                    let at = usize::try_from(offset).unwrap_or(usize::MAX);
                    if at >= len {
                        nak(ERR_EOF)
                    } else if opcode == OP_READ {
                        let n = len.saturating_sub(at).min(size.max(1)).min(DATA_LEN);
                        ack(Data::Slice { file: f, len: n })
                    } else {
                        self.burst = Some(Burst {
                            next_seq: reply_seq,
                            offset,
                            left: BURST_PACKETS,
                            chunk: if size == 0 {
                                DATA_LEN
                            } else {
                                size.min(DATA_LEN)
                            },
                        });
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

    /// The file a request's path names (leading slashes and a trailing NUL ignored).
    fn find(&self, path: &[u8]) -> Option<usize> {
        let end = path.iter().position(|&b| b == 0).unwrap_or(path.len());
        let mut name = path.get(..end)?;
        while let Some(rest) = name.strip_prefix(b"/") {
            name = rest;
        }
        self.files.iter().position(|f| f.name.as_bytes() == name)
    }

    /// The next packet to send and to whom: a pending reply, else the next of a burst (at most
    /// `budget` burst packets; the caller counts them per poll).
    pub fn next(&mut self, budget: &mut usize) -> Option<(MavMessage, Peer)> {
        if let Some((r, to)) = self.reply.take() {
            return Some((self.message(&r, to), to));
        }
        let b = self.burst?;
        let (f, to) = self.session?;
        if *budget == 0 {
            return None;
        }
        *budget = budget.saturating_sub(1);
        let len = self.file(f).map_or(0, |f| f.bytes.len());
        let at = usize::try_from(b.offset).unwrap_or(usize::MAX);
        let r = if at >= len {
            self.burst = None;
            Reply {
                seq: b.next_seq,
                opcode: NAK,
                req_opcode: OP_BURST,
                burst_complete: false,
                offset: b.offset,
                data: Data::Error(ERR_EOF),
            }
        } else {
            let n = len.saturating_sub(at).min(b.chunk);
            let last = b.left <= 1;
            self.burst = (!last).then_some(Burst {
                next_seq: b.next_seq.wrapping_add(1),
                offset: b.offset.saturating_add(n as u32),
                left: b.left.saturating_sub(1),
                chunk: b.chunk,
            });
            Reply {
                seq: b.next_seq,
                opcode: ACK,
                req_opcode: OP_BURST,
                burst_complete: last,
                offset: b.offset,
                data: Data::Slice { file: f, len: n },
            }
        };
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
}
