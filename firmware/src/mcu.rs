//! The STM32F405 board layer.
//!
//! Clock set-up is skipped: QEMU's netduinoplus2 does not emulate RCC, and polling a ready bit
//! there hangs (on a real board the reset clock, 16 MHz HSI, runs this loop as well). USART1
//! carries the simulator link and USART2 the ground link; both are busy-polled, which also
//! keeps QEMU's instruction-counting mode exact.

use cortex_m_rt::entry;
use defmt_semihosting as _;
use firmware::app::App;
use panic_probe as _;

/// One STM32F4 USART's registers.
struct Usart {
    base: usize,
}

const SR: usize = 0x00;
const DR: usize = 0x04;
const CR1: usize = 0x0C;
const SR_RXNE: u32 = 1 << 5;
const SR_TXE: u32 = 1 << 7;
const CR1_UE_TE_RE: u32 = (1 << 13) | (1 << 3) | (1 << 2);

impl Usart {
    const USART1: Usart = Usart { base: 0x4001_1000 };
    const USART2: Usart = Usart { base: 0x4000_4400 };

    fn reg(&self, offset: usize) -> *mut u32 {
        (self.base + offset) as *mut u32
    }

    fn enable(&self) {
        // SAFETY: a fixed, aligned MMIO register of the STM32F405; single-threaded.
        unsafe { core::ptr::write_volatile(self.reg(CR1), CR1_UE_TE_RE) };
    }

    fn try_read(&self) -> Option<u8> {
        // SAFETY: as above; reading DR clears RXNE, which is the intent.
        unsafe {
            if core::ptr::read_volatile(self.reg(SR)) & SR_RXNE != 0 {
                Some(core::ptr::read_volatile(self.reg(DR)) as u8)
            } else {
                None
            }
        }
    }

    /// Reads what has arrived, up to `buf.len()` bytes.
    fn read_into(&self, buf: &mut [u8]) -> usize {
        let mut n = 0;
        while n < buf.len() {
            match self.try_read() {
                Some(b) => {
                    buf[n] = b;
                    n += 1;
                }
                None => break,
            }
        }
        n
    }

    fn write(&self, bytes: &[u8]) {
        for &b in bytes {
            // SAFETY: as above.
            unsafe {
                while core::ptr::read_volatile(self.reg(SR)) & SR_TXE == 0 {}
                core::ptr::write_volatile(self.reg(DR), u32::from(b));
            }
        }
    }
}

#[entry]
fn main() -> ! {
    let sim = Usart::USART1;
    let gcs = Usart::USART2;
    sim.enable();
    gcs.enable();
    defmt::info!("autopilot booted: STM32F405, USART1 sim link, USART2 ground link");
    let mut app = App::new();
    sim.write(&firmware::app::heartbeat_frame(&mut app));
    let mut chunk = [0u8; 64];
    loop {
        // Gather what has arrived on each UART, then hand it over in one piece.
        let n = sim.read_into(&mut chunk);
        if let Some(bytes) = chunk.get(..n).filter(|b| !b.is_empty()) {
            app.on_sim_bytes(bytes, &mut |out| sim.write(out));
        }
        let n = gcs.read_into(&mut chunk);
        if let Some(bytes) = chunk.get(..n).filter(|b| !b.is_empty()) {
            app.on_gcs_bytes(bytes);
        }
        // Telemetry and answers for the ground, produced by both calls above.
        app.drain_gcs(&mut |out| gcs.write(out));
    }
}
