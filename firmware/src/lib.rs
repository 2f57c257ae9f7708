//! primo's firmware on a Cortex-M4F (the MPS2 AN386 board under QEMU): the
//! learning coprocessor and the load-cell scale. Here: the UART driver, the
//! load cell's ADC, the scale's settings page, a stack-depth probe, and the
//! panic handler shared by the images, their footprint probes and the
//! on-target tests.
//!
//! The learning itself is [`primo_learner::Service`], the scale
//! [`primo_device::scale::Scale`], unchanged; the messages between them and
//! the host are [`primo_protocol`]'s.
#![no_std]
#![deny(missing_docs)]
#![deny(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing,
    clippy::unreachable,
    clippy::todo,
    clippy::unimplemented
)]

pub mod load_cell;
pub mod settings;
pub mod uart;

use core::panic::PanicInfo;

use cortex_m_semihosting::{debug, hprintln};

/// Reports the panic over semihosting and exits QEMU with a failure, so a
/// test run fails loudly instead of hanging.
#[panic_handler]
fn panic(info: &PanicInfo) -> ! {
    hprintln!("primo-firmware panicked: {}", info);
    loop {
        debug::exit(debug::EXIT_FAILURE);
    }
}

/// A fault (bad memory access, stack overflow into the statics, …) is
/// reported and ends the run with a failure instead of spinning forever.
#[cortex_m_rt::exception]
unsafe fn HardFault(frame: &cortex_m_rt::ExceptionFrame) -> ! {
    hprintln!("primo-firmware hard fault at pc {:#010x}", frame.pc());
    exit(false)
}

/// Ends the program under QEMU with `ok` as the exit status.
pub fn exit(ok: bool) -> ! {
    loop {
        debug::exit(if ok {
            debug::EXIT_SUCCESS
        } else {
            debug::EXIT_FAILURE
        });
    }
}

/// The paint of free stack words (cortex-m-rt's `paint-stack` value).
const PAINT: u32 = 0xCCCC_CCCC;

/// Stack bytes that `f` uses below the caller: paints the free stack below
/// the current frame (as cortex-m-rt's `paint-stack` does at reset, but
/// around one call), runs
/// `f`, and finds the deepest word that lost its paint.
pub fn stack_used_by(f: impl FnOnce()) -> usize {
    unsafe extern "C" {
        static _stack_end: u32;
    }
    let bottom = core::ptr::addr_of!(_stack_end) as usize;
    let sp = cortex_m::register::msp::read() as usize;
    // Leave this function's own frame and call into `f` alone.
    let limit = sp.saturating_sub(64);
    let mut at = bottom;
    while at < limit {
        // SAFETY: between the statics' end and below the live frames: free
        // stack no one uses now (no interrupts are enabled).
        unsafe { core::ptr::write_volatile(at as *mut u32, PAINT) };
        at += 4;
    }
    f();
    let mut at = bottom;
    // SAFETY: reads of the same free stack.
    while at < sp && unsafe { core::ptr::read_volatile(at as *const u32) } == PAINT {
        at += 4;
    }
    sp - at
}
