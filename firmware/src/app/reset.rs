//! Why the board last reset, told to the ground station once it is listening.
//!
//! The board reads the reset flags of `RCC_CSR` and a fault record its panic and HardFault
//! handlers left in a RAM word that start-up does not clear (`.uninit`): a tag with the kind
//! and the line or program counter. This module turns both into one STATUSTEXT.

use common::gcs::texts::Line;

/// `RCC_CSR` reset flags (RM0090 7.3.21).
pub mod csr {
    /// Low-power reset.
    pub const LPWRRSTF: u32 = 1 << 31;
    /// Window watchdog reset.
    pub const WWDGRSTF: u32 = 1 << 30;
    /// Independent watchdog reset.
    pub const IWDGRSTF: u32 = 1 << 29;
    /// Software reset (SCB system reset).
    pub const SFTRSTF: u32 = 1 << 28;
    /// Power-on reset.
    pub const PORRSTF: u32 = 1 << 27;
    /// Reset pin.
    pub const PINRSTF: u32 = 1 << 26;
    /// Brown-out reset.
    pub const BORRSTF: u32 = 1 << 25;
    /// Clears the flags.
    pub const RMVF: u32 = 1 << 24;
}

/// What the fault handlers leave for the next boot: a tag word and a value word.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fault {
    /// A panic at this source line.
    Panic {
        /// Line of the panic.
        line: u32,
    },
    /// A HardFault at this program counter.
    HardFault {
        /// Faulting instruction's address.
        pc: u32,
    },
    /// A reboot the ground station asked for.
    Requested,
}

const TAG_PANIC: u32 = 0xFA17_0001;
const TAG_HARDFAULT: u32 = 0xFA17_0002;
const TAG_REQUESTED: u32 = 0xFA17_0003;

impl Fault {
    /// The two words stored.
    pub fn encode(self) -> [u32; 2] {
        match self {
            Fault::Panic { line } => [TAG_PANIC, line],
            Fault::HardFault { pc } => [TAG_HARDFAULT, pc],
            Fault::Requested => [TAG_REQUESTED, 0],
        }
    }

    /// The record in two words of RAM that nothing initialised: anything else than a tag
    /// (power-on garbage) is no record.
    pub fn decode(words: [u32; 2]) -> Option<Self> {
        match words {
            [TAG_PANIC, line] => Some(Fault::Panic { line }),
            [TAG_HARDFAULT, pc] => Some(Fault::HardFault { pc }),
            [TAG_REQUESTED, _] => Some(Fault::Requested),
            _ => None,
        }
    }
}

/// The STATUSTEXT of a boot: the fault record first (it says most), else the `RCC_CSR` flag
/// that is set, `unknown` when none is (QEMU does not emulate RCC: it reads 0). A fault or
/// watchdog reset is a warning worth the pilot's attention.
pub fn boot_text(rcc_csr: u32, fault: Option<Fault>) -> (bool, heapless::String<50>) {
    let mut s = Line::<50>::new();
    let warn = match fault {
        Some(Fault::Panic { line }) => {
            s.str("Reset by a panic (line ")
                .uint(u64::from(line))
                .str(")");
            true
        }
        Some(Fault::HardFault { pc }) => {
            s.str("Reset by a HardFault (pc ").hex8(pc).str(")");
            true
        }
        Some(Fault::Requested) => {
            s.str("Rebooted on request");
            false
        }
        None => {
            let (warn, why) = if rcc_csr & csr::IWDGRSTF != 0 {
                (true, "independent watchdog")
            } else if rcc_csr & csr::WWDGRSTF != 0 {
                (true, "window watchdog")
            } else if rcc_csr & csr::LPWRRSTF != 0 {
                (true, "low-power")
            } else if rcc_csr & csr::BORRSTF != 0 && rcc_csr & csr::PORRSTF == 0 {
                (true, "brown-out")
            } else if rcc_csr & csr::PORRSTF != 0 {
                (false, "power-on")
            } else if rcc_csr & csr::SFTRSTF != 0 {
                (false, "software")
            } else if rcc_csr & csr::PINRSTF != 0 {
                (false, "reset pin")
            } else {
                (false, "unknown")
            };
            s.str("Reset cause: ").str(why);
            warn
        }
    };
    (warn, s.into_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fault_record_round_trips_and_power_on_garbage_is_none() {
        for f in [
            Fault::Panic { line: 42 },
            Fault::HardFault { pc: 0x0800_c123 },
            Fault::Requested,
        ] {
            assert_eq!(Fault::decode(f.encode()), Some(f));
        }
        assert_eq!(Fault::decode([0, 0]), None);
        assert_eq!(Fault::decode([0xdead_beef, 1]), None);
    }

    #[test]
    fn the_boot_text_names_the_fault_first_then_the_reset_flag() {
        let t = |csr, f| boot_text(csr, f);
        assert_eq!(
            t(csr::SFTRSTF | csr::PINRSTF, Some(Fault::Panic { line: 7 })),
            (true, "Reset by a panic (line 7)".try_into().unwrap())
        );
        assert_eq!(
            t(0, Some(Fault::HardFault { pc: 0x0800_c0de })).1.as_str(),
            "Reset by a HardFault (pc 0x0800c0de)"
        );
        // A watchdog reset also sets the pin flag (the reset drives NRST): the watchdog wins.
        assert_eq!(
            t(csr::IWDGRSTF | csr::PINRSTF, None),
            (
                true,
                "Reset cause: independent watchdog".try_into().unwrap()
            )
        );
        // Power-on sets POR and BOR together: power-on, not a brown-out.
        assert_eq!(
            t(csr::PORRSTF | csr::BORRSTF | csr::PINRSTF, None)
                .1
                .as_str(),
            "Reset cause: power-on"
        );
        assert!(t(csr::BORRSTF | csr::PINRSTF, None).0, "a brown-out warns");
        assert_eq!(t(csr::PINRSTF, None).1.as_str(), "Reset cause: reset pin");
        assert_eq!(t(0, None).1.as_str(), "Reset cause: unknown");
    }
}
