//! The MCU image's budget: its flash and static RAM from the ELF's section headers, and what
//! the image measured of itself in flight (instructions per control period, stack peak), as
//! `sim-host fly --link qemu --json` reports them in its object `mcu`.
//!
//! The image counts core clock cycles with SysTick; under QEMU's `-icount` they stand in a
//! fixed ratio to instructions, which the image measures itself on a loop of a known number of
//! instructions (`CYC_CAL`). The figures here are instructions: cycles times that ratio.

use object::{Object, ObjectSection, SectionFlags, SectionKind};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;

/// Instructions of the image's calibration loop (`firmware`'s `mcu/budget.rs`).
pub const CAL_INSTRUCTIONS: f64 = 20_000.0;

/// Start of the STM32F405's SRAM: sections placed from here are RAM.
const RAM_START: u64 = 0x2000_0000;

/// ELF section flag: the section occupies memory on the target.
const SHF_ALLOC: u64 = 0x2;

/// What the image occupies of its chip.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct ImageSize {
    /// Flash: vector table, code, read-only data and the initial values of `.data`.
    pub flash_bytes: u64,
    /// RAM taken by statics: `.data`, `.bss` and `.uninit`.
    pub static_ram_bytes: u64,
}

/// Reads [`ImageSize`] from the section headers of the ELF at `path`.
pub fn image_size(path: &Path) -> anyhow::Result<ImageSize> {
    use anyhow::Context;
    let bytes = std::fs::read(path).with_context(|| format!("cannot read `{}`", path.display()))?;
    let elf = object::File::parse(&*bytes)
        .with_context(|| format!("`{}` is not an ELF file", path.display()))?;
    let mut size = ImageSize::default();
    for s in elf.sections() {
        let alloc =
            matches!(s.flags(), SectionFlags::Elf { sh_flags } if sh_flags & SHF_ALLOC != 0);
        if !alloc || s.size() == 0 {
            continue;
        }
        let in_ram = s.address() >= RAM_START;
        let has_bytes = !matches!(
            s.kind(),
            SectionKind::UninitializedData | SectionKind::UninitializedTls
        );
        if in_ram {
            size.static_ram_bytes += s.size();
        }
        // `.data` lives in RAM and its initial values in flash.
        if has_bytes {
            size.flash_bytes += s.size();
        }
    }
    Ok(size)
}

/// The image's figures of itself: the `mcu` object of `sim-host fly --link qemu --json`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct McuBudget {
    /// Flash (see [`ImageSize`]).
    pub flash_bytes: u64,
    /// RAM taken by statics (see [`ImageSize`]).
    pub static_ram_bytes: u64,
    /// Deepest the stack went, bytes (painted stack).
    pub stack_peak_bytes: u64,
    /// Instructions per 20 ms control period, mean over the flight.
    pub instr_per_control_period_mean: f64,
    /// Instructions of the costliest control period of the flight.
    pub instr_per_control_period_max: f64,
    /// Control periods measured.
    pub control_periods: u64,
}

impl McuBudget {
    /// The budget of an image of `size` from the NAMED_VALUE_INT figures it sent; `None` when
    /// it sent none (an image that does not measure itself) or no calibration.
    pub fn from_reports(size: ImageSize, named: &BTreeMap<String, i32>) -> Option<Self> {
        let get = |n: &str| named.get(n).copied();
        let cal = f64::from(get("CYC_CAL").filter(|c| *c > 0)?);
        let per_cycle = CAL_INSTRUCTIONS / cal;
        let instr = |n: &str| get(n).map_or(f64::NAN, |c| (f64::from(c) * per_cycle).round());
        Some(Self {
            flash_bytes: size.flash_bytes,
            static_ram_bytes: size.static_ram_bytes,
            stack_peak_bytes: get("STACK_PEAK").map_or(0, |v| v.max(0) as u64),
            instr_per_control_period_mean: instr("CYC_MEAN"),
            instr_per_control_period_max: instr("CYC_MAX"),
            control_periods: get("CYC_N").map_or(0, |v| v.max(0) as u64),
        })
    }

    /// Statics and the stack's peak: the RAM the image needs.
    pub fn ram_bytes(&self) -> u64 {
        self.static_ram_bytes + self.stack_peak_bytes
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cycles_become_instructions_by_the_images_own_calibration() {
        // 26,880 cycles for the 20,000-instruction loop: QEMU's 168 MHz SysTick clock at
        // -icount shift=3 (8 ns per instruction) counts 1.344 cycles per instruction.
        let named: BTreeMap<String, i32> = [
            ("CYC_CAL", 26_880),
            ("CYC_MEAN", 134_400),
            ("CYC_MAX", 268_800),
            ("CYC_N", 50),
            ("STACK_PEAK", 4096),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect();
        let size = ImageSize {
            flash_bytes: 1000,
            static_ram_bytes: 200,
        };
        let b = McuBudget::from_reports(size, &named).expect("figures");
        assert_eq!(b.instr_per_control_period_mean, 100_000.0);
        assert_eq!(b.instr_per_control_period_max, 200_000.0);
        assert_eq!((b.control_periods, b.stack_peak_bytes), (50, 4096));
        assert_eq!(b.ram_bytes(), 4296);
        assert_eq!(McuBudget::from_reports(size, &BTreeMap::new()), None);
    }
}
