//! `fogsim upload` on bad local input (issues 17.1, 17.3): counter 0 is refused in one
//! line; a model or key file that is endless (`/dev/zero`) or huge (a 2 GiB sparse file)
//! is refused by its size before it is read, with a short message, before any connection
//! (the port named is closed: reaching it would be another error).

use crate::app_support;

use app_support::{fogsim, scratch_dir, stderr};

/// A loopback port nobody listens on.
const DEAD_PORT: &str = "tcp:127.0.0.1:9";

fn one_short_line(e: &str) -> &str {
    let lines: Vec<&str> = e.lines().filter(|l| !l.contains("WARNING")).collect();
    assert_eq!(lines.len(), 1, "{e}");
    assert!(
        lines[0].len() < 300,
        "{} bytes: {}",
        lines[0].len(),
        &lines[0][..300]
    );
    lines[0]
}

#[test]
fn counter_zero_is_refused_in_one_line() {
    let dir = scratch_dir("upload-zero");
    let o = fogsim(
        &dir,
        &[
            "upload",
            "--port",
            DEAD_PORT,
            "--security-counter",
            "0",
            "m.fogm",
        ],
    );
    assert!(!o.status.success());
    let e = stderr(&o);
    let line = one_short_line(&e);
    assert!(
        line.contains("--security-counter 0") && line.contains("never accepted"),
        "{line}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `fogsim upload` towards the dead port with a scratch registry and `extra` arguments:
/// it must fail, with one short line; that line.
fn refused_upload(dir: &std::path::Path, extra: &[&str]) -> String {
    let mut args = vec!["upload", "--port", DEAD_PORT, "--registry", "reg.sqlite"];
    args.extend_from_slice(extra);
    let o = fogsim(dir, &args);
    assert!(!o.status.success(), "{extra:?} was accepted");
    one_short_line(&stderr(&o)).to_string()
}

/// A sparse file of 2 GiB (`truncate -s 2G`).
fn sparse_2gib(path: &std::path::Path) {
    std::fs::File::create(path)
        .unwrap()
        .set_len(2 << 30)
        .unwrap();
}

#[cfg(unix)]
#[test]
fn endless_and_huge_files_are_refused_before_reading() {
    let dir = scratch_dir("upload-bounds");
    let t0 = std::time::Instant::now();
    // The model: /dev/zero (was read whole: OOM), then a 2 GiB sparse file.
    let line = refused_upload(&dir, &["/dev/zero"]);
    assert!(
        line.contains("/dev/zero") && line.contains("2048 bytes"),
        "{line}"
    );
    sparse_2gib(&dir.join("big.fogm"));
    let line = refused_upload(&dir, &["big.fogm"]);
    assert!(
        line.contains("big.fogm") && line.contains("2048 bytes"),
        "{line}"
    );

    // A valid model, then a 2 GiB sparse key (was echoed back as a 2.1 GB message) and
    // /dev/zero as the key.
    app_support::campaign_and_model(&dir, 3);
    sparse_2gib(&dir.join("big.key"));
    for key in ["big.key", "/dev/zero"] {
        let line = refused_upload(&dir, &["--key", key, "model.bin"]);
        assert!(line.contains(key) && line.contains("256"), "{line}");
    }
    // A key of the right size but not hex: quoted short.
    std::fs::write(dir.join("bad.key"), "z".repeat(64)).unwrap();
    let line = refused_upload(&dir, &["--key", "bad.key", "model.bin"]);
    assert!(
        line.contains("zzzzzzzzzzzz...") && !line.contains(&"z".repeat(13)),
        "{line}"
    );
    assert!(t0.elapsed().as_secs() < 60);
    // Nothing was issued: every refusal came before the registry was touched.
    assert!(!dir.join("reg.sqlite").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
