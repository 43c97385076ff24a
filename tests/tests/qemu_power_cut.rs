//! QEMU scenario (issue 17 item 6): a power cut during an upload, across a real QEMU
//! restart. `fog-app` keeps its model flash in a host file (`flash-file=models.img`,
//! written through at every flash write). With `flash-cut-at=K` the K-th write to that
//! file is not made: the firmware prints `FOG-FLASH-CUT write=K` and waits, and the test
//! kills QEMU there (SIGKILL, no shutdown), which is a power cut between two flash
//! operations at a known point of the commit. QEMU is then started again on the same
//! file: the old model must be the one in use (intact, signature verified), the
//! half-written slot must be refused as what it is (never used), and a new upload must
//! go through. Cut points: the first write (slot erase), the middle, the last body
//! write, the header and the commit marker (the commit's last write); a commit that
//! reaches its end is in use after the restart (run 2). `FOG_POWER_CUT_ALL=1` cuts at
//! every write of the commit instead (about 45 restarts).
//!
//! Skips loudly without QEMU / the target unless FOG_REQUIRE_QEMU=1. Every wait is
//! bounded; QEMU is killed when each run ends.

use crate::qemu_support;
use crate::upload_support;

use std::net::TcpStream;
use std::path::Path;
use std::sync::mpsc::Receiver;
use std::time::Duration;

use fog_core::link::upload::ModelInfo;
use fog_core::model::crc::crc32;
use fog_sim::device::upload::UploadClient;
use fog_tests::console::wait_line;
use fog_tests::{qemu_ready, scratch_dir, KillOnDrop};
use qemu_support::boot_in;
use upload_support::*;

const WAIT: Duration = Duration::from_secs(30);

/// One QEMU process on `dir/models.img` with `extra` arguments.
fn boot(dir: &Path, extra: &[String]) -> (KillOnDrop, TcpStream, Receiver<String>) {
    let mut args = vec!["flash-file=models.img".to_string()];
    args.extend_from_slice(extra);
    boot_in(dir, args)
}

fn upload(link: &TcpStream, bytes: &[u8], counter: u32) -> ModelInfo {
    UploadClient::new(link.try_clone().unwrap(), Duration::from_secs(20))
        .upload(
            bytes,
            counter,
            &sign_for_gyro(counter, QEMU_GYRO, bytes),
            |_, _| {},
        )
        .expect("upload")
}

/// The writes to the image that a commit of `bytes` made (its console line).
fn committed_writes(console: &Receiver<String>) -> u32 {
    let line = wait_line(console, "FOG-COMMITTED flash_writes=", WAIT);
    line.rsplit('=').next().unwrap().parse().unwrap()
}

#[test]
fn qemu_power_cut_during_an_upload_keeps_the_old_model_across_a_restart() {
    if !qemu_ready("qemu_power_cut") {
        return;
    }
    let dir = scratch_dir("qemu_power_cut");
    let image = dir.join("models.img");
    let old = encode(&sample_model(QEMU_GYRO, 35, 1.0));
    let new = encode(&sample_model(QEMU_GYRO, 48, 0.5));

    // Run 1: model A (counter 1) in slot A; the file is the baseline of every cut.
    let old_info = {
        let (_qemu, link, console) = boot(&dir, &[]);
        let info = upload(&link, &old, 1);
        committed_writes(&console);
        info
    };
    let baseline = std::fs::read(&image).unwrap();

    // Run 2: how many writes B's commit makes, uncut; after a restart B is in use.
    let writes = {
        let (_qemu, link, console) = boot(&dir, &[]);
        upload(&link, &new, 2);
        committed_writes(&console)
    };
    {
        let (_qemu, _link, console) = boot(&dir, &[]);
        wait_line(&console, "FOG-SLOT B in use", WAIT);
    }
    assert!(
        writes >= 5,
        "a commit erases, writes the body, header, marker"
    );

    let cuts: Vec<u32> = if std::env::var_os("FOG_POWER_CUT_ALL").is_some() {
        (1..=writes).collect()
    } else {
        vec![1, writes / 2, writes - 2, writes - 1, writes]
    };
    for k in cuts {
        std::fs::write(&image, &baseline).unwrap();
        // The cut: B's upload stops before write k; QEMU is killed there.
        {
            let (qemu, link, console) = boot(&dir, &[format!("flash-cut-at={k}")]);
            let bytes = new.clone();
            let uploader = std::thread::spawn(move || {
                UploadClient::new(link, Duration::from_secs(5))
                    .upload(&bytes, 2, &sign_for_gyro(2, QEMU_GYRO, &bytes), |_, _| {})
                    .is_ok()
            });
            wait_line(&console, &format!("FOG-FLASH-CUT write={k} "), WAIT);
            drop(qemu);
            assert!(
                !uploader.join().unwrap(),
                "cut {k}: the commit never finished"
            );
        }
        assert_eq!(std::fs::read(&image).unwrap().len(), baseline.len());
        // The restart on the same file: the old model runs, the torn slot is refused.
        let (_qemu, link, console) = boot(&dir, &[]);
        wait_line(&console, "FOG-FLASH file=models.img loaded", WAIT);
        wait_line(&console, "FOG-SLOT A in use", WAIT);
        let b = wait_line(&console, "FOG-SLOT B ", WAIT);
        assert!(
            b == "FOG-SLOT B empty" || b.starts_with("FOG-SLOT B refused:"),
            "cut {k}: the torn slot is never used: {b}"
        );
        let mut client = UploadClient::new(link.try_clone().unwrap(), Duration::from_secs(20));
        let status = client.status().expect("status after the restart");
        assert_eq!(status.active, Some(old_info.clone()), "cut {k}");
        // And the store takes the upload again.
        let info = upload(&link, &new, 2);
        assert_eq!((info.slot, info.model_crc32), (1, crc32(&new)), "cut {k}");
        eprintln!("cut at write {k} of {writes}: old model kept, slot B {b:?}, re-upload ok");
    }
}
