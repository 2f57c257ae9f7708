//! The load cell's 24-bit ADC behind [`LoadCell`]: a board reads an
//! HX711 or an ADS1232 through `primo_loadcell`'s drivers; under QEMU the
//! host's simulated cell sends the raw counts over UART1
//! ([`primo_device::scale::encode_sample`]).

use core::convert::Infallible;

use primo_device::scale::SampleReader;
pub use primo_loadcell::LoadCell;

use crate::uart::Uart;

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
    type Error = Infallible;

    fn sample(&mut self) -> Result<Option<i32>, Infallible> {
        while let Some(byte) = self.uart.try_read_byte() {
            if let Some(counts) = self.reader.push(byte) {
                return Ok(Some(counts));
            }
        }
        Ok(None)
    }
}
