//! The flight-log store on NOR flash in RAM, with power cuts at every operation.

extern crate std;

use super::*;
use crate::storage::{RamFlash, RamFlashError};

const SECTOR: u32 = 2048; // four blocks
const SECTORS: u32 = 4;
const N: usize = (SECTOR * SECTORS) as usize;
const REGION: LogRegion = LogRegion {
    start: 0,
    sector_len: SECTOR,
    sectors: SECTORS,
};

fn pattern(seed: u8, n: usize) -> std::vec::Vec<u8> {
    (0..n)
        .map(|i| (i as u8).wrapping_mul(31).wrapping_add(seed))
        .collect()
}

fn write_log(f: &mut RamFlash<N>, bytes: &[u8], sectors: u32) -> u32 {
    let (logs, next) = scan(f, &REGION).unwrap();
    let mut w = LogWriter::start(f, &REGION, &logs, next, sectors).unwrap();
    // In messages of varied sizes, as a logger hands them over.
    for chunk in bytes.chunks(37) {
        w.append(f, chunk).unwrap().unwrap();
    }
    let id = w.id();
    w.close(f).unwrap();
    id
}

fn read_all(f: &mut RamFlash<N>, log: &LogInfo) -> std::vec::Vec<u8> {
    let mut out = std::vec![0u8; log.bytes as usize];
    // Odd-sized reads, as LOG_REQUEST_DATA's 90-byte pieces cross block boundaries.
    let mut at = 0;
    while at < out.len() {
        let end = (at + 90).min(out.len());
        let n = read(f, &REGION, log, at as u32, &mut out[at..end]).unwrap();
        assert!(n > 0);
        at += n;
    }
    out
}

#[test]
fn a_log_reads_back_byte_for_byte_across_its_blocks() {
    let mut f = RamFlash::<N>::new(SECTOR);
    let data = pattern(1, 3 * PAYLOAD_LEN + 100);
    assert_eq!(write_log(&mut f, &data, 2), 1);
    let (logs, next) = scan(&mut f, &REGION).unwrap();
    assert_eq!(logs.len(), 1);
    assert_eq!(next, 2);
    assert_eq!(logs[0].blocks, 4);
    assert_eq!(logs[0].bytes as usize, data.len());
    assert_eq!(read_all(&mut f, &logs[0]), data);
}

#[test]
fn a_read_at_the_end_gives_nothing_and_past_it_is_refused() {
    let mut f = RamFlash::<N>::new(SECTOR);
    write_log(&mut f, &pattern(2, 700), 1);
    let (logs, _) = scan(&mut f, &REGION).unwrap();
    let mut b = [0u8; 10];
    assert_eq!(read(&mut f, &REGION, &logs[0], 700, &mut b), Ok(0));
    assert_eq!(
        read(&mut f, &REGION, &logs[0], 701, &mut b),
        Err(LogError::Range)
    );
    assert_eq!(read(&mut f, &REGION, &logs[0], 695, &mut b), Ok(5));
}

#[test]
fn new_logs_erase_the_oldest_first_and_never_reuse_a_number() {
    let mut f = RamFlash::<N>::new(SECTOR);
    let logs: std::vec::Vec<_> = (0..4).map(|k| pattern(k, 1500)).collect();
    for d in &logs {
        write_log(&mut f, d, 1);
    }
    let (found, _) = scan(&mut f, &REGION).unwrap();
    assert_eq!(
        found.iter().map(|l| l.id).collect::<std::vec::Vec<_>>(),
        [1, 2, 3, 4]
    );
    // A fifth log of one sector takes the oldest's sector; a sixth of two takes the next two.
    write_log(&mut f, &pattern(9, 1500), 1);
    let (found, next) = scan(&mut f, &REGION).unwrap();
    assert_eq!(
        found.iter().map(|l| l.id).collect::<std::vec::Vec<_>>(),
        [2, 3, 4, 5]
    );
    assert_eq!(next, 6);
    for l in &found[..3] {
        assert_eq!(read_all(&mut f, l), logs[l.id as usize - 1]);
    }
    write_log(&mut f, &pattern(10, 3000), 2);
    let (found, next) = scan(&mut f, &REGION).unwrap();
    assert_eq!(
        found.iter().map(|l| l.id).collect::<std::vec::Vec<_>>(),
        [4, 5, 6]
    );
    assert_eq!(next, 7);
    assert_eq!(read_all(&mut f, &found[2]), pattern(10, 3000));
}

#[test]
fn a_full_region_refuses_a_message_whole_and_keeps_what_came_before() {
    let mut f = RamFlash::<N>::new(SECTOR);
    let (logs, next) = scan(&mut f, &REGION).unwrap();
    let mut w = LogWriter::start(&mut f, &REGION, &logs, next, 1).unwrap();
    let room = 4 * PAYLOAD_LEN;
    let data = pattern(3, room - 10);
    w.append(&mut f, &data).unwrap().unwrap();
    assert!(w.has_room(10));
    assert_eq!(w.append(&mut f, &[0; 11]).unwrap(), Err(LogFull));
    w.append(&mut f, &[7; 10]).unwrap().unwrap();
    assert_eq!(w.append(&mut f, &[1]).unwrap(), Err(LogFull));
    w.close(&mut f).unwrap();
    let (found, _) = scan(&mut f, &REGION).unwrap();
    let mut want = data;
    want.extend_from_slice(&[7; 10]);
    assert_eq!(read_all(&mut f, &found[0]), want);
}

#[test]
fn a_power_cut_at_any_write_keeps_earlier_logs_whole_and_the_current_one_up_to_its_last_block() {
    let first = pattern(4, 2 * PAYLOAD_LEN + 50);
    let second = pattern(5, 3 * PAYLOAD_LEN + 20);
    let mut base = RamFlash::<N>::new(SECTOR);
    write_log(&mut base, &first, 1);
    // Count the operations writing the second log takes.
    let mut probe = base.clone();
    let before = probe.ops();
    write_log(&mut probe, &second, 2);
    let ops = probe.ops() - before;
    for cut in 1..=ops {
        let mut f = base.clone();
        f.cut_after(Some(cut));
        let (logs, next) = scan(&mut f, &REGION).unwrap();
        let written = LogWriter::start(&mut f, &REGION, &logs, next, 2).and_then(|mut w| {
            for chunk in second.chunks(37) {
                w.append(&mut f, chunk).map_err(LogError::Flash)?.ok();
            }
            w.close(&mut f).map_err(LogError::Flash)
        });
        assert_eq!(
            written,
            Err(LogError::Flash(RamFlashError::PowerLost)),
            "cut {cut}"
        );
        f.cut_after(None);
        let (found, next) = scan(&mut f, &REGION).unwrap();
        assert_eq!(found[0].id, 1, "cut {cut}");
        assert_eq!(read_all(&mut f, &found[0]), first, "cut {cut}");
        if let Some(cur) = found.get(1) {
            assert_eq!(cur.id, 2);
            assert_eq!(
                cur.bytes as usize % PAYLOAD_LEN,
                0,
                "only whole blocks, cut {cut}"
            );
            assert_eq!(
                read_all(&mut f, cur),
                second[..cur.bytes as usize],
                "cut {cut}"
            );
        }
        assert!(found.len() <= 2 && next >= 2, "cut {cut}");
        // The store still takes a new log after the cut, and keeps the first.
        write_log(&mut f, &pattern(6, 600), 1);
        let (found, _) = scan(&mut f, &REGION).unwrap();
        assert_eq!(read_all(&mut f, &found[0]), first, "cut {cut}");
        assert_eq!(
            read_all(&mut f, found.last().unwrap()),
            pattern(6, 600),
            "cut {cut}"
        );
    }
}

#[test]
fn a_region_of_an_unusable_shape_is_refused() {
    let mut f = RamFlash::<N>::new(SECTOR);
    for bad in [
        LogRegion {
            sectors: 0,
            ..REGION
        },
        LogRegion {
            sector_len: 100,
            ..REGION
        },
        LogRegion {
            sectors: 17,
            ..REGION
        },
        LogRegion {
            start: u32::MAX - 10,
            ..REGION
        },
    ] {
        assert_eq!(scan(&mut f, &bad).unwrap_err(), LogError::Region);
    }
}

#[test]
fn garbage_in_the_region_is_no_log() {
    let mut img = std::vec![0u8; N];
    for (i, b) in img.iter_mut().enumerate() {
        *b = (i as u32).wrapping_mul(2_654_435_761).to_le_bytes()[1];
    }
    // A header with the right magic and a bad CRC.
    img[..4].copy_from_slice(&LOG_MAGIC.to_le_bytes());
    img[12..14].copy_from_slice(&10u16.to_le_bytes());
    let mut f = RamFlash::<N>::from_image(&img, SECTOR);
    let (logs, _) = scan(&mut f, &REGION).unwrap();
    assert!(logs.is_empty());
}

/// Logs found out of number order (the ring wrapped: a newer log in an earlier sector) are
/// listed by number, each moved down to its place as it is found.
#[test]
fn logs_found_out_of_order_are_listed_by_number() {
    let mut logs = LogList::new();
    for id in [5, 2, 9, 1, 7] {
        let info = LogInfo {
            id,
            first_sector: 0,
            blocks: 1,
            bytes: 0,
        };
        assert!(logs.push(info).is_ok());
        settle_last(&mut logs);
    }
    let ids: std::vec::Vec<u32> = logs.iter().map(|l| l.id).collect();
    assert_eq!(ids, [1, 2, 5, 7, 9]);
}
