//! A register-level model of the STM32G4 flash controller and its flash
//! memory, from RM0440 ("Embedded flash memory", "FLASH registers"), for
//! the driver's host tests. What it models:
//!
//! - Reset: `FLASH_CR` locked (`LOCK`, `OPTLOCK`), `FLASH_SR` clear,
//!   `FLASH_ACR` with both caches enabled (0x0000_0600); the memory keeps
//!   its bytes.
//! - `FLASH_KEYR`: [`KEY1`] then [`KEY2`] unlock `FLASH_CR`; any other
//!   value or order (or a key while unlocked) locks it until reset and is
//!   a bus error (a HardFault on the part), counted.
//! - `FLASH_CR` ignores writes while locked; `LOCK` written 1 locks it.
//!   Writes while `BSY` (the part stalls or ignores them) are counted as
//!   violations and ignored.
//! - `STRT` with `PER` (and neither `PG` nor `MER1`) erases page `PNB`:
//!   `BSY` for [`ERASE_READS`] reads of `FLASH_SR`, then the page is all
//!   0xFF. With a program error flag still set, or nothing (or too much)
//!   selected, it sets `PGSERR` instead. A write-protected page: `WRPERR`.
//! - Programming: with `PG` set, a 32-bit write to a double word's first
//!   word then one to its second starts it (`BSY` for [`PROGRAM_READS`]
//!   reads); the memory then holds the old bits AND the new (flash bits
//!   only go from 1 to 0 without an erase). A double word not erased:
//!   `PROGERR` (unless the new value is all zeros); a first word at an odd
//!   word or a second not at the next word: `PGAERR`; a write narrower
//!   than 32 bits: `SIZERR`; a write without `PG`, or with a program error
//!   flag still set: `PGSERR`; to a write-protected page: `WRPERR`.
//!   Flash writes while `BSY` are counted as violations.
//! - `EOP` when an operation ends, only while `EOPIE` is set.
//!   `FLASH_SR`'s flags clear by writing 1.
//! - The data cache: while `DCEN` is set, reads fill lines of 32 bytes (8
//!   at most) that later reads are served from, stale after an erase or a
//!   program until `DCRST` (written while `DCEN` is clear; written while
//!   set it is ignored and counted as a violation) or a reset.
//! - Power loss: [`G4Flash::cut_power_after`] counts the driver's
//!   accesses; at zero an erase under way leaves the page partly erased,
//!   a program the double word half programmed, and from then on the
//!   controller is dead (`FLASH_SR` reads all ones: busy forever, every
//!   error) until [`G4Flash::reset`].
//!
//! Not modelled: option bytes (write protection is [`G4Flash::protect`]),
//! fast programming, mass erase, PCROP, ECC, timing beyond read counts.
#![allow(dead_code)]

use primo_device::stm32g4::{
    FLASH_BASE, FlashRegs, KEY1, KEY2, PAGE_SIZE, PAGES, Reg, acr, cr, sr,
};

/// `FLASH_SR` reads an erase stays busy for.
pub const ERASE_READS: u32 = 40;
/// `FLASH_SR` reads a double word's programming stays busy for.
pub const PROGRAM_READS: u32 = 3;
const ACR_RESET: u32 = 0x0000_0600;
const CR_RESET: u32 = cr::LOCK | cr::OPTLOCK;
const LINE: u32 = 32;
const LINES: usize = 8;
const SIZE: usize = PAGE_SIZE as usize * PAGES as usize;

#[derive(Debug, Clone, Copy)]
enum Op {
    Erase { page: u8 },
    Program { address: u32, value: u64 },
}

#[derive(Debug, Clone, Copy)]
struct Busy {
    op: Op,
    left: u32,
    total: u32,
}

/// The controller and its 128 KiB of flash.
pub struct G4Flash {
    /// The flash memory, from [`FLASH_BASE`].
    pub memory: Vec<u8>,
    acr: u32,
    cr: u32,
    sr: u32,
    /// The first key was written.
    key1: bool,
    /// A wrong key sequence: locked until reset.
    lockout: bool,
    busy: Option<Busy>,
    /// A double word's first word, waiting for its second.
    first: Option<(u32, u32)>,
    protected: Vec<u8>,
    cache: Vec<(u32, [u8; LINE as usize])>,
    /// Driver accesses left before the power goes.
    power: Option<u64>,
    dead: bool,
    /// Accesses the driver made (reads, writes, flash writes and reads).
    pub accesses: u64,
    /// Bus errors: wrong key sequences, flash writes outside the memory.
    pub bus_errors: u32,
    /// Accesses the part would stall on or ignore: `FLASH_CR` or flash
    /// writes while busy, `DCRST` with the cache on.
    pub violations: u32,
    /// Erases started.
    pub erases: u32,
    /// Double words programmed.
    pub programs: u32,
}

impl Default for G4Flash {
    fn default() -> Self {
        Self::new()
    }
}

impl G4Flash {
    /// A part fresh from the factory: all flash erased, just reset.
    pub fn new() -> Self {
        G4Flash {
            memory: vec![0xFF; SIZE],
            acr: ACR_RESET,
            cr: CR_RESET,
            sr: 0,
            key1: false,
            lockout: false,
            busy: None,
            first: None,
            protected: Vec::new(),
            cache: Vec::new(),
            power: None,
            dead: false,
            accesses: 0,
            bus_errors: 0,
            violations: 0,
            erases: 0,
            programs: 0,
        }
    }

    /// A system reset (or power back on): registers to their reset
    /// values, the caches empty, the memory as it is.
    pub fn reset(&mut self) {
        self.acr = ACR_RESET;
        self.cr = CR_RESET;
        self.sr = 0;
        self.key1 = false;
        self.lockout = false;
        self.busy = None;
        self.first = None;
        self.cache.clear();
        self.power = None;
        self.dead = false;
    }

    /// Write-protects page `page` (as the option bytes' WRP areas do).
    pub fn protect(&mut self, page: u8) {
        self.protected.push(page);
    }

    /// The power goes after `accesses` more driver accesses.
    pub fn cut_power_after(&mut self, accesses: u64) {
        self.power = Some(accesses);
    }

    /// The power went.
    pub fn dead(&self) -> bool {
        self.dead
    }

    /// `FLASH_SR` as it is, without the side effects of a read.
    pub fn status(&self) -> u32 {
        self.sr | if self.busy.is_some() { sr::BSY } else { 0 }
    }

    /// `FLASH_CR` as it is.
    pub fn control(&self) -> u32 {
        self.cr
    }

    /// Sets `FLASH_SR` flags, as an earlier failed operation leaves them.
    pub fn set_flags(&mut self, flags: u32) {
        self.sr |= flags;
    }

    /// A write to the flash memory of `width` bytes (1, 2 or 4).
    pub fn write_sized(&mut self, address: u32, value: u32, width: u32) {
        if !self.tick() {
            return;
        }
        self.flash_write(address, value, width);
    }

    /// The bytes of page `page`.
    pub fn page(&self, page: u8) -> &[u8] {
        let start = page as usize * PAGE_SIZE as usize;
        &self.memory[start..start + PAGE_SIZE as usize]
    }

    /// Counts one access; false once the power is gone.
    fn tick(&mut self) -> bool {
        if self.dead {
            return false;
        }
        self.accesses += 1;
        if let Some(left) = self.power.as_mut() {
            if *left == 0 {
                self.lose_power();
                return false;
            }
            *left -= 1;
        }
        true
    }

    /// The power goes: an operation under way is left half done.
    fn lose_power(&mut self) {
        self.dead = true;
        let Some(busy) = self.busy.take() else {
            return;
        };
        match busy.op {
            Op::Erase { page } => {
                // Erased up to how far it got, the next double word's
                // cells half way.
                let start = page as usize * PAGE_SIZE as usize;
                let done =
                    (busy.total - busy.left) as usize * PAGE_SIZE as usize / busy.total as usize;
                let done = done / 8 * 8;
                for (i, byte) in self.memory[start..start + PAGE_SIZE as usize]
                    .iter_mut()
                    .enumerate()
                {
                    if i < done {
                        *byte = 0xFF;
                    } else if i < done + 8 {
                        *byte |= 0xF0;
                    }
                }
            }
            Op::Program { address, value } => {
                // The low word's zeros landed, the high word's did not.
                let torn = value | 0xFFFF_FFFF_0000_0000;
                self.merge(address, torn);
            }
        }
    }

    fn offset(address: u32) -> Option<usize> {
        let offset = address.checked_sub(FLASH_BASE)? as usize;
        (offset < SIZE).then_some(offset)
    }

    fn page_of(address: u32) -> u8 {
        ((address - FLASH_BASE) / PAGE_SIZE) as u8
    }

    fn double(&self, address: u32) -> u64 {
        let at = Self::offset(address).unwrap();
        u64::from_le_bytes(self.memory[at..at + 8].try_into().unwrap())
    }

    fn merge(&mut self, address: u32, value: u64) {
        let at = Self::offset(address).unwrap();
        let old = self.double(address);
        self.memory[at..at + 8].copy_from_slice(&(old & value).to_le_bytes());
    }

    fn flash_write(&mut self, address: u32, value: u32, width: u32) {
        let Some(_) = Self::offset(address) else {
            self.bus_errors += 1;
            return;
        };
        if self.busy.is_some() {
            self.violations += 1;
            return;
        }
        if self.cr & cr::PG == 0 || self.sr & sr::PROGRAM_ERRORS != 0 {
            self.sr |= sr::PGSERR;
            self.first = None;
            return;
        }
        if width != 4 {
            self.sr |= sr::SIZERR;
            self.first = None;
            return;
        }
        if self.protected.contains(&Self::page_of(address)) {
            self.sr |= sr::WRPERR;
            self.first = None;
            return;
        }
        match self.first.take() {
            None if address.is_multiple_of(8) => self.first = Some((address, value)),
            Some((first, low)) if address == first + 4 => {
                let value = u64::from(low) | u64::from(value) << 32;
                if self.double(first) != u64::MAX && value != 0 {
                    self.sr |= sr::PROGERR;
                    return;
                }
                self.busy = Some(Busy {
                    op: Op::Program {
                        address: first,
                        value,
                    },
                    left: PROGRAM_READS,
                    total: PROGRAM_READS,
                });
            }
            _ => self.sr |= sr::PGAERR,
        }
    }

    fn write_cr(&mut self, value: u32) {
        if self.cr & cr::LOCK != 0 {
            return;
        }
        if self.busy.is_some() {
            self.violations += 1;
            return;
        }
        if value & cr::LOCK != 0 {
            self.cr |= cr::LOCK;
            self.key1 = false;
        }
        self.cr = (value & !cr::STRT) | (self.cr & cr::LOCK);
        if value & cr::PG == 0 {
            self.first = None;
        }
        if value & cr::STRT == 0 || self.cr & cr::LOCK != 0 {
            return;
        }
        let selected = value & (cr::PG | cr::PER | cr::MER1 | cr::FSTPG);
        if self.sr & sr::PROGRAM_ERRORS != 0 || selected != cr::PER {
            self.sr |= sr::PGSERR;
            return;
        }
        let page = ((value & cr::PNB) >> cr::PNB_SHIFT) as u8;
        if page >= PAGES {
            self.sr |= sr::PGSERR;
            return;
        }
        if self.protected.contains(&page) {
            self.sr |= sr::WRPERR;
            return;
        }
        self.cr |= cr::STRT;
        self.busy = Some(Busy {
            op: Op::Erase { page },
            left: ERASE_READS,
            total: ERASE_READS,
        });
    }

    fn write_keyr(&mut self, value: u32) {
        if self.lockout || self.cr & cr::LOCK == 0 {
            self.wrong_key();
            return;
        }
        match (self.key1, value) {
            (false, KEY1) => self.key1 = true,
            (true, KEY2) => {
                self.key1 = false;
                self.cr &= !cr::LOCK;
            }
            _ => self.wrong_key(),
        }
    }

    fn wrong_key(&mut self) {
        self.lockout = true;
        self.key1 = false;
        self.cr |= cr::LOCK;
        self.bus_errors += 1;
    }

    fn read_sr(&mut self) -> u32 {
        if let Some(busy) = self.busy.as_mut() {
            busy.left -= 1;
            if busy.left == 0 {
                let op = busy.op;
                self.busy = None;
                self.finish(op);
            }
        }
        self.status()
    }

    fn finish(&mut self, op: Op) {
        match op {
            Op::Erase { page } => {
                let start = page as usize * PAGE_SIZE as usize;
                self.memory[start..start + PAGE_SIZE as usize].fill(0xFF);
                self.cr &= !cr::STRT;
                self.erases += 1;
            }
            Op::Program { address, value } => {
                self.merge(address, value);
                self.programs += 1;
            }
        }
        if self.cr & cr::EOPIE != 0 {
            self.sr |= sr::EOP;
        }
    }

    fn write_acr(&mut self, value: u32) {
        if value & acr::DCRST != 0 {
            if self.acr & acr::DCEN != 0 || value & acr::DCEN != 0 {
                self.violations += 1;
            } else {
                self.cache.clear();
            }
        }
        self.acr = value;
    }

    fn read_byte(&mut self, address: u32) -> u8 {
        let Some(at) = Self::offset(address) else {
            self.bus_errors += 1;
            return 0;
        };
        if self.acr & acr::DCEN == 0 {
            return self.memory[at];
        }
        let line = address / LINE * LINE;
        if let Some((_, bytes)) = self.cache.iter().find(|(a, _)| *a == line) {
            return bytes[(address - line) as usize];
        }
        let start = Self::offset(line).unwrap();
        let mut bytes = [0u8; LINE as usize];
        bytes.copy_from_slice(&self.memory[start..start + LINE as usize]);
        if self.cache.len() == LINES {
            self.cache.remove(0);
        }
        self.cache.push((line, bytes));
        self.memory[at]
    }
}

impl FlashRegs for G4Flash {
    fn read(&mut self, reg: Reg) -> u32 {
        if !self.tick() {
            return u32::MAX;
        }
        match reg {
            Reg::Acr => self.acr,
            Reg::Keyr => 0,
            Reg::Sr => self.read_sr(),
            Reg::Cr => self.cr,
        }
    }

    fn write(&mut self, reg: Reg, value: u32) {
        if !self.tick() {
            return;
        }
        match reg {
            Reg::Acr => self.write_acr(value),
            Reg::Keyr => self.write_keyr(value),
            Reg::Sr => self.sr &= !(value & (sr::ERRORS | sr::EOP)),
            Reg::Cr => self.write_cr(value),
        }
    }

    fn program_word(&mut self, address: u32, word: u32) {
        self.write_sized(address, word, 4);
    }

    fn read_flash(&mut self, address: u32, buf: &mut [u8]) {
        if !self.tick() {
            buf.fill(0);
            return;
        }
        for (i, byte) in buf.iter_mut().enumerate() {
            *byte = self.read_byte(address + i as u32);
        }
    }
}
