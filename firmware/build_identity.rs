//! Build-time identity of a firmware image (shared by `firmware/build.rs` and
//! `board-f407/build.rs` through `#[path]`): the model-verifying public key and the gyro
//! id, from `FOG_VERIFY_KEY` (a file: 32 raw bytes or 64 hex digits) and `FOG_GYRO_ID`
//! (1..=16 bytes); with the `test-key` feature they default to the repository's public
//! TEST key and "QEMU-FOG-1". Written to OUT_DIR as `verify_key.bin` and `gyro_id.txt`.

use std::{env, fs, path::PathBuf};

/// Writes `verify_key.bin` and `gyro_id.txt` into OUT_DIR for `fog-app`.
pub fn write_identity(out: &std::path::Path) {
    println!("cargo:rerun-if-env-changed=FOG_VERIFY_KEY");
    println!("cargo:rerun-if-env-changed=FOG_GYRO_ID");
    let test_key = env::var_os("CARGO_FEATURE_TEST_KEY").is_some();
    let root = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it")).join("..");
    let key_path = match env::var_os("FOG_VERIFY_KEY") {
        Some(p) => PathBuf::from(p),
        None if test_key => root.join("keys/TEST-ONLY-public-key.bin"),
        None => panic!(
            "no model-verifying key: set FOG_VERIFY_KEY=<file with the 32-byte Ed25519 public key> \
             (or build with --features test-key for QEMU/CI only)"
        ),
    };
    println!("cargo:rerun-if-changed={}", key_path.display());
    let raw = fs::read(&key_path)
        .unwrap_or_else(|e| panic!("FOG_VERIFY_KEY {}: {e}", key_path.display()));
    let key = parse_key(&raw).unwrap_or_else(|| {
        panic!(
            "FOG_VERIFY_KEY {}: expected 32 raw bytes or 64 hex digits, found {} bytes",
            key_path.display(),
            raw.len()
        )
    });
    let gyro_id = match env::var("FOG_GYRO_ID") {
        Ok(id) => id,
        Err(_) if test_key => "QEMU-FOG-1".to_string(),
        Err(_) => panic!("no gyro id: set FOG_GYRO_ID=<the gyro's id, at most 16 bytes>"),
    };
    assert!(
        !gyro_id.is_empty() && gyro_id.len() <= 16,
        "FOG_GYRO_ID {gyro_id:?}: must be 1..=16 bytes"
    );
    fs::write(out.join("verify_key.bin"), key).expect("write verify_key.bin");
    fs::write(out.join("gyro_id.txt"), gyro_id).expect("write gyro_id.txt");
}

/// 32 raw bytes, or 64 hex digits (surrounding whitespace allowed).
fn parse_key(raw: &[u8]) -> Option<[u8; 32]> {
    if let Ok(key) = <[u8; 32]>::try_from(raw) {
        return Some(key);
    }
    let text = std::str::from_utf8(raw).ok()?.trim();
    if text.len() != 64 {
        return None;
    }
    let mut key = [0u8; 32];
    for (i, b) in key.iter_mut().enumerate() {
        *b = u8::from_str_radix(text.get(2 * i..2 * i + 2)?, 16).ok()?;
    }
    Some(key)
}
