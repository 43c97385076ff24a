//! Units in every flag, one convention across `fogsim`'s subcommands: a flag that carries a
//! physical quantity ends in its unit (`--latitude-deg`, `--ambient-c`, `--dwell-s`,
//! `--duration-min`, `--heading-bias-dph`, `--raw-rate-hz`); the names before the rename still
//! parse, to the same values, as hidden aliases; every help text prints a default the same way
//! (`[default: ...]`).

use std::process::Command;

use clap::{Args, FromArgMatches};
use fog_sim::cmd;

/// `fogsim ARGS` stdout (must succeed).
fn fogsim_stdout(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_fogsim"))
        .args(args)
        .output()
        .expect("fogsim runs");
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The subcommands `fogsim --help` lists (without `help`).
fn subcommands() -> Vec<String> {
    let help = fogsim_stdout(&["--help"]);
    help.lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .map(str::to_string)
        .collect()
}

/// The long flags a help text shows (`--name` at the start of an option line).
fn shown_flags(help: &str) -> Vec<String> {
    help.lines()
        .map(str::trim_start)
        .filter(|l| l.starts_with('-'))
        .filter_map(|l| l.split_whitespace().find(|t| t.starts_with("--")))
        .map(|t| t.trim_end_matches(',').to_string())
        .collect()
}

/// Renamed flags: (subcommand, old name, new name).
const RENAMED: [(&str, &str, &str); 11] = [
    ("campaign", "--ambient", "--ambient-c"),
    ("campaign", "--minutes", "--duration-min"),
    ("campaign", "--latitude", "--latitude-deg"),
    ("reproduce", "--ambient", "--ambient-c"),
    ("reproduce", "--minutes", "--duration-min"),
    ("north-seek", "--latitude", "--latitude-deg"),
    ("north-seek", "--ambient", "--ambient-c"),
    ("north-seek", "--azimuth", "--azimuth-deg"),
    ("north-seek", "--dwell", "--dwell-s"),
    ("monitor", "--latitude", "--latitude-deg"),
    ("monitor", "--start", "--positions"),
];

/// Word stems of physical quantities: a flag containing one must end in a unit.
const QUANTITY_STEMS: [&str; 16] = [
    "latitude",
    "longitude",
    "azimuth",
    "heading",
    "ambient",
    "temp",
    "temperature",
    "tilt",
    "dwell",
    "duration",
    "minutes",
    "timeout",
    "time",
    "bias",
    "rate",
    "target",
];
/// Unit suffixes of the convention (deg, degC, s, min, h, deg/h, Hz, ms).
const UNIT_SUFFIXES: [&str; 8] = ["-deg", "-c", "-s", "-min", "-h", "-dph", "-hz", "-ms"];

#[test]
fn every_quantity_flag_in_every_help_ends_in_its_unit() {
    let subs = subcommands();
    assert!(subs.len() >= 11, "{subs:?}");
    for sub in &subs {
        let help = fogsim_stdout(&[sub, "--help"]);
        for flag in shown_flags(&help) {
            let quantity = flag
                .trim_start_matches("--")
                .split('-')
                .any(|w| QUANTITY_STEMS.contains(&w));
            if quantity {
                assert!(
                    UNIT_SUFFIXES.iter().any(|u| flag.ends_with(u)),
                    "fogsim {sub}: {flag} carries a quantity but no unit suffix"
                );
            }
        }
        // Defaults read the same everywhere: clap's `[default: ...]`, also for the
        // computed ones written in the doc comment.
        for (at, _) in help.match_indices("default:") {
            assert!(
                help[..at].ends_with('['),
                "fogsim {sub}: a default not written as `[default: ...]`:\n{help}"
            );
        }
    }
    for (sub, old, new) in RENAMED {
        let help = fogsim_stdout(&[sub, "--help"]);
        let flags = shown_flags(&help);
        assert!(
            flags.iter().any(|f| f == new),
            "fogsim {sub} --help lacks {new}: {flags:?}"
        );
        assert!(
            !flags.iter().any(|f| f == old),
            "fogsim {sub} --help still shows {old}"
        );
    }
}

/// Parses `argv` (after the subcommand) into `A`.
fn parse<A: Args + FromArgMatches>(argv: &[&str]) -> A {
    let command = A::augment_args(clap::Command::new("sub").no_binary_name(true));
    let matches = command
        .try_get_matches_from(argv)
        .unwrap_or_else(|e| panic!("{argv:?}: {e}"));
    A::from_arg_matches(&matches).unwrap()
}

/// `argv` with every new name in it replaced by the old one.
fn with_old_names(sub: &str, argv: &[&str]) -> Vec<String> {
    argv.iter()
        .map(|a| {
            let (flag, value) = a.split_once('=').map_or((*a, None), |(f, v)| (f, Some(v)));
            let flag = RENAMED
                .iter()
                .find(|(s, _, new)| *s == sub && *new == flag)
                .map_or(flag, |(_, old, _)| *old);
            value.map_or(flag.to_string(), |v| format!("{flag}={v}"))
        })
        .collect()
}

/// Parses `argv` with the new names and with the old ones: the same options (and not the
/// defaults, so the renamed flags were taken).
fn same_with_old_names<A: Args + FromArgMatches + std::fmt::Debug>(
    sub: &str,
    base: &[&str],
    renamed: &[&str],
) {
    let new: Vec<&str> = base.iter().chain(renamed).copied().collect();
    let old = with_old_names(sub, &new);
    assert_ne!(old, new.iter().map(|s| s.to_string()).collect::<Vec<_>>());
    let old: Vec<&str> = old.iter().map(String::as_str).collect();
    let (a, b) = (
        format!("{:?}", parse::<A>(&new)),
        format!("{:?}", parse::<A>(&old)),
    );
    assert_eq!(a, b, "fogsim {sub}: old names parse differently");
    assert_ne!(
        a,
        format!("{:?}", parse::<A>(base)),
        "fogsim {sub}: the renamed flags were ignored"
    );
}

#[test]
fn old_names_still_parse_to_the_same_options() {
    same_with_old_names::<cmd::campaign::Args>(
        "campaign",
        &["--out", "x"],
        &[
            "--ambient-c=-10,20",
            "--duration-min",
            "30",
            "--latitude-deg",
            "-12.5",
        ],
    );
    same_with_old_names::<cmd::reproduce::Args>(
        "reproduce",
        &[],
        &["--ambient-c", "0,20", "--duration-min=35"],
    );
    same_with_old_names::<cmd::north_seek::Args>(
        "north-seek",
        &[],
        &[
            "--latitude-deg",
            "-30",
            "--ambient-c",
            "-5",
            "--azimuth-deg",
            "12.5",
            "--dwell-s",
            "90",
        ],
    );
    same_with_old_names::<cmd::monitor::Args>(
        "monitor",
        &["--port", "tcp:127.0.0.1:1", "--csv", "r.csv"],
        &["--latitude-deg", "-33.9", "--positions", "4"],
    );
}
