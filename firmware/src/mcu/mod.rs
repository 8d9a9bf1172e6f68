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
use common::gcs::logs::NoLogs;
use firmware::app::flash_logs::FlashLogs;
use firmware::app::persist::Persistence;

/// Sectors of 128 KiB a flight log may fill (of six): a log of 384 KiB, and the newest log
/// before it kept beside it.
const LOG_SECTORS_PER_LOG: u32 = 3;
/// No topic of the flash log faster than this, Hz: 2.6 KB a second, 384 KiB in 2.5 minutes
/// (docs/LOGGING.md).
const LOG_RATE_CAP_HZ: u16 = 4;
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

/// Interrupts of the STM32F405 (RM0090's vector table: 82, WWDG at 0 to FPU at 81).
const IRQS: usize = 82;

/// The interrupts' part of the vector table, each to `DefaultHandler`, which serves the USARTs
/// by the interrupt's number. As many as the chip has: without a device crate cortex-m-rt
/// fills the 240 an ARMv7-M core may have, 632 bytes of flash for interrupts that do not exist
/// (its `device` feature leaves the table to the image; `build.rs` writes the `device.x` it
/// includes).
#[link_section = ".vector_table.interrupts"]
#[no_mangle]
static __INTERRUPTS: [unsafe extern "C" fn(); IRQS] = {
    extern "C" {
        fn DefaultHandler();
    }
    [DefaultHandler; IRQS]
};

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
    // The flight logs: sectors 6 to 11 (or the host file's), scanned once here, before the
    // watchdog runs (a scan reads the whole region). On a board with no room for logs the
    // vehicle flies without them.
    let mut logs = FlashLogs::open(
        flash::BoardFlash::open_logs(),
        flash::LOG_REGION,
        LOG_SECTORS_PER_LOG,
        app,
    )
    .ok();
    app.flight_log_mut().set_rate_cap(LOG_RATE_CAP_HZ);
    defmt::info!(
        "flight logs: {} kept",
        logs.as_ref().map_or(0, |l| l.logs().len())
    );
    watchdog::start();
    sim.write(&firmware::app::heartbeat_frame(app));
    let (mut sim_held, mut gcs_held) = (Held::new(), Held::new());
    loop {
        // Fed on every pass, idle ones included: a pass that never returns starves it.
        watchdog::feed();
        // Gather what has arrived on each UART, then hand it over in one piece once there is
        // as much as the link's parser waits for (a frame's first three bytes, then the rest
        // of the frame): a frame costs one or two passes, not one per byte (bytes arrive one
        // at a time on a UART). The rings are emptied on every pass as before; what waits is
        // held here, never more than a frame.
        sim_held.take_from(&mut sim);
        let sim_bytes = sim_held.ready(app.sim_bytes_wanted());
        gcs_held.take_from(&mut gcs);
        let gcs_bytes = gcs_held.ready(app.gcs_bytes_wanted());
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
        // The log's ring into flash, a sector of the next log's room erased on the ground,
        // and the stations' log requests: in the passes between frames, outside the control
        // period's cost; log data only takes what the UART can send now.
        if idle {
            if let Some(l) = logs.as_mut() {
                l.service(app);
            }
            if app.ground_link().logs_busy() {
                app.drain_gcs(&mut |out| gcs.write(out));
                let room = gcs.tx_free();
                match logs.as_mut() {
                    Some(l) => app.serve_logs(l, room),
                    None => app.serve_logs(&mut NoLogs, room),
                }
            }
        }
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

/// Bytes of the longest frame: MAVLink 2, a 255-byte payload, signed.
const HELD: usize = 280;

/// Bytes taken from a UART's receive ring and held until the link's parser can use them.
struct Held {
    buf: [u8; HELD],
    len: usize,
}

impl Held {
    const fn new() -> Self {
        Self {
            buf: [0; HELD],
            len: 0,
        }
    }

    /// Takes what has arrived, as much as there is room for.
    fn take_from(&mut self, usart: &mut Usart) {
        if let Some(room) = self.buf.get_mut(self.len..) {
            self.len = self.len.saturating_add(usart.read_into(room));
        }
    }

    /// The bytes held, to be handed over now and forgotten here, once there are `wanted` of
    /// them (or the buffer is full: a parser never waits for more than a frame).
    fn ready(&mut self, wanted: usize) -> Option<&[u8]> {
        if self.len == 0 || self.len < wanted.min(HELD) {
            return None;
        }
        let n = core::mem::take(&mut self.len);
        self.buf.get(..n)
    }
}
