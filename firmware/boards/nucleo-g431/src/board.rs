//! The NUCLEO-G431RB's I/O for the scale, on the `stm32g4` PAC without a
//! HAL: the core clock, a DWT cycle-counter delay, GPIO pins as
//! embedded-hal 1.0 pins, USART2 polled as the host's [`Port`], the flash
//! controller's registers as [`FlashRegs`], the user LED, and the wake-up
//! tick.

use core::convert::Infallible;
use core::ptr::{read_volatile, write_volatile};

use cortex_m::peripheral::{DWT, SCB, SYST, syst::SystClkSource};
use embedded_hal::delay::DelayNs;
use embedded_hal::digital::{ErrorType, InputPin, OutputPin};
use primo_device::Port;
use primo_device::stm32g4::{FLASH_BASE, FlashRegs, PAGE_SIZE, PAGES, Reg};
use stm32g4::stm32g431::{self as pac, FLASH, GPIOA, GPIOB, RCC, USART2};

/// The core clock: HSI16, the clock the part resets to (no PLL, flash at
/// 0 wait states). It times the delay, USART2's baud rate and the tick.
pub const CLOCK_HZ: u32 = 16_000_000;
/// The host line's rate (8N1), as the QEMU image's.
pub const BAUD: u32 = 115_200;
/// The wake-up tick's period, core cycles (100 µs): the core sleeps
/// between ticks; USART2's FIFO holds 8 bytes (690 µs at 115,200 baud)
/// and the HX711 converts every 12.5 ms, so neither is missed.
const TICK_CYCLES: u32 = CLOCK_HZ / 10_000;

/// USART2's ISR in FIFO mode: a byte in the receive FIFO.
const RXFNE: u32 = 1 << 5;
/// USART2's ISR in FIFO mode: room in the transmit FIFO.
const TXFNF: u32 = 1 << 7;

/// Busy-waits on the core's DWT cycle counter, at [`CLOCK_HZ`]: at least
/// the time asked (rounded up to whole cycles), longer if an interrupt
/// runs (none does: the scale runs with interrupts masked).
pub struct DwtDelay(());

impl DwtDelay {
    /// Starts the cycle counter.
    pub fn new(dcb: &mut cortex_m::peripheral::DCB, dwt: &mut DWT) -> Self {
        dcb.enable_trace();
        dwt.enable_cycle_counter();
        DwtDelay(())
    }
}

impl DelayNs for DwtDelay {
    fn delay_ns(&mut self, ns: u32) {
        let cycles = (u64::from(ns) * u64::from(CLOCK_HZ)).div_ceil(1_000_000_000);
        let cycles = u32::try_from(cycles).unwrap_or(u32::MAX);
        let start = DWT::cycle_count();
        while DWT::cycle_count().wrapping_sub(start) < cycles {}
    }
}

/// Pin `N` of GPIOB.
pub struct PortB<const N: u8>(());

impl<const N: u8> PortB<N> {
    fn regs() -> &'static pac::gpiob::RegisterBlock {
        // SAFETY: GPIOB's registers, at their fixed address for the whole
        // run; each pin writes only its own bits (BSRR is atomic).
        unsafe { &*GPIOB::ptr() }
    }

    /// The pin as a push-pull output, low.
    pub fn output(gpiob: &GPIOB) -> Self {
        gpiob.bsrr().write(|w| unsafe { w.bits(1 << (N + 16)) });
        gpiob
            .moder()
            .modify(|r, w| unsafe { w.bits(r.bits() & !(0b11 << (2 * N)) | 0b01 << (2 * N)) });
        PortB(())
    }

    /// The pin as an input with its pull-up (an unwired HX711's DOUT
    /// reads high: no conversion ready, rather than zeros).
    pub fn input_pulled_up(gpiob: &GPIOB) -> Self {
        gpiob
            .pupdr()
            .modify(|r, w| unsafe { w.bits(r.bits() & !(0b11 << (2 * N)) | 0b01 << (2 * N)) });
        gpiob
            .moder()
            .modify(|r, w| unsafe { w.bits(r.bits() & !(0b11 << (2 * N))) });
        PortB(())
    }
}

impl<const N: u8> ErrorType for PortB<N> {
    type Error = Infallible;
}

impl<const N: u8> OutputPin for PortB<N> {
    fn set_low(&mut self) -> Result<(), Infallible> {
        Self::regs()
            .bsrr()
            .write(|w| unsafe { w.bits(1 << (N + 16)) });
        Ok(())
    }

    fn set_high(&mut self) -> Result<(), Infallible> {
        Self::regs().bsrr().write(|w| unsafe { w.bits(1 << N) });
        Ok(())
    }
}

impl<const N: u8> InputPin for PortB<N> {
    fn is_high(&mut self) -> Result<bool, Infallible> {
        Ok(Self::regs().idr().read().bits() & (1 << N) != 0)
    }

    fn is_low(&mut self) -> Result<bool, Infallible> {
        self.is_high().map(|high| !high)
    }
}

/// The clocks of the GPIO ports and USART2.
pub fn enable_clocks(rcc: &RCC) {
    rcc.ahb2enr()
        .modify(|_, w| w.gpioaen().set_bit().gpioben().set_bit());
    rcc.apb1enr1().modify(|_, w| w.usart2en().set_bit());
    // Two reads of the bus, as RM0440 asks between a clock enable and
    // the first access to the peripheral.
    let _ = rcc.apb1enr1().read();
    let _ = rcc.apb1enr1().read();
}

/// The user LED (LD2, PA5): on when a settings store failed.
pub struct Led(());

impl Led {
    /// PA5 as a push-pull output, off.
    pub fn new(gpioa: &GPIOA) -> Self {
        gpioa.bsrr().write(|w| unsafe { w.bits(1 << (5 + 16)) });
        gpioa
            .moder()
            .modify(|r, w| unsafe { w.bits(r.bits() & !(0b11 << 10) | 0b01 << 10) });
        Led(())
    }

    /// Lights it.
    pub fn on(&mut self) {
        // SAFETY: GPIOA's registers; BSRR sets PA5 alone.
        let gpioa = unsafe { &*GPIOA::ptr() };
        gpioa.bsrr().write(|w| unsafe { w.bits(1 << 5) });
    }
}

/// USART2 on PA2 (TX) and PA3 (RX), alternate function 7: the ST-LINK's
/// virtual COM port. 8N1, FIFOs on, overrun detection off (a byte lost
/// to a full FIFO is a damaged frame, which the host retransmits).
pub struct Usart2(USART2);

impl Usart2 {
    /// Sets the pins and the USART up at [`BAUD`].
    pub fn new(usart: USART2, gpioa: &GPIOA) -> Self {
        gpioa
            .afrl()
            .modify(|r, w| unsafe { w.bits(r.bits() & !(0xFF << 8) | 0x77 << 8) });
        gpioa
            .moder()
            .modify(|r, w| unsafe { w.bits(r.bits() & !(0b1111 << 4) | 0b1010 << 4) });
        // The kernel clock is PCLK1 (CCIPR's reset value) = CLOCK_HZ.
        usart
            .brr()
            .write(|w| unsafe { w.bits((CLOCK_HZ + BAUD / 2) / BAUD) });
        usart.cr3().write(|w| w.ovrdis().set_bit());
        usart.cr1().write(|w| {
            w.fifoen()
                .set_bit()
                .te()
                .set_bit()
                .re()
                .set_bit()
                .ue()
                .set_bit()
        });
        Usart2(usart)
    }
}

impl Port for Usart2 {
    fn try_read_byte(&mut self) -> Option<u8> {
        (self.0.isr().read().bits() & RXFNE != 0).then(|| self.0.rdr().read().bits() as u8)
    }

    fn write_all(&mut self, bytes: &[u8]) {
        for byte in bytes {
            while self.0.isr().read().bits() & TXFNF == 0 {}
            self.0.tdr().write(|w| unsafe { w.bits(u32::from(*byte)) });
        }
    }
}

/// The flash controller's registers and the flash memory, volatile.
pub struct G4FlashRegs(FLASH);

impl G4FlashRegs {
    /// Over the controller.
    pub fn new(flash: FLASH) -> Self {
        G4FlashRegs(flash)
    }

    /// `address` lies in the part's flash, `len` bytes of it.
    fn in_flash(address: u32, len: u32) -> bool {
        let end = FLASH_BASE + PAGE_SIZE * u32::from(PAGES);
        address >= FLASH_BASE && address.checked_add(len).is_some_and(|e| e <= end)
    }
}

impl FlashRegs for G4FlashRegs {
    fn read(&mut self, reg: Reg) -> u32 {
        match reg {
            Reg::Acr => self.0.acr().read().bits(),
            // Write only.
            Reg::Keyr => 0,
            Reg::Sr => self.0.sr().read().bits(),
            Reg::Cr => self.0.cr().read().bits(),
        }
    }

    fn write(&mut self, reg: Reg, value: u32) {
        // SAFETY (the `bits` writes): the driver writes these registers as
        // RM0440 gives their bits (primo_device::stm32g4).
        match reg {
            Reg::Acr => self.0.acr().write(|w| unsafe { w.bits(value) }),
            Reg::Keyr => self.0.keyr().write(|w| unsafe { w.bits(value) }),
            Reg::Sr => self.0.sr().write(|w| unsafe { w.bits(value) }),
            Reg::Cr => self.0.cr().write(|w| unsafe { w.bits(value) }),
        };
    }

    fn program_word(&mut self, address: u32, word: u32) {
        if !address.is_multiple_of(4) || !Self::in_flash(address, 4) {
            return;
        }
        // SAFETY: an aligned word of the flash memory, written while the
        // controller's PG is set (the driver's sequence): the controller
        // takes it as half of a double word to program.
        unsafe { write_volatile(address as *mut u32, word) };
        cortex_m::asm::dsb();
    }

    fn read_flash(&mut self, address: u32, buf: &mut [u8]) {
        let Ok(len) = u32::try_from(buf.len()) else {
            return;
        };
        if !Self::in_flash(address, len) {
            buf.fill(0xFF);
            return;
        }
        for (at, byte) in (address..).zip(buf.iter_mut()) {
            // SAFETY: within the part's flash, which reads as memory.
            *byte = unsafe { read_volatile(at as *const u8) };
        }
    }
}

/// The wake-up tick: SysTick pends its exception every 100 µs. Interrupts
/// stay masked (PRIMASK), so no handler runs; the pending exception only
/// ends a [`sleep`].
pub fn start_tick(syst: &mut SYST) {
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(TICK_CYCLES - 1);
    syst.clear_current();
    syst.enable_interrupt();
    syst.enable_counter();
}

/// Clears the tick's pending exception: the next tick ends the next
/// [`sleep`]. Call before polling.
pub fn rearm() {
    SCB::clear_pendst();
}

/// Sleeps until the next tick (at once if one came since [`rearm`]).
pub fn sleep() {
    cortex_m::asm::wfi();
}
