//! The STM32F405 board layer.
//!
//! Clock set-up is skipped: QEMU's netduinoplus2 does not emulate RCC, and polling a ready bit
//! there hangs. USART1 (sim link) and USART2 (ground link) are enabled with UE|TE|RE.

use cortex_m_rt::entry;
use defmt_semihosting as _;
use panic_probe as _;

const USART1_BASE: usize = 0x4001_1000;
const USART2_BASE: usize = 0x4000_4400;
const CR1_OFFSET: usize = 0x0C;
const CR1_UE_TE_RE: u32 = (1 << 13) | (1 << 3) | (1 << 2);

fn enable_usart(base: usize) {
    let cr1 = (base + CR1_OFFSET) as *mut u32;
    // SAFETY: fixed, aligned MMIO register of the STM32F405 USART; single-threaded start-up.
    unsafe { core::ptr::write_volatile(cr1, CR1_UE_TE_RE) };
}

#[entry]
fn main() -> ! {
    enable_usart(USART1_BASE);
    enable_usart(USART2_BASE);
    defmt::info!("autopilot booted: STM32F405, USART1 sim link, USART2 ground link");
    loop {
        cortex_m::asm::nop();
    }
}
