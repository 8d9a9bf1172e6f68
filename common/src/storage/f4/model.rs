//! A register-level model of the STM32F4 flash controller (RM0090 section 3), for testing
//! the driver on the host. It models the four 16 KiB sectors 0..3 and enforces what the
//! silicon enforces: `CR` is locked until `KEY1` then `KEY2` are written to `KEYR` (any
//! other value locks it until reset); the array is programmed only with `PG` set, by an
//! access as wide as `PSIZE` (`PGPERR` otherwise), aligned to it (`PGAERR`); an access with
//! `PG` clear is a sequence error (`PGSERR`); write-protected sectors set `WRPERR`; an erase
//! sets every byte to 0xFF; programming can only clear bits; `BSY` stays set for a few
//! polls of `SR` after each operation.

use super::{cr, reg, sr, FlashRegs, FLASH_BASE, KEY1, KEY2};

/// Bytes modelled: sectors 0..3.
pub const MODEL_BYTES: usize = 64 * 1024;
const SECTOR: usize = 16 * 1024;

/// The controller and sectors 0..3 of the array.
pub struct F4Model {
    /// The array.
    pub mem: [u8; MODEL_BYTES],
    cr: u32,
    sr: u32,
    locked: bool,
    key_stage: u8,
    /// A wrong key was written: locked until reset.
    pub key_fault: bool,
    busy: u32,
    /// Polls of `SR` that read `BSY` after each operation.
    pub busy_polls: u32,
    /// Write-protected sectors, one bit each.
    pub write_protected: u16,
    /// Sector erases done.
    pub erases: u32,
    /// Array accesses that programmed it.
    pub programs: u32,
    /// Array accesses refused with an error flag.
    pub refused: u32,
}

impl Default for F4Model {
    fn default() -> Self {
        Self::new()
    }
}

impl F4Model {
    /// An erased array, controller locked (as after reset).
    pub fn new() -> Self {
        Self {
            mem: [0xff; MODEL_BYTES],
            cr: 0,
            sr: 0,
            locked: true,
            key_stage: 0,
            key_fault: false,
            busy: 0,
            busy_polls: 3,
            write_protected: 0,
            erases: 0,
            programs: 0,
            refused: 0,
        }
    }

    /// Whether `CR` is locked.
    pub fn locked(&self) -> bool {
        self.locked
    }

    /// `SR` without `BSY`.
    pub fn status(&self) -> u32 {
        self.sr
    }

    fn index(addr: u32) -> Option<usize> {
        let i = addr.checked_sub(FLASH_BASE)? as usize;
        (i < MODEL_BYTES).then_some(i)
    }

    fn protected(&self, i: usize) -> bool {
        self.write_protected & (1 << (i / SECTOR)) != 0
    }

    fn program(&mut self, addr: u32, bytes: &[u8], psize: u32) {
        let width = bytes.len() as u32;
        let error = if self.locked || self.cr & cr::PG == 0 || self.cr & (cr::SER | cr::MER) != 0 {
            sr::PGSERR
        } else if self.cr & cr::PSIZE_MASK != psize {
            sr::PGPERR
        } else if !addr.is_multiple_of(width) {
            sr::PGAERR
        } else {
            match Self::index(addr) {
                Some(i) if self.protected(i) => sr::WRPERR,
                Some(i) => {
                    for (k, b) in bytes.iter().enumerate() {
                        self.mem[i + k] &= *b;
                    }
                    self.programs += 1;
                    self.busy = self.busy_polls;
                    0
                }
                None => sr::PGAERR,
            }
        };
        if error != 0 {
            self.sr |= error;
            self.refused += 1;
        }
    }
}

impl FlashRegs for F4Model {
    fn read_reg(&mut self, offset: u32) -> u32 {
        match offset {
            reg::SR if self.busy > 0 => {
                self.busy -= 1;
                self.sr | sr::BSY
            }
            reg::SR => self.sr,
            reg::CR => self.cr | if self.locked { cr::LOCK } else { 0 },
            _ => 0,
        }
    }

    fn write_reg(&mut self, offset: u32, value: u32) {
        match offset {
            reg::KEYR if self.locked && !self.key_fault => match (self.key_stage, value) {
                (0, KEY1) => self.key_stage = 1,
                (1, KEY2) => {
                    self.locked = false;
                    self.key_stage = 0;
                }
                _ => self.key_fault = true,
            },
            reg::SR => self.sr &= !(value & (sr::ERRORS | sr::EOP)),
            reg::CR if !self.locked => {
                self.cr = value & !(cr::STRT | cr::LOCK);
                if value & cr::LOCK != 0 {
                    self.locked = true;
                }
                if value & cr::STRT != 0 && value & cr::SER != 0 {
                    let n = ((value & cr::SNB_MASK) >> cr::SNB_SHIFT) as usize;
                    if value & cr::PG != 0 || n * SECTOR >= MODEL_BYTES {
                        self.sr |= sr::PGSERR;
                    } else if self.write_protected & (1 << n) != 0 {
                        self.sr |= sr::WRPERR;
                    } else {
                        self.mem[n * SECTOR..(n + 1) * SECTOR].fill(0xff);
                        self.erases += 1;
                        self.busy = self.busy_polls;
                    }
                }
            }
            _ => {}
        }
    }

    fn read_mem(&mut self, addr: u32, buf: &mut [u8]) {
        for (k, b) in buf.iter_mut().enumerate() {
            *b = Self::index(addr + k as u32).map_or(0, |i| self.mem[i]);
        }
    }

    fn write_mem_u8(&mut self, addr: u32, value: u8) {
        self.program(addr, &[value], cr::PSIZE_X8);
    }

    fn write_mem_u32(&mut self, addr: u32, value: u32) {
        self.program(addr, &value.to_le_bytes(), cr::PSIZE_X32);
    }
}
