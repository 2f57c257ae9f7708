//! The settings page's bytes: one wire frame ([`primo_protocol::frame`]: COBS,
//! CRC-32C, the 0x00 delimiter) of the scale's [`Settings`] at the page's
//! start, padded with erased bytes (0xFF) to whole 64-bit double words,
//! the unit an STM32G4 programs. A page that does not begin with an intact
//! frame (erased, torn by a power loss mid-write, or anything else) holds
//! no settings: the scale keeps its factory ones, never garbage.

use primo_protocol::frame::{self as wire, FrameError, MAX_FRAME};

use crate::scale::Settings;

/// The unit a page is written in, bytes (an STM32G4 double word).
pub const UNIT: usize = 8;
/// The longest page image: a whole frame, padded to whole units.
pub const IMAGE: usize = MAX_FRAME.div_ceil(UNIT) * UNIT;
/// An erased byte.
pub const ERASED: u8 = 0xFF;

/// The page image of `settings`, written into `buf`: the frame, then
/// [`ERASED`] bytes to the next whole [`UNIT`].
pub fn encode<'a>(settings: &Settings, buf: &'a mut [u8; IMAGE]) -> Result<&'a [u8], FrameError> {
    let mut frame = [0u8; MAX_FRAME];
    let frame = wire::encode(0, settings, &mut frame)?;
    let len = frame.len().div_ceil(UNIT) * UNIT;
    buf.fill(ERASED);
    buf.get_mut(..frame.len())
        .ok_or(FrameError::Overflow)?
        .copy_from_slice(frame);
    buf.get(..len).ok_or(FrameError::Overflow)
}

/// The settings a page's first bytes hold, if they begin with an intact
/// frame (`page` may be longer: what follows the frame is ignored).
pub fn decode(page: &[u8]) -> Option<Settings> {
    let end = page.iter().take(MAX_FRAME).position(|&b| b == 0)?;
    let frame = wire::decode::<Settings>(page.get(..end)?).ok()?;
    Some(frame.body)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scale::Calibration;

    fn kept() -> Settings {
        Settings {
            calibration: Some(Calibration {
                counts_low: 10_000,
                grams_low: 0.0,
                gain: 0.001,
            }),
            low: None,
            zero: 0.5,
            tare: 110.0,
        }
    }

    #[test]
    fn a_page_image_decodes_to_its_settings_and_is_whole_units() {
        let mut buf = [0u8; IMAGE];
        let image = encode(&kept(), &mut buf).unwrap().to_vec();
        assert_eq!(image.len() % UNIT, 0);
        assert_eq!(decode(&image), Some(kept()));
        // Followed by the rest of an erased page.
        let mut page = image.clone();
        page.resize(2048, ERASED);
        assert_eq!(decode(&page), Some(kept()));
    }

    #[test]
    fn an_erased_or_damaged_page_holds_no_settings() {
        assert_eq!(decode(&[ERASED; 2048]), None);
        assert_eq!(decode(&[0; 2048]), None);
        assert_eq!(decode(&[]), None);
        let mut buf = [0u8; IMAGE];
        let image = encode(&kept(), &mut buf).unwrap().to_vec();
        for i in 0..image.len() {
            for bit in 0..8 {
                let mut bad = image.clone();
                bad[i] ^= 1 << bit;
                let got = decode(&bad);
                assert!(
                    got.is_none() || got == Some(kept()),
                    "byte {i} bit {bit}: {got:?}"
                );
            }
        }
    }
}
