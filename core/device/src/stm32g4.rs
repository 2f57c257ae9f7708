//! The STM32G4 flash controller (RM0440, "Embedded flash memory"): page
//! erase and double-word programming of the settings page, over
//! [`FlashRegs`], the controller's registers and the flash memory as a
//! trait, so that the same sequence runs on the part (a board's adapter
//! over the PAC) and on the host against a model of the controller (the
//! tests).
//!
//! The sequence, as RM0440 gives it:
//!
//! - **Unlock**: after reset `FLASH_CR` is locked (`LOCK`); writing
//!   [`KEY1`] then [`KEY2`] to `FLASH_KEYR` unlocks it. A wrong key or
//!   order locks it until the next reset, and the part raises a bus error
//!   (a HardFault): the driver writes the keys only while `LOCK` is set,
//!   and reports a controller that stays locked as [`FlashError::Locked`].
//! - **Before an operation**: wait until `BSY` clears, then clear the
//!   error flags a previous operation left in `FLASH_SR` (else the next
//!   one fails with `PGSERR`).
//! - **Page erase**: `PER` and the page number `PNB` in `FLASH_CR`, then
//!   `STRT`; wait for `BSY`.
//! - **Programming**: `PG`, then two 32-bit writes to one 64-bit double
//!   word (the first at its address, the second at the next word); wait
//!   for `BSY`. The double word must be erased (else `PROGERR`).
//! - **After each**: the error flags (`WRPERR`, `PGAERR`, `SIZERR`,
//!   `PROGERR`, `MISSERR`, `FASTERR`, `PGSERR`, `OPERR`) are the typed
//!   [`FlashError`]s; `EOP` (set only while `EOPIE` is, so the driver sets
//!   it; the interrupt itself stays off at the NVIC) confirms the end.
//! - **Lock** again (`LOCK`), whatever happened.
//! - **Caches**: the data cache may hold the page's old bytes; it is
//!   reset (disabled, `DCRST`, enabled again) after an erase and after
//!   programming, before the page is read back. The instruction cache is
//!   not: no code runs from the page.
//!
//! The CPU stalls on instruction fetches from flash while an erase or a
//! program runs (the G431 has one bank): a page erase takes up to 40 ms,
//! during which the UART receives into its FIFO only (a request frame sent
//! meanwhile may be lost; the host retransmits).

use crate::scale::Settings;

use crate::SettingsStore;
use crate::page::{self, ERASED, IMAGE, UNIT};

/// The first flash address.
pub const FLASH_BASE: u32 = 0x0800_0000;
/// A page, bytes.
pub const PAGE_SIZE: u32 = 2048;
/// Pages of an STM32G431xB (128 KiB).
pub const PAGES: u8 = 64;
/// The settings' page: the last (0x0801_F800).
pub const SETTINGS_PAGE: u8 = PAGES - 1;
/// `FLASH_KEYR`'s first key.
pub const KEY1: u32 = 0x4567_0123;
/// `FLASH_KEYR`'s second key.
pub const KEY2: u32 = 0xCDEF_89AB;
/// How many times the driver reads `FLASH_SR` for `BSY` to clear before
/// it gives up ([`FlashError::Timeout`]): far longer than a page erase's
/// 40 ms at any clock (a read of the register and a test take at least
/// a few cycles; while an erase runs the CPU stalls on its fetches).
pub const SPINS: u32 = 4_000_000;

/// The address of page `page`'s first byte.
pub const fn page_address(page: u8) -> u32 {
    FLASH_BASE + page as u32 * PAGE_SIZE
}

/// The controller's registers the driver uses (offsets from the
/// controller's base, 0x4002_2000).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reg {
    /// `FLASH_ACR` (0x00): latency, caches.
    Acr,
    /// `FLASH_KEYR` (0x08): the unlock keys (write only).
    Keyr,
    /// `FLASH_SR` (0x10): status and error flags (write 1 to clear).
    Sr,
    /// `FLASH_CR` (0x14): control.
    Cr,
}

impl Reg {
    /// Its offset from the controller's base.
    pub const fn offset(self) -> u32 {
        match self {
            Reg::Acr => 0x00,
            Reg::Keyr => 0x08,
            Reg::Sr => 0x10,
            Reg::Cr => 0x14,
        }
    }
}

/// `FLASH_ACR`'s bits.
pub mod acr {
    /// Data cache enable.
    pub const DCEN: u32 = 1 << 10;
    /// Data cache reset (written only while the data cache is disabled).
    pub const DCRST: u32 = 1 << 12;
}

/// `FLASH_SR`'s bits.
pub mod sr {
    /// End of operation (set only while `FLASH_CR.EOPIE` is).
    pub const EOP: u32 = 1 << 0;
    /// Operation error (set only while `FLASH_CR.ERRIE` is).
    pub const OPERR: u32 = 1 << 1;
    /// Programming error: the double word was not erased.
    pub const PROGERR: u32 = 1 << 3;
    /// Write-protection error.
    pub const WRPERR: u32 = 1 << 4;
    /// Programming alignment error: the two words not of one double word.
    pub const PGAERR: u32 = 1 << 5;
    /// Size error: a byte or half-word write.
    pub const SIZERR: u32 = 1 << 6;
    /// Programming sequence error.
    pub const PGSERR: u32 = 1 << 7;
    /// Fast programming data miss error.
    pub const MISSERR: u32 = 1 << 8;
    /// Fast programming error.
    pub const FASTERR: u32 = 1 << 9;
    /// PCROP read error.
    pub const RDERR: u32 = 1 << 14;
    /// Option validity error.
    pub const OPTVERR: u32 = 1 << 15;
    /// An operation is under way.
    pub const BSY: u32 = 1 << 16;
    /// The flags of a failed program or erase: set, they make the next
    /// operation fail with `PGSERR` until cleared.
    pub const PROGRAM_ERRORS: u32 = PROGERR | WRPERR | PGAERR | SIZERR | PGSERR | MISSERR | FASTERR;
    /// Every flag the driver clears before an operation.
    pub const ERRORS: u32 = OPERR | PROGRAM_ERRORS | RDERR | OPTVERR;
}

/// `FLASH_CR`'s bits.
pub mod cr {
    /// Programming.
    pub const PG: u32 = 1 << 0;
    /// Page erase.
    pub const PER: u32 = 1 << 1;
    /// Mass erase.
    pub const MER1: u32 = 1 << 2;
    /// The page number's lowest bit (`PNB`, bits 3 to 9).
    pub const PNB_SHIFT: u32 = 3;
    /// The page number field.
    pub const PNB: u32 = 0x7F << PNB_SHIFT;
    /// Start an erase.
    pub const STRT: u32 = 1 << 16;
    /// Fast programming.
    pub const FSTPG: u32 = 1 << 18;
    /// End-of-operation interrupt enable (and the `EOP` flag with it).
    pub const EOPIE: u32 = 1 << 24;
    /// Error interrupt enable (and the `OPERR` flag with it).
    pub const ERRIE: u32 = 1 << 25;
    /// Option bytes locked.
    pub const OPTLOCK: u32 = 1 << 30;
    /// `FLASH_CR` locked.
    pub const LOCK: u32 = 1 << 31;
}

/// The flash controller's registers and the flash memory, as a board's
/// adapter reaches them (volatile accesses) or a model does.
pub trait FlashRegs {
    /// Reads a register.
    fn read(&mut self, reg: Reg) -> u32;
    /// Writes a register.
    fn write(&mut self, reg: Reg, value: u32);
    /// One 32-bit write into the flash memory at `address` (half of a
    /// double word being programmed).
    fn program_word(&mut self, address: u32, word: u32);
    /// Reads the flash memory from `address` into `buf`.
    fn read_flash(&mut self, address: u32, buf: &mut [u8]);
}

/// Why an erase, a program or a store failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FlashError {
    /// `FLASH_CR` stayed locked after the keys: a wrong key sequence
    /// earlier locked it until the next reset.
    Locked,
    /// `BSY` did not clear within [`SPINS`] reads of `FLASH_SR`.
    Timeout,
    /// `WRPERR`: the page is write protected (option bytes).
    WriteProtected,
    /// `PGAERR`: the two words were not of one double word.
    Alignment,
    /// `SIZERR`: a write narrower than a word.
    Size,
    /// `PROGERR`: the double word was not erased.
    NotErased,
    /// `MISSERR`: fast programming's data came late.
    Miss,
    /// `FASTERR`: fast programming failed.
    Fast,
    /// `PGSERR`: the controller saw the steps in a wrong order.
    Sequence,
    /// `OPERR`: the operation failed.
    Operation,
    /// The operation ended without an error flag and without `EOP`.
    NoEndOfOperation,
    /// What reads back differs from what was written.
    Verify,
    /// The page is beyond the part, or the data not whole double words
    /// within one page.
    Range,
    /// The settings do not encode into a frame.
    Frame,
}

impl core::fmt::Display for FlashError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            FlashError::Locked => "the flash controller stays locked until reset",
            FlashError::Timeout => "the flash controller stayed busy",
            FlashError::WriteProtected => "the page is write protected",
            FlashError::Alignment => "programming alignment error",
            FlashError::Size => "programming size error",
            FlashError::NotErased => "programming a double word that is not erased",
            FlashError::Miss => "fast programming data miss",
            FlashError::Fast => "fast programming error",
            FlashError::Sequence => "programming sequence error",
            FlashError::Operation => "flash operation error",
            FlashError::NoEndOfOperation => "no end of operation",
            FlashError::Verify => "the page reads back different",
            FlashError::Range => "outside the page or not whole double words",
            FlashError::Frame => "the settings do not fit a frame",
        })
    }
}

impl core::error::Error for FlashError {}

impl FlashError {
    /// The error `FLASH_SR`'s flags say, the most specific first.
    pub fn from_status(status: u32) -> Option<FlashError> {
        [
            (sr::WRPERR, FlashError::WriteProtected),
            (sr::PGAERR, FlashError::Alignment),
            (sr::SIZERR, FlashError::Size),
            (sr::PROGERR, FlashError::NotErased),
            (sr::MISSERR, FlashError::Miss),
            (sr::FASTERR, FlashError::Fast),
            (sr::PGSERR, FlashError::Sequence),
            (sr::OPERR, FlashError::Operation),
        ]
        .into_iter()
        .find_map(|(flag, error)| (status & flag != 0).then_some(error))
    }
}

/// The flash controller's erase and program sequence over `R`.
pub struct Flash<R> {
    regs: R,
    spins: u32,
}

impl<R: FlashRegs> Flash<R> {
    /// The controller behind `regs`, waiting up to [`SPINS`] reads for
    /// an operation.
    pub fn new(regs: R) -> Self {
        Flash { regs, spins: SPINS }
    }

    /// Waits up to `spins` reads of `FLASH_SR` instead.
    pub fn with_spins(mut self, spins: u32) -> Self {
        self.spins = spins;
        self
    }

    /// Its registers (a test's model, to inspect).
    pub fn regs(&mut self) -> &mut R {
        &mut self.regs
    }

    /// Reads the flash memory from `address` into `buf`.
    pub fn read(&mut self, address: u32, buf: &mut [u8]) {
        self.regs.read_flash(address, buf);
    }

    /// Erases page `page` (to [`ERASED`] bytes).
    pub fn erase(&mut self, page: u8) -> Result<(), FlashError> {
        if page >= PAGES {
            return Err(FlashError::Range);
        }
        self.unlocked(|flash| {
            flash.ready()?;
            let cr = flash.regs.read(Reg::Cr) & !(cr::PG | cr::PER | cr::MER1 | cr::PNB);
            let select = cr | cr::EOPIE | cr::PER | (u32::from(page) << cr::PNB_SHIFT);
            flash.regs.write(Reg::Cr, select);
            flash.regs.write(Reg::Cr, select | cr::STRT);
            let done = flash.done();
            let cr = flash.regs.read(Reg::Cr);
            flash
                .regs
                .write(Reg::Cr, cr & !(cr::PER | cr::PNB | cr::EOPIE));
            done
        })
    }

    /// Programs `data` (whole double words, within one page) at `address`
    /// (a double word's), which must be erased.
    pub fn program(&mut self, address: u32, data: &[u8]) -> Result<(), FlashError> {
        let offset = address.wrapping_sub(FLASH_BASE);
        let len = u32::try_from(data.len()).map_err(|_| FlashError::Range)?;
        let in_page = (offset % PAGE_SIZE).checked_add(len);
        if address < FLASH_BASE
            || offset / PAGE_SIZE >= u32::from(PAGES)
            || in_page.is_none_or(|end| end > PAGE_SIZE)
            || !address.is_multiple_of(UNIT as u32)
            || !data.len().is_multiple_of(UNIT)
        {
            return Err(FlashError::Range);
        }
        self.unlocked(|flash| {
            flash.ready()?;
            let cr = flash.regs.read(Reg::Cr) & !(cr::PER | cr::MER1 | cr::PNB | cr::FSTPG);
            flash.regs.write(Reg::Cr, cr | cr::EOPIE | cr::PG);
            let mut result = Ok(());
            let mut at = address;
            for double in data.chunks_exact(UNIT) {
                let (lo, hi) = double.split_at(UNIT / 2);
                flash.regs.program_word(at, word(lo));
                flash.regs.program_word(at + 4, word(hi));
                result = flash.done();
                if result.is_err() {
                    break;
                }
                at += UNIT as u32;
            }
            let cr = flash.regs.read(Reg::Cr);
            flash.regs.write(Reg::Cr, cr & !(cr::PG | cr::EOPIE));
            result
        })
    }

    /// Runs `op` with `FLASH_CR` unlocked, then locks it and resets the
    /// data cache, whatever `op` gave.
    fn unlocked(
        &mut self,
        op: impl FnOnce(&mut Self) -> Result<(), FlashError>,
    ) -> Result<(), FlashError> {
        self.idle()?;
        if self.regs.read(Reg::Cr) & cr::LOCK != 0 {
            self.regs.write(Reg::Keyr, KEY1);
            self.regs.write(Reg::Keyr, KEY2);
            if self.regs.read(Reg::Cr) & cr::LOCK != 0 {
                return Err(FlashError::Locked);
            }
        }
        let result = op(self);
        // Lock even after a failure (once the controller is idle: FLASH_CR
        // does not change while BSY is set).
        let idle = self.idle();
        let cr = self.regs.read(Reg::Cr);
        self.regs.write(Reg::Cr, cr | cr::LOCK);
        self.reset_data_cache();
        result.and(idle.map(drop))
    }

    /// Waits for `BSY` to clear.
    fn idle(&mut self) -> Result<u32, FlashError> {
        for _ in 0..self.spins {
            let status = self.regs.read(Reg::Sr);
            if status & sr::BSY == 0 {
                return Ok(status);
            }
        }
        Err(FlashError::Timeout)
    }

    /// Idle, with the flags of earlier operations cleared.
    fn ready(&mut self) -> Result<(), FlashError> {
        let status = self.idle()?;
        let stale = status & (sr::ERRORS | sr::EOP);
        if stale != 0 {
            self.regs.write(Reg::Sr, stale);
        }
        Ok(())
    }

    /// Waits for the operation started to end; its error, or `EOP`
    /// (cleared).
    fn done(&mut self) -> Result<(), FlashError> {
        let status = self.idle()?;
        let flags = status & (sr::ERRORS | sr::EOP);
        if flags != 0 {
            self.regs.write(Reg::Sr, flags);
        }
        match FlashError::from_status(status) {
            Some(error) => Err(error),
            None if status & sr::EOP == 0 => Err(FlashError::NoEndOfOperation),
            None => Ok(()),
        }
    }

    /// Drops what the data cache holds of the flash (RM0440: `DCRST` is
    /// written only while the cache is disabled).
    fn reset_data_cache(&mut self) {
        let acr = self.regs.read(Reg::Acr);
        if acr & acr::DCEN == 0 {
            return;
        }
        self.regs.write(Reg::Acr, acr & !acr::DCEN);
        self.regs.write(Reg::Acr, (acr & !acr::DCEN) | acr::DCRST);
        self.regs.write(Reg::Acr, acr & !(acr::DCEN | acr::DCRST));
        self.regs.write(Reg::Acr, acr & !acr::DCRST);
    }
}

/// A little-endian word of up to 4 bytes (the flash is little endian, as
/// the core).
fn word(bytes: &[u8]) -> u32 {
    bytes
        .iter()
        .rev()
        .fold(0, |word, byte| word << 8 | u32::from(*byte))
}

/// The scale's settings in a flash page through the controller: a store
/// erases the page and programs the settings' page image ([`page`]),
/// then reads it back; one that would write what the page already holds
/// writes nothing. Power lost mid-store leaves a page whose frame does
/// not check: the next boot finds no settings and the scale starts from
/// its factory ones.
pub struct FlashSettings<R> {
    flash: Flash<R>,
    page: u8,
}

impl<R: FlashRegs> FlashSettings<R> {
    /// The settings in page `page` of `flash` ([`SETTINGS_PAGE`] on a
    /// board).
    pub fn new(flash: Flash<R>, page: u8) -> Self {
        FlashSettings { flash, page }
    }

    /// The controller (a test's model, to inspect).
    pub fn flash(&mut self) -> &mut Flash<R> {
        &mut self.flash
    }

    /// Gives the controller back.
    pub fn release(self) -> Flash<R> {
        self.flash
    }

    /// The page's first [`IMAGE`] bytes.
    fn image(&mut self) -> [u8; IMAGE] {
        let mut held = [ERASED; IMAGE];
        self.flash.read(page_address(self.page), &mut held);
        held
    }
}

impl<R: FlashRegs> SettingsStore for FlashSettings<R> {
    type Error = FlashError;

    fn load(&mut self) -> Option<Settings> {
        if self.page >= PAGES {
            return None;
        }
        page::decode(&self.image())
    }

    fn store(&mut self, settings: &Settings) -> Result<(), FlashError> {
        let mut buf = [0u8; IMAGE];
        let image = page::encode(settings, &mut buf).map_err(|_| FlashError::Frame)?;
        if self.page >= PAGES {
            return Err(FlashError::Range);
        }
        let held = self.image();
        // The frame's delimiter ends it: what follows in the page is not
        // read, so an equal image needs no write.
        if held.get(..image.len()) == Some(image) {
            return Ok(());
        }
        self.flash.erase(self.page)?;
        self.flash.program(page_address(self.page), image)?;
        let held = self.image();
        if held.get(..image.len()) != Some(image) {
            return Err(FlashError::Verify);
        }
        Ok(())
    }
}
