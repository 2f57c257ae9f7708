//! The CMSDK APB UARTs of the MPS2 boards, polled, without a HAL.

use core::ptr::{read_volatile, write_volatile};

/// UART0's and UART1's registers on the MPS2 AN386 (QEMU's first and
/// second `-serial`).
const UART0: usize = 0x4000_4000;
const UART1: usize = 0x4000_5000;
const DATA: usize = 0x00;
const STATE: usize = 0x04;
const CTRL: usize = 0x08;
const BAUDDIV: usize = 0x10;
const TX_FULL: u32 = 1 << 0;
const RX_FULL: u32 = 1 << 1;
const TX_ENABLE: u32 = 1 << 0;
const RX_ENABLE: u32 = 1 << 1;
/// System clock of the board.
const CLOCK_HZ: u32 = 25_000_000;

/// A UART, enabled for both directions.
pub struct Uart {
    base: usize,
}

impl Uart {
    /// Enables UART0 at `baud` (the divider is clamped to the hardware's
    /// minimum of 16; QEMU ignores the rate).
    pub fn uart0(baud: u32) -> Self {
        Self::enable(UART0, baud)
    }

    /// Enables UART1 at `baud`, as [`Uart::uart0`].
    pub fn uart1(baud: u32) -> Self {
        Self::enable(UART1, baud)
    }

    fn enable(base: usize, baud: u32) -> Self {
        let uart = Uart { base };
        uart.write(BAUDDIV, (CLOCK_HZ / baud.max(1)).max(16));
        uart.write(CTRL, TX_ENABLE | RX_ENABLE);
        uart
    }

    fn read(&self, reg: usize) -> u32 {
        // SAFETY: an aligned register of the UART block, which this driver
        // alone touches.
        unsafe { read_volatile((self.base + reg) as *const u32) }
    }

    fn write(&self, reg: usize, value: u32) {
        // SAFETY: as in `read`.
        unsafe { write_volatile((self.base + reg) as *mut u32, value) }
    }

    /// Waits for a byte and returns it.
    pub fn read_byte(&self) -> u8 {
        loop {
            if let Some(b) = self.try_read_byte() {
                return b;
            }
        }
    }

    /// The byte received, if one is waiting.
    pub fn try_read_byte(&self) -> Option<u8> {
        (self.read(STATE) & RX_FULL != 0).then(|| self.read(DATA) as u8)
    }

    /// Sends `bytes`, waiting while the transmitter is full.
    pub fn write_all(&self, bytes: &[u8]) {
        for b in bytes {
            while self.read(STATE) & TX_FULL != 0 {}
            self.write(DATA, u32::from(*b));
        }
    }
}
