//! The STM32F4 USARTs: registers, enable, polled receive and blocking transmit.

/// One STM32F4 USART's registers.
pub struct Usart {
    base: usize,
}

const SR: usize = 0x00;
const DR: usize = 0x04;
const CR1: usize = 0x0C;
const SR_RXNE: u32 = 1 << 5;
const SR_TXE: u32 = 1 << 7;
const CR1_UE_TE_RE: u32 = (1 << 13) | (1 << 3) | (1 << 2);

impl Usart {
    pub const USART1: Usart = Usart { base: 0x4001_1000 };
    pub const USART2: Usart = Usart { base: 0x4000_4400 };

    fn reg(&self, offset: usize) -> *mut u32 {
        (self.base + offset) as *mut u32
    }

    pub fn enable(&self) {
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
    pub fn read_into(&self, buf: &mut [u8]) -> usize {
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

    pub fn write(&self, bytes: &[u8]) {
        for &b in bytes {
            // SAFETY: as above.
            unsafe {
                while core::ptr::read_volatile(self.reg(SR)) & SR_TXE == 0 {}
                core::ptr::write_volatile(self.reg(DR), u32::from(b));
            }
        }
    }
}
