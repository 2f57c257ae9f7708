//! The STM32G4 flash driver against the register-level model of the
//! controller (`model/mod.rs`, from RM0440): first the model itself, then
//! the settings page's store and load over it, a reset, torn writes at
//! every access, and every error as a typed error.

mod model;

use model::{ERASE_READS, G4Flash, PROGRAM_READS};
use primo_device::SettingsStore;
use primo_device::page;
use primo_device::scale::{Calibration, Settings};
use primo_device::stm32g4::{
    Flash, FlashError, FlashRegs, FlashSettings, KEY1, KEY2, PAGE_SIZE, Reg, SETTINGS_PAGE, acr,
    cr, page_address, sr,
};

const PAGE: u32 = page_address(SETTINGS_PAGE);

fn unlock(m: &mut G4Flash) {
    m.write(Reg::Keyr, KEY1);
    m.write(Reg::Keyr, KEY2);
}

fn wait(m: &mut G4Flash) -> u32 {
    loop {
        let status = m.read(Reg::Sr);
        if status & sr::BSY == 0 {
            return status;
        }
    }
}

#[test]
fn the_model_is_locked_after_reset_and_a_wrong_key_locks_it_until_reset() {
    let mut m = G4Flash::new();
    assert_ne!(m.read(Reg::Cr) & cr::LOCK, 0);
    // Locked: writes to FLASH_CR do nothing.
    m.write(Reg::Cr, cr::PER | cr::STRT);
    assert_eq!(m.read(Reg::Cr), cr::LOCK | cr::OPTLOCK);
    unlock(&mut m);
    assert_eq!(m.read(Reg::Cr) & cr::LOCK, 0);
    assert_eq!(m.bus_errors, 0);
    // LOCK locks it again; the keys unlock it again.
    m.write(Reg::Cr, cr::LOCK);
    assert_ne!(m.read(Reg::Cr) & cr::LOCK, 0);
    unlock(&mut m);
    assert_eq!(m.read(Reg::Cr) & cr::LOCK, 0);
    // A wrong second key: locked, and the right keys no longer help.
    m.write(Reg::Cr, cr::LOCK);
    m.write(Reg::Keyr, KEY1);
    m.write(Reg::Keyr, KEY1);
    assert_eq!(m.bus_errors, 1);
    unlock(&mut m);
    assert_ne!(m.read(Reg::Cr) & cr::LOCK, 0);
    // The keys in the wrong order, after a reset: the same.
    m.reset();
    m.write(Reg::Keyr, KEY2);
    m.write(Reg::Keyr, KEY1);
    assert_ne!(m.read(Reg::Cr) & cr::LOCK, 0);
    m.reset();
    unlock(&mut m);
    assert_eq!(m.read(Reg::Cr) & cr::LOCK, 0);
}

#[test]
fn the_model_erases_to_ff_and_programs_erased_double_words_only() {
    let mut m = G4Flash::new();
    m.memory[(PAGE - 0x0800_0000) as usize] = 0x12;
    unlock(&mut m);
    m.write(
        Reg::Cr,
        cr::EOPIE | cr::PER | u32::from(SETTINGS_PAGE) << cr::PNB_SHIFT,
    );
    m.write(Reg::Cr, m.control() | cr::STRT);
    // Busy for ERASE_READS reads of FLASH_SR, then EOP.
    for _ in 1..ERASE_READS {
        assert_ne!(m.read(Reg::Sr) & sr::BSY, 0);
    }
    assert_eq!(m.read(Reg::Sr), sr::EOP);
    assert!(m.page(SETTINGS_PAGE).iter().all(|&b| b == 0xFF));
    m.write(Reg::Sr, sr::EOP);
    // Programming: two words of one double word.
    m.write(Reg::Cr, cr::EOPIE | cr::PG);
    m.program_word(PAGE, 0x0403_0201);
    assert_eq!(m.status() & sr::BSY, 0, "waits for the second word");
    m.program_word(PAGE + 4, 0x0807_0605);
    for _ in 1..PROGRAM_READS {
        assert_ne!(m.read(Reg::Sr) & sr::BSY, 0);
    }
    assert_eq!(m.read(Reg::Sr), sr::EOP);
    assert_eq!(&m.page(SETTINGS_PAGE)[..9], &[1, 2, 3, 4, 5, 6, 7, 8, 0xFF]);
    m.write(Reg::Sr, sr::EOP);
    // Again on the same double word: not erased.
    m.program_word(PAGE, 0);
    m.program_word(PAGE + 4, 1);
    assert_eq!(m.read(Reg::Sr), sr::PROGERR);
    // With the error flag set, the next write is a sequence error.
    m.program_word(PAGE + 8, 0);
    assert_eq!(m.read(Reg::Sr) & sr::PGSERR, sr::PGSERR);
    // And so is an erase.
    m.write(Reg::Sr, sr::PGSERR);
    m.write(
        Reg::Cr,
        cr::PER | u32::from(SETTINGS_PAGE) << cr::PNB_SHIFT | cr::STRT,
    );
    assert_eq!(m.read(Reg::Sr), sr::PROGERR | sr::PGSERR);
    // All zeros may be written over programmed bits.
    m.write(Reg::Sr, sr::ERRORS);
    m.write(Reg::Cr, cr::EOPIE | cr::PG);
    m.program_word(PAGE, 0);
    m.program_word(PAGE + 4, 0);
    assert_eq!(wait(&mut m), sr::EOP);
    assert_eq!(&m.page(SETTINGS_PAGE)[..8], &[0; 8]);
    assert_eq!((m.bus_errors, m.violations), (0, 0));
}

#[test]
fn the_model_flags_order_size_and_sequence_errors() {
    let mut m = G4Flash::new();
    unlock(&mut m);
    // A flash write without PG.
    m.program_word(PAGE, 0);
    assert_eq!(m.read(Reg::Sr), sr::PGSERR);
    m.write(Reg::Sr, sr::PGSERR);
    m.write(Reg::Cr, cr::PG);
    // The second word first.
    m.program_word(PAGE + 4, 0);
    assert_eq!(m.read(Reg::Sr), sr::PGAERR);
    m.write(Reg::Sr, sr::PGAERR);
    // The second word of another double word.
    m.program_word(PAGE, 0);
    m.program_word(PAGE + 12, 0);
    assert_eq!(m.read(Reg::Sr), sr::PGAERR);
    m.write(Reg::Sr, sr::PGAERR);
    // A byte, a half word.
    m.write_sized(PAGE, 0xAB, 1);
    assert_eq!(m.read(Reg::Sr), sr::SIZERR);
    m.write(Reg::Sr, sr::SIZERR);
    m.write_sized(PAGE, 0xABCD, 2);
    assert_eq!(m.read(Reg::Sr), sr::SIZERR);
    m.write(Reg::Sr, sr::SIZERR);
    // STRT with PG set, or with nothing selected.
    m.write(Reg::Cr, cr::PG | cr::PER | cr::STRT);
    assert_eq!(m.read(Reg::Sr), sr::PGSERR);
    m.write(Reg::Sr, sr::PGSERR);
    m.write(Reg::Cr, cr::STRT);
    assert_eq!(m.read(Reg::Sr), sr::PGSERR);
    m.write(Reg::Sr, sr::PGSERR);
    // A write-protected page.
    m.protect(SETTINGS_PAGE);
    m.write(
        Reg::Cr,
        cr::PER | u32::from(SETTINGS_PAGE) << cr::PNB_SHIFT | cr::STRT,
    );
    assert_eq!(m.read(Reg::Sr), sr::WRPERR);
    // Without EOPIE an operation ends without EOP.
    m.write(Reg::Sr, sr::WRPERR);
    m.write(
        Reg::Cr,
        cr::PER | (u32::from(SETTINGS_PAGE) - 1) << cr::PNB_SHIFT | cr::STRT,
    );
    assert_eq!(wait(&mut m), 0);
    assert!(m.page(SETTINGS_PAGE).iter().all(|&b| b == 0xFF));
    assert_eq!(
        m.page(SETTINGS_PAGE)[..8],
        [0xFF; 8],
        "nothing was programmed"
    );
}

fn kept(tare: f32) -> Settings {
    Settings {
        calibration: Some(Calibration {
            counts_low: 10_000,
            grams_low: 0.0,
            gain: 0.001,
        }),
        low: None,
        zero: 0.25,
        tare,
    }
}

/// The settings page of a model, the driver giving up after few reads.
fn store_on(m: G4Flash) -> FlashSettings<G4Flash> {
    FlashSettings::new(Flash::new(m).with_spins(1_000), SETTINGS_PAGE)
}

fn model(s: &mut FlashSettings<G4Flash>) -> &mut G4Flash {
    s.flash().regs()
}

/// The part misused nothing: no bus error (a wrong key), no access it
/// would stall on or ignore; and it is locked again.
fn clean(s: &mut FlashSettings<G4Flash>) {
    let m = model(s);
    assert_eq!((m.bus_errors, m.violations), (0, 0));
    assert_ne!(m.control() & cr::LOCK, 0, "locked after the store");
    assert_eq!(m.control() & (cr::PG | cr::PER | cr::STRT), 0);
}

#[test]
fn settings_survive_a_store_and_a_reset() {
    let mut s = store_on(G4Flash::new());
    assert_eq!(s.load(), None, "an erased page: the factory settings");
    assert_eq!(s.store(&kept(110.0)), Ok(()));
    clean(&mut s);
    // Read at once (the data cache reset after the write) and after a
    // reset.
    assert_eq!(s.load(), Some(kept(110.0)));
    model(&mut s).reset();
    assert_eq!(s.load(), Some(kept(110.0)));
    // The page holds the frame, then erased bytes.
    let mut buf = [0u8; page::IMAGE];
    let image = page::encode(&kept(110.0), &mut buf).unwrap().to_vec();
    let bytes = model(&mut s).page(SETTINGS_PAGE).to_vec();
    assert_eq!(&bytes[..image.len()], &image[..]);
    assert!(bytes[image.len()..].iter().all(|&b| b == 0xFF));
    // A change replaces them; the same settings again write nothing.
    assert_eq!(s.store(&kept(42.5)), Ok(()));
    assert_eq!(s.load(), Some(kept(42.5)));
    let (erases, programs) = (model(&mut s).erases, model(&mut s).programs);
    assert_eq!(erases, 2);
    assert_eq!(programs as usize, 2 * image.len() / 8);
    assert_eq!(s.store(&kept(42.5)), Ok(()));
    assert_eq!(model(&mut s).erases, 2);
    clean(&mut s);
    model(&mut s).reset();
    assert_eq!(s.load(), Some(kept(42.5)));
}

#[test]
fn without_the_data_cache_reset_a_read_after_a_store_could_be_stale() {
    // The model's cache does hold old lines: read the page, erase and
    // program it by hand, read again without DCRST.
    let mut m = G4Flash::new();
    let mut first = [0u8; 8];
    m.read_flash(PAGE, &mut first);
    assert_eq!(first, [0xFF; 8]);
    unlock(&mut m);
    m.write(Reg::Cr, cr::EOPIE | cr::PG);
    m.program_word(PAGE, 0);
    m.program_word(PAGE + 4, 0);
    wait(&mut m);
    let mut again = [0u8; 8];
    m.read_flash(PAGE, &mut again);
    assert_eq!(again, [0xFF; 8], "stale: the cached line");
    m.write(Reg::Acr, 0x600 & !acr::DCEN);
    m.write(Reg::Acr, (0x600 & !acr::DCEN) | acr::DCRST);
    m.write(Reg::Acr, 0x600);
    m.read_flash(PAGE, &mut again);
    assert_eq!(again, [0; 8]);
}

#[test]
fn a_torn_store_gives_the_old_settings_or_none_never_garbage() {
    // How many accesses a whole store takes.
    let mut s = store_on(G4Flash::new());
    s.store(&kept(110.0)).unwrap();
    let before = model(&mut s).accesses;
    s.store(&kept(42.5)).unwrap();
    let whole = model(&mut s).accesses - before;
    let mut outcomes = [0usize; 3];
    for cut in 0..=whole {
        let mut s = store_on(G4Flash::new());
        s.store(&kept(110.0)).unwrap();
        model(&mut s).cut_power_after(cut);
        let result = s.store(&kept(42.5));
        let m = model(&mut s);
        assert!(m.dead() || result.is_ok(), "cut {cut}: {result:?}");
        assert_eq!(m.violations, 0);
        m.reset();
        // The next boot: whatever the page holds, it is the old settings,
        // the new, or none (the factory settings); never anything else.
        match s.load() {
            Some(k) if k == kept(110.0) => outcomes[0] += 1,
            Some(k) if k == kept(42.5) => outcomes[1] += 1,
            None => outcomes[2] += 1,
            Some(other) => panic!("cut {cut}: garbage settings {other:?}"),
        }
        // And the store after the boot succeeds over whatever was left.
        assert_eq!(s.store(&kept(7.0)), Ok(()), "cut {cut}");
        assert_eq!(s.load(), Some(kept(7.0)));
        clean(&mut s);
    }
    // Cut before the erase: the old; cut during the erase or the
    // programming: none; cut after the last double word: the new.
    assert!(outcomes.iter().all(|&n| n > 0), "{outcomes:?}");
    assert!(outcomes[2] as u64 > u64::from(ERASE_READS), "{outcomes:?}");
}

#[test]
fn a_torn_first_store_on_an_erased_page_gives_none() {
    let mut s = store_on(G4Flash::new());
    s.store(&kept(110.0)).unwrap();
    let whole = model(&mut s).accesses;
    for cut in 0..whole {
        let mut s = store_on(G4Flash::new());
        model(&mut s).cut_power_after(cut);
        let _ = s.store(&kept(110.0));
        model(&mut s).reset();
        let got = s.load();
        assert!(
            got.is_none() || got == Some(kept(110.0)),
            "cut {cut}: {got:?}"
        );
    }
}

#[test]
fn failures_are_typed_errors() {
    // A write-protected page: WRPERR, the page untouched, locked again.
    let mut m = G4Flash::new();
    m.protect(SETTINGS_PAGE);
    let mut s = store_on(m);
    assert_eq!(s.store(&kept(1.0)), Err(FlashError::WriteProtected));
    clean(&mut s);
    assert!(model(&mut s).page(SETTINGS_PAGE).iter().all(|&b| b == 0xFF));
    assert_eq!(s.load(), None);

    // A wrong key sequence earlier (someone else's): locked until reset.
    let mut m = G4Flash::new();
    m.write(Reg::Keyr, 0);
    let mut s = store_on(m);
    assert_eq!(s.store(&kept(1.0)), Err(FlashError::Locked));
    model(&mut s).bus_errors = 0;
    clean(&mut s);
    model(&mut s).reset();
    assert_eq!(s.store(&kept(1.0)), Ok(()));

    // Flags an earlier failure left are cleared first.
    let mut m = G4Flash::new();
    m.set_flags(sr::PROGERR | sr::PGSERR | sr::SIZERR | sr::EOP);
    let mut s = store_on(m);
    assert_eq!(s.store(&kept(2.0)), Ok(()));
    assert_eq!(s.load(), Some(kept(2.0)));
    assert_eq!(model(&mut s).status(), 0);

    // A controller that never ends its operation: a timeout, no hang.
    let mut m = G4Flash::new();
    m.cut_power_after(0);
    let mut s = store_on(m);
    assert_eq!(s.store(&kept(3.0)), Err(FlashError::Timeout));

    // Programming over bits an erase did not clear: PROGERR as NotErased.
    let mut flash = Flash::new(G4Flash::new()).with_spins(1_000);
    assert_eq!(flash.program(PAGE, &[0, 1, 2, 3, 4, 5, 6, 7]), Ok(()));
    assert_eq!(flash.program(PAGE, &[1; 8]), Err(FlashError::NotErased));
    assert_eq!(flash.regs().control() & cr::LOCK, cr::LOCK);
    // Only whole double words within a page, only pages of the part.
    assert_eq!(flash.program(PAGE + 4, &[0; 8]), Err(FlashError::Range));
    assert_eq!(flash.program(PAGE, &[0; 7]), Err(FlashError::Range));
    assert_eq!(
        flash.program(PAGE + PAGE_SIZE - 8, &[0; 16]),
        Err(FlashError::Range)
    );
    assert_eq!(flash.program(0x0802_0000, &[0; 8]), Err(FlashError::Range));
    assert_eq!(flash.program(0x2000_0000, &[0; 8]), Err(FlashError::Range));
    assert_eq!(flash.erase(64), Err(FlashError::Range));
    assert_eq!(flash.erase(SETTINGS_PAGE), Ok(()));
    assert_eq!(flash.program(PAGE, &[1; 8]), Ok(()));
    let m = flash.regs();
    assert_eq!((m.bus_errors, m.violations), (0, 0));

    // A page beyond the part.
    let mut s = FlashSettings::new(Flash::new(G4Flash::new()), 64);
    assert_eq!(s.store(&kept(4.0)), Err(FlashError::Range));
    assert_eq!(s.load(), None);
}

#[test]
fn the_error_flags_map_to_typed_errors() {
    for (flag, error) in [
        (sr::WRPERR, FlashError::WriteProtected),
        (sr::PGAERR, FlashError::Alignment),
        (sr::SIZERR, FlashError::Size),
        (sr::PROGERR, FlashError::NotErased),
        (sr::MISSERR, FlashError::Miss),
        (sr::FASTERR, FlashError::Fast),
        (sr::PGSERR, FlashError::Sequence),
        (sr::OPERR, FlashError::Operation),
    ] {
        assert_eq!(FlashError::from_status(flag | sr::EOP), Some(error));
        assert!(!error.to_string().is_empty());
    }
    assert_eq!(FlashError::from_status(sr::EOP | sr::BSY), None);
}
