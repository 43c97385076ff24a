//! Build script of the STM32F407 board binary: its own `memory.x` (1 MiB flash, model
//! slots in sectors 10/11, 128 KiB RAM) where cortex-m-rt's `link.x` finds it, the
//! linker scripts, and the build-time model key and gyro id (shared with the QEMU
//! firmware: `firmware/build_identity.rs`).

#[path = "../firmware/build_identity.rs"]
mod identity;

use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let dir = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it"));
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=../firmware/build_identity.rs");
    if !env::var("TARGET").unwrap_or_default().starts_with("thumb") {
        return;
    }
    identity::write_identity(&out);
    fs::copy(dir.join("memory.x"), out.join("memory.x")).expect("copy memory.x into OUT_DIR");
    println!("cargo:rustc-link-arg-bins=-L{}", out.display());
    println!("cargo:rustc-link-arg-bins=--nmagic");
    println!("cargo:rustc-link-arg-bins=--icf=all");
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
}
