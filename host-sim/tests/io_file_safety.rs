//! File handling of issue 12, one test per case: an output that is an input is refused
//! (input untouched), outputs are checked before any computation, temporary files never
//! outlive a failure, and the fog-runs reader accepts a BOM and names file:line(:column)
//! for non-UTF-8 bytes, absurd values and over-long input, with bounded messages.

use crate::app_support;

use std::fs;
use std::path::Path;
use std::time::{Duration, Instant};

use app_support::{fogsim, scratch_dir, stderr};
use fog_sim::io::runs::{parse_run, read_run, RunErrorKind};

const GOOD_RUN: &str =
    "# fog-runs v1\n# ambient_c: 20\nt_s,rate_dph,temp_c\n10,0.1,20.0\n20,0.1,20.1\n30,0.1,20.2\n";

/// Runs fogsim, expects a failure whose error line contains every needle.
fn refused(dir: &Path, args: &[&str], needles: &[&str]) -> String {
    let out = fogsim(dir, args);
    let err = stderr(&out);
    assert!(!out.status.success(), "{args:?} should fail");
    assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
    for n in needles {
        assert!(err.contains(n), "{args:?}: error lacks `{n}`: {err}");
    }
    err
}

fn tmp_leftovers(dir: &Path) -> Vec<String> {
    fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains("tmp"))
        .collect()
}

#[test]
fn train_out_equal_to_an_input_is_refused_and_the_input_kept() {
    let dir = scratch_dir("io-train-out");
    fs::create_dir_all(dir.join("c")).unwrap();
    for n in ["a", "b", "d"] {
        fs::write(dir.join(format!("c/{n}.csv")), GOOD_RUN).unwrap();
    }
    let args = ["train", "c/a.csv", "c/b.csv", "c/d.csv", "--out", "c/a.csv"];
    refused(&dir, &args, &["--out", "c/a.csv", "input"]);
    // The same file by another spelling, and through a directory input.
    refused(&dir, &["train", "c", "--out", "./c/../c/b.csv"], &["input"]);
    refused(
        &dir,
        &["train", "c/a.csv", "--json", "c/a.csv", "--out", "m.bin"],
        &["--json"],
    );
    for n in ["a", "b", "d"] {
        assert_eq!(
            fs::read_to_string(dir.join(format!("c/{n}.csv"))).unwrap(),
            GOOD_RUN
        );
    }
    assert!(tmp_leftovers(&dir.join("c")).is_empty());
}

#[test]
fn compensate_json_equal_to_a_run_or_the_model_is_refused() {
    let dir = scratch_dir("io-comp-json");
    fs::write(dir.join("run.csv"), GOOD_RUN).unwrap();
    fs::write(dir.join("model.bin"), b"model bytes, never read").unwrap();
    let base = ["compensate", "run.csv", "--model", "model.bin", "--json"];
    refused(
        &dir,
        &[&base[..], &["run.csv"]].concat(),
        &["--json", "input"],
    );
    refused(
        &dir,
        &[&base[..], &["model.bin"]].concat(),
        &["--json", "input"],
    );
    assert_eq!(fs::read_to_string(dir.join("run.csv")).unwrap(), GOOD_RUN);
    assert_eq!(
        fs::read(dir.join("model.bin")).unwrap(),
        b"model bytes, never read"
    );
}

/// The output checks come before reading, so a bad output is reported even when an
/// input is garbage (reading first would report the garbage) and no training starts.
#[test]
fn outputs_are_checked_before_any_input_is_read_or_trained_on() {
    let dir = scratch_dir("io-early");
    fs::write(dir.join("good.csv"), GOOD_RUN).unwrap();
    fs::write(dir.join("garbage.csv"), "not a fog-runs file\n").unwrap();
    let started = Instant::now();
    refused(
        &dir,
        &[
            "train",
            "good.csv",
            "garbage.csv",
            "--out",
            "missing-dir/m.bin",
        ],
        &["--out", "does not exist"],
    );
    refused(
        &dir,
        &["diagnose", "garbage.csv", "--json", "missing-dir/d.json"],
        &["--json", "does not exist"],
    );
    refused(
        &dir,
        &[
            "compensate",
            "garbage.csv",
            "--model",
            "nope.bin",
            "--json",
            "garbage.csv",
        ],
        &["--json", "input"],
    );
    assert!(started.elapsed() < Duration::from_secs(20));
}

#[test]
fn diagnose_json_to_a_directory_leaves_no_temporary_file() {
    let dir = scratch_dir("io-diag-dir");
    fs::write(dir.join("run.csv"), GOOD_RUN).unwrap();
    fs::create_dir(dir.join("DIR")).unwrap();
    refused(
        &dir,
        &["diagnose", "run.csv", "--json", "DIR"],
        &["--json", "directory"],
    );
    assert!(tmp_leftovers(&dir).is_empty(), "{:?}", tmp_leftovers(&dir));
    assert!(dir.join("DIR").is_dir());
}

#[test]
fn a_utf8_bom_is_accepted() {
    let with_bom = format!("\u{feff}{GOOD_RUN}");
    let run = parse_run(Path::new("bom.csv"), &with_bom).unwrap();
    assert_eq!(run, parse_run(Path::new("bom.csv"), GOOD_RUN).unwrap());
}

#[test]
fn non_utf8_bytes_are_reported_with_file_and_line() {
    let dir = scratch_dir("io-utf8");
    let mut bytes = b"# fog-runs v1\nt_s,rate_dph,temp_c\n10,0.1,20\n20,0.1".to_vec();
    bytes.extend_from_slice(b"\xff\xfe,20\n");
    let p = dir.join("latin.csv");
    fs::write(&p, &bytes).unwrap();
    let e = read_run(&p).unwrap_err();
    assert_eq!((e.kind.clone(), e.line), (RunErrorKind::NotUtf8, Some(4)));
    assert!(e.to_string().contains("latin.csv:4:2"), "{e}");
    // In the metadata too.
    fs::write(
        &p,
        b"# fog-runs v1\n# site: M\xfcnchen\nt_s,rate_dph,temp_c\n1,0,20\n",
    )
    .unwrap();
    let e = read_run(&p).unwrap_err();
    assert_eq!((e.kind, e.line), (RunErrorKind::NotUtf8, Some(2)));
}

#[test]
fn an_absurd_rate_is_rejected_with_file_line_and_column() {
    let text = "# fog-runs v1\nt_s,rate_dph,temp_c\n10,0.1,20\n20,1e300,20.1\n";
    let e = parse_run(Path::new("big.csv"), text).unwrap_err();
    assert!(matches!(e.kind, RunErrorKind::OutOfBounds { .. }), "{e}");
    let msg = e.to_string();
    assert!(msg.starts_with("big.csv:4:2: column `rate_dph`"), "{msg}");
    // A temperature below absolute zero, likewise.
    let cold = "# fog-runs v1\nt_s,rate_dph,temp_c\n10,0.1,-300\n";
    let e = parse_run(Path::new("cold.csv"), cold).unwrap_err();
    assert!(e.to_string().starts_with("cold.csv:3:3"), "{e}");
}

#[test]
fn compensate_and_train_reject_1e300_naming_the_place() {
    let dir = scratch_dir("io-1e300");
    fs::write(
        dir.join("r.csv"),
        "# fog-runs v1\nt_s,rate_dph,temp_c\n10,0.1,20\n20,1e300,20.1\n",
    )
    .unwrap();
    // Enough runs for grouped validation (fewer are refused before any row is read).
    fs::write(dir.join("g1.csv"), GOOD_RUN).unwrap();
    fs::write(dir.join("g2.csv"), GOOD_RUN).unwrap();
    refused(
        &dir,
        &["train", "r.csv", "g1.csv", "g2.csv", "--out", "m.bin"],
        &["r.csv:4:2", "rate_dph"],
    );
    fs::write(dir.join("m.bin"), b"x").unwrap();
    refused(
        &dir,
        &["compensate", "r.csv", "--model", "m.bin"],
        &["r.csv:4:2"],
    );
}

/// A huge line is rejected once it passes the line limit, without being read whole,
/// and every message stays one short line.
#[test]
fn huge_input_is_rejected_early_with_a_bounded_message() {
    let dir = scratch_dir("io-huge");
    let p = dir.join("huge.csv");
    let mut text = String::from("# fog-runs v1\nt_s,rate_dph,temp_c\n");
    text.push_str(&"9".repeat(64 * 1024 * 1024));
    fs::write(&p, &text).unwrap();
    let started = Instant::now();
    let e = read_run(&p).unwrap_err();
    assert!(started.elapsed() < Duration::from_secs(5));
    assert_eq!(
        (e.kind.clone(), e.line),
        (RunErrorKind::LineTooLong, Some(3))
    );
    assert!(e.to_string().len() < 300);
    // A long cell within the limit: quoted, but cut to 200 characters.
    let cell = "x".repeat(50_000);
    let text = format!("# fog-runs v1\nt_s,rate_dph,temp_c\n10,{cell},20\n");
    let e = parse_run(Path::new("long.csv"), &text).unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.lines().count() == 1 && msg.len() < 320,
        "{} chars",
        msg.len()
    );
    assert!(msg.starts_with("long.csv:3:2"), "{}", &msg[..40]);
    // A file whose bad row comes first is rejected at once however long the rest is.
    let mut text = String::from("# fog-runs v1\nt_s,rate_dph,temp_c\n10,abc,20\n");
    text.push_str(&"20,0.1,20\n".repeat(5_000_000));
    fs::write(&p, &text).unwrap();
    let started = Instant::now();
    let e = read_run(&p).unwrap_err();
    assert!(
        started.elapsed() < Duration::from_secs(1),
        "{:?}",
        started.elapsed()
    );
    assert_eq!(e.line, Some(3));
}
