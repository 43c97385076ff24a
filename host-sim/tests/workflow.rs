//! docs/workflow.md, run as written (issue 16.4): every fenced `sh` block of the page, in
//! order, each line one command. `fogsim` is the binary under test; `cargo fw-run -- ARGS`
//! is its runner (`scripts/fw-qemu.sh`) on the firmware the QEMU tests build; a trailing
//! `&` starts a background job (killed when the test ends); the ports 4444-4447 become
//! free loopback ports; the default registry lives in a scratch `XDG_DATA_HOME`.
//!
//! Checked: every command succeeds, the path's steps all among them (import, train,
//! compensate, heading-cal, upload, rig, monitor, field pull, train --field, registry); the
//! seek's azimuth is within 3 of its reported sigma of the rig's truth and its tilt
//! (measured over the inclinometer link, no `tilt-mdeg=`) within 0.01 deg of the rig's
//! base; the seek's field record pulled and counted by `train --field` (all read from
//! the commands' own output lines); the model carries the heading calibration; the
//! registry shows the upload and the result. Prints the error, sigma and wall time.
//!
//! Skips loudly without QEMU / the target unless FOG_REQUIRE_QEMU=1.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

use fog_tests::{firmware_elf, free_loopback_port, qemu_ready, workspace_root, KillOnDrop};

/// The commands of the page's `sh` blocks, comments and blank lines dropped.
fn page_commands(page: &str) -> Vec<String> {
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

/// A command line split on spaces (the page uses no quoting).
fn words(line: &str) -> Vec<String> {
    line.split_whitespace().map(str::to_string).collect()
}

struct Walk {
    dir: PathBuf,
    ports: [(String, String); 4],
    jobs: Vec<(String, KillOnDrop, PathBuf)>,
    outputs: Vec<(String, String)>,
}

impl Walk {
    fn command(&self, argv: &[String]) -> Command {
        let (program, args): (PathBuf, Vec<String>) = match argv[0].as_str() {
            "fogsim" => (env!("CARGO_BIN_EXE_fogsim").into(), argv[1..].to_vec()),
            "cargo" if argv.get(1).map(String::as_str) == Some("fw-run") => {
                assert_eq!(argv.get(2).map(String::as_str), Some("--"), "{argv:?}");
                let mut a = vec![firmware_elf("fog-app").display().to_string()];
                a.extend(argv[3..].iter().cloned());
                (workspace_root().join("scripts/fw-qemu.sh"), a)
            }
            other => panic!("docs/workflow.md runs {other:?}: not a command this test knows"),
        };
        let mut cmd = Command::new(program);
        cmd.args(args)
            .current_dir(&self.dir)
            .env("XDG_DATA_HOME", self.dir.join("data"))
            .env("FOG_HOST_PORT", &self.ports[0].1)
            .env("FOG_GYRO_PORT", &self.ports[1].1)
            .env("FOG_TABLE_PORT", &self.ports[2].1)
            .env("FOG_INCL_PORT", &self.ports[3].1)
            .stdin(Stdio::null());
        cmd
    }

    fn run(&mut self, line: &str) {
        let mut line = line.to_string();
        for (doc, free) in &self.ports {
            line = line.replace(&format!("127.0.0.1:{doc}"), &format!("127.0.0.1:{free}"));
        }
        let background = line.ends_with('&');
        let argv = words(line.trim_end_matches('&'));
        let t0 = Instant::now();
        if background {
            let log = self.dir.join(format!("job-{}.log", self.jobs.len()));
            let file = std::fs::File::create(&log).unwrap();
            let child = self
                .command(&argv)
                .stdout(file.try_clone().unwrap())
                .stderr(file)
                .spawn()
                .unwrap_or_else(|e| panic!("{line}: {e}"));
            self.jobs.push((line, KillOnDrop(child), log));
            return;
        }
        let out = self.command(&argv).output().unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
        let stderr = String::from_utf8_lossy(&out.stderr);
        eprintln!("$ {line}   ({:.1} s)", t0.elapsed().as_secs_f64());
        assert!(
            out.status.success(),
            "{line}\n{stdout}\n{stderr}\n{}",
            self.job_logs()
        );
        self.outputs.push((line, stdout));
    }

    fn job_logs(&self) -> String {
        self.jobs
            .iter()
            .map(|(l, _, log)| format!("--- {l}\n{}", tail(log)))
            .collect()
    }

    fn output_of(&self, prefix: &str) -> &str {
        &self
            .outputs
            .iter()
            .find(|(l, _)| l.starts_with(prefix))
            .unwrap_or_else(|| panic!("no `{prefix}` in docs/workflow.md"))
            .1
    }
}

/// The last lines of a job's log (QEMU's console carries binary defmt frames: lossy).
fn tail(log: &Path) -> String {
    let bytes = std::fs::read(log).unwrap_or_default();
    let text = String::from_utf8_lossy(&bytes[bytes.len().saturating_sub(4000)..]).into_owned();
    text
}

/// The value of `key=` in a `key=value` line.
fn field(line: &str, key: &str) -> f64 {
    line.split_whitespace()
        .find_map(|w| w.strip_prefix(&format!("{key}=")))
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no {key}= in {line:?}"))
}

/// The seek's field record: pulled, then counted by `train --field` as measured under the
/// heading-calibrated variant of the retrained model (the registry knows it); one power-on
/// has no test power, the model is left unchanged.
fn check_field_step(walk: &Walk, dir: &Path) {
    let pull = walk.output_of("fogsim field pull");
    assert!(
        pull.contains("pulled=1 ") && pull.contains("registry_added=1"),
        "{pull}"
    );
    let refined = walk.output_of("fogsim train runs --type type.json --out model-field.fogm");
    assert!(
        refined
            .contains("field refinement: 1 field seeks used (1 of them under heading-calibrated")
            && refined.contains("no test power"),
        "{refined}"
    );
    assert_eq!(
        std::fs::read(dir.join("model-field.fogm")).unwrap(),
        std::fs::read(dir.join("model.fogm")).unwrap(),
        "no test power: the model unchanged"
    );
}

#[test]
fn the_workflow_page_runs_as_written_and_finds_north() {
    if !qemu_ready("workflow") {
        return;
    }
    let _ = firmware_elf("fog-app"); // built before the clock starts
    let dir = std::env::temp_dir().join(format!("fogsim-workflow-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let page = std::fs::read_to_string(workspace_root().join("docs/workflow.md")).unwrap();
    let ports =
        ["4444", "4445", "4446", "4447"].map(|p| (p.to_string(), free_loopback_port().to_string()));
    let mut walk = Walk {
        dir: dir.clone(),
        ports,
        jobs: Vec::new(),
        outputs: Vec::new(),
    };
    let t0 = Instant::now();
    let commands = page_commands(&page);
    for step in [
        "fogsim import",
        "fogsim campaign --out fleet --units",
        "fogsim train fleet --type-out",
        "fogsim train runs --type",
        "fogsim compensate",
        "fogsim heading-cal --from-runs",
        "cargo fw-run",
        "fogsim rig",
        "fogsim upload",
        "fogsim monitor",
        "fogsim field pull",
        "fogsim train runs --type type.json --out model-field.fogm",
        "fogsim registry show",
    ] {
        assert!(
            commands.iter().any(|c| c.starts_with(step)),
            "docs/workflow.md lost its `{step}` step"
        );
    }
    assert!(
        !commands.iter().any(|c| c.contains("tilt-mdeg=")),
        "the walk's tilt comes over the inclinometer link"
    );
    for c in &commands {
        walk.run(c);
    }
    let wall = t0.elapsed().as_secs_f64();

    let rig_log = &walk
        .jobs
        .iter()
        .find(|(l, _, _)| l.starts_with("fogsim rig"))
        .expect("the page starts the rig")
        .2;
    let rig = tail(rig_log);
    let truth_line = rig
        .lines()
        .find(|l| l.starts_with("rig truth"))
        .unwrap_or_else(|| panic!("rig output: {rig}"));
    let truth = field(truth_line, "azimuth_deg");
    let monitor = walk.output_of("fogsim monitor");
    let result = monitor
        .lines()
        .find(|l| l.starts_with("result "))
        .unwrap_or_else(|| panic!("no result line: {monitor}\n{}", walk.job_logs()));
    let (azimuth, sigma) = (field(result, "azimuth_deg"), field(result, "sigma_deg"));
    let err = (azimuth - truth + 540.0).rem_euclid(360.0) - 180.0;
    eprintln!(
        "workflow: azimuth {azimuth:.4} deg, truth {truth:.4}, error {err:+.4} deg, reported sigma {sigma:.4} deg ({:.2} sigma); {} commands, wall {wall:.1} s",
        err.abs() / sigma,
        commands.len()
    );
    assert!(result.contains("verdict=valid"), "{result}");
    assert!(sigma > 0.0 && err.abs() <= 3.0 * sigma, "{result}");
    for axis in ["pitch_deg", "roll_deg"] {
        let (measured, base) = (field(result, axis), field(truth_line, axis));
        eprintln!("workflow: {axis} {measured} over the inclinometer link, rig base {base}");
        assert!(
            (measured - base).abs() <= 0.01,
            "{axis}: device {measured} over the inclinometer link, rig base {base}"
        );
    }
    assert!(
        walk.output_of("fogsim heading-cal")
            .contains("heading calibration a ="),
        "{}",
        walk.output_of("fogsim heading-cal")
    );
    check_field_step(&walk, &dir);
    let show = walk.output_of("fogsim registry show");
    assert!(
        show.contains("committed") && show.contains("seek results: 1"),
        "{show}"
    );
    let csv = std::fs::read_to_string(dir.join("results.csv")).unwrap();
    assert_eq!(csv.lines().count(), 2, "{csv}");
    drop(walk);
    std::fs::remove_dir_all(&dir).unwrap();
}
