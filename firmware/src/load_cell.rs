//! The load cell's 24-bit ADC behind a small trait: a board reads an HX711
//! or an ADS1232 here; under QEMU the host's simulated cell sends the raw
//! counts over UART1 ([`primo_core::scale::encode_sample`]).

use primo_core::scale::SampleReader;

use crate::uart::Uart;

/// A 24-bit load-cell ADC, polled.
pub trait LoadCell {
    /// The next conversion's counts, if one is ready; `None` means
    /// nothing more is waiting.
    fn sample(&mut self) -> Option<i32>;
}

/// The counts arriving on a UART, as the host's simulated cell sends
/// them; damaged samples are dropped.
pub struct UartCell {
    uart: Uart,
    reader: SampleReader,
}

impl UartCell {
    /// Samples from `uart`.
    pub fn new(uart: Uart) -> Self {
        UartCell {
            uart,
            reader: SampleReader::new(),
        }
    }

    /// Its UART, to sleep on.
    pub fn uart(&self) -> &Uart {
        &self.uart
    }
}

impl LoadCell for UartCell {
    fn sample(&mut self) -> Option<i32> {
        loop {
            let byte = self.uart.try_read_byte()?;
            if let Some(counts) = self.reader.push(byte) {
                return Some(counts);
            }
        }
    }
}
