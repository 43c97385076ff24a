//! `fogsim diagnose` keeps memory bounded per row (issue 18 item 8, issue 17 item 5:
//! at most 300 B per 10 s row). Two campaigns of the same shape, one `SCALE` times the
//! runs of the other, are diagnosed as child processes; each child's peak RSS comes from
//! `wait4` (that child's own rusage, not the campaign generator's). The bytes per row are
//! the slope between the two (the binary and the fixed tables cancel).
//!
//! `DIAG_MEM_MINUTES` sets the record length (default 240 min, 11 ambients x 1 and x 3
//! runs: 15,840 and 47,520 rows, ~35 s with the optimised test profile). Below ~60,000
//! rows the trainer cross-check's candidate count still grows with the rows (up to its
//! cap of 500), so its Grams add to the slope: at 120 min the same measurement reads
//! 464 B/row, at 240 min 171 B/row (1,513 and 507 B/row before the trainer's Grams
//! were built one fold at a time and the residuals of each degree dropped after
//! scoring); 149-157 B/row since the simulator's design and the bases compute their rows
//! on demand (154 before: at these sizes the peak is still the trainer cross-check's, the
//! diagnosis' own gain shows on long campaigns). The bound is 200 B/row, 27-34 % above
//! what is measured. Measured figures and the 316,800-row campaign (226 B/row whole,
//! 167 B/row slope from 63,360 rows): docs/record/diagnose.md, "Memory".

use crate::app_support;

use std::path::Path;
use std::process::Command;

/// The bound, bytes of peak RSS per 10 s row (the 300, tightened to what the
/// diagnosis now needs plus a margin: 149-157 measured).
const MAX_BYTES_PER_ROW: f64 = 200.0;
/// Run-count ratio between the large and the small campaign.
const SCALE: usize = 3;

fn fogsim(args: &[&str]) {
    app_support::fogsim_ok(args);
}

/// Peak RSS of one `fogsim diagnose` child, bytes.
fn diagnose_peak_rss_bytes(camp: &Path, json: &Path) -> f64 {
    let child = Command::new(env!("CARGO_BIN_EXE_fogsim"))
        .args([
            "diagnose",
            camp.to_str().unwrap(),
            "--json",
            json.to_str().unwrap(),
        ])
        .stdout(std::process::Stdio::null())
        .spawn()
        .expect("spawn fogsim diagnose");
    let pid = child.id() as libc::pid_t;
    let mut status = 0;
    // SAFETY: plain syscall on our own child; `usage` is a valid out-pointer.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let r = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    assert_eq!(r, pid, "wait4 failed");
    assert!(
        libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0,
        "fogsim diagnose failed on {}",
        camp.display()
    );
    std::mem::forget(child); // already reaped by wait4
    usage.ru_maxrss as f64 * 1024.0 // Linux: KiB
}

fn rows_of(camp: &Path) -> usize {
    std::fs::read_dir(camp)
        .unwrap()
        .map(|e| {
            let text = std::fs::read_to_string(e.unwrap().path()).unwrap();
            text.lines()
                .filter(|l| !l.starts_with('#') && !l.starts_with("t_s"))
                .count()
        })
        .sum()
}

#[test]
fn diagnose_peak_memory_grows_at_most_200_bytes_per_row() {
    let minutes = std::env::var("DIAG_MEM_MINUTES").unwrap_or_else(|_| "240".into());
    let dir = tempfile_dir();
    let mut points = Vec::new();
    for runs in [1, SCALE] {
        let camp = dir.join(format!("c{runs}"));
        let runs_s = runs.to_string();
        fogsim(&[
            "campaign",
            "--out",
            camp.to_str().unwrap(),
            "--runs",
            &runs_s,
            "--duration-min",
            &minutes,
            "--seed",
            "3",
        ]);
        let rows = rows_of(&camp);
        let rss = diagnose_peak_rss_bytes(&camp, &dir.join(format!("c{runs}.json")));
        points.push((rows as f64, rss));
    }
    let (small, large) = (points[0], points[1]);
    let per_row = (large.1 - small.1) / (large.0 - small.0);
    eprintln!(
        "peak RSS {:.1} MB at {} rows, {:.1} MB at {} rows: {per_row:.0} B per row",
        small.1 / 1e6,
        small.0,
        large.1 / 1e6,
        large.0
    );
    assert!(
        per_row <= MAX_BYTES_PER_ROW,
        "diagnose keeps {per_row:.0} B per 10 s row (bound {MAX_BYTES_PER_ROW})"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A fresh directory of this test's own (pid in the name: concurrent runs never mix).
fn tempfile_dir() -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("fog_diag_mem_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}
