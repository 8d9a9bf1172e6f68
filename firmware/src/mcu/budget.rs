//! The image's measure of itself: core clock cycles per 20 ms control period (SysTick) and
//! the stack's peak (a painted stack), reported to the ground once a second.
//!
//! SysTick counts core clock cycles. On a board they are the processor's cycles (DWT's cycle
//! counter would give the same); under QEMU's `-icount` the virtual clock advances by a fixed
//! step per instruction, so the same count is proportional to instructions executed. To turn
//! cycles into instructions without knowing QEMU's clock or its `-icount` shift, the image
//! also reports the cycles of a loop of a known number of instructions (`CYC_CAL`, for
//! [`CAL_INSTRUCTIONS`]); `sim-host` divides by it.
//!
//! A control period is the work for the sensor frame that runs the control tick and the one
//! after it (both 100 Hz frames of one 20 ms period, [`CONTROL_PERIOD_US`] of the vehicle's
//! clock): the simulator and ground link's bytes, the estimator, navigation, control and
//! the telemetry they produce. Time spent waiting for bytes is not counted.
//!
//! Names of the NAMED_VALUE_INT reports (MAVLink's 10 characters):
//! - `CYC_MEAN`, `CYC_MAX`: mean and largest cycles per control period since boot;
//! - `CYC_N`: control periods measured;
//! - `CYC_CAL`: cycles of [`CAL_INSTRUCTIONS`] instructions;
//! - `STACK_PEAK`: bytes of the stack ever used (from the paint left untouched).

use firmware::app::{App, CONTROL_PERIOD_US};

const SYST_CSR: *mut u32 = 0xE000_E010 as *mut u32;
const SYST_RVR: *mut u32 = 0xE000_E014 as *mut u32;
const SYST_CVR: *mut u32 = 0xE000_E018 as *mut u32;
/// SysTick's counter is 24 bits wide.
const SYST_MASK: u32 = 0x00FF_FFFF;
/// ENABLE and CLKSOURCE (the core clock); no interrupt.
const CSR_ENABLE_CORE_CLOCK: u32 = 0b101;

/// The paint cortex-m-rt's `paint-stack` leaves on the whole stack before `main`.
const PAINT: u32 = 0xCCCC_CCCC;

/// The reports fall due this long before each whole second of the vehicle's clock, µs.
const REPORT_PHASE_US: u64 = 500_000;

/// Instructions of the calibration loop: two per iteration (`subs`, `bne`).
pub const CAL_INSTRUCTIONS: u32 = 20_000;

extern "C" {
    /// Lowest address of the stack (memory.x).
    static _stack_end: u32;
    /// Highest address of the stack, where it starts (memory.x).
    static _stack_start: u32;
}

/// Starts SysTick free-running over its whole range.
pub fn start() {
    // SAFETY: the architecture's SysTick registers, written once before anything reads them.
    unsafe {
        core::ptr::write_volatile(SYST_RVR, SYST_MASK);
        core::ptr::write_volatile(SYST_CVR, 0);
        core::ptr::write_volatile(SYST_CSR, CSR_ENABLE_CORE_CLOCK);
    }
}

/// SysTick's counter now (it counts down).
#[inline(always)]
pub fn now() -> u32 {
    // SAFETY: a read of SysTick's current value register has no side effect.
    unsafe { core::ptr::read_volatile(SYST_CVR) }
}

/// Cycles since `then` (one wrap of the 24-bit counter at most: 0.1 s at 168 MHz).
#[inline(always)]
pub fn since(then: u32) -> u32 {
    then.wrapping_sub(now()) & SYST_MASK
}

/// SysTick now, at the start of a pass's work. Never inlined, under a fixed name: its entry
/// marks the start of the measured work in QEMU's instruction trace, which
/// `sim-host fly --link qemu --profile` reads to profile the image by function.
#[inline(never)]
#[no_mangle]
pub extern "C" fn budget_work_start() -> u32 {
    now()
}

/// Cycles of a pass's work since `t0` (from [`budget_work_start`]); its entry marks the end of
/// the measured work in the instruction trace.
#[inline(never)]
#[no_mangle]
pub extern "C" fn budget_work_end(t0: u32) -> u32 {
    since(t0)
}

/// Cycles of [`CAL_INSTRUCTIONS`] instructions.
pub fn calibrate() -> u32 {
    let t0 = now();
    // SAFETY: a register-only countdown loop; it touches no memory.
    unsafe {
        core::arch::asm!(
            "2:",
            "subs {n}, {n}, #1",
            "bne 2b",
            n = inout(reg) CAL_INSTRUCTIONS / 2 => _,
            options(nomem, nostack),
        );
    }
    since(t0)
}

/// Bytes of the stack used at its deepest so far: from the top down to the lowest word whose
/// paint is gone.
pub fn stack_peak_bytes() -> u32 {
    let bottom = core::ptr::addr_of!(_stack_end) as usize;
    let top = core::ptr::addr_of!(_stack_start) as usize;
    let mut p = bottom;
    // SAFETY: every word from the stack's bottom to its top is RAM of the stack region.
    while p < top && unsafe { core::ptr::read_volatile(p as *const u32) } == PAINT {
        p += 4;
    }
    (top - p) as u32
}

/// Cycles per control period.
#[derive(Default)]
pub struct Budget {
    period: Option<u64>,
    this_period: u32,
    sum: u64,
    periods: u32,
    max: u32,
    last_report_s: Option<u64>,
    cal: u32,
}

impl Budget {
    /// A budget with the calibration measured now.
    pub fn new() -> Self {
        Self {
            cal: calibrate(),
            ..Self::default()
        }
    }

    /// Charges `cycles` of work to the control period of the vehicle's clock `time_us` (none
    /// before the first sensor frame: nothing is charged).
    pub fn charge(&mut self, cycles: u32, time_us: Option<u64>) {
        let Some(t) = time_us else { return };
        let period = t / CONTROL_PERIOD_US;
        if self.period != Some(period) {
            if self.period.is_some() {
                self.close();
            }
            self.period = Some(period);
            self.this_period = 0;
        }
        self.this_period = self.this_period.saturating_add(cycles);
    }

    fn close(&mut self) {
        self.sum = self.sum.saturating_add(u64::from(self.this_period));
        self.periods = self.periods.saturating_add(1);
        self.max = self.max.max(self.this_period);
    }

    /// Once a second of the vehicle's clock, half-way through it: the figures to the ground.
    /// Their frames are sent from the next pass, whose period is measured: not at the whole
    /// second, where the heartbeat and the fast telemetry streams fall due together.
    pub fn report(&mut self, app: &mut App) {
        let Some(s) = app
            .vehicle()
            .time_us()
            .map(|t| t.saturating_add(REPORT_PHASE_US) / 1_000_000)
        else {
            return;
        };
        if self.last_report_s == Some(s) {
            return;
        }
        self.last_report_s = Some(s);
        let mean = match self.periods {
            0 => 0,
            n => self.sum / u64::from(n),
        };
        let clip = |v: u64| i32::try_from(v).unwrap_or(i32::MAX);
        app.report_figure("CYC_MEAN", clip(mean));
        app.report_figure("CYC_MAX", clip(u64::from(self.max)));
        app.report_figure("CYC_N", clip(u64::from(self.periods)));
        app.report_figure("CYC_CAL", clip(u64::from(self.cal)));
        app.report_figure("STACK_PEAK", clip(u64::from(stack_peak_bytes())));
    }
}
