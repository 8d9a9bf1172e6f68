//! The log protocol against the MAVLink guide's "Onboard Log Download": what a station that
//! lists, downloads (losing packets and asking again) and erases sees.

extern crate std;

use super::*;
use std::vec;
use std::vec::Vec;

/// Logs in memory.
#[derive(Default)]
struct Memory {
    logs: Vec<Vec<u8>>,
    /// What `refresh` made visible (a log added after it is not listed).
    visible: usize,
    refreshed: usize,
}

impl LogStore for Memory {
    fn refresh(&mut self) {
        self.visible = self.logs.len();
        self.refreshed += 1;
    }
    fn count(&self) -> u16 {
        self.visible as u16
    }
    fn entry(&self, index: u16) -> Option<LogEntryInfo> {
        (usize::from(index) < self.visible).then(|| LogEntryInfo {
            size_bytes: self.logs[usize::from(index)].len() as u32,
            time_utc_s: 1_700_000_000 + u32::from(index),
        })
    }
    fn read(&mut self, index: u16, offset: u32, buf: &mut [u8]) -> Option<usize> {
        let log = self.logs.get(usize::from(index))?;
        let from = (offset as usize).min(log.len());
        let n = buf.len().min(log.len() - from);
        buf[..n].copy_from_slice(&log[from..from + n]);
        Some(n)
    }
    fn erase_all(&mut self) -> bool {
        self.logs.clear();
        true
    }
}

fn bytes(n: usize, salt: u8) -> Vec<u8> {
    (0..n).map(|k| (k as u8).wrapping_mul(31) ^ salt).collect()
}

const STATION: Peer = Peer {
    system: 255,
    component: 190,
    channel: 3,
};

fn list(start: u16, end: u16) -> LOG_REQUEST_LIST_DATA {
    LOG_REQUEST_LIST_DATA {
        start,
        end,
        target_system: 1,
        target_component: 1,
    }
}

fn request(id: u16, ofs: u32, count: u32) -> LOG_REQUEST_DATA_DATA {
    LOG_REQUEST_DATA_DATA {
        ofs,
        count,
        id,
        target_system: 1,
        target_component: 1,
    }
}

/// One call of `serve` with `room` bytes: what it sent, each to where.
fn serve(
    s: &mut LogService,
    store: &mut Memory,
    armed: bool,
    room: usize,
) -> Vec<(Dest, MavMessage)> {
    let mut out = Vec::new();
    let mut outbox = Outbox::default();
    s.serve(store, &mut Pace::new(room, armed), &mut outbox, |d, m| {
        out.push((d, m))
    });
    out
}

fn entries(out: &[(Dest, MavMessage)]) -> Vec<LOG_ENTRY_DATA> {
    out.iter()
        .filter_map(|(_, m)| match m {
            MavMessage::LOG_ENTRY(e) => Some(e.clone()),
            _ => None,
        })
        .collect()
}

fn data(out: &[(Dest, MavMessage)]) -> Vec<LOG_DATA_DATA> {
    out.iter()
        .filter_map(|(_, m)| match m {
            MavMessage::LOG_DATA(d) => Some(d.clone()),
            _ => None,
        })
        .collect()
}

/// Serves until nothing more comes (a station that reads everything at once).
fn serve_all(s: &mut LogService, store: &mut Memory) -> Vec<(Dest, MavMessage)> {
    let mut all = Vec::new();
    for _ in 0..10_000 {
        let out = serve(s, store, false, 8192);
        if out.is_empty() {
            break;
        }
        all.extend(out);
    }
    all
}

#[test]
fn a_list_with_no_log_kept_is_one_entry_of_id_0_and_no_logs() {
    let (mut s, mut store) = (LogService::new(), Memory::default());
    s.on_request_list(&list(0, 0xffff), STATION);
    let out = serve_all(&mut s, &mut store);
    let e = entries(&out);
    assert_eq!(e.len(), 1);
    assert_eq!((e[0].id, e[0].num_logs, e[0].size), (0, 0, 0));
    assert!(!s.busy());
}

#[test]
fn a_list_names_every_log_oldest_first_from_id_1_with_its_size_to_the_asker_only() {
    let mut store = Memory {
        logs: vec![bytes(1000, 1), bytes(2345, 2), bytes(7, 3)],
        ..Memory::default()
    };
    let mut s = LogService::new();
    s.on_request_list(&list(0, 0xffff), STATION);
    let out = serve_all(&mut s, &mut store);
    assert!(out.iter().all(|(d, _)| *d == Dest::Channel(3)));
    let e = entries(&out);
    let got: Vec<(u16, u16, u16, u32)> = e
        .iter()
        .map(|e| (e.id, e.num_logs, e.last_log_num, e.size))
        .collect();
    assert_eq!(
        got,
        vec![(1, 3, 3, 1000), (2, 3, 3, 2345), (3, 3, 3, 7)],
        "ids 1..=3, oldest first"
    );
    assert_eq!(e[1].time_utc, 1_700_000_001);
    // A range asks for those ids only; the list is looked at again for each request.
    s.on_request_list(&list(2, 2), STATION);
    let e = entries(&serve_all(&mut s, &mut store));
    assert_eq!(e.iter().map(|e| e.id).collect::<Vec<_>>(), vec![2]);
    assert_eq!(store.refreshed, 2);
}

/// Downloads log `id` whole, as MAVProxy does: one request for everything, then the ranges
/// lost asked for again, until a packet shorter than 90 bytes (or of none) ends it.
fn download(s: &mut LogService, store: &mut Memory, id: u16, lose_every: usize) -> Vec<u8> {
    let mut got: std::collections::BTreeMap<u32, Vec<u8>> = Default::default();
    let mut end: Option<u32> = None;
    s.on_request_data(&request(id, 0, 0xffff_ffff), STATION);
    let mut k = 0usize;
    for _round in 0..100 {
        for d in data(&serve_all(s, store)) {
            k += 1;
            if lose_every > 0 && k.is_multiple_of(lose_every) {
                continue;
            }
            assert_eq!(d.id, id);
            if (d.count as usize) < DATA_LEN {
                end = Some(d.ofs + u32::from(d.count));
            }
            got.insert(d.ofs, d.data[..usize::from(d.count)].to_vec());
        }
        // The first gap, asked for again.
        let mut at = 0u32;
        while let Some(chunk) = got.get(&at) {
            if chunk.is_empty() {
                break;
            }
            at += chunk.len() as u32;
        }
        match end {
            Some(e) if at >= e => break,
            _ => s.on_request_data(&request(id, at, 90 * 8), STATION),
        }
    }
    let mut whole = Vec::new();
    let mut at = 0u32;
    while let Some(chunk) = got.get(&at) {
        if chunk.is_empty() {
            break;
        }
        whole.extend_from_slice(chunk);
        at += chunk.len() as u32;
    }
    whole
}

#[test]
fn a_log_downloads_byte_for_byte_and_ends_with_a_packet_under_90_bytes() {
    let log = bytes(10_000, 7);
    let mut store = Memory {
        logs: vec![bytes(100, 1), log.clone()],
        visible: 2,
        ..Memory::default()
    };
    let mut s = LogService::new();
    s.on_request_data(&request(2, 0, 0xffff_ffff), STATION);
    let d = data(&serve_all(&mut s, &mut store));
    // 10,000 bytes: 111 packets of 90 and one of 10.
    assert_eq!(d.len(), 112);
    assert!(d[..111].iter().all(|p| p.count == 90));
    assert_eq!((d[111].ofs, d[111].count), (9990, 10));
    assert!(!s.busy());
    assert_eq!(download(&mut s, &mut store, 2, 0), log);
}

#[test]
fn a_log_of_whole_packets_ends_with_an_empty_packet_at_its_size() {
    let mut store = Memory {
        logs: vec![bytes(900, 1)],
        visible: 1,
        ..Memory::default()
    };
    let mut s = LogService::new();
    s.on_request_data(&request(1, 0, 0xffff_ffff), STATION);
    let d = data(&serve_all(&mut s, &mut store));
    assert_eq!(d.len(), 11);
    assert_eq!((d[10].ofs, d[10].count), (900, 0));
    // A request past the end: one empty packet.
    s.on_request_data(&request(1, 5000, 90), STATION);
    let d = data(&serve_all(&mut s, &mut store));
    assert_eq!(d.iter().map(|p| p.count).collect::<Vec<_>>(), vec![0]);
}

#[test]
fn lost_packets_asked_for_again_are_sent_again_and_the_log_arrives_whole() {
    let log = bytes(25_000, 9);
    let mut store = Memory {
        logs: vec![log.clone()],
        visible: 1,
        ..Memory::default()
    };
    let mut s = LogService::new();
    // One packet in seven lost, the end marker among them at times.
    assert_eq!(download(&mut s, &mut store, 1, 7), log);
}

#[test]
fn a_range_request_is_answered_with_that_range_only() {
    let log = bytes(5000, 4);
    let mut store = Memory {
        logs: vec![log.clone()],
        visible: 1,
        ..Memory::default()
    };
    let mut s = LogService::new();
    s.on_request_data(&request(1, 1000, 200), STATION);
    let d = data(&serve_all(&mut s, &mut store));
    let got: Vec<(u32, u8)> = d.iter().map(|p| (p.ofs, p.count)).collect();
    assert_eq!(got, vec![(1000, 90), (1090, 90), (1180, 20)]);
    assert_eq!(&d[2].data[..20], &log[1180..1200]);
}

#[test]
fn an_unknown_log_id_gets_nothing_and_the_end_request_stops_a_transfer() {
    let mut store = Memory {
        logs: vec![bytes(50_000, 4)],
        visible: 1,
        ..Memory::default()
    };
    let mut s = LogService::new();
    s.on_request_data(&request(9, 0, 0xffff_ffff), STATION);
    assert!(serve_all(&mut s, &mut store).is_empty());
    s.on_request_data(&request(1, 0, 0xffff_ffff), STATION);
    assert!(!data(&serve(&mut s, &mut store, false, 4096)).is_empty());
    s.on_request_end();
    assert!(serve_all(&mut s, &mut store).is_empty());
}

#[test]
fn in_the_air_a_download_takes_two_packets_a_call_and_never_more_than_the_room() {
    let mut store = Memory {
        logs: vec![bytes(50_000, 4)],
        visible: 1,
        ..Memory::default()
    };
    let mut s = LogService::new();
    s.on_request_data(&request(1, 0, 0xffff_ffff), STATION);
    assert_eq!(data(&serve(&mut s, &mut store, true, 8192)).len(), 2);
    // On the ground, as many as the room holds: 4096 / 122 = 33.
    let n = data(&serve(&mut s, &mut store, false, 4096)).len();
    assert_eq!(n, 33);
    // No room for a whole packet: nothing.
    assert!(serve(&mut s, &mut store, false, LOG_DATA_FRAME - 1).is_empty());
}

#[test]
fn an_erase_is_refused_in_the_air_and_done_on_the_ground() {
    let mut store = Memory {
        logs: vec![bytes(10, 1), bytes(20, 2)],
        visible: 2,
        ..Memory::default()
    };
    let mut s = LogService::new();
    let mut outbox = Outbox::default();
    s.on_erase(true, &mut outbox);
    assert!(!s.busy());
    assert_eq!(store.logs.len(), 2);
    s.on_erase(false, &mut outbox);
    serve_all(&mut s, &mut store);
    assert!(store.logs.is_empty());
    s.on_request_list(&list(0, 0xffff), STATION);
    let e = entries(&serve_all(&mut s, &mut store));
    assert_eq!((e.len(), e[0].num_logs), (1, 0));
}
