//! Command-line errors as one line (what, where, why), like every other fogsim error.
//! clap's own report spans several lines (the error, a tip, the usage, "For more
//! information") and, for an argument that is not UTF-8, does not say which one; help
//! and version requests are printed as clap prints them.

use std::ffi::OsString;

use clap::error::ErrorKind;

use crate::io::run_format::excerpt;

/// Longest quoted value kept whole in the line, characters.
const MAX_QUOTED_CHARS: usize = 40;

/// Prints `e` (help, version) or its one-line form, and exits as clap does (status 2
/// for an error).
pub fn exit(e: clap::Error) -> ! {
    match e.kind() {
        ErrorKind::DisplayHelp
        | ErrorKind::DisplayVersion
        | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => e.exit(),
        _ => {
            eprintln!("fogsim: error: {}", one_line(&e, std::env::args_os()));
            std::process::exit(2)
        }
    }
}

/// `e` as one line; `args` (the command line) names the argument that is not UTF-8.
pub fn one_line(e: &clap::Error, args: impl IntoIterator<Item = OsString>) -> String {
    if e.kind() == ErrorKind::InvalidUtf8 {
        let args: Vec<OsString> = args.into_iter().collect();
        if let Some(i) = args.iter().position(|a| a.to_str().is_none()) {
            let value = short_value(&args[i].to_string_lossy());
            let flag = (i > 0)
                .then(|| args[i - 1].to_str())
                .flatten()
                .filter(|f| f.starts_with('-'));
            return match flag {
                Some(f) => format!("{f} '{value}': not UTF-8"),
                None => format!("argument {i} '{value}': not UTF-8"),
            };
        }
    }
    let text = e.render().to_string();
    let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
    let first = lines.next().unwrap_or("invalid command line");
    let mut line = first.trim_start_matches("error: ").to_string();
    // "the following required arguments were not provided:" and the list under it.
    if line.ends_with(':') {
        let listed: Vec<&str> = lines
            .take_while(|l| !l.starts_with("Usage:") && !l.starts_with("For more"))
            .collect();
        line = format!("{} {}", line, listed.join(", "));
    }
    excerpt(&shorten_quoted(&line))
}

/// `line` with every `'...'` quotation longer than [`MAX_QUOTED_CHARS`] cut short.
fn shorten_quoted(line: &str) -> String {
    let mut out = String::new();
    for (i, part) in line.split('\'').enumerate() {
        if i > 0 {
            out.push('\'');
        }
        // Odd parts are inside quotes.
        out.push_str(&if i % 2 == 1 {
            short_value(part)
        } else {
            part.to_string()
        });
    }
    out
}

fn short_value(v: &str) -> String {
    if v.chars().count() <= MAX_QUOTED_CHARS {
        return v.to_string();
    }
    let head: String = v.chars().take(MAX_QUOTED_CHARS - 3).collect();
    format!("{head}...")
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser, Debug)]
    #[command(name = "t")]
    struct Cli {
        #[arg(long)]
        seed: u64,
        #[arg(long)]
        out: String,
    }

    fn error_of(args: &[OsString]) -> String {
        let e = Cli::try_parse_from(args).unwrap_err();
        one_line(&e, args.to_vec())
    }

    fn os(v: &[&str]) -> Vec<OsString> {
        v.iter().map(OsString::from).collect()
    }

    #[test]
    fn every_clap_error_is_one_short_line_naming_the_argument() {
        let cases: [(Vec<OsString>, &str); 4] = [
            (os(&["t", "--seed", "abc", "--out", "x"]), "'--seed <SEED>'"),
            (os(&["t", "--seed", "1", "--out"]), "'--out <OUT>'"),
            (os(&["t", "--seed", "1"]), "--out <OUT>"),
            (
                os(&["t", "--seed", "1", "--out", "x", "--nope"]),
                "'--nope'",
            ),
        ];
        for (args, needle) in cases {
            let line = error_of(&args);
            assert!(line.contains(needle), "{args:?}: {line}");
            assert!(!line.contains('\n') && !line.contains("For more"), "{line}");
        }
        let long = format!("{}x", "9".repeat(100_000));
        let line = error_of(&os(&["t", "--seed", &long, "--out", "x"]));
        assert!(
            line.len() < 200 && line.contains("'--seed <SEED>'"),
            "{line}"
        );
    }

    #[cfg(unix)]
    #[test]
    fn an_argument_that_is_not_utf8_is_named_with_its_flag() {
        use std::os::unix::ffi::OsStringExt;
        let mut args = os(&["t", "--seed", "1", "--out"]);
        args.push(OsString::from_vec(b"a\xFFb".to_vec()));
        assert_eq!(error_of(&args), "--out 'a\u{FFFD}b': not UTF-8");
    }
}
