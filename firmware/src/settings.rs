//! The scale's settings (calibration, zero, tare) in a flash page, so they
//! survive a reset: one wire frame ([`primo_core::wire`], CRC-checked),
//! read at power-on; a page that does not decode means factory defaults
//! (uncalibrated).
//!
//! Under QEMU the MPS2 AN386's code memory is RAM, so a store is plain
//! writes: the page survives a system reset (QEMU re-copies only the ELF's
//! own segments, and the page is none), not the end of QEMU. A run under
//! QEMU that needs a calibration from the start has the host load the
//! page with the image (`-device loader`), as a factory would program it.
//! On the STM32G431 a store is an erase of the page and double-word
//! programming through the flash controller (not written yet: no board).

use primo_core::scale::Settings;
use primo_core::wire::{self, MAX_FRAME};

/// The page: the last 2 KiB of the part's 128 KiB (`memory/scale.x`).
pub const PAGE: usize = 0x0001_F800;

/// The settings kept in the page, if it holds an intact frame.
pub fn load() -> Option<Settings> {
    let mut frame = [0u8; MAX_FRAME];
    let mut len = 0;
    for (i, slot) in frame.iter_mut().enumerate() {
        // SAFETY: within the page, which nothing else maps or writes.
        let byte = unsafe { core::ptr::read_volatile((PAGE + i) as *const u8) };
        if byte == 0 {
            break;
        }
        *slot = byte;
        len = i + 1;
    }
    let raw = frame.get(..len)?;
    wire::decode::<Settings>(raw).ok().map(|f| f.body)
}

/// Writes `settings` to the page.
pub fn store(settings: &Settings) {
    let mut buf = [0u8; MAX_FRAME];
    let Ok(frame) = wire::encode(0, settings, &mut buf) else {
        return;
    };
    for (i, byte) in frame.iter().enumerate() {
        // SAFETY: as in `load`.
        unsafe { core::ptr::write_volatile((PAGE + i) as *mut u8, *byte) };
    }
}
