//! Every `fogsim` command shown in the docs names a subcommand and flags the binary has
//! (issue 39 item 2). docs/workflow.md is run as written by `workflow.rs`; the other
//! pages show commands with placeholders (`RUNS...`, `[--registry DB]`), hardware ports and
//! campaigns of hours, so they are not run here: each command line in a fenced block is
//! checked against `fogsim <subcommand> --help`, which catches the usual drift of a page
//! (a renamed or removed flag, a subcommand that moved). Lines that are a command's output
//! (`fogsim upload: WARNING ...`) are skipped by their colon.

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
    // `fogsim`, a path ending in it, or `$B` / `$F` standing for the built binary.
    let at = words
        .iter()
        .position(|w| *w == "fogsim" || w.ends_with("/fogsim") || *w == "$B" || *w == "$F")?;
    let rest: Vec<String> = words[at + 1..].iter().map(|w| w.to_string()).collect();
    // A command's output ("fogsim upload: ...") or a sentence, not a command.
    let command = rest
        .first()
        .is_some_and(|w| w.chars().all(|c| c.is_ascii_lowercase() || c == '-'));
    command.then_some(rest)
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
}
