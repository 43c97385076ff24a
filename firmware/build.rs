//! Build script: puts `memory.x` where cortex-m-rt's `link.x` finds it and passes the
//! linker scripts to the firmware binaries only (the portable library and its host
//! tests never see them). Linker arguments live here rather than in rustflags because
//! rustflags apply only when cargo is run from the directory holding `.cargo/`.
//!
//! It also chooses the model-verifying key and the gyro id `fog-app` is bound to, at
//! build time: `FOG_VERIFY_KEY` (a file holding the 32-byte Ed25519 public key, raw or
//! as 64 hex digits) and `FOG_GYRO_ID` (at most 16 bytes). Only with the `test-key`
//! feature (QEMU and CI builds) do they default to the repository's public TEST key and
//! gyro "QEMU-FOG-1"; any other target build without them fails here.

#[path = "build_identity.rs"]
mod identity;

use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    // In the crate, not the workspace root: the linker looks in its working directory
    // (the workspace root) before any search path, so a root memory.x would also be
    // linked into the STM32F407 board binary.
    let memory_x =
        PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it")).join("memory.x");
    println!("cargo:rerun-if-changed={}", memory_x.display());
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=build_identity.rs");

    let target = env::var("TARGET").unwrap_or_default();
    if !target.starts_with("thumb") {
        return;
    }
    if env::var_os("CARGO_FEATURE_TARGET").is_some() {
        identity::write_identity(&out);
    }
    fs::copy(&memory_x, out.join("memory.x")).expect("copy memory.x into OUT_DIR");
    // Only this package's binaries search OUT_DIR: a search path of the library would
    // reach every crate linking it (the STM32F407 board crate has its own memory.x).
    println!("cargo:rustc-link-arg-bins=-L{}", out.display());
    println!("cargo:rustc-link-arg-bins=--nmagic");
    // Fold identical functions (monomorphised copies): smaller flash, same behaviour.
    println!("cargo:rustc-link-arg-bins=--icf=all");
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
}
