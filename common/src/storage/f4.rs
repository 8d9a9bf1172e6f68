//! The STM32F4 embedded-flash controller (RM0090 section 3.5-3.9) as a [`Flash`].
//!
//! The driver talks to the controller through [`FlashRegs`], so the same code runs on the
//! MCU (volatile accesses to `FLASH` at `0x4002_3C00` and to the memory-mapped array) and on
//! the host (in its tests) against `model::F4Model`, a register-level model that enforces the
//! rules the silicon enforces (the unlock sequence, `PSIZE` against the access width,
//! alignment, programming only with `PG` set, write protection) and sets the same error flags.
//!
//! Each operation: wait for `BSY` to clear, clear stale error flags, unlock with the two
//! keys, set the operation (`SER` + `SNB` for a sector erase, `PG` for programming) with
//! `PSIZE`, start it, wait for `BSY`, read the error flags, clear the operation bits and lock
//! again. The controller is locked between operations, so a stray write cannot program the
//! array. Words are programmed with `PSIZE` x32 (the width for 2.7-3.6 V supplies); the
//! unaligned head and tail of a write with `PSIZE` x8. Every write is read back.

// Addresses and lengths come from the record layer: every operation on them is checked.
#![cfg_attr(not(test), deny(clippy::arithmetic_side_effects))]

use super::Flash;

/// Start of the flash array.
pub const FLASH_BASE: u32 = 0x0800_0000;

/// Offsets of the controller's registers from `FLASH` (`0x4002_3C00`).
pub mod reg {
    /// Key register: `KEY1` then `KEY2` unlocks `CR`.
    pub const KEYR: u32 = 0x04;
    /// Status register.
    pub const SR: u32 = 0x0C;
    /// Control register.
    pub const CR: u32 = 0x10;
}

/// First unlock key.
pub const KEY1: u32 = 0x4567_0123;
/// Second unlock key.
pub const KEY2: u32 = 0xCDEF_89AB;

/// `SR` bits.
pub mod sr {
    /// End of operation (only with `EOPIE`).
    pub const EOP: u32 = 1 << 0;
    /// Operation error.
    pub const OPERR: u32 = 1 << 1;
    /// Write-protection error.
    pub const WRPERR: u32 = 1 << 4;
    /// Programming alignment error.
    pub const PGAERR: u32 = 1 << 5;
    /// Programming parallelism error (access width against `PSIZE`).
    pub const PGPERR: u32 = 1 << 6;
    /// Programming sequence error.
    pub const PGSERR: u32 = 1 << 7;
    /// Busy.
    pub const BSY: u32 = 1 << 16;
    /// Every error flag (cleared by writing 1).
    pub const ERRORS: u32 = OPERR | WRPERR | PGAERR | PGPERR | PGSERR;
}

/// `CR` bits.
pub mod cr {
    /// Programming.
    pub const PG: u32 = 1 << 0;
    /// Sector erase.
    pub const SER: u32 = 1 << 1;
    /// Mass erase.
    pub const MER: u32 = 1 << 2;
    /// Sector number, bits 6:3.
    pub const SNB_SHIFT: u32 = 3;
    /// Sector number mask.
    pub const SNB_MASK: u32 = 0xF << SNB_SHIFT;
    /// Program size, bits 9:8.
    pub const PSIZE_SHIFT: u32 = 8;
    /// Program size mask.
    pub const PSIZE_MASK: u32 = 0b11 << PSIZE_SHIFT;
    /// x8.
    pub const PSIZE_X8: u32 = 0b00 << PSIZE_SHIFT;
    /// x32.
    pub const PSIZE_X32: u32 = 0b10 << PSIZE_SHIFT;
    /// Start (erase).
    pub const STRT: u32 = 1 << 16;
    /// Lock.
    pub const LOCK: u32 = 1 << 31;
}

/// Start and length of each sector of the 1 MiB STM32F405/407 (four of 16 KiB, one of
/// 64 KiB, seven of 128 KiB).
pub fn sector_of(addr: u32) -> Option<(u8, u32, u32)> {
    const K: u32 = 1024;
    let off = addr.checked_sub(FLASH_BASE)?;
    let (n, start, len) = match off {
        o if o < 64 * K => ((o / (16 * K)) as u8, o & !(16 * K - 1), 16 * K),
        o if o < 128 * K => (4, 64 * K, 64 * K),
        o if o < 1024 * K => (
            ((o / (128 * K)) as u8).saturating_add(4),
            o & !(128 * K - 1),
            128 * K,
        ),
        _ => return None,
    };
    Some((n, FLASH_BASE.saturating_add(start), len))
}

/// Access to the controller and the array: volatile MMIO on the MCU, a model on the host.
pub trait FlashRegs {
    /// Reads a controller register (offset from `FLASH`).
    fn read_reg(&mut self, offset: u32) -> u32;
    /// Writes a controller register.
    fn write_reg(&mut self, offset: u32, value: u32);
    /// Reads the array (memory-mapped).
    fn read_mem(&mut self, addr: u32, buf: &mut [u8]);
    /// A byte access to the array (programs it when `PG` is set with `PSIZE` x8).
    fn write_mem_u8(&mut self, addr: u32, value: u8);
    /// A word access to the array (programs it when `PG` is set with `PSIZE` x32).
    fn write_mem_u32(&mut self, addr: u32, value: u32);
    /// Called while waiting for `BSY` (the board feeds its watchdog here: a 16 KiB sector
    /// erase takes up to 0.8 s).
    fn waiting(&mut self) {}
}

/// Why a flash operation failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum F4Error {
    /// Not a sector start, or outside the array or the sectors this driver may touch.
    Address,
    /// The keys did not unlock `CR` (a wrong sequence locks it until reset).
    Locked,
    /// The controller set these `SR` error flags.
    Status(u32),
    /// `BSY` never cleared.
    Timeout,
    /// The array does not read back what was programmed (a bit already 0 stays 0).
    Verify,
}

impl core::fmt::Display for F4Error {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            F4Error::Address => f.write_str("address outside the allowed sectors"),
            F4Error::Locked => f.write_str("flash control register stayed locked"),
            F4Error::Status(sr) => write!(f, "flash controller error flags {sr:#x}"),
            F4Error::Timeout => f.write_str("flash controller stayed busy"),
            F4Error::Verify => f.write_str("flash does not read back what was programmed"),
        }
    }
}

impl core::error::Error for F4Error {}

/// Polls of `SR` before an operation is given up (a sector erase is about 2 million polls at
/// 168 MHz; this is far more).
const BUSY_POLLS: u32 = 200_000_000;

/// The STM32F4 flash controller, allowed to erase and program only `[start, end)`.
pub struct F4Flash<R> {
    regs: R,
    start: u32,
    end: u32,
    polls: u32,
}

impl<R: FlashRegs> F4Flash<R> {
    /// A driver that may touch only the sectors in `[start, end)` (the ones `memory.x`
    /// reserves): the code and vector table can never be erased by a wrong address.
    pub fn new(regs: R, start: u32, end: u32) -> Self {
        Self {
            regs,
            start,
            end,
            polls: BUSY_POLLS,
        }
    }

    /// Gives up an operation after `polls` reads of a busy `SR` (tests of a stuck controller).
    pub fn with_poll_limit(mut self, polls: u32) -> Self {
        self.polls = polls;
        self
    }

    /// The register access, back.
    pub fn regs(&mut self) -> &mut R {
        &mut self.regs
    }

    fn allowed(&self, addr: u32, len: u32) -> bool {
        addr >= self.start && addr.checked_add(len).is_some_and(|e| e <= self.end)
    }

    fn wait(&mut self) -> Result<(), F4Error> {
        for _ in 0..self.polls {
            if self.regs.read_reg(reg::SR) & sr::BSY == 0 {
                return Ok(());
            }
            self.regs.waiting();
        }
        Err(F4Error::Timeout)
    }

    /// Waits, clears old errors, unlocks and sets `CR` to `op`.
    fn begin(&mut self, op: u32) -> Result<(), F4Error> {
        self.wait()?;
        self.regs.write_reg(reg::SR, sr::ERRORS | sr::EOP);
        if self.regs.read_reg(reg::CR) & cr::LOCK != 0 {
            self.regs.write_reg(reg::KEYR, KEY1);
            self.regs.write_reg(reg::KEYR, KEY2);
            if self.regs.read_reg(reg::CR) & cr::LOCK != 0 {
                return Err(F4Error::Locked);
            }
        }
        self.regs.write_reg(reg::CR, op);
        Ok(())
    }

    /// Waits for the operation, reads its errors, clears `CR` and locks.
    fn finish(&mut self) -> Result<(), F4Error> {
        let waited = self.wait();
        let errors = self.regs.read_reg(reg::SR) & sr::ERRORS;
        self.regs.write_reg(reg::SR, errors);
        self.regs.write_reg(reg::CR, cr::LOCK);
        waited?;
        if errors != 0 {
            return Err(F4Error::Status(errors));
        }
        Ok(())
    }

    fn program(&mut self, addr: u32, data: &[u8]) -> Result<(), F4Error> {
        let mut at = addr;
        let mut rest = data;
        while let Some((&b, tail)) = rest.split_first() {
            let word = rest.get(..4).and_then(|w| <[u8; 4]>::try_from(w).ok());
            match word {
                Some(w) if at.is_multiple_of(4) => {
                    self.begin(cr::PG | cr::PSIZE_X32)?;
                    self.regs.write_mem_u32(at, u32::from_le_bytes(w));
                    self.finish()?;
                    rest = rest.get(4..).unwrap_or(&[]);
                    at = at.saturating_add(4);
                }
                _ => {
                    self.begin(cr::PG | cr::PSIZE_X8)?;
                    self.regs.write_mem_u8(at, b);
                    self.finish()?;
                    rest = tail;
                    at = at.saturating_add(1);
                }
            }
        }
        Ok(())
    }
}

impl<R: FlashRegs> Flash for F4Flash<R> {
    type Error = F4Error;

    fn erase_sector(&mut self, addr: u32) -> Result<(), F4Error> {
        let (n, start, len) = sector_of(addr).ok_or(F4Error::Address)?;
        if start != addr || !self.allowed(start, len) {
            return Err(F4Error::Address);
        }
        let snb = (u32::from(n) << cr::SNB_SHIFT) & cr::SNB_MASK;
        self.begin(cr::SER | snb | cr::PSIZE_X32)?;
        self.regs
            .write_reg(reg::CR, cr::SER | snb | cr::PSIZE_X32 | cr::STRT);
        self.finish()
    }

    fn write(&mut self, addr: u32, data: &[u8]) -> Result<(), F4Error> {
        let len = u32::try_from(data.len()).map_err(|_| F4Error::Address)?;
        if !self.allowed(addr, len) {
            return Err(F4Error::Address);
        }
        self.program(addr, data)?;
        // Read back in small pieces: programming can only clear bits, so a location that was
        // not erased holds something else.
        let mut chunk = [0u8; 32];
        for (i, want) in data.chunks(chunk.len()).enumerate() {
            let got = chunk.get_mut(..want.len()).ok_or(F4Error::Verify)?;
            let off = (i as u32).saturating_mul(32);
            self.regs.read_mem(addr.saturating_add(off), got);
            if got != want {
                return Err(F4Error::Verify);
            }
        }
        Ok(())
    }

    fn read(&mut self, addr: u32, buf: &mut [u8]) -> Result<(), F4Error> {
        let len = u32::try_from(buf.len()).map_err(|_| F4Error::Address)?;
        if !self.allowed(addr, len) {
            return Err(F4Error::Address);
        }
        self.regs.read_mem(addr, buf);
        Ok(())
    }
}

#[cfg(test)]
pub mod model;

#[cfg(test)]
mod tests;
