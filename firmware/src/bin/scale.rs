//! The load-cell scale, which also serves the learner: frames in on UART0
//! go to the scale or to the learner service, under one sequence; the
//! load cell's counts come in on UART1; streamed readings, and the answer
//! to a weighing that waits for the next stable reading, go out on UART0.
//! Between bytes the core sleeps. The loop is `primo_device::ScaleDevice`,
//! the board images' too; here are its adapters.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use primo_device::ScaleDevice;
use primo_device::scale::{Scale, ScaleConfig};
use primo_firmware::load_cell::UartCell;
use primo_firmware::settings::RamPage;
use primo_firmware::uart::{self, Uart};
use primo_learner::Coprocessor as Service;
use primo_protocol::frame::FrameReader;

#[entry]
fn main() -> ! {
    // In .bss, as in the coprocessor (see src/main.rs).
    static mut SERVICE: Service = Service::new();
    static mut SCALE: Scale = Scale::new(ScaleConfig::LAB);
    static mut READER: FrameReader = FrameReader::new();
    let mut host = Uart::uart0(115_200);
    let mut cell = UartCell::new(Uart::uart1(115_200));
    host.wake_on_receive();
    cell.uart().wake_on_receive();
    let mut device = ScaleDevice::new(SERVICE, SCALE, READER);
    let mut page = RamPage;
    device.boot(&mut page);
    loop {
        host.rearm();
        cell.uart().rearm();
        if device.poll(&mut host, &mut cell, &mut page).idle {
            uart::sleep();
        }
    }
}
