//! Same seed, same report bytes: every JSON report writer (`train --json`, `compensate
//! --json`, `north-seek --json`, `reproduce --json` (the demo's `report.json` is the same
//! writer on a bigger campaign), `diagnose --json`) runs twice on the same inputs and seed
//! and must write byte-identical files. Wall times are kept out of the JSON for this; the
//! runs that fan out use a different thread count the second time, so a result that
//! depended on scheduling would show too. Small campaign, a few seconds in all.

use crate::app_support;

use std::path::Path;

use app_support::{fogsim, scratch_dir, stderr};

/// Runs `fogsim args extra[0] --json NAME_1.json`, then `fogsim args extra[1] --json
/// NAME_2.json`, and asserts both reports are byte-identical and not trivially short.
fn twice_identical(dir: &Path, name: &str, args: &[&str], extra: [&[&str]; 2]) {
    let files = [format!("{name}_1.json"), format!("{name}_2.json")];
    for (json, more) in files.iter().zip(extra) {
        let run: Vec<&str> = args
            .iter()
            .chain(more)
            .copied()
            .chain(["--json", json])
            .collect();
        let out = fogsim(dir, &run);
        assert!(out.status.success(), "{run:?}: {}", stderr(&out));
    }
    let [x, y] = files.map(|f| std::fs::read(dir.join(f)).unwrap());
    assert!(x.len() > 100, "{name}: report too short");
    if x != y {
        let at = x
            .iter()
            .zip(&y)
            .position(|(p, q)| p != q)
            .unwrap_or(x.len().min(y.len()));
        let show = |v: &[u8]| {
            String::from_utf8_lossy(&v[at.saturating_sub(80)..(at + 80).min(v.len())]).into_owned()
        };
        panic!(
            "{name}: reports differ at byte {at}:\n{}\n---\n{}",
            show(&x),
            show(&y)
        );
    }
}

#[test]
fn every_json_report_is_byte_identical_for_the_same_seed() {
    let dir = scratch_dir("report-bytes");
    let out = fogsim(
        &dir,
        &[
            "campaign",
            "--out",
            "runs",
            "--ambient-c=0,20",
            "--runs",
            "2",
            "--duration-min",
            "30",
            "--raw-rate-hz",
            "1",
            "--seed",
            "3",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));

    // Training: the JSON once carried the wall times of validation and of the final fit.
    twice_identical(
        &dir,
        "train",
        &["train", "runs"],
        [&["--out", "model_1.bin"], &["--out", "model_2.bin"]],
    );
    assert_eq!(
        std::fs::read(dir.join("model_1.bin")).unwrap(),
        std::fs::read(dir.join("model_2.bin")).unwrap(),
        "the same runs train the same model bytes"
    );
    twice_identical(
        &dir,
        "compensate",
        &["compensate", "runs", "--model", "model_1.bin"],
        [&[], &[]],
    );
    twice_identical(
        &dir,
        "north_seek",
        &[
            "north-seek",
            "--model",
            "model_1.bin",
            "--starts",
            "2",
            "--seeks",
            "2",
            "--seed",
            "5",
        ],
        [&["--threads", "1"], &["--threads", "2"]],
    );
    twice_identical(
        &dir,
        "reproduce",
        &[
            "reproduce",
            "--ambient-c",
            "0,20",
            "--runs",
            "4",
            "--duration-min",
            "30",
            "--starts",
            "2",
            "--qualification-runs",
            "6",
            "--seed",
            "7",
        ],
        [&["--threads", "1"], &["--threads", "2"]],
    );
    twice_identical(&dir, "diagnose", &["diagnose", "runs"], [&[], &[]]);
    let _ = std::fs::remove_dir_all(&dir);
}
