//! The flight logs of a board that keeps them in a region of its flash (the MCU): the
//! application's log drained into `common::storage::flight_log`'s ring of sectors, and the
//! logs kept served to the ground stations' log protocol ([`LogStore`]).
//!
//! No erase ever falls in a flight: erasing a sector of the STM32F405's single flash bank
//! stalls every instruction fetch for a second or more. The sectors of the next log are erased
//! while the vehicle is disarmed, one a call of [`FlashLogs::service`], ahead of the arming
//! that starts it; a log started before they all are gets the ones ready. When its room is
//! used up the log stops (the aircraft flies on) and says so in [`FlashLogs::full`].
//!
//! The list of logs is scanned from flash once, when the board opens the region, and kept up
//! to date as logs are written and erased: a scan reads the whole region, which no control
//! period could afford.

use super::App;
use common::gcs::logs::{LogEntryInfo, LogStore};
use common::storage::flight_log::{
    first_sector_after, read, scan, LogError, LogInfo, LogList, LogRegion, LogWriter, PAYLOAD_LEN,
};
use common::storage::Flash;

/// The logs in a flash region and the one being written.
pub struct FlashLogs<F> {
    flash: F,
    region: LogRegion,
    sectors_per_log: u32,
    logs: LogList,
    next_id: u32,
    writer: Option<LogWriter>,
    /// Sectors erased for the next log, from `next_first`.
    ready: u32,
    /// Where the next log starts: [`first_sector_after`] the newest when its erasing began.
    next_first: u32,
    seen: u32,
    full: bool,
    flash_errors: u32,
}

impl<F: Flash> FlashLogs<F> {
    /// The logs of `region` on `flash`, each new one given up to `sectors_per_log` sectors,
    /// and the next one's sectors made ready (erased unless blank already: a log from boot,
    /// `SDLOG_MODE` 1, starts at once); switches the application's log on. Called at boot,
    /// where a scan and an erase may take seconds.
    pub fn open(
        mut flash: F,
        region: LogRegion,
        sectors_per_log: u32,
        app: &mut App,
    ) -> Result<Self, LogError<F::Error>> {
        let (logs, next_id) = scan(&mut flash, &region)?;
        app.flight_log_mut().enable(true);
        let mut this = Self {
            flash,
            region,
            sectors_per_log: sectors_per_log.clamp(1, region.sectors),
            logs,
            next_id,
            writer: None,
            ready: 0,
            next_first: 0,
            seen: app.flight_log().logs_started(),
            full: false,
            flash_errors: 0,
        };
        while this.ready < this.sectors_per_log && this.prepare_next() {}
        Ok(this)
    }

    /// The logs kept, oldest first (the one being written with what is in flash so far).
    pub fn logs(&self) -> &LogList {
        &self.logs
    }

    /// The current (or last) log ran out of room and stopped.
    pub fn full(&self) -> bool {
        self.full
    }

    /// Writes and erases the flash refused.
    pub fn flash_errors(&self) -> u32 {
        self.flash_errors
    }

    /// Sectors ready for the next log.
    pub fn ready(&self) -> u32 {
        self.ready
    }

    /// Drains what the application's log has into flash: a log opens when one starts and
    /// closes once a stopped log is drained; on the ground, one sector of the next log's room
    /// is erased. Returns whether it erased a sector.
    pub fn service(&mut self, app: &mut App) -> bool {
        let armed = app.armed();
        let log = app.flight_log_mut();
        let started = log.logs_started();
        if started != self.seen && self.writer.is_none() {
            self.seen = started;
            self.begin();
        }
        while log.pending_len() > 0 {
            let bytes = log.pending();
            let n = bytes.len();
            if let Some(w) = self.writer.as_mut() {
                match w.append(&mut self.flash, bytes) {
                    Ok(Ok(())) => {}
                    // What does not fit is dropped; the log stays readable up to here.
                    Ok(Err(_)) => self.full = true,
                    Err(_) => self.flash_errors = self.flash_errors.saturating_add(1),
                }
            }
            log.consume(n);
        }
        if let Some(w) = self.writer.as_ref() {
            self.note(w.info());
        }
        if !log.recording() {
            if let Some(w) = self.writer.take() {
                // A close that failed leaves the log as its whole blocks have it.
                let whole = w.info();
                let info = w.close(&mut self.flash).unwrap_or_else(|_| {
                    self.flash_errors = self.flash_errors.saturating_add(1);
                    whole
                });
                self.note(info);
            }
        }
        if armed || self.writer.is_some() || self.ready >= self.sectors_per_log {
            return false;
        }
        self.prepare_next()
    }

    /// A log started: it takes the sectors erased for it (none ready: it is not kept).
    fn begin(&mut self) {
        self.full = false;
        if self.ready == 0 {
            self.full = true;
            return;
        }
        let first = self.next_first;
        let Ok(w) =
            LogWriter::open_erased::<F::Error>(&self.region, first, self.next_id, self.ready)
        else {
            return;
        };
        self.next_id = self.next_id.wrapping_add(1).max(1);
        self.ready = 0;
        if self.logs.is_full() {
            drop_oldest(&mut self.logs);
        }
        let _ = self.logs.push(w.info());
        self.writer = Some(w);
    }

    /// Makes the next sector of the next log's room ready, erasing it unless it is blank; the
    /// logs that had blocks in it lose them (a log whose first sector it was is gone). The
    /// newest log is kept unless the next log would have no room at all.
    fn prepare_next(&mut self) -> bool {
        if self.ready == 0 {
            self.next_first = first_sector_after(&self.region, &self.logs);
        }
        let sector = (self.next_first.saturating_add(self.ready))
            .checked_rem(self.region.sectors)
            .unwrap_or(0);
        let newest = self
            .logs
            .iter()
            .max_by_key(|l| l.id)
            .map(|l| l.first_sector);
        if self.ready > 0 && newest == Some(sector) {
            return false;
        }
        let addr = self.region.sector_addr(sector);
        if !self.blank(addr) && self.flash.erase_sector(addr).is_err() {
            self.flash_errors = self.flash_errors.saturating_add(1);
            return false;
        }
        self.forget_sector(sector);
        self.ready = self.ready.saturating_add(1);
        true
    }

    /// Whether the sector at `addr` reads erased throughout (erasing it again would cost a
    /// second or more of stalled flash for nothing).
    fn blank(&mut self, addr: u32) -> bool {
        let mut chunk = [0u8; 64];
        let mut at = 0u32;
        while at < self.region.sector_len {
            if self
                .flash
                .read(addr.saturating_add(at), &mut chunk)
                .is_err()
                || chunk.iter().any(|&b| b != 0xff)
            {
                return false;
            }
            at = at.saturating_add(chunk.len() as u32);
        }
        true
    }

    /// What erasing `sector` left of each log.
    fn forget_sector(&mut self, sector: u32) {
        let per_sector = self.region.sector_len / common::storage::flight_log::BLOCK_LEN;
        let sectors = self.region.sectors;
        self.logs.retain(|l| l.first_sector != sector);
        for l in self.logs.iter_mut() {
            // Sectors from the log's first to the erased one, round the ring.
            let ahead = (sector
                .saturating_add(sectors)
                .saturating_sub(l.first_sector))
            .checked_rem(sectors)
            .unwrap_or(0);
            let kept_blocks = ahead.saturating_mul(per_sector);
            if l.blocks > kept_blocks {
                l.blocks = kept_blocks;
                l.bytes = l.bytes.min(kept_blocks.saturating_mul(PAYLOAD_LEN as u32));
            }
        }
    }

    /// Puts the current figures of log `info.id` in the list.
    fn note(&mut self, info: LogInfo) {
        if let Some(l) = self.logs.iter_mut().find(|l| l.id == info.id) {
            *l = info;
        }
    }
}

impl<F: Flash> LogStore for FlashLogs<F> {
    fn refresh(&mut self) {
        // The list is kept as logs are written and erased.
    }

    fn count(&self) -> u16 {
        u16::try_from(self.logs.len()).unwrap_or(u16::MAX)
    }

    fn entry(&self, index: u16) -> Option<LogEntryInfo> {
        self.logs.get(usize::from(index)).map(|l| LogEntryInfo {
            size_bytes: l.bytes,
            // The board keeps no calendar.
            time_utc_s: 0,
        })
    }

    fn read(&mut self, index: u16, offset: u32, buf: &mut [u8]) -> Option<usize> {
        let info = *self.logs.get(usize::from(index))?;
        read(&mut self.flash, &self.region, &info, offset, buf).ok()
    }

    fn erase_all(&mut self) -> bool {
        if self.writer.is_some() {
            return false;
        }
        for s in 0..self.region.sectors {
            if self.flash.erase_sector(self.region.sector_addr(s)).is_err() {
                self.flash_errors = self.flash_errors.saturating_add(1);
                return false;
            }
        }
        self.logs.clear();
        // Every sector is erased: the next log (from sector 0) has its room.
        self.next_first = 0;
        self.ready = self.sectors_per_log;
        true
    }
}

/// Drops the list's first (oldest) log, the others kept in order: each swapped one place
/// towards the front, so the first ends last and is popped. `Vec::remove(0)` moves them with
/// `memmove`, which nothing else in the image calls (1.6 KB of flash for one call a log).
fn drop_oldest(logs: &mut LogList) {
    let mut rest = logs.iter_mut();
    if let Some(mut slot) = rest.next() {
        for next in rest {
            core::mem::swap(slot, next);
            slot = next;
        }
    }
    logs.pop();
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use common::storage::RamFlash;
    use std::vec;

    const SECTOR: u32 = 4096;
    /// Four sectors of 4 KiB: eight blocks each, two sectors a log (15,744 bytes of payload).
    const REGION: LogRegion = LogRegion {
        start: 0,
        sector_len: SECTOR,
        sectors: 4,
    };

    #[test]
    fn the_oldest_log_is_dropped_and_the_others_keep_their_order() {
        let log = |id| LogInfo {
            id,
            first_sector: id,
            blocks: 1,
            bytes: id * 10,
        };
        let mut logs = LogList::new();
        for id in 1..=3 {
            logs.push(log(id)).unwrap();
        }
        drop_oldest(&mut logs);
        assert_eq!(logs.as_slice(), &[log(2), log(3)]);
        drop_oldest(&mut logs);
        drop_oldest(&mut logs);
        assert!(logs.is_empty());
        drop_oldest(&mut logs);
        assert!(logs.is_empty());
    }

    /// Feeds a frame of the sensors at rest at `time_us`; whether the vehicle answered it.
    fn frame(app: &mut App, time_us: u64) -> bool {
        let mut answered = false;
        app.on_sim_bytes(&crate::app::tests::frame_at(time_us), &mut |_| {
            answered = true
        });
        answered
    }

    /// An application logging from boot (`SDLOG_MODE` 1) and its logs in the four sectors.
    fn logging_from_boot() -> (App, FlashLogs<RamFlash<{ 4 * 4096 }>>) {
        let mut app = App::new();
        app.vehicle_mut()
            .params_mut()
            .set("SDLOG_MODE", 1.0)
            .expect("SDLOG_MODE");
        let flash = RamFlash::<{ 4 * 4096 }>::new(SECTOR);
        let logs = FlashLogs::open(flash, REGION, 2, &mut app).expect("the region");
        (app, logs)
    }

    #[test]
    fn a_log_that_fills_its_sectors_stops_and_the_vehicle_answers_every_frame_after() {
        let (mut app, mut logs) = logging_from_boot();
        // Blank sectors are made ready without an erase.
        assert_eq!((logs.ready(), logs.flash_errors()), (2, 0));
        let mut answered = 0;
        // 10 s of frames at 100 Hz: some 80 KB of log for 15.7 KB of room.
        for k in 1..=1000u64 {
            answered += usize::from(frame(&mut app, k * 10_000));
            logs.service(&mut app);
        }
        assert_eq!(answered, 1000, "every frame answered");
        assert!(logs.full(), "the log filled its room");
        assert_eq!(logs.flash_errors(), 0);
        let kept = logs.logs().clone();
        assert_eq!(kept.len(), 1);
        // Whole blocks only, as many as the two sectors hold (or one fewer when the next
        // message did not fit the last).
        assert!(kept[0].blocks >= 15 && kept[0].blocks <= 16, "{kept:?}");
        let mut head = vec![0u8; 16];
        let n = LogStore::read(&mut logs, 0, 0, &mut head).expect("reads");
        assert_eq!(&head[..n.min(7)], b"ULog\x01\x12\x35");
        // The store answers the log protocol with what flash holds.
        assert_eq!(
            LogStore::entry(&logs, 0).map(|e| e.size_bytes),
            Some(kept[0].bytes)
        );
    }

    #[test]
    fn an_erase_leaves_no_log_and_the_next_one_its_room() {
        let (mut app, mut logs) = logging_from_boot();
        for k in 1..=50u64 {
            frame(&mut app, k * 10_000);
            logs.service(&mut app);
        }
        // Being written: not erased.
        assert!(!LogStore::erase_all(&mut logs));
        app.vehicle_mut()
            .params_mut()
            .set("SDLOG_MODE", -1.0)
            .expect("SDLOG_MODE");
        for k in 51..=60u64 {
            frame(&mut app, k * 10_000);
            logs.service(&mut app);
        }
        assert_eq!(logs.logs().len(), 1, "the log closed and kept");
        assert!(LogStore::erase_all(&mut logs));
        assert_eq!((LogStore::count(&logs), logs.ready()), (0, 2));
    }
}
