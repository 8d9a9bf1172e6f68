//! Flight logs in a region of flash: written front to back in blocks, read back by number,
//! the oldest erased first, and safe against a power cut at any write.
//!
//! The region is a ring of equal sectors. Each log starts at a sector's start and runs on
//! through consecutive blocks of [`BLOCK_LEN`] bytes, across sectors and round the end of the
//! region. A block is
//!
//! ```text
//! offset 0   magic   u32 LE   the region's magic (and format version)
//!        4   log     u32 LE   the log's number; each new log takes the highest seen + 1
//!        8   index   u32 LE   the block's place in its log, from 0
//!       12   len     u16 LE   payload bytes, 1..=PAYLOAD_LEN
//!       14   spare   u16      0xFFFF
//!       16   crc     u32 LE   CRC-32 of bytes 4..16 and the payload
//!       20   payload
//! ```
//!
//! written payload first and header last, so until its last header byte is programmed a block
//! fails its CRC and is not part of its log: a power cut at any write leaves the logs before
//! it whole and the current one readable up to its last complete block.
//!
//! Sectors are erased only when a log starts ([`LogWriter::start`]), never while it is
//! written: erasing a sector of a single-bank flash stalls every instruction fetch for a
//! second or more, which no control period can absorb. The sectors a new log erases are the
//! ones after the newest log, which in a ring are the oldest logs': the oldest log goes first.
//! When the erased room runs out the log stops ([`LogFull`]), the aircraft flies on.

// Addresses, counts and lengths here come from flash that may hold anything: every operation
// on them is checked.
#![cfg_attr(not(test), deny(clippy::arithmetic_side_effects))]

use super::Flash;
use crate::crc::Crc32;

/// Bytes of one block, header included.
pub const BLOCK_LEN: u32 = 512;
/// Bytes of a block's header.
pub const HEADER_LEN: u32 = 20;
/// Payload bytes of a full block.
pub const PAYLOAD_LEN: usize = (BLOCK_LEN - HEADER_LEN) as usize;
/// The most logs a region is scanned for (each log holds at least one sector).
pub const MAX_LOGS: usize = 16;
/// Magic of a flight-log block, format 1.
pub const LOG_MAGIC: u32 = 0x4c4f_4731; // "LOG1"

/// A region of flash for flight logs: `sectors` sectors of `sector_len` bytes from `start`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LogRegion {
    /// First byte (a sector start).
    pub start: u32,
    /// Bytes of each sector (a multiple of [`BLOCK_LEN`]).
    pub sector_len: u32,
    /// Sectors in the ring (at most [`MAX_LOGS`]).
    pub sectors: u32,
}

/// One log found in the region.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LogInfo {
    /// Its number (increasing with age: the newest has the highest).
    pub id: u32,
    /// The sector it starts in (0-based within the region).
    pub first_sector: u32,
    /// Complete blocks.
    pub blocks: u32,
    /// Payload bytes in them.
    pub bytes: u32,
}

/// The logs of a region, oldest first.
pub type LogList = heapless::Vec<LogInfo, MAX_LOGS>;

/// Why the region cannot be used.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LogError<E> {
    /// The region's shape is not one this store can use (no sectors, more than
    /// [`MAX_LOGS`], a sector not a whole number of blocks, or past the address space).
    Region,
    /// A read past the end of the log.
    Range,
    /// The flash device failed.
    Flash(E),
}

impl<E: core::fmt::Debug> core::fmt::Display for LogError<E> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            LogError::Region => f.write_str("flight-log region of an unusable shape"),
            LogError::Range => f.write_str("read past the end of the log"),
            LogError::Flash(e) => write!(f, "flash failed: {e:?}"),
        }
    }
}

impl<E: core::fmt::Debug> core::error::Error for LogError<E> {}

/// The erased room of the current log is used up: nothing more is written until the next
/// log starts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LogFull;

impl core::fmt::Display for LogFull {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("flight-log region full")
    }
}

impl core::error::Error for LogFull {}

struct Header {
    log: u32,
    index: u32,
    len: u16,
    crc: u32,
}

impl LogRegion {
    fn check<E>(&self) -> Result<(), LogError<E>> {
        let fits = self
            .sector_len
            .checked_mul(self.sectors)
            .and_then(|n| self.start.checked_add(n))
            .is_some();
        let usable = self.sectors > 0
            && self.sectors as usize <= MAX_LOGS
            && self.sector_len >= BLOCK_LEN
            && self.sector_len.is_multiple_of(BLOCK_LEN);
        if fits && usable {
            Ok(())
        } else {
            Err(LogError::Region)
        }
    }

    fn blocks_per_sector(&self) -> u32 {
        self.sector_len.checked_div(BLOCK_LEN).unwrap_or(0)
    }

    fn total_blocks(&self) -> u32 {
        self.blocks_per_sector().saturating_mul(self.sectors)
    }

    /// Address of block `n` after the start of `sector`, round the ring.
    fn block_addr(&self, sector: u32, n: u32) -> u32 {
        let total = self.total_blocks().max(1);
        let first = sector.saturating_mul(self.blocks_per_sector());
        let at = (u64::from(first).saturating_add(u64::from(n)))
            .checked_rem(u64::from(total))
            .unwrap_or(0);
        // `at` < total blocks, which fit the address space (`check`).
        let offset = u32::try_from(at).unwrap_or(0).saturating_mul(BLOCK_LEN);
        self.start.saturating_add(offset)
    }

    /// The address of sector `sector` of the region (0-based).
    pub fn sector_addr(&self, sector: u32) -> u32 {
        self.start.saturating_add(
            sector
                .checked_rem(self.sectors)
                .unwrap_or(0)
                .saturating_mul(self.sector_len),
        )
    }
}

fn read_header<F: Flash>(flash: &mut F, addr: u32) -> Result<Option<Header>, F::Error> {
    let mut h = [0u8; HEADER_LEN as usize];
    flash.read(addr, &mut h)?;
    let word = |i: usize| {
        h.get(i..i.saturating_add(4))
            .and_then(|b| b.try_into().ok())
            .map_or(0, u32::from_le_bytes)
    };
    if word(0) != LOG_MAGIC {
        return Ok(None);
    }
    let len = u16::from_le_bytes([h[12], h[13]]);
    if len == 0 || usize::from(len) > PAYLOAD_LEN {
        return Ok(None);
    }
    Ok(Some(Header {
        log: word(4),
        index: word(8),
        len,
        crc: word(16),
    }))
}

/// The block at `addr` if it is a complete block of log `log` at `index`: header and payload
/// pass the CRC.
fn valid_block<F: Flash>(
    flash: &mut F,
    addr: u32,
    want: Option<(u32, u32)>,
) -> Result<Option<Header>, F::Error> {
    let Some(h) = read_header(flash, addr)? else {
        return Ok(None);
    };
    if want.is_some_and(|(log, index)| (h.log, h.index) != (log, index)) {
        return Ok(None);
    }
    let mut head = [0u8; 12];
    flash.read(addr.saturating_add(4), &mut head)?;
    let mut crc = Crc32::ieee();
    crc.digest(&head);
    let mut payload = [0u8; 64];
    let mut done = 0usize;
    let len = usize::from(h.len);
    while done < len {
        let n = (len.saturating_sub(done)).min(payload.len());
        let chunk = payload.get_mut(..n).unwrap_or(&mut []);
        let at = addr
            .saturating_add(HEADER_LEN)
            .saturating_add(u32::try_from(done).unwrap_or(0));
        flash.read(at, chunk)?;
        crc.digest(chunk);
        done = done.saturating_add(n);
    }
    Ok((crc.get() == h.crc).then_some(h))
}

/// The logs in the region, oldest first, and the number the next log takes.
///
/// A log is found from its first block, at a sector's start, and runs while its blocks follow
/// in order and pass their CRC. Blocks of a log whose start was erased are not a log, but
/// their numbers still count for the next one, so a number is never given twice.
pub fn scan<F: Flash>(
    flash: &mut F,
    region: &LogRegion,
) -> Result<(LogList, u32), LogError<F::Error>> {
    region.check()?;
    let mut logs = LogList::new();
    let mut highest: Option<u32> = None;
    for b in 0..region.total_blocks() {
        if let Some(h) = read_header(flash, region.block_addr(0, b)).map_err(LogError::Flash)? {
            highest = Some(highest.map_or(h.log, |m| m.max(h.log)));
        }
    }
    for sector in 0..region.sectors {
        let first = region.block_addr(sector, 0);
        let Some(h) = valid_block(flash, first, None).map_err(LogError::Flash)? else {
            continue;
        };
        if h.index != 0 {
            continue;
        }
        let mut info = LogInfo {
            id: h.log,
            first_sector: sector,
            blocks: 1,
            bytes: u32::from(h.len),
        };
        while info.blocks < region.total_blocks() {
            let addr = region.block_addr(sector, info.blocks);
            match valid_block(flash, addr, Some((h.log, info.blocks))).map_err(LogError::Flash)? {
                Some(next) => {
                    info.blocks = info.blocks.saturating_add(1);
                    info.bytes = info.bytes.saturating_add(u32::from(next.len));
                }
                None => break,
            }
        }
        // At most one log per sector start and `sectors` <= MAX_LOGS: it always fits.
        if logs.push(info).is_ok() {
            settle_last(&mut logs);
        }
    }
    let next = highest.map_or(1, |h| h.wrapping_add(1).max(1));
    Ok((logs, next))
}

/// Moves the last log of `logs` down to its place by number, the others being in order: an
/// insertion sort of at most [`MAX_LOGS`] entries, where `core`'s sort brought 2.3 KB of
/// flash into the MCU image for the same order (`docs/PERFORMANCE.md`).
fn settle_last(logs: &mut LogList) {
    let mut i = logs.len().saturating_sub(1);
    while let Some(before) = i.checked_sub(1) {
        match (logs.get(before), logs.get(i)) {
            (Some(a), Some(b)) if a.id > b.id => logs.swap(before, i),
            _ => break,
        }
        i = before;
    }
}

/// Reads `buf.len()` bytes (or what is left) of `log` from byte `offset`; returns how many.
pub fn read<F: Flash>(
    flash: &mut F,
    region: &LogRegion,
    log: &LogInfo,
    offset: u32,
    buf: &mut [u8],
) -> Result<usize, LogError<F::Error>> {
    region.check()?;
    if offset > log.bytes {
        return Err(LogError::Range);
    }
    let mut done = 0usize;
    let mut at = offset;
    while done < buf.len() && at < log.bytes {
        // Every block but the last is full: the block and the place in it follow from `at`.
        let payload = PAYLOAD_LEN as u32;
        let (block, within) = (
            at.checked_div(payload).unwrap_or(0),
            at.checked_rem(payload).unwrap_or(0),
        );
        let addr = region.block_addr(log.first_sector, block);
        let h = read_header(flash, addr)
            .map_err(LogError::Flash)?
            .filter(|h| (h.log, h.index) == (log.id, block))
            .ok_or(LogError::Range)?;
        let left_in_block = u32::from(h.len).saturating_sub(within);
        let n = (buf.len().saturating_sub(done)).min(left_in_block as usize);
        if n == 0 {
            break;
        }
        let dst = buf
            .get_mut(done..done.saturating_add(n))
            .ok_or(LogError::Range)?;
        flash
            .read(addr.saturating_add(HEADER_LEN).saturating_add(within), dst)
            .map_err(LogError::Flash)?;
        done = done.saturating_add(n);
        at = at.saturating_add(n as u32);
    }
    Ok(done)
}

/// The sector a new log starts in: the one after the sector holding the newest log's last
/// block (the ring runs on from the newest log, over the oldest), the first with no log.
pub fn first_sector_after(region: &LogRegion, logs: &LogList) -> u32 {
    let bps = region.blocks_per_sector();
    match logs.iter().max_by_key(|l| l.id) {
        Some(newest) => {
            let last = newest
                .blocks
                .saturating_sub(1)
                .checked_div(bps)
                .unwrap_or(0);
            (newest.first_sector.saturating_add(last).saturating_add(1))
                .checked_rem(region.sectors)
                .unwrap_or(0)
        }
        None => 0,
    }
}

/// A log being written: bytes gather in a block's payload in RAM and go to flash a whole block
/// at a time; only the last block, written by [`LogWriter::close`], is partly filled (a reader
/// finds any byte of the log from that).
#[derive(Clone, Debug)]
pub struct LogWriter {
    region: LogRegion,
    id: u32,
    first_sector: u32,
    /// Blocks written.
    blocks: u32,
    /// Blocks erased for this log.
    room: u32,
    buf: [u8; PAYLOAD_LEN],
    len: usize,
    bytes: u32,
}

impl LogWriter {
    /// Starts log number `next` (from [`scan`]) in the sector after the newest log of `logs`,
    /// erasing up to `sectors` sectors for it: the oldest logs' sectors, since the ring
    /// runs on from the newest. `sectors` is at least one and at most the region's.
    pub fn start<F: Flash>(
        flash: &mut F,
        region: &LogRegion,
        logs: &LogList,
        next: u32,
        sectors: u32,
    ) -> Result<Self, LogError<F::Error>> {
        region.check()?;
        let first_sector = first_sector_after(region, logs);
        let n = sectors.clamp(1, region.sectors);
        for k in 0..n {
            let s = first_sector
                .saturating_add(k)
                .checked_rem(region.sectors)
                .unwrap_or(0);
            flash
                .erase_sector(region.sector_addr(s))
                .map_err(LogError::Flash)?;
        }
        Self::open_erased(region, first_sector, next, n)
    }

    /// Starts log number `next` in `sectors` sectors from `first_sector` that the caller has
    /// erased already (a board that erases while on the ground, a sector at a time, so that
    /// no erase falls in a flight: see [`first_sector_after`] for where).
    pub fn open_erased<E>(
        region: &LogRegion,
        first_sector: u32,
        next: u32,
        sectors: u32,
    ) -> Result<Self, LogError<E>> {
        region.check()?;
        if first_sector >= region.sectors {
            return Err(LogError::Region);
        }
        let n = sectors.clamp(1, region.sectors);
        Ok(Self {
            region: *region,
            id: next,
            first_sector,
            blocks: 0,
            room: n.saturating_mul(region.blocks_per_sector()),
            buf: [0xff; PAYLOAD_LEN],
            len: 0,
            bytes: 0,
        })
    }

    /// The sector the log starts in.
    pub fn first_sector(&self) -> u32 {
        self.first_sector
    }

    /// The log as a reader finds it in flash now: its programmed blocks (what waits in RAM
    /// for a whole block is not there yet).
    pub fn info(&self) -> LogInfo {
        LogInfo {
            id: self.id,
            first_sector: self.first_sector,
            blocks: self.blocks,
            bytes: self.blocks.saturating_mul(PAYLOAD_LEN as u32),
        }
    }

    /// The log's number.
    pub fn id(&self) -> u32 {
        self.id
    }

    /// Bytes taken so far (those still in RAM included).
    pub fn bytes(&self) -> u32 {
        self.bytes
    }

    /// Whether `n` more bytes fit the room erased for this log.
    pub fn has_room(&self, n: usize) -> bool {
        let used = (self.blocks as usize)
            .saturating_mul(PAYLOAD_LEN)
            .saturating_add(self.len);
        let room = (self.room as usize).saturating_mul(PAYLOAD_LEN);
        used.saturating_add(n) <= room
    }

    /// Takes `bytes` whole, programming at most one block per full payload; or refuses them
    /// whole with [`LogFull`] when the erased room cannot hold them.
    pub fn append<F: Flash>(
        &mut self,
        flash: &mut F,
        bytes: &[u8],
    ) -> Result<Result<(), LogFull>, F::Error> {
        if !self.has_room(bytes.len()) {
            return Ok(Err(LogFull));
        }
        let mut rest = bytes;
        while !rest.is_empty() {
            let free = PAYLOAD_LEN.saturating_sub(self.len);
            let (now, later) = rest.split_at(free.min(rest.len()));
            if let Some(dst) = self
                .buf
                .get_mut(self.len..self.len.saturating_add(now.len()))
            {
                // Byte by byte: a `copy_from_slice` keeps a length check that panics in the
                // image, though the lengths are equal.
                for (d, b) in dst.iter_mut().zip(now) {
                    *d = *b;
                }
            }
            self.len = self.len.saturating_add(now.len());
            rest = later;
            if self.len == PAYLOAD_LEN {
                self.program(flash)?;
            }
        }
        self.bytes = self
            .bytes
            .saturating_add(u32::try_from(bytes.len()).unwrap_or(u32::MAX));
        Ok(Ok(()))
    }

    /// Ends the log: what is gathered in RAM goes to flash as its last, partly filled block.
    /// Returns the log as a reader now finds it.
    pub fn close<F: Flash>(mut self, flash: &mut F) -> Result<LogInfo, F::Error> {
        if self.len > 0 {
            self.program(flash)?;
        }
        Ok(LogInfo {
            bytes: self.bytes,
            ..self.info()
        })
    }

    fn program<F: Flash>(&mut self, flash: &mut F) -> Result<(), F::Error> {
        let addr = self.region.block_addr(self.first_sector, self.blocks);
        let payload = self.buf.get(..self.len).unwrap_or(&[]);
        // `len` <= PAYLOAD_LEN < 2^16.
        let len = u16::try_from(self.len).unwrap_or(0);
        let mut head = [0u8; 12];
        head[0..4].copy_from_slice(&self.id.to_le_bytes());
        head[4..8].copy_from_slice(&self.blocks.to_le_bytes());
        head[8..10].copy_from_slice(&len.to_le_bytes());
        head[10..12].copy_from_slice(&[0xff, 0xff]);
        let mut crc = Crc32::ieee();
        crc.digest(&head);
        crc.digest(payload);
        flash.write(addr.saturating_add(HEADER_LEN), payload)?;
        let mut header = [0u8; HEADER_LEN as usize];
        header[0..4].copy_from_slice(&LOG_MAGIC.to_le_bytes());
        header[4..16].copy_from_slice(&head);
        header[16..20].copy_from_slice(&crc.get().to_le_bytes());
        flash.write(addr, &header)?;
        self.blocks = self.blocks.saturating_add(1);
        self.len = 0;
        self.buf = [0xff; PAYLOAD_LEN];
        Ok(())
    }
}

#[cfg(test)]
mod tests;
