//! Probe (issue 17): bad invocations of `fogsim`, every subcommand. Each must exit with
//! a non-zero status (not a signal), print exactly one line on stderr that names what
//! was wrong and where (the flag, the value or the file), never panic, leave every input
//! file as it was, and end within a time and an address-space limit.
//!
//! The invocations: each subcommand's good base command (on a small simulated campaign
//! and a model trained on it) with one fault put in: an unknown flag; every value flag
//! of its `--help` with the value missing, malformed (`abc`, empty, `nan`, `inf`,
//! `1e400`, not UTF-8) or unknown (text flags); every input file replaced by a bad file
//! (missing, empty, binary, truncated inside its last row, a 3 GiB sparse file, a
//! directory, `/dev/zero`, not UTF-8, a non-UTF-8 name; for `train --field DIR`, a
//! directory whose field-record file is each of these, or of another format, with a
//! record out of range, or measured under another model); every output pointed at an
//! input.
//! That catalogue is run first (in a seeded order); past it, seeded random faults of
//! the same kinds (random garbage, random overflowing exponents, random bytes, random
//! cuts and bit flips). The subcommands and flags come from `fogsim --help` (nested:
//! `field pull`, `registry show`, ...): a test fails when a command has no base command
//! here or a value flag is in none of the lists below (file, name, text, number).
//!
//! `cargo test` runs `FOG_PROBE_INVOCATIONS` invocations (default 60, a few seconds);
//! the figures in docs/record/robustness.md come from
//! `FOG_PROBE_INVOCATIONS=5600 cargo test -p fog-sim --test integration
//! probe_invocations:: -- --nocapture` (the test profile's fogsim), or with
//! `cargo build --release -p fog-sim` first and `FOG_PROBE_FOGSIM=target/release/fogsim`
//! (the release binary probed).
//! `FOG_PROBE_SEED` changes the order and the random faults; `FOG_PROBE_FOGSIM=PATH`
//! probes another `fogsim` binary (the release build, or main's).

use crate::app_support;

use std::ffi::{OsStr, OsString};
use std::os::unix::ffi::{OsStrExt, OsStringExt};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use app_support::{campaign_and_model, scratch_dir};
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Wall time one invocation may take.
const TIME_LIMIT: Duration = Duration::from_secs(30);
/// Address space one invocation may map (`ulimit -v`, KiB): 4 GiB.
const ADDRESS_SPACE_KIB: u64 = 4 * 1024 * 1024;
/// Size of the sparse "huge" input file (no disk used).
const HUGE_SPARSE_BYTES: u64 = 3 << 30;

/// Flags whose value is a file the command reads.
const INPUT_FLAGS: &[&str] = &[
    "--model",
    "--key",
    "--from-diagnose",
    "--from-runs",
    "--field",
    "--unit-spread",
    "--type",
];
/// Of `INPUT_FLAGS`, those whose value is a directory (of field records).
const DIR_INPUT_FLAGS: &[&str] = &["--field"];
/// Flags whose value is a file or directory the command writes.
const OUTPUT_FLAGS: &[&str] = &[
    "--out",
    "--json",
    "--plot",
    "--plots",
    "--export-design",
    "--csv",
    "--logger-csv",
    "--save-model",
    "--type-out",
];
/// Flags with a free-text value: only a missing or non-UTF-8 value is bad for certain.
const FREE_TEXT_FLAGS: &[&str] = &["--gyro-id", "--gyro"];
/// Flags naming a store the command creates if absent (a missing or non-UTF-8 path is
/// a new registry): only a missing value and files that are not databases are bad.
const STORE_FLAGS: &[&str] = &["--registry"];
/// Flags whose value is a name from a set (an enum, a column, a port): an unknown name
/// is bad.
const NAME_FLAGS: &[&str] = &[
    "--column",
    "--taus",
    "--kind",
    "--method",
    "--criterion",
    "--inputs",
    "--warmup-clock",
    "--qualification-inputs",
    "--preset",
    "--axis",
    "--time",
    "--rate",
    "--temp",
    "--keep",
    "--columns",
    "--heading-col",
    "--port",
    "--gyro-port",
    "--table-port",
    "--width-search",
    "--incl-port",
    "--laws",
    "--sequence",
    "--seek-sequence",
    "--type-shape",
    "--misfit",
];
/// Flags with a number (or a list of numbers) for value.
const NUMBER_FLAGS: &[&str] = &[
    "--a-dph",
    "--ambient-c",
    "--azimuth-deg",
    "--b-dph",
    "--baud",
    "--collinearity-tol",
    "--connect-timeout-s",
    "--duration-min",
    "--duration-s",
    "--dwell-s",
    "--earth-dph",
    "--eval-starts",
    "--field-seeks",
    "--field-seeks-per-start",
    "--field-weight",
    "--folds",
    "--from",
    "--gyro-baud",
    "--heading-bias-dph",
    "--heading-deg",
    "--headings-deg",
    "--incl-baud",
    "--latitude-deg",
    "--max-candidates",
    "--max-centers",
    "--n-headings",
    "--pitch-deg",
    "--poly-degrees",
    "--positions",
    "--qualification-runs",
    "--rate-hz",
    "--raw-rate-hz",
    "--restart-above-c",
    "--results",
    "--rho",
    "--roll-deg",
    "--runs",
    "--security-counter",
    "--seed",
    "--seek-dwell-s",
    "--seek-latitude-deg",
    "--seek-period-s",
    "--seeks",
    "--sigma-dph",
    "--speed",
    "--split-gap-s",
    "--starts",
    "--table-baud",
    "--target-dph",
    "--threads",
    "--tilt-deg",
    "--timeout-s",
    "--training-restarts-above-c",
    "--training-runs",
    "--type-ambients-c",
    "--type-unit-runs",
    "--type-seed",
    "--type-units",
    "--unit-ambients-c",
    "--unit-fit",
    "--unit-prior-weight",
    "--unit-runs",
    "--unit-terms",
    "--units",
    "--widths",
];
/// Malformed numbers: bad for every numeric flag.
const BAD_NUMBERS: &[&str] = &["abc", "", "nan", "inf", "-inf", "1e400", "-1e400", "0x10"];

/// One subcommand: its words and a good base command. In `base`, `@path` marks an input
/// file the probe replaces by bad files and `!path` an output it points at an input.
struct Sub {
    words: &'static [&'static str],
    base: &'static [&'static str],
}

const SUBS: &[Sub] = &[
    Sub {
        words: &["allan"],
        base: &["@runs/run4.csv", "--json", "!out/allan.json"],
    },
    Sub {
        words: &["campaign"],
        base: &[
            "--out",
            "!out/campaign",
            "--runs",
            "1",
            "--duration-min",
            "1",
            "--headings-deg",
            "0,180",
        ],
    },
    // A fleet, so that `--unit-spread`'s bad files are read (without `--units` it is refused
    // unread); with a heading, which `--heading-bias-dph` needs.
    Sub {
        words: &["campaign"],
        base: &[
            "--out",
            "!out/fleet",
            "--units",
            "2",
            "--ambient-c",
            "20",
            "--runs",
            "1",
            "--duration-min",
            "1",
            "--headings-deg",
            "0",
        ],
    },
    Sub {
        words: &["train"],
        base: &[
            "--out",
            "!out/m.bin",
            "@runs/run4.csv",
            "@runs/run5.csv",
            "@runs/run6.csv",
        ],
    },
    // `--field DIR`: a directory of field records measured under the model this base
    // trains (written in `fixtures`); its bad files are put inside the directory.
    Sub {
        words: &["train"],
        base: &[
            "--out",
            "!out/mf.bin",
            "--field",
            "@field",
            "@runs/run4.csv",
            "@runs/run5.csv",
            "@runs/run6.csv",
        ],
    },
    // A gyro type learnt from a small fleet (`fleet/`: units U1..U3 of 2 runs each, written
    // in `fixtures`), and unit U4 calibrated against it (`type.json`, made in `fixtures` by
    // the first of these bases; the second must then succeed).
    Sub {
        words: &["train"],
        base: &[
            "--type-out",
            "!out/type.json",
            "--out",
            "!out/shared.bin",
            "@fleet/u1r1.csv",
            "@fleet/u1r2.csv",
            "@fleet/u2r1.csv",
            "@fleet/u2r2.csv",
            "@fleet/u3r1.csv",
            "@fleet/u3r2.csv",
        ],
    },
    Sub {
        words: &["train"],
        base: &[
            "--type",
            "@type.json",
            "--out",
            "!out/unit.bin",
            "@fleet/u4r1.csv",
            "@fleet/u4r2.csv",
        ],
    },
    Sub {
        words: &["compensate"],
        base: &[
            "--model",
            "@model.bin",
            "@runs/run4.csv",
            "--json",
            "!out/c.json",
        ],
    },
    Sub {
        words: &["north-seek"],
        base: &["--model", "@model.bin", "--starts", "1", "--seeks", "1"],
    },
    // The unit recipe: a type from 3 simulated units of 3 runs, the unit's own 2 (about 4 s
    // when it runs whole; every fault here stops it before it trains).
    Sub {
        words: &["north-seek"],
        base: &[
            "--type-units",
            "3",
            "--unit-runs",
            "2",
            "--type-unit-runs",
            "3",
            "--starts",
            "1",
            "--seeks",
            "1",
        ],
    },
    Sub {
        words: &["reproduce"],
        base: &["--runs", "1", "--duration-min", "1", "--starts", "1"],
    },
    Sub {
        words: &["demo"],
        base: &["--out", "!out/demo", "--starts", "1"],
    },
    Sub {
        words: &["diagnose"],
        base: &["@runs/run4.csv", "--json", "!out/d.json"],
    },
    Sub {
        words: &["import"],
        base: &[
            "@logger.csv",
            "--out",
            "!out/imported",
            "--time",
            "t",
            "--rate",
            "r:dph",
            "--temp",
            "T:c",
        ],
    },
    Sub {
        words: &["upload"],
        base: &[
            "--port",
            "tcp:127.0.0.1:9",
            "--security-counter",
            "1",
            "--timeout-s",
            "1",
            "@model.bin",
        ],
    },
    Sub {
        words: &["heading-cal"],
        base: &[
            "--model",
            "@model.bin",
            "--out",
            "!out/hc.bin",
            "--a-dph",
            "0.01",
            "--b-dph",
            "0",
            "--sigma-dph",
            "0.002",
            "--n-headings",
            "4",
        ],
    },
    Sub {
        words: &["monitor"],
        base: &[
            "--port",
            "tcp:127.0.0.1:9",
            "--duration-s",
            "1",
            "--registry",
            "@reg.sqlite",
            "--csv",
            "!out/m.csv",
        ],
    },
    Sub {
        words: &["registry", "show"],
        base: &["--registry", "@reg.sqlite", "FOG-A17"],
    },
    Sub {
        words: &["registry", "export"],
        base: &["--registry", "@reg.sqlite", "--csv", "!out/r.csv"],
    },
    Sub {
        words: &["field", "pull"],
        base: &[
            "--port",
            "tcp:127.0.0.1:9",
            "--timeout-s",
            "1",
            "--registry",
            "@reg.sqlite",
            "--out",
            "!out/field",
        ],
    },
    Sub {
        words: &["field", "aging"],
        base: &[
            "--laws",
            "none",
            "--field-seeks",
            "5",
            "--eval-starts",
            "1",
            "--seeks",
            "1",
            "--threads",
            "1",
            "--json",
            "!out/aging.json",
        ],
    },
    Sub {
        words: &["rig"],
        base: &[
            "--gyro-port",
            "tcp:127.0.0.1:9",
            "--table-port",
            "tcp:127.0.0.1:9",
            "--duration-s",
            "1",
            "--connect-timeout-s",
            "1",
        ],
    },
];

/// The binary probed: this build's `fogsim`, or `FOG_PROBE_FOGSIM` (e.g. a release
/// build, or main's binary to see what the probe finds there).
fn fogsim_exe() -> PathBuf {
    std::env::var_os("FOG_PROBE_FOGSIM")
        .map_or_else(|| env!("CARGO_BIN_EXE_fogsim").into(), PathBuf::from)
}

/// What a flag of `--help` takes.
#[derive(Clone, Copy, Debug, PartialEq)]
enum FlagKind {
    Switch,
    Number,
    Name,
    FreeText,
    Input,
    Output,
    Store,
}

fn classify(flag: &str, takes_value: bool) -> FlagKind {
    match () {
        _ if !takes_value => FlagKind::Switch,
        _ if INPUT_FLAGS.contains(&flag) => FlagKind::Input,
        _ if OUTPUT_FLAGS.contains(&flag) => FlagKind::Output,
        _ if FREE_TEXT_FLAGS.contains(&flag) => FlagKind::FreeText,
        _ if STORE_FLAGS.contains(&flag) => FlagKind::Store,
        _ if NAME_FLAGS.contains(&flag) => FlagKind::Name,
        _ => FlagKind::Number,
    }
}

/// What `fogsim <words> --help` prints.
fn help_text(words: &[&str]) -> String {
    let out = Command::new(fogsim_exe())
        .args(words)
        .arg("--help")
        .output()
        .expect("fogsim --help runs");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The long flags of `fogsim <words> --help` and whether each takes a value.
fn help_flags(words: &[&str]) -> Vec<(String, bool)> {
    help_text(words)
        .lines()
        .filter_map(|l| {
            let l = l.trim_start().trim_start_matches("-h, ");
            let rest = l.strip_prefix("--")?;
            let name: String = rest
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '-')
                .collect();
            let after = &rest[name.len()..];
            (name != "help" && name != "version")
                .then(|| (format!("--{name}"), after.starts_with(" <")))
        })
        .collect()
}

/// The subcommands `fogsim <words> --help` lists (its `Commands:` section), `help` left
/// out.
fn help_commands(words: &[&str]) -> Vec<String> {
    help_text(words)
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| !l.trim().is_empty())
        .filter_map(|l| l.split_whitespace().next().map(str::to_string))
        .filter(|c| c != "help")
        .collect()
}

/// Every command of `fogsim <words> --help` that has no subcommands of its own, as its
/// words (`field pull`, `registry show`, ...), found recursively.
fn leaf_commands(words: &[String]) -> Vec<Vec<String>> {
    let as_str: Vec<&str> = words.iter().map(String::as_str).collect();
    let subs = help_commands(&as_str);
    if subs.is_empty() {
        return vec![words.to_vec()];
    }
    subs.into_iter()
        .flat_map(|c| {
            let mut w = words.to_vec();
            w.push(c);
            leaf_commands(&w)
        })
        .collect()
}

/// One bad invocation: its arguments and the words the error line must contain (any
/// one of them).
#[derive(Clone, Debug)]
struct Case {
    kind: &'static str,
    args: Vec<OsString>,
    names: Vec<String>,
}

/// The scratch directory with its good inputs and bad files.
struct Fixtures {
    dir: PathBuf,
    /// Inputs that must never change: (path, bytes).
    inputs: Vec<(PathBuf, Vec<u8>)>,
    bad_files: Vec<(&'static str, PathBuf)>,
    /// For a directory input (`train --field DIR`): directories whose field-record file
    /// is bad (and a few that are not directories).
    bad_dirs: Vec<(&'static str, PathBuf)>,
}

const LOGGER: &str = "t,r,T\n0,0.01,20.0\n0.1,0.02,20.0\n0.2,0.01,20.1\n0.3,0.03,20.1\n";

fn fixtures() -> Fixtures {
    let dir = scratch_dir("probe");
    campaign_and_model(&dir, 6);
    std::fs::write(dir.join("logger.csv"), LOGGER).unwrap();
    // An empty calibration registry.
    drop(fog_sim::registry::Registry::open(&dir.join("reg.sqlite")).unwrap());
    let bad = dir.join("bad");
    std::fs::create_dir_all(bad.join("a-directory")).unwrap();
    let run = std::fs::read(dir.join("runs/run4.csv")).unwrap();
    std::fs::write(bad.join("empty.csv"), b"").unwrap();
    let mut binary = vec![0u8, 0xFF, 0x13, 0x37];
    binary.extend((0..4000u32).map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8));
    std::fs::write(bad.join("binary.bin"), &binary).unwrap();
    std::fs::write(bad.join("truncated.csv"), cut_inside_last_row(&run)).unwrap();
    let model = std::fs::read(dir.join("model.bin")).unwrap();
    std::fs::write(bad.join("truncated-model.bin"), &model[..model.len() / 2]).unwrap();
    let huge = std::fs::File::create(bad.join("huge-sparse.csv")).unwrap();
    huge.set_len(HUGE_SPARSE_BYTES).unwrap();
    let mut not_utf8 = run[..run.len() / 2].to_vec();
    not_utf8.extend_from_slice(b"\n1\xFF\xFE,0.1,20\n");
    std::fs::write(bad.join("not-utf8.csv"), not_utf8).unwrap();
    let bad_files = vec![
        ("missing file", bad.join("no-such-file.csv")),
        ("empty file", bad.join("empty.csv")),
        ("binary file", bad.join("binary.bin")),
        ("truncated run", bad.join("truncated.csv")),
        ("truncated model", bad.join("truncated-model.bin")),
        ("huge sparse file", bad.join("huge-sparse.csv")),
        ("directory", bad.join("a-directory")),
        ("/dev/zero", PathBuf::from("/dev/zero")),
        ("non-UTF-8 content", bad.join("not-utf8.csv")),
        (
            "non-UTF-8 name",
            bad.join(OsStr::from_bytes(b"no-such-\xFF\xFE.csv")),
        ),
    ];
    field_records_of_the_train_base(&dir);
    fleet_and_type_of_the_type_bases(&dir);
    let bad_dirs = bad_field_dirs(&dir, &bad);
    let mut inputs = Vec::new();
    for p in walk(&dir) {
        // The registry is a store the tools open read-write: not compared.
        if !p.starts_with(&bad) && p.extension() != Some(OsStr::new("sqlite")) {
            let bytes = std::fs::read(&p).unwrap();
            inputs.push((p, bytes));
        }
    }
    Fixtures {
        dir,
        inputs,
        bad_files,
        bad_dirs,
    }
}

/// The `Sub` of `words` whose base has (`with`) or has not `flag`.
fn sub_of(words: &[&str], flag: &str, with: bool) -> &'static Sub {
    SUBS.iter()
        .find(|s| s.words == words && s.base.contains(&flag) == with)
        .unwrap()
}

/// `dir/field/`: field records measured under the model the `train` base trains (its
/// CRC-32, from one run of that base here), written by the library's own writer; then
/// the `train --field` base must succeed on them (else its faults would fail for
/// another reason).
fn field_records_of_the_train_base(dir: &Path) {
    use fog_sim::io::field_records::merge_into_dir;
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    let plain = sub_of(&["train"], "--field", false);
    let o = run(dir, &base_args(plain));
    assert_eq!(o.code, Some(0), "the train base fails: {}", o.stderr);
    let model_path = out.join("m.bin");
    let model =
        fog_core::model::format::RbfModel::decode(&std::fs::read(&model_path).unwrap()).unwrap();
    let crc = fog_sim::io::model::model_crc32(&model).unwrap();
    let records = app_support::linear_field_records("sim", 8, 1.5, |_| Some(crc));
    merge_into_dir(&dir.join("field"), &records).unwrap();
    let with_field = sub_of(&["train"], "--field", true);
    let o = run(dir, &base_args(with_field));
    assert_eq!(
        o.code,
        Some(0),
        "the train --field base fails: {}",
        o.stderr
    );
    std::fs::remove_dir_all(&out).unwrap();
}

/// `dir/fleet/`: four simulated units of one type, 2 cold starts each (`u1r1.csv` ..
/// `u4r2.csv`); `dir/type.json`: the type the `train --type-out` base learns from U1..U3;
/// then the `train --type` base (U4 against it) must succeed.
fn fleet_and_type_of_the_type_bases(dir: &Path) {
    use fog_sim::pipeline::campaign::CampaignSpec;
    use fog_sim::pipeline::fleet::{fleet_runs, FleetType};
    let fleet = FleetType::paper(fog_sim::sim::TypeSpread::default_spread(), "default", 3);
    let plan = CampaignSpec {
        ambients_c: vec![20.0],
        runs_per_ambient: 2,
        minutes: 15.0,
        raw_rate_hz: 10.0,
        ..CampaignSpec::paper(5)
    };
    std::fs::create_dir_all(dir.join("fleet")).unwrap();
    for u in 0..4 {
        for (r, c) in fleet_runs(&fleet, u, &plan, None)
            .unwrap()
            .iter()
            .enumerate()
        {
            let path = dir.join(format!("fleet/u{}r{}.csv", u + 1, r + 1));
            fog_sim::io::runs::write_run(path, &c.run).unwrap();
        }
    }
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    let learn = sub_of(&["train"], "--type-out", true);
    let o = run(dir, &base_args(learn));
    assert_eq!(
        o.code,
        Some(0),
        "the train --type-out base fails: {}",
        o.stderr
    );
    std::fs::rename(out.join("type.json"), dir.join("type.json")).unwrap();
    let calibrate = sub_of(&["train"], "--type", true);
    let o = run(dir, &base_args(calibrate));
    assert_eq!(o.code, Some(0), "the train --type base fails: {}", o.stderr);
    std::fs::remove_dir_all(&out).unwrap();
}

/// Directories of bad field records, each a fault of `dir/field/`'s record file, or not a
/// directory.
fn bad_field_dirs(dir: &Path, bad: &Path) -> Vec<(&'static str, PathBuf)> {
    use fog_sim::io::field_records::{merge_into_dir, read_dir_records, JSON_NAME};
    let good = std::fs::read(dir.join("field").join(JSON_NAME)).unwrap();
    let text = String::from_utf8(good.clone()).unwrap();
    let with_json = |name: &str, json: &[u8]| {
        let d = bad.join(name);
        std::fs::create_dir_all(&d).unwrap();
        std::fs::write(d.join(JSON_NAME), json).unwrap();
        d
    };
    let no_records = bad.join("field-no-records");
    std::fs::create_dir_all(&no_records).unwrap();
    let huge = bad.join("field-huge");
    std::fs::create_dir_all(&huge).unwrap();
    let file = std::fs::File::create(huge.join(JSON_NAME)).unwrap();
    file.set_len(HUGE_SPARSE_BYTES).unwrap();
    let a_directory = bad.join("field-json-a-directory");
    std::fs::create_dir_all(a_directory.join(JSON_NAME)).unwrap();
    let dev_zero = bad.join("field-dev-zero");
    std::fs::create_dir_all(&dev_zero).unwrap();
    std::os::unix::fs::symlink("/dev/zero", dev_zero.join(JSON_NAME)).unwrap();
    let mut binary = vec![0u8, 0xFF, 0x13, 0x37];
    binary.extend((0..4000u32).map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8));
    // The gyro id "sim" made "s\xFF\xFE".
    let at = text.find("\"sim\"").unwrap() + 2;
    let mut not_utf8 = good.clone();
    not_utf8.splice(at..at + 2, [0xFF, 0xFE]);
    // Written by the library: one record's residual bias out of range (1e30 dph), and
    // every record's model CRC-32 changed (measured under another model).
    let records = read_dir_records(&dir.join("field")).unwrap();
    let mut implausible_records = records.clone();
    implausible_records[3].residual_bias_dph = 1e30;
    let implausible = bad.join("field-implausible");
    merge_into_dir(&implausible, &implausible_records).unwrap();
    let mut other_model = records;
    for r in &mut other_model {
        r.model_crc32 = r.model_crc32.map(|c| c ^ 1);
    }
    let other = bad.join("field-other-model");
    merge_into_dir(&other, &other_model).unwrap();
    vec![
        ("missing file", no_records),
        ("empty file", with_json("field-empty", b"")),
        ("binary file", with_json("field-binary", &binary)),
        (
            "truncated JSON",
            with_json("field-truncated", &cut_inside_last_row(&good)),
        ),
        ("huge sparse file", huge),
        ("directory", a_directory),
        ("/dev/zero", dev_zero),
        ("non-UTF-8 content", with_json("field-not-utf8", &not_utf8)),
        (
            "another format",
            with_json(
                "field-other-format",
                br#"{"format":"fog-runs","version":1,"records":[]}"#,
            ),
        ),
        ("implausible record", implausible),
        ("records of another model", other),
        ("a file, not a directory", bad.join("binary.bin")),
        (
            "non-UTF-8 name",
            bad.join(OsStr::from_bytes(b"field-\xFF\xFE")),
        ),
    ]
}

/// The bad files for the input at `path` (relative to the scratch directory): bad
/// directories for a directory.
fn bad_inputs<'a>(fx: &'a Fixtures, path: &OsStr) -> &'a [(&'static str, PathBuf)] {
    if fx.dir.join(path).is_dir() {
        &fx.bad_dirs
    } else {
        &fx.bad_files
    }
}

/// `run` cut inside its last row, before that row's last comma: one column short.
fn cut_inside_last_row(run: &[u8]) -> Vec<u8> {
    let body = run.strip_suffix(b"\n").unwrap_or(run);
    let last_comma = body.iter().rposition(|&b| b == b',').unwrap();
    run[..last_comma].to_vec()
}

fn walk(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            files.extend(walk(&p));
        } else {
            files.push(p);
        }
    }
    files
}

fn os(s: &str) -> OsString {
    OsString::from(s)
}

/// The base command of `sub` as arguments (markers removed).
fn base_args(sub: &Sub) -> Vec<OsString> {
    sub.words
        .iter()
        .map(|w| os(w))
        .chain(
            sub.base
                .iter()
                .map(|a| os(a.trim_start_matches(['@', '!']))),
        )
        .collect()
}

/// `base` with `flag`'s value set to `value` (replaced if the base has it, else added),
/// as `--flag=value` so that a value starting with `-` is a value.
fn with_value(sub: &Sub, flag: &str, value: OsString) -> Vec<OsString> {
    let mut args = base_args(sub);
    if let Some(i) = args.iter().position(|a| a == flag) {
        args.drain(i..i + 2);
    }
    let mut joined = OsString::from(format!("{flag}="));
    joined.push(value);
    args.push(joined);
    args
}

/// `base` without `flag` (and its value), then `flag` last with no value.
fn without_value(sub: &Sub, flag: &str) -> Vec<OsString> {
    let mut args = base_args(sub);
    if let Some(i) = args.iter().position(|a| a == flag) {
        args.drain(i..i + 2);
    }
    args.push(os(flag));
    args
}

fn lossy(s: &OsStr) -> String {
    s.to_string_lossy().into_owned()
}

/// The flag in `args` just before position `i`, if `args[i]` is a flag's value.
fn flag_before(sub: &Sub, i: usize) -> Option<String> {
    let args = base_args(sub);
    let prev = lossy(&args[i - 1]);
    prev.starts_with("--").then_some(prev)
}

/// Every deterministic case of the catalogue.
fn catalogue(fx: &Fixtures) -> Vec<Case> {
    let mut cases = Vec::new();
    for sub in SUBS {
        let mut args = base_args(sub);
        args.push(os("--no-such-flag"));
        cases.push(Case {
            kind: "unknown flag",
            args,
            names: vec!["--no-such-flag".into()],
        });
        for (flag, takes_value) in help_flags(sub.words) {
            let kind = classify(&flag, takes_value);
            if kind == FlagKind::Switch {
                continue;
            }
            cases.push(Case {
                kind: "missing value",
                args: without_value(sub, &flag),
                names: vec![flag.clone()],
            });
            if kind != FlagKind::Output && kind != FlagKind::Store {
                cases.push(Case {
                    kind: "non-UTF-8 value",
                    args: with_value(sub, &flag, OsString::from_vec(b"v\xFF\xFE".to_vec())),
                    names: vec![flag.clone(), "v\u{FFFD}\u{FFFD}".into()],
                });
            }
            let bad_values: &[&str] = match kind {
                FlagKind::Number => BAD_NUMBERS,
                FlagKind::Name => &["no-such-name", ""],
                _ => &[],
            };
            for v in bad_values {
                cases.push(Case {
                    kind: if kind == FlagKind::Number {
                        "malformed number"
                    } else {
                        "unknown name"
                    },
                    args: with_value(sub, &flag, os(v)),
                    names: vec![
                        flag.clone(),
                        (*v).to_string(),
                        format!("'{v}'"),
                        format!("`{v}`"),
                    ],
                });
            }
            if kind == FlagKind::Input && !sub.base.contains(&flag.as_str()) {
                let bad = if DIR_INPUT_FLAGS.contains(&flag.as_str()) {
                    &fx.bad_dirs
                } else {
                    &fx.bad_files
                };
                for (what, file) in bad {
                    cases.push(Case {
                        kind: what,
                        args: with_value(sub, &flag, file.clone().into_os_string()),
                        names: vec![flag.clone(), file_name(file)],
                    });
                }
            }
        }
        let offset = sub.words.len();
        for (i, a) in sub.base.iter().enumerate() {
            let at = offset + i;
            let mut names: Vec<String> = flag_before(sub, at).into_iter().collect();
            if let Some(input) = a.strip_prefix('@') {
                // A registry that is absent is created, and SQLite takes an empty file
                // for an empty database: neither is a bad file there.
                let registry = a.ends_with(".sqlite");
                for (what, file) in bad_inputs(fx, OsStr::new(input)) {
                    let creates = ["empty file", "missing file", "non-UTF-8 name"];
                    if registry && creates.contains(what) {
                        continue;
                    }
                    let mut args = base_args(sub);
                    args[at] = file.clone().into_os_string();
                    let mut names = names.clone();
                    names.push(file_name(file));
                    cases.push(Case {
                        kind: what,
                        args,
                        names,
                    });
                }
            } else if a.starts_with('!') {
                // The output pointed at each input of the base, then at the model.
                let targets = sub.base.iter().filter_map(|b| b.strip_prefix('@'));
                for target in targets {
                    let mut args = base_args(sub);
                    args[at] = os(target);
                    names.push(file_name(Path::new(target)));
                    cases.push(Case {
                        kind: "output onto an input",
                        args,
                        names: names.clone(),
                    });
                }
            }
        }
    }
    cases
}

fn file_name(p: &Path) -> String {
    p.file_name().map_or_else(|| lossy(p.as_os_str()), lossy)
}

/// A seeded random fault of the catalogue's kinds, on a random subcommand.
fn random_case(fx: &Fixtures, rng: &mut ChaCha8Rng, n: usize) -> Case {
    let sub = &SUBS[rng.random_range(0..SUBS.len())];
    let flags: Vec<_> = help_flags(sub.words)
        .into_iter()
        .filter(|(f, v)| classify(f, *v) == FlagKind::Number)
        .collect();
    let file_slots: Vec<usize> = sub
        .base
        .iter()
        .enumerate()
        .filter(|(_, a)| a.starts_with('@'))
        .map(|(i, _)| i + sub.words.len())
        .collect();
    if file_slots.is_empty() || rng.random_bool(0.5) && !flags.is_empty() {
        let (flag, _) = &flags[rng.random_range(0..flags.len())];
        let value = match rng.random_range(0..3) {
            0 => {
                let len = rng.random_range(1..12);
                (0..len)
                    .map(|_| rng.random_range(b'a'..=b'z') as char)
                    .collect::<String>()
            }
            1 => format!(
                "{}{}e{}",
                if rng.random_bool(0.5) { "-" } else { "" },
                rng.random_range(1..10),
                rng.random_range(309..100_000)
            ),
            _ => [
                "NaN",
                "nan",
                "+nan",
                "-NaN",
                "inf",
                "+infinity",
                "-Infinity",
            ][rng.random_range(0..7)]
            .to_string(),
        };
        return Case {
            kind: "random malformed number",
            args: with_value(sub, flag, os(&value)),
            names: vec![flag.clone(), value],
        };
    }
    let at = file_slots[rng.random_range(0..file_slots.len())];
    let mut args = base_args(sub);
    let good = fx.dir.join(lossy(&args[at]));
    let path = fx.dir.join("bad").join(format!("random-{n}"));
    // A directory of field records: its record file is the one made bad.
    let json = fog_sim::io::field_records::JSON_NAME;
    let (bytes, bad_file) = if good.is_dir() {
        std::fs::create_dir_all(&path).unwrap();
        (std::fs::read(good.join(json)).unwrap(), path.join(json))
    } else {
        (std::fs::read(&good).unwrap(), path.clone())
    };
    // A JSON with a bit flipped may still be valid: cut or NUL only, as a run.
    let is_model = good.extension() == Some(OsStr::new("bin"));
    // A cut or a NUL inside a SQLite file may still be a database: random bytes only.
    let is_registry = good.extension() == Some(OsStr::new("sqlite"));
    let kind = if is_registry {
        0
    } else {
        rng.random_range(0..3)
    };
    let bad: Vec<u8> = match kind {
        // Random bytes, a NUL first (never text).
        0 => std::iter::once(0)
            .chain((0..rng.random_range(0..5000)).map(|_| rng.random()))
            .collect(),
        // A model cut anywhere / a run cut inside its last row.
        1 if is_model => bytes[..rng.random_range(0..bytes.len())].to_vec(),
        1 => cut_inside_last_row(&bytes[..rng.random_range(bytes.len() / 2..bytes.len())]),
        // A model with a bit flipped (its CRC breaks) / a run with a NUL in a row.
        _ if is_model => {
            let mut b = bytes.clone();
            let i = rng.random_range(0..b.len());
            b[i] ^= 1 << rng.random_range(0..8);
            b
        }
        _ => {
            let mut b = bytes.clone();
            let from = b.len() / 2;
            let i = rng.random_range(from..b.len() - 1);
            b[i] = 0;
            b
        }
    };
    std::fs::write(&bad_file, bad).unwrap();
    let mut names: Vec<String> = flag_before(sub, at).into_iter().collect();
    names.push(file_name(&path));
    args[at] = path.into_os_string();
    Case {
        kind: "random bad file",
        args,
        names,
    }
}

/// What one invocation did.
struct Outcome {
    code: Option<i32>,
    stderr: String,
    elapsed: Duration,
    peak_rss_kib: u64,
    timed_out: bool,
}

fn run(dir: &Path, args: &[OsString]) -> Outcome {
    let t0 = Instant::now();
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v {ADDRESS_SPACE_KIB} && exec \"$0\" \"$@\""
        ))
        .arg(fogsim_exe())
        .args(args)
        .current_dir(dir)
        .env("XDG_DATA_HOME", dir.join("xdg"))
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("sh runs");
    let mut stderr_pipe = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut buf = Vec::new();
        let _ = std::io::Read::read_to_end(
            &mut std::io::Read::take(&mut stderr_pipe, 1 << 20),
            &mut buf,
        );
        buf
    });
    let status_path = format!("/proc/{}/status", child.id());
    let mut peak_rss_kib = 0;
    let mut timed_out = false;
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if let Some(kib) = std::fs::read_to_string(&status_path)
            .ok()
            .and_then(|s| vm_hwm_kib(&s))
        {
            peak_rss_kib = peak_rss_kib.max(kib);
        }
        if t0.elapsed() > TIME_LIMIT {
            timed_out = true;
            let _ = child.kill();
        }
        std::thread::sleep(Duration::from_millis(2));
    };
    let stderr = String::from_utf8_lossy(&reader.join().unwrap()).into_owned();
    Outcome {
        code: status.code(),
        stderr,
        elapsed: t0.elapsed(),
        peak_rss_kib,
        timed_out,
    }
}

fn vm_hwm_kib(status: &str) -> Option<u64> {
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// The rules a bad invocation breaks, if any.
fn violations(case: &Case, o: &Outcome) -> Vec<String> {
    let mut v = Vec::new();
    if o.timed_out {
        v.push(format!("ran over {TIME_LIMIT:?}"));
    }
    match o.code {
        None => v.push("killed by a signal (crash or out of memory)".into()),
        Some(0) => v.push("exit status 0".into()),
        Some(_) => {}
    }
    if o.stderr.contains("panicked") {
        v.push("panicked".into());
    }
    // One error line; a warning printed before it (e.g. signing with the TEST key) is
    // not part of the error.
    let lines: Vec<&str> = o
        .stderr
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.contains("WARNING"))
        .collect();
    if lines.len() != 1 {
        v.push(format!("{} lines on stderr", lines.len()));
    }
    if let Some(line) = lines.first() {
        if !case.names.iter().any(|n| !n.is_empty() && line.contains(n)) {
            v.push(format!("the error names none of {:?}", case.names));
        }
        if line.len() > 400 {
            v.push(format!("error line of {} bytes", line.len()));
        }
    }
    v
}

/// `FOG_PROBE_*` from the environment, else `default`.
fn count_from_env(var: &str, default: u64) -> u64 {
    match std::env::var(var) {
        Ok(text) => text.parse().expect("FOG_PROBE_* must be a count"),
        Err(_) => default,
    }
}

/// A subcommand or a value flag added to `fogsim` later cannot be left out: every command
/// of `fogsim --help` (nested ones too) has a base command here, every `Sub` is such a
/// command, and every value flag of each is in exactly one of the lists above (a new flag
/// must be classified, not probed as a number by default).
#[test]
fn the_catalogue_has_every_subcommand_and_every_flag_is_classified() {
    let leaves: Vec<String> = leaf_commands(&[]).iter().map(|w| w.join(" ")).collect();
    let in_subs: Vec<String> = SUBS.iter().map(|s| s.words.join(" ")).collect();
    assert!(
        leaves.contains(&"field pull".to_string()) && leaves.contains(&"allan".to_string()),
        "`fogsim --help` not read: {leaves:?}"
    );
    let missing: Vec<&String> = leaves.iter().filter(|l| !in_subs.contains(l)).collect();
    assert!(
        missing.is_empty(),
        "commands of `fogsim --help` with no base command in SUBS: {missing:?}"
    );
    let stale: Vec<&String> = in_subs.iter().filter(|s| !leaves.contains(s)).collect();
    assert!(
        stale.is_empty(),
        "SUBS entries that are no command of `fogsim --help`: {stale:?}"
    );
    let lists = [
        INPUT_FLAGS,
        OUTPUT_FLAGS,
        FREE_TEXT_FLAGS,
        STORE_FLAGS,
        NAME_FLAGS,
        NUMBER_FLAGS,
    ];
    let mut unclassified = Vec::new();
    for sub in SUBS {
        for (flag, takes_value) in help_flags(sub.words) {
            let n = lists.iter().filter(|l| l.contains(&flag.as_str())).count();
            if takes_value && n != 1 {
                unclassified.push(format!("{} {flag} (in {n} lists)", sub.words.join(" ")));
            }
        }
    }
    assert!(
        unclassified.is_empty(),
        "value flags not in exactly one of the flag lists: {unclassified:?}"
    );
}

/// docs/reference/cli.md has a section headed by every command of `fogsim --help`
/// (`` ## `fogsim north-seek` ``, `` ### `fogsim field pull` ``), and that section or its
/// parent command's (a flag shared by `registry show` and `registry export`) names every
/// long flag the command's `--help` lists, in backticks: the reference cannot fall behind
/// the tool.
#[test]
fn the_cli_reference_names_every_command_and_flag() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/reference/cli.md");
    let page = std::fs::read_to_string(&path).expect("docs/reference/cli.md");
    let section = |words: &[String]| -> Option<String> {
        let name = format!("`fogsim {}`", words.join(" "));
        let start = page
            .lines()
            .position(|l| l.starts_with('#') && l.trim_start_matches('#').trim() == name)?;
        let body: Vec<&str> = page
            .lines()
            .skip(start + 1)
            .take_while(|l| !l.starts_with("## ") && !l.starts_with("### "))
            .collect();
        Some(body.join("\n"))
    };
    let mut missing = Vec::new();
    for words in leaf_commands(&[]) {
        if section(&words).is_none() {
            missing.push(format!("no section `fogsim {}`", words.join(" ")));
            continue;
        }
        let sections: Vec<String> = (1..=words.len())
            .filter_map(|k| section(&words[..k]))
            .collect();
        let as_str: Vec<&str> = words.iter().map(String::as_str).collect();
        for (flag, _) in help_flags(&as_str) {
            if !sections.iter().any(|s| s.contains(&format!("`{flag}"))) {
                missing.push(format!("`fogsim {}`: {flag}", words.join(" ")));
            }
        }
    }
    assert!(
        missing.is_empty(),
        "docs/reference/cli.md is behind `fogsim --help`: {missing:#?}"
    );
}

#[test]
fn bad_invocations_fail_with_one_line_naming_the_fault_and_change_no_input() {
    let n = count_from_env("FOG_PROBE_INVOCATIONS", 60) as usize;
    let seed = count_from_env("FOG_PROBE_SEED", 17);
    let fx = fixtures();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut cases = catalogue(&fx);
    let catalogue_len = cases.len();
    cases.shuffle(&mut rng);
    cases.truncate(n);
    let mut failures = Vec::new();
    let (mut slowest, mut peak_kib) = (Duration::ZERO, 0);
    let mut slowest_case = String::new();
    let t0 = Instant::now();
    for i in 0..n {
        let case = if i < cases.len() {
            cases[i].clone()
        } else {
            random_case(&fx, &mut rng, i)
        };
        let before: std::collections::HashSet<PathBuf> = walk(&fx.dir).into_iter().collect();
        std::fs::create_dir_all(fx.dir.join("out")).unwrap();
        let o = run(&fx.dir, &case.args);
        if o.elapsed > slowest {
            slowest_case = format!("{} {:?}", case.kind, case.args);
        }
        slowest = slowest.max(o.elapsed);
        peak_kib = peak_kib.max(o.peak_rss_kib);
        let mut v = violations(&case, &o);
        for (path, bytes) in &fx.inputs {
            if std::fs::read(path).ok().as_deref() != Some(bytes.as_slice()) {
                v.push(format!("input {} changed", path.display()));
                std::fs::write(path, bytes).unwrap();
            }
        }
        let _ = std::fs::remove_dir_all(fx.dir.join("out"));
        let _ = std::fs::remove_dir_all(fx.dir.join("bad").join(format!("random-{i}")));
        // What a failed run left (e.g. a registry created before the link failed), and
        // this case's random file.
        for p in walk(&fx.dir) {
            if !before.contains(&p)
                || p.file_name()
                    .is_some_and(|n| n.to_string_lossy().starts_with("random-"))
            {
                let _ = std::fs::remove_file(&p);
            }
        }
        if !v.is_empty() {
            let args: Vec<String> = case.args.iter().map(|a| lossy(a)).collect();
            failures.push(format!(
                "[{}] fogsim {}: {} | stderr: {}",
                case.kind,
                args.join(" "),
                v.join("; "),
                o.stderr.trim().chars().take(300).collect::<String>()
            ));
        }
    }
    println!(
        "probe_invocations: seed {seed}: {n} invocations ({} of a catalogue of {catalogue_len}, \
         {} random) in {:.1} s: {} broke a rule; slowest {:.2} s ({slowest_case}), peak RSS {:.1} MB",
        cases.len().min(n),
        n.saturating_sub(cases.len()),
        t0.elapsed().as_secs_f64(),
        failures.len(),
        slowest.as_secs_f64(),
        peak_kib as f64 / 1024.0
    );
    for f in failures.iter().take(300) {
        println!("  {f}");
    }
    assert!(
        failures.is_empty(),
        "{} bad invocations broke a rule",
        failures.len()
    );
}
