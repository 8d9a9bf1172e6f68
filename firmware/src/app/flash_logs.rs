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
    /// The logs of `region` on `flash`, each new one given up to `sectors_per_log` sectors;
    /// switches the application's log on.
    pub fn open(
        mut flash: F,
        region: LogRegion,
        sectors_per_log: u32,
        app: &mut App,
    ) -> Result<Self, LogError<F::Error>> {
        let (logs, next_id) = scan(&mut flash, &region)?;
        app.flight_log_mut().enable(true);
        Ok(Self {
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
        })
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
                let bytes = w.bytes();
                let mut info = w.info();
                match w.close(&mut self.flash) {
                    Ok(()) => {
                        info.bytes = bytes;
                        info.blocks = bytes.div_ceil(PAYLOAD_LEN as u32);
                    }
                    Err(_) => self.flash_errors = self.flash_errors.saturating_add(1),
                }
                self.note(info);
            }
        }
        if armed || self.writer.is_some() || self.ready >= self.sectors_per_log {
            return false;
        }
        self.erase_next()
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
            self.logs.remove(0);
        }
        let _ = self.logs.push(w.info());
        self.writer = Some(w);
    }

    /// Erases the next sector of the next log's room; the logs that had blocks in it lose
    /// them (a log whose first sector it was is gone). The newest log is kept unless the next
    /// log would have no room at all.
    fn erase_next(&mut self) -> bool {
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
        if self
            .flash
            .erase_sector(self.region.sector_addr(sector))
            .is_err()
        {
            self.flash_errors = self.flash_errors.saturating_add(1);
            return false;
        }
        self.forget_sector(sector);
        self.ready = self.ready.saturating_add(1);
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
