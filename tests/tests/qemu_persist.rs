//! QEMU scenario (issue 11 item 5): the model store persists across a QEMU restart.
//!
//! `fog-app` runs under `qemu-system-arm -machine mps2-an386` with the semihosting
//! argument `flash-file=models.img`: its model region is mirrored into that host file
//! (`fog_firmware::store::mirrored`, `src/bin/target/flash_file.rs`). The scenario
//! uploads two signed models over the host link, kills QEMU (no clean shutdown), starts
//! it again on the same file and finds the newer model active; then flips one byte of
//! a stored model in the file: the next boot refuses that slot, says why on its
//! console (`FOG-SLOT B refused: ...`), falls back to the older intact model and keeps
//! answering; with both slots damaged it runs without a model. A file that is not a
//! flash image is refused whole and left as it was.
//!
//! The boot with a stored model in use also bounds fog-app's painted boot stack peak
//! (`FOG-STACK`); with `FOG_BUDGETS_BOOT_STACK_OUT=<file>` its budget-table row is
//! written there (scripts/budgets.sh).
//!
//! Skips loudly without QEMU / the target unless FOG_REQUIRE_QEMU=1. Every wait is
//! bounded; QEMU is killed when each run ends.

use crate::qemu_support;
use crate::upload_support;

use std::net::TcpStream;
use std::path::Path;
use std::sync::mpsc::Receiver;
use std::time::Duration;

use fog_core::link::upload::{DeviceStatus, ModelInfo, ResetCause};
use fog_sim::device::upload::UploadClient;
use fog_tests::console::wait_line;
use fog_tests::{qemu_ready, scratch_dir, KillOnDrop};
use qemu_support::boot_in;
use upload_support::*;

/// The model region of the QEMU build: the last 16 KiB of flash (memory.x).
const IMAGE_LEN: usize = 16 * 1024;
const WAIT: Duration = Duration::from_secs(30);
/// Bound on fog-app's painted boot stack peak with a model in use (store scan, Ed25519
/// re-check, model decode, configuration): measured 13,668 B, bound +1,436 B (10.5 %).
/// The model decoded on the stack again (+1,664 B: 15,332 B) trips it; it was 29,660 B
/// with the upload server and the model built by value (docs/explain/stack.md).
const BOOT_STACK_BOUND_B: usize = 15_104;

/// One QEMU process on `file` (relative to `dir`): QEMU, the host link, the console.
fn boot(dir: &Path, file: &str) -> (KillOnDrop, UploadClient<TcpStream>, Receiver<String>) {
    let (qemu, link, console) = boot_in(dir, vec![format!("flash-file={file}")]);
    (
        qemu,
        UploadClient::new(link, Duration::from_secs(20)),
        console,
    )
}

/// Flips every bit of the byte in the middle of `needle`'s copy in `path`.
fn flip_byte_inside(path: &Path, needle: &[u8]) {
    let mut image = std::fs::read(path).unwrap();
    let at = image
        .windows(needle.len())
        .position(|w| w == needle)
        .expect("the model's bytes are in the flash image");
    image[at + needle.len() / 2] ^= 0xFF;
    std::fs::write(path, image).unwrap();
}

/// A status answered after a boot that was not a reset loop.
fn first_boot_status(client: &mut UploadClient<TcpStream>) -> DeviceStatus {
    let status = client.status().expect("the firmware answers after booting");
    assert_eq!(
        (status.last_reset.cause, status.last_reset.boots),
        (ResetCause::PowerOn, 1),
        "booted once, no reset"
    );
    status
}

/// The painted stack peak of a boot that verified and decoded a stored model
/// (`FOG-STACK boot_peak_bytes=N of=M`, fog-app's console), bounded: docs/explain/stack.md.
fn check_boot_stack(console: &Receiver<String>) {
    let line = wait_line(console, "FOG-STACK boot_peak_bytes=", WAIT);
    let field = |key: &str| -> usize {
        line.split_whitespace()
            .find_map(|w| w.strip_prefix(key))
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("stack line lacks `{key}N`: {line}"))
    };
    let (peak, stack) = (field("boot_peak_bytes="), field("of="));
    eprintln!("qemu_persist: fog-app boot stack peak {peak} B of {stack} B (model in use)");
    assert!(
        peak > 256 && peak < BOOT_STACK_BOUND_B,
        "fog-app boot stack peak {peak} bytes is implausible or over {BOOT_STACK_BOUND_B} B \
         (a model or the upload server built by value on the stack? docs/explain/stack.md)"
    );
    if let Ok(path) = std::env::var("FOG_BUDGETS_BOOT_STACK_OUT") {
        let row = format!(
            "| stack peak at boot, `fog-app` (store scan, signature re-check, model decode; painted) \
             | {peak} B | CI bound {BOOT_STACK_BOUND_B} B |\n"
        );
        std::fs::write(path, row).expect("write the boot stack row");
    }
}

#[test]
fn qemu_model_survives_restart_and_a_flipped_byte_is_refused_with_its_reason() {
    if !qemu_ready("qemu_persist") {
        return;
    }
    let dir = scratch_dir("qemu_persist");
    let image = dir.join("models.img");
    let first = encode(&sample_model(QEMU_GYRO, 35, 1.0));
    let second = encode(&sample_model(QEMU_GYRO, 48, 0.5));

    // Run 1: a new file; two signed models (slot A, then slot B); QEMU killed.
    let (info1, info2): (ModelInfo, ModelInfo) = {
        let (_qemu, mut client, console) = boot(&dir, "models.img");
        wait_line(&console, "FOG-FLASH file=models.img created", WAIT);
        let status = first_boot_status(&mut client);
        assert_eq!(status.active, None, "a new flash holds no model");
        let info1 = client
            .upload(&first, 1, &sign_for_gyro(1, QEMU_GYRO, &first), |_, _| {})
            .expect("upload 1");
        let info2 = client
            .upload(&second, 2, &sign_for_gyro(2, QEMU_GYRO, &second), |_, _| {})
            .expect("upload 2");
        assert_eq!((info1.slot, info2.slot), (0, 1));
        (info1, info2)
    };
    assert_eq!(std::fs::read(&image).unwrap().len(), IMAGE_LEN);

    // Run 2: same file, the newer model is active without any upload.
    {
        let (_qemu, mut client, console) = boot(&dir, "models.img");
        wait_line(&console, "FOG-FLASH file=models.img loaded", WAIT);
        wait_line(&console, "FOG-SLOT A standby", WAIT);
        wait_line(&console, "FOG-SLOT B in use", WAIT);
        check_boot_stack(&console);
        assert_eq!(first_boot_status(&mut client).active, Some(info2.clone()));
    }

    // Run 3: one byte of the newer model flipped in the file: refused with its
    // reason, the older intact model is used, the firmware answers.
    flip_byte_inside(&image, &second);
    {
        let (_qemu, mut client, console) = boot(&dir, "models.img");
        wait_line(&console, "FOG-FLASH file=models.img loaded", WAIT);
        wait_line(&console, "FOG-SLOT A in use", WAIT);
        wait_line(
            &console,
            "FOG-SLOT B refused: model bytes do not match the header CRC-32",
            WAIT,
        );
        assert_eq!(first_boot_status(&mut client).active, Some(info1.clone()));
    }

    // Run 4: both slots damaged: no model, still running and answering.
    flip_byte_inside(&image, &first);
    {
        let (_qemu, mut client, console) = boot(&dir, "models.img");
        wait_line(&console, "FOG-SLOT A refused: model bytes", WAIT);
        wait_line(&console, "FOG-SLOT B refused: model bytes", WAIT);
        assert_eq!(first_boot_status(&mut client).active, None);
    }
}

#[test]
fn qemu_file_that_is_not_a_flash_image_is_refused_whole_and_kept() {
    if !qemu_ready("qemu_persist") {
        return;
    }
    let dir = scratch_dir("qemu_persist_bad");
    let short = dir.join("short.img");
    let content: Vec<u8> = (0..IMAGE_LEN / 2).map(|i| (i % 251) as u8).collect();
    std::fs::write(&short, &content).unwrap();
    let (_qemu, mut client, console) = boot(&dir, "short.img");
    let line = wait_line(&console, "FOG-FLASH file=short.img refused:", WAIT);
    assert!(line.contains("8192") && line.contains("16384"), "{line}");
    assert_eq!(first_boot_status(&mut client).active, None);
    assert_eq!(
        std::fs::read(&short).unwrap(),
        content,
        "a refused file is never written"
    );
}
