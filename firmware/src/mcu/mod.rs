//! The STM32F405 board layer.
//!
//! Clock set-up is skipped: QEMU's netduinoplus2 does not emulate RCC, and polling a ready bit
//! there hangs (on a real board the reset clock, 16 MHz HSI, runs this loop as well). USART1
//! carries the simulator link and USART2 the ground link; their interrupts fill and drain ring
//! buffers ([`usart`]) while the main loop keeps polling those rings (no WFI: under `-icount`
//! it stalls QEMU 7.2 when UART interrupts are on).

use cortex_m_rt::{entry, exception};
use defmt_semihosting as _;
use firmware::app::App;

mod budget;
mod fault;
mod flash;
mod usart;
mod watchdog;
use firmware::app::persist::Persistence;
use usart::{Id, Usart};

/// Every interrupt without a handler of its own comes here (cortex-m-rt's vector table): the
/// USARTs' are served, anything else spins as cortex-m-rt's default does, until the watchdog
/// resets the board.
#[exception]
unsafe fn DefaultHandler(irqn: i16) {
    match Id::of_irq(irqn) {
        Some(id) => usart::on_interrupt(id),
        None => loop {
            cortex_m::asm::nop();
        },
    }
}

#[entry]
fn main() -> ! {
    let (Some(mut sim), Some(mut gcs)) = (Usart::open(Id::Usart1), Usart::open(Id::Usart2)) else {
        loop {
            cortex_m::asm::nop();
        }
    };
    defmt::info!("autopilot booted: STM32F405, USART1 sim link, USART2 ground link");
    let (warn, boot_text) = firmware::app::reset::boot_text(fault::reset_flags(), fault::take());
    defmt::info!("{=str}", boot_text.as_str());
    let mut boot_text = Some(boot_text);
    budget::start();
    let mut budget = budget::Budget::new();
    // The application lives in `main`'s frame (`main` never returns), built where it is
    // bound: `App::fresh` writes it there with no copy, and the parameters are applied in
    // place. Its bytes are part of the measured stack peak.
    let mut app = App::fresh();
    let app = &mut app;
    app.apply_params();
    let board_flash = flash::BoardFlash::open();
    let host_file = board_flash.is_host_file();
    let mut store = Persistence::new(board_flash, flash::REGION);
    let loaded = store.load_into(app);
    defmt::info!(
        "storage ({}): parameters {}, {} mission items, unreadable {}",
        if host_file {
            "host file"
        } else {
            "flash sectors 1-2"
        },
        loaded.params.map_or(0, |r| r.loaded),
        loaded.mission_items,
        loaded.unreadable
    );
    watchdog::start();
    sim.write(&firmware::app::heartbeat_frame(app));
    let (mut sim_chunk, mut gcs_chunk) = ([0u8; 128], [0u8; 64]);
    loop {
        // Fed on every pass, idle ones included: a pass that never returns starves it.
        watchdog::feed();
        // Gather what has arrived on each UART, then hand it over in one piece; bytes are
        // left in the ring until they can complete what the link's parser waits for (a frame's
        // header, then the frame), so a frame costs one or two passes and not one per byte
        // (bytes arrive one at a time on a UART). Neither ring fills meanwhile: a parser
        // never waits for more than a frame (280 bytes), and a ring holds 512.
        let n = if sim.received() >= app.sim_bytes_wanted() {
            sim.read_into(&mut sim_chunk)
        } else {
            0
        };
        let sim_bytes = sim_chunk.get(..n).filter(|b| !b.is_empty());
        let n = if gcs.received() >= app.gcs_bytes_wanted() {
            gcs.read_into(&mut gcs_chunk)
        } else {
            0
        };
        let gcs_bytes = gcs_chunk.get(..n).filter(|b| !b.is_empty());
        let idle = sim_bytes.is_none() && gcs_bytes.is_none();
        let t0 = budget::budget_work_start();
        if let Some(bytes) = sim_bytes {
            app.on_sim_bytes(bytes, &mut |out| sim.write(out));
        }
        if let Some(bytes) = gcs_bytes {
            app.on_gcs_bytes(bytes);
        }
        // Why the board reset, once a ground station is listening.
        if app.ground_link().gcs_last_seen_us().is_some() {
            if let Some(text) = boot_text.take() {
                app.announce(warn, &text);
            }
        }
        let done = store.service(app);
        // Telemetry and answers for the ground, produced by the calls above.
        app.drain_gcs(&mut |out| gcs.write(out));
        // Only the passes that had work are the control period's cost.
        if !idle {
            budget.charge(budget::budget_work_end(t0), app.vehicle().time_us());
        }
        if done.reboot {
            defmt::info!("rebooting on the ground station's request");
            fault::record(firmware::app::reset::Fault::Requested);
            gcs.flush();
            sim.flush();
            cortex_m::peripheral::SCB::sys_reset();
        }
        // Outside the measured work: the report scans the stack (sent with the next frames).
        budget.report(app);
    }
}
