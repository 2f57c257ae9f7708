//! The scale's settings (calibration, zero, tare) in a flash page, so they
//! survive a reset: one wire frame ([`primo_device::page`], CRC-checked),
//! read at power-on; a page that does not decode means factory defaults
//! (uncalibrated).
//!
//! Under QEMU the MPS2 AN386's code memory is RAM, so a store is plain
//! writes: the page survives a system reset (QEMU re-copies only the ELF's
//! own segments, and the page is none), not the end of QEMU. A run under
//! QEMU that needs a calibration from the start has the host load the
//! page with the image (`-device loader`), as a factory would program it.
//! On the STM32G431 a store is an erase of the page and double-word
//! programming through the flash controller: the board image
//! (`boards/nucleo-g431`, `primo_device::stm32g4`).

use core::convert::Infallible;

use primo_device::SettingsStore;
use primo_device::page::{self, IMAGE};
use primo_device::scale::Settings;

/// The page: the last 2 KiB of the part's 128 KiB (`memory/scale.x`).
pub const PAGE: usize = 0x0001_F800;

/// The settings kept in the page, if it holds an intact frame.
pub fn load() -> Option<Settings> {
    let mut image = [0u8; IMAGE];
    for (i, slot) in image.iter_mut().enumerate() {
        // SAFETY: within the page, which nothing else maps or writes.
        *slot = unsafe { core::ptr::read_volatile((PAGE + i) as *const u8) };
    }
    page::decode(&image)
}

/// Writes `settings` to the page.
pub fn store(settings: &Settings) {
    let mut buf = [0u8; IMAGE];
    let Ok(image) = page::encode(settings, &mut buf) else {
        return;
    };
    for (i, byte) in image.iter().enumerate() {
        // SAFETY: as in `load`.
        unsafe { core::ptr::write_volatile((PAGE + i) as *mut u8, *byte) };
    }
}

/// The page as the scale's [`SettingsStore`].
pub struct RamPage;

impl SettingsStore for RamPage {
    type Error = Infallible;

    fn load(&mut self) -> Option<Settings> {
        load()
    }

    fn store(&mut self, settings: &Settings) -> Result<(), Infallible> {
        store(settings);
        Ok(())
    }
}
