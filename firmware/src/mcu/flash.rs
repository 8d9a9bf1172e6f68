//! The board's persistent storage: sectors 1 and 2 of the STM32F405's flash (reserved in
//! `memory.x`) for the board record, sectors 6 to 11 for the flight logs, through the flash
//! controller; or, in QEMU, which does not emulate the flash controller, a host file of the
//! same sectors over semihosting (the record's two first, the logs' six after them).
//!
//! The file is chosen by a semihosting argument `storage=PATH`
//! (`-semihosting-config enable=on,target=native,arg=firmware,arg=storage=PATH`, as
//! `sim-host --link qemu` passes it). It behaves like NOR flash: an erase sets a sector to
//! 0xFF, a write can only clear bits, so the record layer's power-cut reasoning holds.

use common::storage::f4::{F4Error, F4Flash, FlashRegs};
use common::storage::flight_log::LogRegion;
use common::storage::{AbRegion, Flash, BOARD_MAGIC};
use cortex_m_semihosting::{nr, syscall};

/// First byte of the reserved sectors.
pub const START: u32 = 0x0800_4000;
/// End of the reserved sectors.
pub const END: u32 = 0x0800_C000;
const SECTOR: u32 = 16 * 1024;

/// First byte of the flight logs' sectors (6 to 11, 128 KiB each).
pub const LOG_START: u32 = 0x0804_0000;
/// End of the flight logs' sectors (the end of the flash).
pub const LOG_END: u32 = 0x0810_0000;
const LOG_SECTOR: u32 = 128 * 1024;

/// The flight logs' region: six sectors of 128 KiB (768 KiB).
pub const LOG_REGION: LogRegion = LogRegion {
    start: LOG_START,
    sector_len: LOG_SECTOR,
    sectors: (LOG_END - LOG_START) / LOG_SECTOR,
};

/// A window of the flash kept in the host file: its addresses, where they sit in the file,
/// and its sectors' size.
#[derive(Clone, Copy)]
struct Window {
    start: u32,
    end: u32,
    file_offset: u32,
    sector: u32,
}

const RECORD_WINDOW: Window = Window {
    start: START,
    end: END,
    file_offset: 0,
    sector: SECTOR,
};
const LOG_WINDOW: Window = Window {
    start: LOG_START,
    end: LOG_END,
    file_offset: END - START,
    sector: LOG_SECTOR,
};

/// The board record in sectors 1 and 2.
pub const REGION: AbRegion = AbRegion {
    magic: BOARD_MAGIC,
    slot_a: START,
    slot_b: START + SECTOR,
    slot_len: SECTOR,
};

/// The flash controller's registers (`FLASH` at `0x4002_3C00`) and the mapped array.
pub struct Mmio;

const FLASH_REGS: usize = 0x4002_3C00;

impl FlashRegs for Mmio {
    fn read_reg(&mut self, offset: u32) -> u32 {
        // SAFETY: a register of the STM32F405's flash interface; single-threaded.
        unsafe { core::ptr::read_volatile((FLASH_REGS + offset as usize) as *const u32) }
    }
    fn write_reg(&mut self, offset: u32, value: u32) {
        // SAFETY: as above.
        unsafe { core::ptr::write_volatile((FLASH_REGS + offset as usize) as *mut u32, value) }
    }
    fn read_mem(&mut self, addr: u32, buf: &mut [u8]) {
        for (k, b) in buf.iter_mut().enumerate() {
            // SAFETY: the driver checked the address lies in the reserved sectors.
            *b = unsafe { core::ptr::read_volatile((addr as usize + k) as *const u8) };
        }
    }
    fn write_mem_u8(&mut self, addr: u32, value: u8) {
        // SAFETY: as above; with PG set this access programs the byte.
        unsafe { core::ptr::write_volatile(addr as usize as *mut u8, value) }
    }
    fn write_mem_u32(&mut self, addr: u32, value: u32) {
        // SAFETY: as above, word-aligned (the driver's rule).
        unsafe { core::ptr::write_volatile(addr as usize as *mut u32, value) }
    }
    fn waiting(&mut self) {
        super::watchdog::feed();
    }
}

/// The reserved sectors in a host file (QEMU), one window of them per handle.
pub struct HostFile {
    handle: usize,
    window: Window,
}

/// Why the host file failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum HostError {
    /// Outside the reserved sectors.
    Address,
    /// A semihosting call failed.
    Io,
}

impl core::fmt::Display for HostError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            HostError::Address => "address outside the reserved sectors",
            HostError::Io => "semihosting call failed",
        })
    }
}

impl core::error::Error for HostError {}

impl HostFile {
    /// The file named by the `storage=PATH` semihosting argument, its record sectors
    /// created erased when missing; `None` without the argument or when it cannot be opened.
    pub fn open() -> Option<Self> {
        Self::open_window(RECORD_WINDOW)
    }

    /// The same file's flight-log sectors, created erased when the file does not reach them
    /// yet.
    pub fn open_logs() -> Option<Self> {
        let mut f = Self::open_window(LOG_WINDOW)?;
        // SAFETY: a handle this file opened; returns the file's length or -1.
        let len = unsafe { syscall!(FLEN, f.handle) };
        let needed = (LOG_WINDOW.file_offset + (LOG_END - LOG_START)) as usize;
        if len == usize::MAX || len < needed {
            let mut at = LOG_START;
            while at < LOG_END {
                f.erase(at).ok()?;
                at += LOG_SECTOR;
            }
        }
        Some(f)
    }

    fn open_window(window: Window) -> Option<Self> {
        let mut cmdline = [0u8; 256];
        let mut block = [cmdline.as_mut_ptr() as usize, cmdline.len()];
        // SAFETY: SYS_GET_CMDLINE writes at most block[1] bytes into the buffer.
        if unsafe { cortex_m_semihosting::syscall1!(GET_CMDLINE, block.as_mut_ptr()) } != 0 {
            return None;
        }
        let line = cmdline.get(..block.get(1).copied()?.min(cmdline.len()))?;
        let path = line
            .split(|&b| b == b' ')
            .find_map(|arg| arg.strip_prefix(b"storage="))?;
        let mut name = [0u8; 240];
        name.get_mut(..path.len())?.copy_from_slice(path);
        let open = |mode: usize| {
            // SAFETY: a NUL-terminated name and its length.
            let h = unsafe { syscall!(OPEN, name.as_ptr(), mode, path.len()) };
            (h != usize::MAX).then_some(Self { handle: h, window })
        };
        if let Some(f) = open(nr::open::RW_BINARY) {
            return Some(f);
        }
        let mut f = open(nr::open::RW_TRUNC_BINARY)?;
        let mut record = Self {
            handle: f.handle,
            window: RECORD_WINDOW,
        };
        record.erase(START).ok()?;
        record.erase(START + SECTOR).ok()?;
        f.window = window;
        Some(f)
    }

    fn seek(&mut self, addr: u32, len: usize) -> Result<(), HostError> {
        let w = self.window;
        let end = addr.checked_add(len as u32).ok_or(HostError::Address)?;
        if addr < w.start || end > w.end {
            return Err(HostError::Address);
        }
        // SAFETY: a handle this file opened.
        match unsafe { syscall!(SEEK, self.handle, w.file_offset + (addr - w.start)) } {
            0 => Ok(()),
            _ => Err(HostError::Io),
        }
    }

    fn put(&mut self, addr: u32, data: &[u8]) -> Result<(), HostError> {
        self.seek(addr, data.len())?;
        // SAFETY: the buffer and its length; the call returns the bytes not written.
        match unsafe { syscall!(WRITE, self.handle, data.as_ptr(), data.len()) } {
            0 => Ok(()),
            _ => Err(HostError::Io),
        }
    }

    fn get(&mut self, addr: u32, buf: &mut [u8]) -> Result<(), HostError> {
        self.seek(addr, buf.len())?;
        // SAFETY: as above; returns the bytes not read.
        match unsafe { syscall!(READ, self.handle, buf.as_mut_ptr(), buf.len()) } {
            0 => Ok(()),
            _ => Err(HostError::Io),
        }
    }

    fn erase(&mut self, addr: u32) -> Result<(), HostError> {
        let w = self.window;
        if !(addr - w.start.min(addr)).is_multiple_of(w.sector) {
            return Err(HostError::Address);
        }
        let ones = [0xffu8; 256];
        for k in 0..w.sector / 256 {
            self.put(addr + k * 256, &ones)?;
        }
        Ok(())
    }
}

impl Flash for HostFile {
    type Error = HostError;
    fn erase_sector(&mut self, addr: u32) -> Result<(), HostError> {
        self.erase(addr)
    }
    fn write(&mut self, addr: u32, data: &[u8]) -> Result<(), HostError> {
        // NOR: programming only clears bits.
        let mut chunk = [0u8; 64];
        for (i, piece) in data.chunks(chunk.len()).enumerate() {
            let at = addr + (i * 64) as u32;
            let old = chunk.get_mut(..piece.len()).ok_or(HostError::Address)?;
            self.get(at, old)?;
            for (o, d) in old.iter_mut().zip(piece) {
                *o &= *d;
            }
            self.put(at, old)?;
        }
        Ok(())
    }
    fn read(&mut self, addr: u32, buf: &mut [u8]) -> Result<(), HostError> {
        self.get(addr, buf)
    }
}

/// The board's flash: a host file under QEMU, the controller on a board.
pub enum BoardFlash {
    /// QEMU: the host file.
    Host(HostFile),
    /// The STM32F405's flash controller.
    Chip(F4Flash<Mmio>),
}

/// Error of [`BoardFlash`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum BoardFlashError {
    /// The host file.
    Host(HostError),
    /// The controller.
    Chip(F4Error),
}

impl core::fmt::Display for BoardFlashError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            BoardFlashError::Host(e) => write!(f, "host file: {e}"),
            BoardFlashError::Chip(e) => write!(f, "flash controller: {e}"),
        }
    }
}

impl core::error::Error for BoardFlashError {
    fn source(&self) -> Option<&(dyn core::error::Error + 'static)> {
        match self {
            BoardFlashError::Host(e) => Some(e),
            BoardFlashError::Chip(e) => Some(e),
        }
    }
}

impl BoardFlash {
    /// The host file when QEMU names one, else the controller on sectors 1 and 2.
    pub fn open() -> Self {
        match HostFile::open() {
            Some(f) => BoardFlash::Host(f),
            None => BoardFlash::Chip(F4Flash::new(Mmio, START, END)),
        }
    }

    /// The flight logs' sectors: the host file's under QEMU, the controller's on a board.
    pub fn open_logs() -> Self {
        match HostFile::open_logs() {
            Some(f) => BoardFlash::Host(f),
            None => BoardFlash::Chip(F4Flash::new(Mmio, LOG_START, LOG_END)),
        }
    }

    /// Where the record lives, for the boot log.
    pub fn is_host_file(&self) -> bool {
        matches!(self, BoardFlash::Host(_))
    }
}

impl Flash for BoardFlash {
    type Error = BoardFlashError;
    fn erase_sector(&mut self, addr: u32) -> Result<(), BoardFlashError> {
        match self {
            BoardFlash::Host(f) => f.erase_sector(addr).map_err(BoardFlashError::Host),
            BoardFlash::Chip(f) => f.erase_sector(addr).map_err(BoardFlashError::Chip),
        }
    }
    fn write(&mut self, addr: u32, data: &[u8]) -> Result<(), BoardFlashError> {
        match self {
            BoardFlash::Host(f) => f.write(addr, data).map_err(BoardFlashError::Host),
            BoardFlash::Chip(f) => f.write(addr, data).map_err(BoardFlashError::Chip),
        }
    }
    fn read(&mut self, addr: u32, buf: &mut [u8]) -> Result<(), BoardFlashError> {
        match self {
            BoardFlash::Host(f) => f.read(addr, buf).map_err(BoardFlashError::Host),
            BoardFlash::Chip(f) => f.read(addr, buf).map_err(BoardFlashError::Chip),
        }
    }
}
