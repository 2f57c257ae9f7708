//! The coprocessor: frames in on UART0, the learner service, replies out.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use primo_firmware::uart::Uart;
use primo_learner::Coprocessor as Service;
use primo_protocol::frame::{FrameReader, MAX_FRAME};

#[entry]
fn main() -> ! {
    // cortex-m-rt turns these into `&'static mut`. A new service is all
    // zero bytes, so its 15 KiB sit in .bss, with no flash image and no
    // temporary on the stack.
    static mut SERVICE: Service = Service::new();
    static mut READER: FrameReader = FrameReader::new();
    let uart = Uart::uart0(115_200);
    let mut out = [0u8; MAX_FRAME];
    loop {
        let byte = uart.read_byte();
        if let Some(raw) = READER.push(byte) {
            uart.write_all(SERVICE.handle(raw, &mut out));
        }
    }
}
