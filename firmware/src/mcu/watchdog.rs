//! The independent watchdog (IWDG): clocked by the 32 kHz LSI, it resets the chip unless the
//! main loop reloads it within [`TIMEOUT_MS`]. Once started it cannot be stopped.
//!
//! QEMU's netduinoplus2 does not emulate the IWDG (its registers read 0 and ignore writes),
//! so under QEMU this starts nothing and the reset it would cause is not shown; docs/PIL.md
//! says how the rest of the fault path is tested.

const IWDG: usize = 0x4000_3000;
const KR: usize = 0x00;
const PR: usize = 0x04;
const RLR: usize = 0x08;
/// LSI / 64: 2 ms per count (LSI 32 kHz nominal, 17 to 47 kHz over temperature).
const PRESCALER_64: u32 = 4;
/// Reset after this long without a feed (nominal LSI). Longer than a 16 KiB sector erase
/// (0.8 s at most), which also feeds it while it waits.
pub const TIMEOUT_MS: u32 = 1000;

fn write(offset: usize, value: u32) {
    // SAFETY: a register of the STM32F405's IWDG; single-threaded.
    unsafe { core::ptr::write_volatile((IWDG + offset) as *mut u32, value) }
}

/// Starts the watchdog.
pub fn start() {
    write(KR, 0xCCCC);
    write(KR, 0x5555);
    write(PR, PRESCALER_64);
    write(RLR, TIMEOUT_MS / 2);
    write(KR, 0xAAAA);
}

/// Reloads the counter.
pub fn feed() {
    write(KR, 0xAAAA);
}
