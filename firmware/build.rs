//! Puts `memory.x` where the linker finds it, and computes on the host the
//! bits the on-target numerics test must reproduce.
use std::{env, fs, path::PathBuf};

mod checks {
    include!("checks/numerics.rs");
}

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    fs::copy("memory.x", out.join("memory.x")).expect("memory.x is readable");
    println!("cargo:rustc-link-search={}", out.display());
    for (file, digest) in [
        ("expected.rs", checks::digest()),
        ("expected_orientation.rs", checks::orientation_digest()),
    ] {
        fs::write(out.join(file), format!("{digest:#018x}")).expect("OUT_DIR is writable");
    }
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=checks/numerics.rs");
    println!("cargo:rerun-if-changed=../core/src");
}
