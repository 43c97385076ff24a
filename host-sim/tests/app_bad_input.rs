//! Bad input to `compensate`, `north-seek`, `reproduce`: a one-line error naming the file,
//! line or option, a non-zero exit, no panic and no output file.

use crate::app_support;

use std::path::Path;

use app_support::{fogsim, scratch_dir, stderr};

/// Runs fogsim, expects failure with one error line containing every `needle`, and checks
/// that `report.json` was not created.
fn rejects(dir: &Path, args: &[&str], needles: &[&str]) {
    let out = fogsim(dir, args);
    let err = stderr(&out);
    assert!(!out.status.success(), "{args:?} should fail");
    assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
    let line = err
        .lines()
        .find(|l| l.contains("error"))
        .unwrap_or_else(|| panic!("{args:?}: no error line: {err}"));
    for n in needles {
        assert!(line.contains(n), "{args:?}: error line lacks `{n}`: {line}");
    }
    assert!(
        !dir.join("report.json").exists(),
        "{args:?} left a report behind"
    );
}

const GOOD_RUN: &str =
    "# fog-runs v1\n# ambient_c: 20\nt_s,rate_dph,temp_c\n10,0.1,20.0\n20,0.1,20.1\n30,0.1,20.2\n";

/// The options that shape the model `north-seek` trains (`--inputs`, `--training-runs`,
/// `--save-model`, `--training-restarts-above-c`): with `--model` they would be ignored,
/// so each is refused by name; an impossible value is refused with the allowed ones.
#[test]
fn training_options_are_refused_by_name() {
    let dir = scratch_dir("bad-training");
    std::fs::write(dir.join("garbage.bin"), b"not a model at all").unwrap();
    let json = ["--json", "report.json"];
    rejects(
        &dir,
        &[
            &["north-seek", "--model", "garbage.bin", "--inputs", "t,rise"][..],
            &json,
        ]
        .concat(),
        &["--inputs", "--model garbage.bin"],
    );
    rejects(
        &dir,
        &[
            &[
                "north-seek",
                "--model",
                "garbage.bin",
                "--save-model",
                "m.bin",
            ][..],
            &json,
        ]
        .concat(),
        &["--save-model", "--model garbage.bin"],
    );
    rejects(
        &dir,
        &[&["north-seek", "--training-runs", "1"][..], &json].concat(),
        &["--training-runs 1", "2..=192"],
    );
    rejects(
        &dir,
        &[&["north-seek", "--inputs", "t,accel"][..], &json].concat(),
        &["--inputs", "t,rise"],
    );
    rejects(
        &dir,
        &[
            &[
                "north-seek",
                "--model",
                "garbage.bin",
                "--training-runs",
                "96",
            ][..],
            &json,
        ]
        .concat(),
        &["--training-runs", "--model garbage.bin"],
    );
    rejects(
        &dir,
        &[
            &[
                "north-seek",
                "--model",
                "garbage.bin",
                "--training-restarts-above-c",
                "4",
            ][..],
            &json,
        ]
        .concat(),
        &["--training-restarts-above-c", "--model garbage.bin"],
    );
    for bad in ["0", "31", "nan"] {
        rejects(
            &dir,
            &[
                &["north-seek", "--training-restarts-above-c", bad][..],
                &json,
            ]
            .concat(),
            &["--training-restarts-above-c", "0 < C <= 30"],
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Two outputs of one command on one file, however spelled (`./a`, `d/../a`): the later
/// would overwrite the earlier; refused before any work, naming both flags and spellings.
#[test]
fn two_outputs_on_one_file_are_refused_however_spelled() {
    let dir = scratch_dir("bad-outputs");
    let json = ["--json", "report.json"];
    rejects(
        &dir,
        &[&["north-seek", "--save-model", "./report.json"][..], &json].concat(),
        &[
            "--json report.json and --save-model ./report.json",
            "same file",
        ],
    );
    std::fs::write(dir.join("good.csv"), GOOD_RUN).unwrap();
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    rejects(
        &dir,
        &[
            "train",
            "good.csv",
            "--out",
            "report.json",
            "--json",
            "sub/../report.json",
        ],
        &[
            "--out report.json and --json sub/../report.json",
            "same file",
        ],
    );
    rejects(
        &dir,
        &[
            "allan",
            "good.csv",
            "--json",
            "report.json",
            "--plot",
            "report.json",
        ],
        &["--json report.json and --plot report.json", "same file"],
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn malformed_files_and_impossible_options_are_rejected() {
    let dir = scratch_dir("bad");
    std::fs::write(
        dir.join("ragged.csv"),
        "# fog-runs v1\nt_s,rate_dph,temp_c\n10,0.1,20.0\n20,0.1\n",
    )
    .unwrap();
    std::fs::write(dir.join("good.csv"), GOOD_RUN).unwrap();
    std::fs::write(dir.join("garbage.bin"), b"not a model at all").unwrap();
    let json = ["--json", "report.json"];

    // A malformed run: the file and its line are named.
    let args = [
        &["compensate", "ragged.csv", "--model", "garbage.bin"][..],
        &json,
    ]
    .concat();
    rejects(&dir, &args, &["ragged.csv", "4"]);
    // A model that fails validation: the option and the file are named.
    let args = [
        &["compensate", "good.csv", "--model", "garbage.bin"][..],
        &json,
    ]
    .concat();
    rejects(&dir, &args, &["--model", "garbage.bin"]);
    let args = [
        &["compensate", "good.csv", "--model", "missing.bin"][..],
        &json,
    ]
    .concat();
    rejects(&dir, &args, &["--model", "missing.bin"]);
    // Impossible options.
    rejects(
        &dir,
        &[&["north-seek", "--latitude", "95"][..], &json].concat(),
        &["--latitude"],
    );
    rejects(
        &dir,
        &[&["north-seek", "--positions", "3"][..], &json].concat(),
        &["--positions"],
    );
    rejects(
        &dir,
        &[&["north-seek", "--starts", "0"][..], &json].concat(),
        &["--starts"],
    );
    rejects(
        &dir,
        &[&["north-seek", "--model", "garbage.bin"][..], &json].concat(),
        &["--model"],
    );
    rejects(
        &dir,
        &[&["reproduce", "--qualification-inputs", "rise"][..], &json].concat(),
        &["--qualification-inputs", "t,rate,rise"],
    );
    rejects(
        &dir,
        &[&["reproduce", "--minutes", "-5"][..], &json].concat(),
        &["--duration-min"],
    );
    rejects(
        &dir,
        &[&["reproduce", "--runs", "3"][..], &json].concat(),
        &["--runs"],
    );
    rejects(
        &dir,
        &[&["reproduce", "--ambient", "-40,500"][..], &json].concat(),
        &["--ambient"],
    );
    rejects(
        &dir,
        &[&["reproduce", "--qualification-runs", "100000"][..], &json].concat(),
        &["--qualification-runs"],
    );
    // An output path in a missing directory is refused before any work.
    rejects(
        &dir,
        &["north-seek", "--json", "no/such/dir/report.json"],
        &["--json"],
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A campaign too large to hold in memory is refused before anything is simulated,
/// whichever flags make it so, and leaves no output behind.
#[test]
fn campaigns_too_large_for_memory_are_refused_before_anything_is_simulated() {
    let dir = scratch_dir("too-large");
    let json = ["--json", "report.json"];
    rejects(
        &dir,
        &[&["reproduce", "--runs", "100000"][..], &json].concat(),
        &["--runs"],
    );
    rejects(
        &dir,
        &["campaign", "--out", "big", "--runs", "1000000"],
        &["--runs"],
    );
    rejects(
        &dir,
        &["campaign", "--out", "long", "--duration-min", "1e9"],
        &["--duration-min"],
    );
    // Each flag within its own range, their product not: 1,000 runs x 11 ambients x 24 h.
    rejects(
        &dir,
        &[
            "campaign",
            "--out",
            "product",
            "--runs",
            "1000",
            "--duration-min",
            "1440",
        ],
        &["--runs", "--duration-min", "in memory"],
    );
    // The same at several headings: 8 x 11 ambients x 200 runs x 45 min.
    rejects(
        &dir,
        &[
            "campaign",
            "--out",
            "headings",
            "--runs",
            "200",
            "--headings-deg",
            "0,45,90,135,180,225,270,315",
        ],
        &["8 headings", "--headings-deg", "in memory"],
    );
    assert!(
        !dir.join("headings").exists(),
        "a refused campaign left its output directory behind"
    );
    assert!(
        !dir.join("product").exists(),
        "a refused campaign left its output directory behind"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
