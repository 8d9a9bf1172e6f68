//! The STM32F4 USARTs, interrupt-driven: the receive interrupt (RXNEIE) moves each byte into a
//! ring the main loop drains, and the transmit interrupt (TXEIE) feeds the data register from
//! a ring the main loop fills, so a long tick neither loses what arrives meanwhile nor waits
//! for what it sends.
//!
//! The rings are `heapless::spsc` queues: the interrupt is the only producer of a receive ring
//! and the only consumer of a transmit ring, the main loop the other end, and neither needs a
//! lock. The interrupts reach their handler through cortex-m-rt's `DefaultHandler`
//! (`mcu::DefaultHandler`), which dispatches on the interrupt number: no device crate (a PAC
//! would bring its register API and an 82-entry vector table for two handlers), and the
//! vector table stays cortex-m-rt's own.
//!
//! - A full receive ring leaves the byte in the data register and masks the interrupt until
//!   the main loop has drained the ring: QEMU then holds the following bytes back (it offers a
//!   byte only once RXNE is clear), a board's USART counts an overrun.
//! - Transmission starts by pending the interrupt from the main loop, so it also runs on a
//!   USART model that raises no TXE interrupt (QEMU 7.2's): the handler sends while TXE is set.
//!   A full transmit ring makes the writer wait for room, the only wait left.
//! - The idle loop keeps polling, no WFI: under `-icount`, WFI with UART interrupts stalls in
//!   QEMU 7.2.

use core::sync::atomic::{AtomicBool, Ordering};
use cortex_m::interrupt::InterruptNumber;
use cortex_m::peripheral::NVIC;
use heapless::spsc::{Consumer, Producer, Queue};

/// Bytes a receive ring holds: at 57,600 baud, 90 ms of a ground link (the longest tick is far
/// shorter); the simulator link sends one frame per answer (lock-step).
const RX_LEN: usize = 512;
/// Bytes a transmit ring holds: a control period's telemetry and answers.
const TX_LEN: usize = 512;

const SR: usize = 0x00;
const DR: usize = 0x04;
const CR1: usize = 0x0C;
const SR_RXNE: u32 = 1 << 5;
const SR_TXE: u32 = 1 << 7;
const SR_TC: u32 = 1 << 6;
const CR1_UE: u32 = 1 << 13;
const CR1_TXEIE: u32 = 1 << 7;
const CR1_RXNEIE: u32 = 1 << 5;
const CR1_TE: u32 = 1 << 3;
const CR1_RE: u32 = 1 << 2;

/// The two USARTs in use.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Id {
    /// USART1 at 0x4001_1000, IRQ 37: the simulator link.
    Usart1 = 0,
    /// USART2 at 0x4000_4400, IRQ 38: the ground link.
    Usart2 = 1,
}

/// The STM32F405's interrupt number of a USART.
#[derive(Clone, Copy)]
struct Irq(u16);

// SAFETY: 37 and 38 are USART1's and USART2's positions in the STM32F405's vector table.
unsafe impl InterruptNumber for Irq {
    fn number(self) -> u16 {
        self.0
    }
}

impl Id {
    const fn base(self) -> usize {
        match self {
            Id::Usart1 => 0x4001_1000,
            Id::Usart2 => 0x4000_4400,
        }
    }

    const fn irq(self) -> Irq {
        match self {
            Id::Usart1 => Irq(37),
            Id::Usart2 => Irq(38),
        }
    }

    /// The USART of interrupt number `irqn`.
    pub fn of_irq(irqn: i16) -> Option<Id> {
        match irqn {
            37 => Some(Id::Usart1),
            38 => Some(Id::Usart2),
            _ => None,
        }
    }

    fn reg(self, offset: usize) -> *mut u32 {
        (self.base() + offset) as *mut u32
    }

    fn read(self, offset: usize) -> u32 {
        // SAFETY: a fixed, aligned MMIO register of the STM32F405.
        unsafe { core::ptr::read_volatile(self.reg(offset)) }
    }

    fn write(self, offset: usize, value: u32) {
        // SAFETY: as above.
        unsafe { core::ptr::write_volatile(self.reg(offset), value) }
    }

    /// Sets or clears bits of CR1, which the interrupt also changes: with interrupts off.
    fn modify_cr1(self, set: u32, clear: u32) {
        cortex_m::interrupt::free(|_| {
            self.write(CR1, (self.read(CR1) | set) & !clear);
        });
    }
}

struct Rings {
    rx: Queue<u8, RX_LEN>,
    tx: Queue<u8, TX_LEN>,
}

/// The interrupt's ends of the rings of one USART.
struct IsrEnds {
    rx: Producer<'static, u8>,
    tx: Consumer<'static, u8>,
}

static mut RINGS: [Rings; 2] = [const {
    Rings {
        rx: Queue::new(),
        tx: Queue::new(),
    }
}; 2];
/// Written once per USART by [`Usart::open`] before its interrupt is unmasked; afterwards only
/// the interrupt handler touches it.
static mut ISR_ENDS: [Option<IsrEnds>; 2] = [None, None];
/// The receive ring was full: the interrupt masked itself until the main loop makes room.
static STALLED: [AtomicBool; 2] = [const { AtomicBool::new(false) }; 2];

/// The main loop's side of one USART.
pub struct Usart {
    id: Id,
    rx: Consumer<'static, u8>,
    tx: Producer<'static, u8>,
}

impl Usart {
    /// Enables the USART with its receive interrupt and unmasks it at the NVIC. Called once
    /// per USART (a second call returns `None`).
    pub fn open(id: Id) -> Option<Usart> {
        let k = id as usize;
        // SAFETY: the interrupt of this USART is still masked (it is unmasked below, once), so
        // nothing else touches its rings or ends; `take`-like check refuses a second open.
        let (rx_p, rx_c, tx_p, tx_c) = unsafe {
            let ends = &mut *core::ptr::addr_of_mut!(ISR_ENDS);
            if ends.get(k)?.is_some() {
                return None;
            }
            let rings = &mut *core::ptr::addr_of_mut!(RINGS);
            let r = rings.get_mut(k)?;
            let (rx_p, rx_c) = r.rx.split();
            let (tx_p, tx_c) = r.tx.split();
            (rx_p, rx_c, tx_p, tx_c)
        };
        // SAFETY: as above: the interrupt cannot run yet.
        unsafe {
            let ends = &mut *core::ptr::addr_of_mut!(ISR_ENDS);
            *ends.get_mut(k)? = Some(IsrEnds { rx: rx_p, tx: tx_c });
        }
        id.write(CR1, CR1_UE | CR1_TE | CR1_RE | CR1_RXNEIE);
        // SAFETY: the handler's state is in place; no critical section relies on the mask.
        unsafe { NVIC::unmask(id.irq()) };
        Some(Usart {
            id,
            rx: rx_c,
            tx: tx_p,
        })
    }

    /// Moves what has arrived into `buf`, up to its length; returns the bytes moved.
    pub fn read_into(&mut self, buf: &mut [u8]) -> usize {
        let mut n = 0;
        for slot in buf.iter_mut() {
            match self.rx.dequeue() {
                Some(b) => {
                    *slot = b;
                    n += 1;
                }
                None => break,
            }
        }
        self.resume();
        n
    }

    /// Lets a receive interrupt that stopped on a full ring take bytes again.
    fn resume(&self) {
        let k = self.id as usize;
        if STALLED
            .get(k)
            .is_some_and(|s| s.swap(false, Ordering::AcqRel))
        {
            // SAFETY: the handler masked itself only to wait for room, which there now is.
            unsafe { NVIC::unmask(self.id.irq()) };
        }
    }

    /// Queues `bytes` for sending and starts the transmit interrupt; waits only while the ring
    /// is full.
    pub fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            while self.tx.enqueue(b).is_err() {
                self.kick();
            }
        }
        self.kick();
    }

    /// Bytes the transmit ring can take now without waiting.
    pub fn tx_free(&self) -> usize {
        self.tx.capacity().saturating_sub(self.tx.len())
    }

    /// Waits until every queued byte has left the USART (before a reset).
    pub fn flush(&mut self) {
        self.kick();
        while !self.tx.is_empty() || self.id.read(SR) & SR_TC == 0 {
            self.kick();
        }
    }

    /// Turns the transmit interrupt on and runs its handler now, which sends while TXE is
    /// set (a model without TXE interrupts sends this way too).
    fn kick(&self) {
        self.id.modify_cr1(CR1_TXEIE, 0);
        self.resume();
        NVIC::pend(self.id.irq());
    }
}

/// The interrupt of USART `id`: sends from the transmit ring while the data register is free,
/// receives into the receive ring while a byte waits.
pub fn on_interrupt(id: Id) {
    let k = id as usize;
    // SAFETY: only this handler uses the ends once `open` has put them in place, and the
    // handler does not preempt itself.
    let Some(Some(ends)) = (unsafe { (*core::ptr::addr_of_mut!(ISR_ENDS)).get_mut(k) }) else {
        return;
    };
    if id.read(CR1) & CR1_TXEIE != 0 {
        while id.read(SR) & SR_TXE != 0 {
            match ends.tx.dequeue() {
                Some(b) => id.write(DR, u32::from(b)),
                None => {
                    id.write(CR1, id.read(CR1) & !CR1_TXEIE);
                    break;
                }
            }
        }
    }
    while id.read(SR) & SR_RXNE != 0 {
        if !ends.rx.ready() {
            // Leave the byte where it is: the main loop unmasks once it has made room.
            NVIC::mask(id.irq());
            if let Some(s) = STALLED.get(k) {
                s.store(true, Ordering::Release);
            }
            break;
        }
        // Reading DR clears RXNE (and an overrun flag read with SR just before).
        let _ = ends.rx.enqueue(id.read(DR) as u8);
    }
}
