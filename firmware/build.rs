//! Puts each image's memory layout where its linker finds it (`link.x`
//! includes `memory.x`: the coprocessor's from `memory/coprocessor.x`, the
//! scale's, the footprint probe's and the tests' from `memory/scale.x`),
//! and computes
//! on the host the bits the on-target numerics test must reproduce.
use std::{env, fs, path::PathBuf};

mod checks {
    include!("checks/numerics.rs");
}

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    for image in ["coprocessor", "scale"] {
        let dir = out.join(image);
        fs::create_dir_all(&dir).expect("OUT_DIR is writable");
        fs::copy(format!("memory/{image}.x"), dir.join("memory.x")).expect("memory/ is readable");
        println!("cargo:rerun-if-changed=memory/{image}.x");
    }
    let (coprocessor, scale) = (out.join("coprocessor"), out.join("scale"));
    println!(
        "cargo:rustc-link-arg-bin=primo-firmware=-L{}",
        coprocessor.display()
    );
    // The probe carries the measuring code besides the images' own: it
    // takes the larger part's room.
    for bin in ["primo-scale", "footprint"] {
        println!("cargo:rustc-link-arg-bin={bin}=-L{}", scale.display());
    }
    // The on-target tests carry code no image has (the numerics test fits
    // DMPs, which only the host does): they take the larger part's room.
    println!("cargo:rustc-link-arg-tests=-L{}", scale.display());
    for (file, digest) in [
        ("expected.rs", checks::digest()),
        ("expected_orientation.rs", checks::orientation_digest()),
    ] {
        fs::write(out.join(file), format!("{digest:#018x}")).expect("OUT_DIR is writable");
    }
    println!("cargo:rerun-if-changed=checks/numerics.rs");
    println!("cargo:rerun-if-changed=../core/core/src");
    println!("cargo:rerun-if-changed=../core/protocol/src");
}
