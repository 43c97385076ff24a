//! A docs page run as written (issue 39 item 2): the runner behind `workflow.rs` and
//! `docs_pages.rs`. Every line of the page's fenced `sh` blocks (comments and blank lines
//! dropped) is one command, run in order by `sh -c` (so globs, `&&`, `for` loops, `mkdir`
//! and `cp` mean what they mean in a terminal) in the page's own scratch directory, which
//! stands for the repository root the pages run from:
//!
//! - `fogsim` is the binary under test (its directory first on `PATH`);
//! - `cargo fw-run -- ARGS` is its runner, `scripts/fw-qemu.sh`, on the `fog-app` the QEMU
//!   tests build; no other `cargo` line is run;
//! - a trailing `&` starts a background job, killed when the walk ends;
//! - the ports 4444-4447 (`127.0.0.1:PORT`) become free loopback ports, also given to the
//!   runner script as `FOG_HOST_PORT` ... `FOG_INCL_PORT`;
//! - the default registry lives in a scratch `XDG_DATA_HOME`;
//! - `../shared/` (the measured data beside the repository, `<repo>/../shared`) resolves as
//!   from the repository root: the scratch directory's parent holds `shared`, a link to the
//!   repository's `../shared`.
//!
//! A page with a `cargo fw-run` line skips loudly without QEMU / the target unless
//! FOG_REQUIRE_QEMU=1 (`fog_tests::qemu_ready`); a page using `../shared/` skips loudly
//! when that directory is not beside the repository.

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

use fog_tests::{firmware_elf, free_loopback_port, qemu_ready, workspace_root, KillOnDrop};

/// The ports the pages show (host, gyro, table, inclinometer), in `scripts/fw-qemu.sh`'s order.
const DOC_PORTS: [&str; 4] = ["4444", "4445", "4446", "4447"];
const PORT_VARS: [&str; 4] = [
    "FOG_HOST_PORT",
    "FOG_GYRO_PORT",
    "FOG_TABLE_PORT",
    "FOG_INCL_PORT",
];

/// The commands of a page's `sh` blocks, comments and blank lines dropped.
pub fn page_commands(page: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut in_sh = false;
    for line in page.lines() {
        let t = line.trim();
        if let Some(lang) = t.strip_prefix("```") {
            in_sh = !in_sh && lang.trim() == "sh";
            continue;
        }
        if in_sh && !t.is_empty() && !t.starts_with('#') {
            out.push(t.to_string());
        }
    }
    out
}

/// README.md and the pages under docs/ with an `sh` block, from the repository root, sorted.
pub fn pages_with_sh() -> Vec<String> {
    let root = workspace_root();
    let mut out = Vec::new();
    let mut todo = vec![root.join("README.md"), root.join("docs")];
    while let Some(p) = todo.pop() {
        if p.is_dir() {
            todo.extend(std::fs::read_dir(&p).unwrap().map(|e| e.unwrap().path()));
        } else if p.extension().is_some_and(|x| x == "md")
            && !page_commands(&std::fs::read_to_string(&p).unwrap()).is_empty()
        {
            out.push(p.strip_prefix(&root).unwrap().display().to_string());
        }
    }
    out.sort();
    out
}

/// One page of the docs: its path from the repository root and its `sh` commands.
pub struct Page {
    pub path: String,
    pub commands: Vec<String>,
}

impl Page {
    pub fn load(path: &str) -> Page {
        let text = std::fs::read_to_string(workspace_root().join(path))
            .unwrap_or_else(|e| panic!("{path}: {e}"));
        let commands = page_commands(&text);
        assert!(!commands.is_empty(), "{path} has no `sh` block left to run");
        Page {
            path: path.to_string(),
            commands,
        }
    }

    /// Asserts the page still has a command starting with each of `steps`.
    pub fn assert_steps(&self, steps: &[&str]) {
        for step in steps {
            assert!(
                self.commands.iter().any(|c| c.starts_with(step)),
                "{} lost its `{step}` step",
                self.path
            );
        }
    }

    /// Runs every command in a fresh scratch directory and returns the finished walk
    /// (background jobs still running), or `None` after a loud banner when this machine
    /// lacks what the page needs (QEMU, `../shared`).
    pub fn run(&self) -> Option<Walk> {
        let name = Path::new(&self.path)
            .file_stem()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        if self.commands.iter().any(|c| c.starts_with("cargo fw-run")) {
            if !qemu_ready(&self.path) {
                return None;
            }
            let _ = firmware_elf("fog-app"); // built before the clock starts
        }
        let shared = workspace_root().join("../shared");
        if self.commands.iter().any(|c| c.contains("../shared/")) && !shared.is_dir() {
            eprintln!("\n**********************************************************************");
            eprintln!(
                "** SKIPPING {}: it reads {} and that is not here",
                self.path,
                shared.display()
            );
            eprintln!("**********************************************************************\n");
            return None;
        }
        let mut walk = Walk::new(&name, &shared);
        let t0 = Instant::now();
        for c in &self.commands {
            walk.run(c);
        }
        walk.wall_s = t0.elapsed().as_secs_f64();
        eprintln!(
            "{}: {} commands, wall {:.1} s",
            self.path,
            self.commands.len(),
            walk.wall_s
        );
        Some(walk)
    }
}

/// A page being run: its scratch directory, ports, background jobs and each command's stdout.
pub struct Walk {
    /// The page's working directory (the repository root of its commands).
    pub dir: PathBuf,
    scratch: PathBuf,
    ports: Vec<(&'static str, String)>,
    jobs: Vec<(String, KillOnDrop, PathBuf)>,
    outputs: Vec<(String, String)>,
    /// Wall time of all the page's commands, seconds.
    pub wall_s: f64,
}

impl Walk {
    fn new(name: &str, shared: &Path) -> Walk {
        let scratch =
            std::env::temp_dir().join(format!("fogsim-docs-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&scratch);
        let dir = scratch.join("repo");
        std::fs::create_dir_all(&dir).unwrap();
        if shared.is_dir() {
            std::os::unix::fs::symlink(shared, scratch.join("shared")).unwrap();
        }
        Walk {
            dir,
            scratch,
            ports: DOC_PORTS
                .iter()
                .map(|p| (*p, free_loopback_port().to_string()))
                .collect(),
            jobs: Vec::new(),
            outputs: Vec::new(),
            wall_s: 0.0,
        }
    }

    /// The page's line as `sh` runs it: ports moved, `cargo fw-run` as its runner script.
    fn shell_line(&self, line: &str) -> String {
        let line = move_ports(line, &self.ports);
        if let Some(rest) = line.strip_prefix("cargo fw-run") {
            let args = rest.trim_start().strip_prefix("--").unwrap_or(rest);
            let script = workspace_root().join("scripts/fw-qemu.sh");
            let elf = firmware_elf("fog-app");
            return format!("{} {}{args}", script.display(), elf.display());
        }
        assert!(
            !line.starts_with("cargo"),
            "{line}: not a command this runner knows (only `cargo fw-run`)"
        );
        line
    }

    fn command(&self, line: &str) -> Command {
        let bin_dir = Path::new(env!("CARGO_BIN_EXE_fogsim")).parent().unwrap();
        let path = std::env::var_os("PATH").unwrap_or_default();
        let mut dirs = vec![bin_dir.to_path_buf()];
        dirs.extend(std::env::split_paths(&path));
        let mut cmd = Command::new("sh");
        cmd.arg("-c")
            .arg(line)
            .current_dir(&self.dir)
            .env("PATH", std::env::join_paths(dirs).unwrap())
            .env("XDG_DATA_HOME", self.scratch.join("data"))
            .stdin(Stdio::null());
        for ((_, free), var) in self.ports.iter().zip(PORT_VARS) {
            cmd.env(var, free);
        }
        cmd
    }

    /// Runs one line of the page; a failure fails the test with its output and the jobs' logs.
    pub fn run(&mut self, line: &str) {
        let background = line.ends_with('&');
        let shell = self.shell_line(line.trim_end_matches('&').trim_end());
        let t0 = Instant::now();
        if background {
            let log = self.scratch.join(format!("job-{}.log", self.jobs.len()));
            let file = std::fs::File::create(&log).unwrap();
            // `exec`: the job is the command itself, so killing it stops it.
            let child = self
                .command(&format!("exec {shell}"))
                .stdout(file.try_clone().unwrap())
                .stderr(file)
                .spawn()
                .unwrap_or_else(|e| panic!("{line}: {e}"));
            self.jobs.push((line.to_string(), KillOnDrop(child), log));
            return;
        }
        let out = self.command(&shell).output().unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
        let stderr = String::from_utf8_lossy(&out.stderr);
        eprintln!("$ {line}   ({:.1} s)", t0.elapsed().as_secs_f64());
        assert!(
            out.status.success(),
            "{line}\n{stdout}\n{stderr}\n{}{}",
            self.earlier_outputs(),
            self.job_logs()
        );
        self.outputs.push((line.to_string(), stdout));
    }

    /// The end of the output of every earlier command that printed something (a failure
    /// can lie upstream: a monitor that saw no result, then a pull that found none).
    fn earlier_outputs(&self) -> String {
        self.outputs
            .iter()
            .filter(|(_, out)| !out.is_empty())
            .map(|(l, out)| format!("--- earlier: {l}\n{}\n", tail_of(out.as_bytes())))
            .collect()
    }

    /// The end of every background job's log.
    pub fn job_logs(&self) -> String {
        self.jobs
            .iter()
            .map(|(l, _, log)| format!("--- {l}\n{}", tail(log)))
            .collect()
    }

    /// The stdout of the first command starting with `prefix`.
    pub fn output_of(&self, prefix: &str) -> &str {
        &self
            .outputs
            .iter()
            .find(|(l, _)| l.starts_with(prefix))
            .unwrap_or_else(|| panic!("no `{prefix}` among the page's commands"))
            .1
    }

    /// The first line starting with `start` of the stdout of the command starting with
    /// `command`.
    pub fn line_of(&self, command: &str, start: &str) -> &str {
        let out = self.output_of(command);
        out.lines()
            .find(|l| l.starts_with(start))
            .unwrap_or_else(|| {
                panic!(
                    "no `{start}` line from `{command}`: {out}\n{}",
                    self.job_logs()
                )
            })
    }

    /// The end of the log of the background job starting with `prefix`.
    pub fn job_log(&self, prefix: &str) -> String {
        let (_, _, log) = self
            .jobs
            .iter()
            .find(|(l, _, _)| l.starts_with(prefix))
            .unwrap_or_else(|| panic!("no `{prefix}` job on the page"));
        tail(log)
    }

    /// The file `rel` of the page's working directory, read as text.
    pub fn read(&self, rel: &str) -> String {
        std::fs::read_to_string(self.dir.join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
    }

    /// Stops the background jobs and removes the scratch directory.
    pub fn finish(mut self) {
        self.jobs.clear();
        std::fs::remove_dir_all(&self.scratch).unwrap();
    }
}

/// The last lines of a job's log (QEMU's console carries binary defmt frames: lossy).
fn tail(log: &Path) -> String {
    tail_of(&std::fs::read(log).unwrap_or_default())
}

/// The last 4,000 bytes of an output, as text (lossy).
fn tail_of(bytes: &[u8]) -> String {
    String::from_utf8_lossy(&bytes[bytes.len().saturating_sub(4000)..]).into_owned()
}

/// `line` with every `127.0.0.1:PORT` whose whole port number is one of `ports`' first
/// elements moved to its second, in one pass: a moved port is never read again (one
/// substitution after another turned 4445 -> 44479 into 44253 + "9" when 4447's free port
/// was 44253).
fn move_ports(line: &str, ports: &[(&str, String)]) -> String {
    const HOST: &str = "127.0.0.1:";
    let mut out = String::with_capacity(line.len());
    let mut rest = line;
    while let Some(at) = rest.find(HOST) {
        let (before, after) = rest.split_at(at + HOST.len());
        out.push_str(before);
        let digits = after.len() - after.trim_start_matches(|c: char| c.is_ascii_digit()).len();
        let (port, tail) = after.split_at(digits);
        match ports.iter().find(|(doc, _)| *doc == port) {
            Some((_, free)) => out.push_str(free),
            None => out.push_str(port),
        }
        rest = tail;
    }
    out.push_str(rest);
    out
}

#[test]
fn a_moved_port_is_not_moved_again() {
    let ports = [("4445", "44479".to_string()), ("4447", "44253".to_string())];
    assert_eq!(
        move_ports(
            "--gyro-port tcp:127.0.0.1:4445 --incl tcp:127.0.0.1:4447 x:127.0.0.1:44451",
            &ports
        ),
        "--gyro-port tcp:127.0.0.1:44479 --incl tcp:127.0.0.1:44253 x:127.0.0.1:44451"
    );
}
