//! What the bad-invocation probe (probe_invocations.rs) found on main, one invocation
//! each, so `cargo test` keeps them fixed whatever sample the probe draws: a bad flag
//! that was ignored (exit 0) or reported under another name, and clap's errors spread
//! over several lines. Each must now fail with one line naming the flag.

use crate::app_support;

use app_support::{fogsim, scratch_dir, stderr};

/// Runs `args`, expects a failure with exactly one stderr line containing `needle`.
fn one_line_naming(dir: &std::path::Path, args: &[&str], needle: &str) {
    let out = fogsim(dir, args);
    let err = stderr(&out);
    assert!(!out.status.success(), "{args:?} accepted");
    assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "{args:?}: one line: {err}");
    assert!(
        lines[0].contains(needle),
        "{args:?}: no `{needle}` in {err}"
    );
}

#[test]
fn flags_the_probe_found_ignored_or_misnamed_are_refused_by_name() {
    let dir = scratch_dir("probe-findings");
    std::fs::write(dir.join("model.bin"), b"any").unwrap();
    let cases: &[(&[&str], &str)] = &[
        // Ignored when --model was given (exit 0).
        (
            &["north-seek", "--model", "model.bin", "--criterion", "bogus"],
            "--criterion",
        ),
        // Ignored without --preset pan (exit 0).
        (
            &["import", "log.csv", "--out", "o", "--axis", "bogus"],
            "--axis",
        ),
        (
            &["import", "log.csv", "--out", "o", "--columns="],
            "--columns",
        ),
        // Reported as `--criterion seek` / `option target-dph` / the simulator's field.
        (
            &["train", "--out", "m.bin", "r.csv", "--seek-dwell-s", "nan"],
            "--seek-dwell-s",
        ),
        (
            &[
                "train",
                "--out",
                "m.bin",
                "r.csv",
                "--seek-latitude-deg=inf",
            ],
            "--seek-latitude-deg",
        ),
        (
            &[
                "heading-cal",
                "--model",
                "model.bin",
                "--out",
                "o.bin",
                "--a-dph",
                "0",
                "--b-dph",
                "1e39",
                "--sigma-dph",
                "0.1",
                "--n-headings",
                "4",
            ],
            "--b-dph",
        ),
        (
            &[
                "rig",
                "--gyro-port",
                "tcp:127.0.0.1:0",
                "--table-port",
                "bogus",
                "--connect-timeout-s",
                "1",
            ],
            "--table-port",
        ),
        (
            &[
                "rig",
                "--gyro-port",
                "tcp:127.0.0.1:0",
                "--table-port",
                "tcp:127.0.0.1:0",
                "--ambient-c=1e400",
            ],
            "--ambient-c",
        ),
        // clap's own errors: several lines before, one now.
        (&["campaign", "--out", "o", "--seed", "abc"], "--seed"),
        (&["campaign", "--out"], "--out"),
        (&["allan", "--no-such-flag"], "--no-such-flag"),
        (&["train", "r.csv"], "--out"),
    ];
    for (args, needle) in cases {
        one_line_naming(&dir, args, needle);
    }
}

#[test]
fn train_config_errors_name_the_flag() {
    let dir = scratch_dir("probe-findings-train");
    for (flag, value) in [("--target-dph", "nan"), ("--widths", "nan")] {
        let out = fogsim(&dir, &["train", "--out", "m.bin", "r.csv", flag, value]);
        let err = stderr(&out);
        assert!(!out.status.success());
        assert!(err.contains(flag), "{flag}: {err}");
    }
}

#[test]
fn a_one_byte_file_is_not_taken_for_an_empty_registry() {
    // SQLite opened it as an empty database and wrote a 28 KB registry over it.
    let dir = scratch_dir("probe-findings-registry");
    std::fs::write(dir.join("one.bin"), [0u8]).unwrap();
    one_line_naming(
        &dir,
        &[
            "registry",
            "--registry",
            "one.bin",
            "export",
            "--csv",
            "o.csv",
        ],
        "one.bin",
    );
    assert_eq!(std::fs::read(dir.join("one.bin")).unwrap(), [0u8]);
}

#[test]
fn field_pull_refuses_a_bad_registry_before_the_link() {
    // Opened only after the pull: the dead link's error was reported instead (after its
    // 10 s of retries), and a directory was skipped as "no registry".
    let dir = scratch_dir("probe-findings-field-pull");
    std::fs::create_dir_all(dir.join("reg-dir")).unwrap();
    std::fs::write(dir.join("reg.bin"), [0u8, 0xFF, 0x13, 0x37]).unwrap();
    for registry in ["reg-dir", "reg.bin"] {
        one_line_naming(
            &dir,
            &[
                "field",
                "pull",
                "--port",
                "tcp:127.0.0.1:9",
                "--registry",
                registry,
                "--out",
                "records",
            ],
            registry,
        );
    }
    assert_eq!(
        std::fs::read(dir.join("reg.bin")).unwrap(),
        [0u8, 0xFF, 0x13, 0x37]
    );
    assert!(!dir.join("records").exists());
}
