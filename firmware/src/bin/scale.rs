//! The load-cell scale, which also serves the learner: frames in on UART0
//! go to the scale or to the learner service, under one sequence; the
//! load cell's counts come in on UART1; streamed readings, and the answer
//! to a weighing that waits for the next stable reading, go out on UART0.
//! Between bytes the core sleeps.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use primo_core::scale::{STREAM, Scale, ScaleConfig};
use primo_core::service::Coprocessor as Service;
use primo_core::wire::{self, FrameReader, MAX_FRAME};
use primo_firmware::load_cell::{LoadCell, UartCell};
use primo_firmware::settings;
use primo_firmware::uart::{self, Uart};

#[entry]
fn main() -> ! {
    // In .bss, as in the coprocessor (see src/main.rs).
    static mut SERVICE: Service = Service::new();
    static mut SCALE: Scale = Scale::new(ScaleConfig::LAB);
    static mut READER: FrameReader = FrameReader::new();
    let host = Uart::uart0(115_200);
    let mut cell = UartCell::new(Uart::uart1(115_200));
    host.wake_on_receive();
    cell.uart().wake_on_receive();
    if let Some(kept) = settings::load() {
        SCALE.restore(kept);
    }
    let mut out = [0u8; MAX_FRAME];
    loop {
        host.rearm();
        cell.uart().rearm();
        let mut idle = true;
        while let Some(byte) = host.try_read_byte() {
            idle = false;
            let Some(raw) = READER.push(byte) else {
                continue;
            };
            host.write_all(SERVICE.handle_with(raw, &mut out, Some(SCALE)));
            if let Some(changed) = SCALE.take_changed() {
                settings::store(changed);
            }
        }
        while let Ok(Some(counts)) = cell.sample() {
            idle = false;
            SCALE.push(counts);
            if let Some(frame) = SERVICE.deferred(SCALE, &mut out) {
                host.write_all(frame);
            }
            if let Some(reading) = SCALE.streamed()
                && let Ok(frame) = wire::encode(STREAM, &reading, &mut out)
            {
                host.write_all(frame);
            }
        }
        if idle {
            uart::sleep();
        }
    }
}
