//! Faults end in a reset that the next boot reports: the panic handler and the HardFault
//! handler log over defmt, leave a [`Fault`] record in two words of `.uninit` RAM (start-up
//! neither zeroes nor copies it, and a system reset keeps SRAM), and reset the chip.

use core::mem::MaybeUninit;
use cortex_m::peripheral::SCB;
use cortex_m_rt::{exception, ExceptionFrame};
use firmware::app::reset::Fault;

#[link_section = ".uninit.FAULT"]
static mut RECORD: MaybeUninit<[u32; 2]> = MaybeUninit::uninit();

const RCC_CSR: usize = 0x4002_3874;

/// Leaves `fault` for the next boot.
pub fn record(fault: Fault) {
    // SAFETY: two words of RAM of our own; written and read only with interrupts off or
    // before the loop starts.
    unsafe { core::ptr::write_volatile(core::ptr::addr_of_mut!(RECORD).cast(), fault.encode()) }
}

/// The record the last run left, if any, and clears it.
pub fn take() -> Option<Fault> {
    // SAFETY: as above; after a power-on the words hold whatever SRAM wakes with, which
    // `Fault::decode` refuses unless it is a tag.
    let words: [u32; 2] =
        unsafe { core::ptr::read_volatile(core::ptr::addr_of!(RECORD).cast::<[u32; 2]>()) };
    record_clear();
    Fault::decode(words)
}

fn record_clear() {
    // SAFETY: as above.
    unsafe { core::ptr::write_volatile(core::ptr::addr_of_mut!(RECORD).cast(), [0u32; 2]) }
}

/// `RCC_CSR`'s reset flags, then cleared for the next reset (`RMVF`).
pub fn reset_flags() -> u32 {
    // SAFETY: RCC_CSR of the STM32F405; single-threaded at boot.
    unsafe {
        let flags = core::ptr::read_volatile(RCC_CSR as *const u32);
        core::ptr::write_volatile(RCC_CSR as *mut u32, flags | firmware::app::reset::csr::RMVF);
        flags
    }
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    cortex_m::interrupt::disable();
    let (file, line) = info.location().map_or(("?", 0), |l| (l.file(), l.line()));
    defmt::error!("panic at {=str}:{=u32}; resetting", file, line);
    record(Fault::Panic { line });
    SCB::sys_reset()
}

#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    let pc = frame.pc();
    defmt::error!("HardFault at pc {=u32:#010x}; resetting", pc);
    record(Fault::HardFault { pc });
    SCB::sys_reset()
}
