//! primo's scale on a NUCLEO-G431RB (STM32G431RB): the loop of the QEMU
//! image `primo-scale` (`primo_device::ScaleDevice`: the scale and the
//! learner service behind one line) with the board's adapters:
//!
//! - the host's frames on USART2, the ST-LINK's virtual COM port (PA2,
//!   PA3), 115,200 baud 8N1, polled;
//! - the load cell through the HX711 driver of `primo_loadcell`, PD_SCK on
//!   PB12 and DOUT on PB13, timed by the DWT cycle counter;
//! - the settings (calibration, zero, tare) in the last flash page (page
//!   63, 0x0801_F800) through the flash controller
//!   (`primo_device::stm32g4`); a failed store lights LD2 (PA5).
//!
//! The core runs on HSI16 (16 MHz) with interrupts masked: nothing
//! interrupts an HX711 read (PD_SCK held high 60 µs would power it down),
//! and a SysTick that pends every 100 µs ends the WFI between passes.
//! A panic or a fault resets the part.
#![no_std]
#![no_main]
#![deny(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing,
    clippy::unreachable,
    clippy::todo,
    clippy::unimplemented
)]

mod board;

use core::panic::PanicInfo;

use cortex_m::peripheral::SCB;
use cortex_m_rt::{ExceptionFrame, entry, exception};
use primo_device::ScaleDevice;
use primo_device::scale::{Scale, ScaleConfig};
use primo_device::stm32g4::{Flash, FlashSettings, SETTINGS_PAGE};
use primo_learner::Coprocessor as Service;
use primo_loadcell::hx711::{Gain, Hx711};
use primo_protocol::frame::FrameReader;
use stm32g4::stm32g431 as pac;

use board::{DwtDelay, G4FlashRegs, Led, PortB, Usart2};

#[entry]
fn main() -> ! {
    // In .bss, as in the QEMU images.
    static mut SERVICE: Service = Service::new();
    static mut SCALE: Scale = Scale::new(ScaleConfig::LAB);
    static mut READER: FrameReader = FrameReader::new();
    cortex_m::interrupt::disable();
    // SAFETY: the only owner of the peripherals, taken once at reset.
    let (mut core, dp) = unsafe { (cortex_m::Peripherals::steal(), pac::Peripherals::steal()) };
    board::enable_clocks(&dp.RCC);
    let mut led = Led::new(&dp.GPIOA);
    let mut host = Usart2::new(dp.USART2, &dp.GPIOA);
    let delay = DwtDelay::new(&mut core.DCB, &mut core.DWT);
    let sck = PortB::<12>::output(&dp.GPIOB);
    let dout = PortB::<13>::input_pulled_up(&dp.GPIOB);
    // The pins' errors are Infallible: the reset never fails.
    let Ok(mut cell) = Hx711::new(sck, dout, delay, Gain::A128) else {
        SCB::sys_reset()
    };
    let mut page = FlashSettings::new(Flash::new(G4FlashRegs::new(dp.FLASH)), SETTINGS_PAGE);
    let mut device = ScaleDevice::new(SERVICE, SCALE, READER);
    device.boot(&mut page);
    board::start_tick(&mut core.SYST);
    loop {
        board::rearm();
        let pass = device.poll(&mut host, &mut cell, &mut page);
        if let Some(Err(_)) = pass.stored {
            led.on();
        }
        if pass.idle {
            board::sleep();
        }
    }
}

/// No board to report to: start again.
#[panic_handler]
fn panic(_: &PanicInfo) -> ! {
    SCB::sys_reset()
}

/// A fault starts the part again rather than hang the scale.
#[exception]
unsafe fn HardFault(_: &ExceptionFrame) -> ! {
    SCB::sys_reset()
}
