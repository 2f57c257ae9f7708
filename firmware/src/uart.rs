//! The CMSDK APB UARTs of the MPS2 boards, polled, without a HAL.

use core::ptr::{read_volatile, write_volatile};

use cortex_m::interrupt::InterruptNumber;
use cortex_m::peripheral::NVIC;

/// UART0's and UART1's registers on the MPS2 AN386 (QEMU's first and
/// second `-serial`).
const UART0: usize = 0x4000_4000;
const UART1: usize = 0x4000_5000;
const DATA: usize = 0x00;
const STATE: usize = 0x04;
const CTRL: usize = 0x08;
const INTSTATUS: usize = 0x0C;
const BAUDDIV: usize = 0x10;
const TX_FULL: u32 = 1 << 0;
const RX_FULL: u32 = 1 << 1;
const TX_ENABLE: u32 = 1 << 0;
const RX_ENABLE: u32 = 1 << 1;
const RX_INTERRUPT: u32 = 1 << 3;
/// The RX bit of INTSTATUS (write 1 to clear).
const RX_PENDING: u32 = 1 << 1;
/// System clock of the board.
const CLOCK_HZ: u32 = 25_000_000;

/// A UART's receive interrupt line on the NVIC (UART0: 0, UART1: 2).
#[derive(Debug, Clone, Copy)]
struct RxIrq(u16);

// SAFETY: the MPS2 AN386's UART receive interrupts are valid lines.
unsafe impl InterruptNumber for RxIrq {
    fn number(self) -> u16 {
        self.0
    }
}

/// A UART, enabled for both directions.
pub struct Uart {
    base: usize,
    irq: RxIrq,
}

impl Uart {
    /// Enables UART0 at `baud` (the divider is clamped to the hardware's
    /// minimum of 16; QEMU ignores the rate).
    pub fn uart0(baud: u32) -> Self {
        Self::enable(UART0, RxIrq(0), baud)
    }

    /// Enables UART1 at `baud`, as [`Uart::uart0`].
    pub fn uart1(baud: u32) -> Self {
        Self::enable(UART1, RxIrq(2), baud)
    }

    fn enable(base: usize, irq: RxIrq, baud: u32) -> Self {
        let uart = Uart { base, irq };
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

    /// Lets a received byte end a [`sleep`]: raises the receive
    /// interrupt, unmasked on the NVIC. With interrupts disabled no handler
    /// runs; the pending line only wakes the core.
    pub fn wake_on_receive(&self) {
        cortex_m::interrupt::disable();
        self.write(CTRL, TX_ENABLE | RX_ENABLE | RX_INTERRUPT);
        // SAFETY: interrupts are disabled, so unmasking starts no handler.
        unsafe { NVIC::unmask(self.irq) };
    }

    /// Clears the receive interrupt: a byte received after this call will
    /// end the next [`sleep`]. Call before reading what is waiting.
    pub fn rearm(&self) {
        self.write(INTSTATUS, RX_PENDING);
        NVIC::unpend(self.irq);
    }

    /// Sends `bytes`, waiting while the transmitter is full.
    pub fn write_all(&self, bytes: &[u8]) {
        for b in bytes {
            while self.read(STATE) & TX_FULL != 0 {}
            self.write(DATA, u32::from(*b));
        }
    }
}

/// Sleeps until a UART set to [`Uart::wake_on_receive`] receives (at
/// once if one did since its [`Uart::rearm`]): the core waits for the
/// interrupt instead of spinning, which leaves the host's CPU to the
/// simulated cell under QEMU.
pub fn sleep() {
    cortex_m::asm::wfi();
}

impl primo_device::Port for Uart {
    fn try_read_byte(&mut self) -> Option<u8> {
        Uart::try_read_byte(self)
    }

    fn write_all(&mut self, bytes: &[u8]) {
        Uart::write_all(self, bytes);
    }
}
