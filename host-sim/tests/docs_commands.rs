//! Every `fogsim` command shown in the docs names a subcommand and flags the binary has
//! (issue 39 item 2), and every concrete one is run. Each command line in a fenced block of
//! README.md and docs/ (but docs/workflow.md) is checked against `fogsim <subcommand>
//! --help`, which catches the usual drift of a page (a renamed or removed flag, a
//! subcommand that moved) with a clearer message than a failed run: the synopses with
//! placeholders (`RUNS...`, `DIR`, `[--registry DB]`, `/dev/ttyUSB0`), the lines of the
//! `sh` blocks too (those are also run as written: docs/workflow.md by `workflow.rs`, every
//! other page by `docs_pages.rs`), and `cargo run [--release] -p fog-sim -- ...` lines
//! (the README's and results page's release runs, minutes each, named only). Lines that are
//! a command's output (`fogsim upload: WARNING ...`) are skipped by their colon.
//!
//! A line starting with `fogsim` outside an `sh` block must show a placeholder (an upper-case word such
//! as `DIR`, `FILE...` or `MODEL.fogm`, a `[`, `...` or `/dev/`): a concrete command goes
//! in an `sh` block, where a test runs it. Exempt: a transcript line (`$ fogsim ...`, a
//! shown run and its output) and docs/record/ (the dated runs that made its figures).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The pages checked: README.md and everything under docs/ but the workflow page.
fn pages() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut out = vec![root.join("README.md")];
    let mut dirs = vec![root.join("docs")];
    while let Some(d) = dirs.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                dirs.push(p);
            } else if p.extension().is_some_and(|x| x == "md") && !p.ends_with("workflow.md") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// The words after `fogsim` on every line of the page's fenced blocks that runs it.
fn command_lines(page: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let mut fenced = false;
    for line in page.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if !fenced {
            continue;
        }
        let code = line.split(" # ").next().unwrap_or("");
        for segment in code.split(['&', ';', '|']) {
            if let Some(rest) = fogsim_words(segment) {
                out.push(rest);
            }
        }
    }
    out
}

/// The words after `fogsim` in one command of a line, if it runs `fogsim`.
fn fogsim_words(segment: &str) -> Option<Vec<String>> {
    let words: Vec<&str> = segment.split_whitespace().collect();
    // `fogsim`, a path ending in it, or `$B` / `$F` standing for the built binary; or the
    // `--` of `cargo run ... -p fog-sim -- ...`.
    let cargo_run = words.starts_with(&["cargo", "run"]) && words.contains(&"fog-sim");
    let at = words.iter().position(|w| {
        *w == "fogsim"
            || w.ends_with("/fogsim")
            || *w == "$B"
            || *w == "$F"
            || (cargo_run && *w == "--")
    })?;
    let rest: Vec<String> = words[at + 1..].iter().map(|w| w.to_string()).collect();
    // A command's output ("fogsim upload: ...") or a sentence, not a command.
    let command = rest
        .first()
        .is_some_and(|w| w.chars().all(|c| c.is_ascii_lowercase() || c == '-'));
    command.then_some(rest)
}

/// The lines starting with `fogsim` in the page's fenced blocks other than `sh` that show
/// no placeholder: concrete commands no test runs.
fn concrete_outside_sh(page: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut block: Option<String> = None;
    for line in page.lines() {
        let t = line.trim();
        if let Some(lang) = t.strip_prefix("```") {
            block = match block {
                None => Some(lang.trim().to_string()),
                Some(_) => None,
            };
            continue;
        }
        let code = t.split(" # ").next().unwrap_or("");
        let outside_sh = block.as_deref().is_some_and(|lang| lang != "sh");
        if outside_sh
            && code.starts_with("fogsim ")
            && fogsim_words(code).is_some()
            && !shows_placeholder(code)
        {
            out.push(t.to_string());
        }
    }
    out
}

/// Whether a command line shows a placeholder: `[`, `...`, `/dev/`, or an upper-case word
/// (`DIR`, `DIR/x.csv`, `FILE...`, `MODEL.fogm`; not a value such as `QEMU-FOG-1`, `U11`).
fn shows_placeholder(line: &str) -> bool {
    let upper = |w: &str| {
        let n = w
            .chars()
            .take_while(|c| c.is_ascii_uppercase() || *c == '_')
            .count();
        n >= 2 && !w[n..].starts_with(|c: char| c.is_ascii_alphanumeric() || c == '-')
    };
    line.contains('[')
        || line.contains("...")
        || line.contains("/dev/")
        || line.split_whitespace().any(|w| w.split('/').any(upper))
}

/// The flag a word gives (`--json`, from `--json`, `[--json`, `--ambient-c=-40`), if any.
fn flag_of(word: &str) -> Option<String> {
    let w = word.trim_start_matches('[').trim_start_matches('(');
    let name: String = w
        .strip_prefix("--")?
        .chars()
        .take_while(|c| c.is_ascii_alphanumeric() || *c == '-')
        .collect();
    (!name.is_empty()).then(|| format!("--{name}"))
}

fn help(args: &[&str]) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_fogsim"))
        .args(args)
        .arg("--help")
        .output()
        .expect("run fogsim --help");
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Whether `help` shows `flag` as an option or a visible alias.
fn shows(help: &str, flag: &str) -> bool {
    help.match_indices(flag).any(|(i, _)| {
        let next = help[i + flag.len()..].chars().next();
        !next.is_some_and(|c| c.is_ascii_alphanumeric() || c == '-')
    })
}

#[test]
fn every_documented_command_names_a_subcommand_and_flags_fogsim_has() {
    let mut helps: BTreeMap<String, String> = BTreeMap::new();
    let top = help(&[]);
    let mut faults = Vec::new();
    let mut checked = 0;
    for page in pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        for words in command_lines(&text) {
            let sub = words[0].clone();
            if !shows(&top, &format!("  {sub} ")) && !top.contains(&format!("  {sub}\n")) {
                faults.push(format!(
                    "{}: `fogsim {sub}`: no such subcommand",
                    page.display()
                ));
                continue;
            }
            // A subcommand with subcommands of its own (`field pull`): its next word.
            let mut path = vec![sub.clone()];
            let first = helps
                .entry(sub.clone())
                .or_insert_with(|| help(&[&sub]))
                .clone();
            if first.contains("Commands:") {
                if let Some(next) = words.get(1).filter(|w| !w.starts_with('-')) {
                    path.push(next.clone());
                }
            }
            let key = path.join(" ");
            let text_help = helps
                .entry(key.clone())
                .or_insert_with(|| help(&path.iter().map(String::as_str).collect::<Vec<_>>()))
                .clone();
            for flag in words.iter().filter_map(|w| flag_of(w)) {
                if flag != "--help" && !shows(&text_help, &flag) {
                    faults.push(format!("{}: `fogsim {key}` has no {flag}", page.display()));
                }
            }
            checked += 1;
        }
    }
    for page in pages()
        .into_iter()
        .filter(|p| !p.parent().unwrap().ends_with("record"))
    {
        for line in concrete_outside_sh(&std::fs::read_to_string(&page).unwrap()) {
            faults.push(format!(
                "{}: `{line}` is concrete but not in an `sh` block (docs_pages.rs runs those)",
                page.display()
            ));
        }
    }
    assert!(checked >= 20, "only {checked} documented commands found");
    assert!(
        faults.is_empty(),
        "{} faults:\n{}",
        faults.len(),
        faults.join("\n")
    );
}

#[test]
fn a_renamed_flag_on_a_page_is_a_fault() {
    let lines = command_lines("```sh\nfogsim campaign --out x --no-such-flag 3\n```\n");
    let h = help(&["campaign"]);
    let flags: Vec<String> = lines[0].iter().filter_map(|w| flag_of(w)).collect();
    assert_eq!(flags, ["--out", "--no-such-flag"]);
    assert!(shows(&h, "--out") && !shows(&h, "--no-such-flag"));
    // Output lines are not commands.
    assert!(command_lines("```text\nfogsim upload: WARNING test key\n```\n").is_empty());
    // A release run through cargo names the subcommand after `--`.
    let cargo = command_lines("```\ncargo run --release -p fog-sim -- demo --json x\n```\n");
    assert_eq!(cargo, [["demo", "--json", "x"]]);
}

#[test]
fn a_concrete_command_outside_an_sh_block_is_a_fault() {
    let page = "```text\nfogsim train runs --out m.fogm --gyro-id QEMU-FOG-1\n\
                fogsim train RUNS... --out MODEL.fogm\nfogsim import DIR --out DIR\n\
                fogsim diagnose DIR/TVCtest3_7_20_gyro_x.csv\n\
                fogsim upload --port /dev/ttyUSB0 m.fogm\nfogsim allan x.csv [--column C]\n\
                $ fogsim upload --port tcp:127.0.0.1:5544 m.fogm\n```\n\
                ```sh\nfogsim train runs --out m.fogm\n```\n";
    assert_eq!(
        concrete_outside_sh(page),
        ["fogsim train runs --out m.fogm --gyro-id QEMU-FOG-1"]
    );
}
