//! On the Cortex-M4F (under QEMU): an orientation DMP's fit and run give
//! the same bits as on the host (build.rs computed the digest there).
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;
use primo_firmware as _;

#[allow(dead_code, clippy::indexing_slicing)]
mod checks {
    include!("../checks/numerics.rs");
}

const EXPECTED: u64 = include!(concat!(env!("OUT_DIR"), "/expected_orientation.rs"));

#[entry]
fn main() -> ! {
    let got = checks::orientation_digest();
    let ok = got == EXPECTED;
    hprintln!(
        "orientation DMP on the M4F: {:#018x}, host {:#018x}: {}",
        got,
        EXPECTED,
        if ok { "same bits" } else { "DIFFERENT" }
    );
    primo_firmware::exit(ok)
}
