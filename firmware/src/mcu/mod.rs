//! The STM32F405 board layer.
//!
//! Clock set-up is skipped: QEMU's netduinoplus2 does not emulate RCC, and polling a ready bit
//! there hangs (on a real board the reset clock, 16 MHz HSI, runs this loop as well). USART1
//! carries the simulator link and USART2 the ground link; both are busy-polled, which also
//! keeps QEMU's instruction-counting mode exact.

use core::mem::MaybeUninit;
use cortex_m_rt::entry;
use defmt_semihosting as _;
use firmware::app::App;
use panic_probe as _;

mod budget;
mod usart;
use usart::Usart;

#[entry]
fn main() -> ! {
    let sim = Usart::USART1;
    let gcs = Usart::USART2;
    sim.enable();
    gcs.enable();
    defmt::info!("autopilot booted: STM32F405, USART1 sim link, USART2 ground link");
    budget::start();
    let mut budget = budget::Budget::new();
    // The application lives in a static, built in place (no stack frame holds it).
    static mut APP: MaybeUninit<App> = MaybeUninit::uninit();
    // SAFETY: `main` runs once and is the only code that names APP.
    let app = App::init_in(unsafe { &mut *core::ptr::addr_of_mut!(APP) });
    sim.write(&firmware::app::heartbeat_frame(app));
    let (mut sim_chunk, mut gcs_chunk) = ([0u8; 64], [0u8; 64]);
    loop {
        // Gather what has arrived on each UART, then hand it over in one piece.
        let n = sim.read_into(&mut sim_chunk);
        let sim_bytes = sim_chunk.get(..n).filter(|b| !b.is_empty());
        let n = gcs.read_into(&mut gcs_chunk);
        let gcs_bytes = gcs_chunk.get(..n).filter(|b| !b.is_empty());
        if sim_bytes.is_none() && gcs_bytes.is_none() {
            continue;
        }
        let t0 = budget::now();
        if let Some(bytes) = sim_bytes {
            app.on_sim_bytes(bytes, &mut |out| sim.write(out));
        }
        if let Some(bytes) = gcs_bytes {
            app.on_gcs_bytes(bytes);
        }
        // Telemetry and answers for the ground, produced by both calls above.
        app.drain_gcs(&mut |out| gcs.write(out));
        budget.charge(budget::since(t0), app.vehicle().time_us());
        // Outside the measured work: the report scans the stack (sent with the next frames).
        budget.report(app);
    }
}
