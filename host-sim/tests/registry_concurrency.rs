//! The calibration registry under concurrent writers (issue 16.5): writer processes and
//! threads at once on one new database, each issuing counters for one gyro, recording
//! an upload per counter and a seek result per counter. Checked: no counter issued twice
//! (every writer's counters collected and compared), counters 1..=N without a gap (no
//! issue lost), and every upload and seek row present.
//!
//! The processes are this test binary run again with `FOGSIM_REGISTRY_WRITER` set (the
//! `writer_process` test, which does nothing otherwise).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use fog_core::link::messages::SeekReport;
use fog_core::seeking::quality::Validity;
use fog_core::seeking::tilt::Tilt;
use fog_sim::registry::{Registry, SeekContext, SeekRecord};

const GYRO: &str = "FOG-CONC";
const PROCESSES: usize = 4;
const THREADS: usize = 4;
const ISSUES_EACH: u32 = 25;

/// One writer: `ISSUES_EACH` x (issue a counter, begin + finish an upload, a seek
/// result); returns the counters it was issued.
fn write(path: &Path, writer: u32) -> Vec<u32> {
    // Start together: say ready, wait (bounded) for the parent's `go` file.
    std::fs::write(path.with_file_name(format!("ready-{writer}")), b"").unwrap();
    let go = path.with_file_name("go");
    let t0 = Instant::now();
    while !go.exists() && t0.elapsed().as_secs() < 30 {
        std::thread::sleep(std::time::Duration::from_millis(1));
    }
    let mut reg = Registry::open(path).unwrap_or_else(|e| panic!("open the registry: {e:#}"));
    (0..ISSUES_EACH)
        .map(|i| {
            let crc = writer * 1000 + i;
            let c = reg.issue_counter(GYRO, None, 0, crc).expect("issue");
            let id = reg.begin_upload(GYRO, c, crc).expect("begin upload");
            reg.finish_upload(id, "committed").expect("finish upload");
            let report = SeekReport {
                sequence: c,
                azimuth_deg: 100.0,
                sigma_deg: 0.02,
                tilt: Tilt::LEVEL,
                duration_s: 270.0,
                t_end_s: 300.0,
                positions: 2,
                validity: Validity::Valid,
            };
            reg.record_seek(&SeekRecord::new(GYRO, &report, SeekContext::default()))
                .expect("record seek");
            // An upload takes seconds on a real link: give the others a turn.
            std::thread::sleep(std::time::Duration::from_millis(1));
            c
        })
        .collect()
}

#[test]
fn writer_process() {
    let Ok(spec) = std::env::var("FOGSIM_REGISTRY_WRITER") else {
        return;
    };
    let (path, writer) = spec.split_once('|').expect("PATH|WRITER");
    let counters = write(Path::new(path), writer.parse().unwrap());
    let list: Vec<String> = counters.iter().map(u32::to_string).collect();
    println!("COUNTERS {}", list.join(","));
}

fn scratch() -> PathBuf {
    let d = std::env::temp_dir().join(format!("fogsim-registry-conc-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn concurrent_writer_processes_and_threads_never_share_a_counter_nor_lose_a_row() {
    let dir = scratch();
    let path = dir.join("registry.sqlite");
    let t0 = Instant::now();
    let children: Vec<_> = (0..PROCESSES)
        .map(|w| {
            Command::new(std::env::current_exe().unwrap())
                .args([
                    "--exact",
                    // The test's full name in the crate's one test binary (`module::name`).
                    concat!(module_path!(), "::writer_process")
                        .split_once("::")
                        .map_or("writer_process", |(_, name)| name),
                    "--nocapture",
                    "--test-threads",
                    "1",
                ])
                .env("FOGSIM_REGISTRY_WRITER", format!("{}|{w}", path.display()))
                .output_async()
        })
        .collect();
    let threads: Vec<_> = (0..THREADS)
        .map(|t| {
            let path = path.clone();
            std::thread::spawn(move || write(&path, (PROCESSES + t) as u32))
        })
        .collect();
    let writers = (PROCESSES + THREADS) as u32;
    let ready = |w: u32| dir.join(format!("ready-{w}")).exists();
    while !(0..writers).all(ready) && t0.elapsed().as_secs() < 30 {
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    std::fs::write(dir.join("go"), b"").unwrap();
    let mut per_writer: Vec<Vec<u32>> = threads
        .into_iter()
        .map(|t| t.join().expect("writer thread"))
        .collect();
    for child in children {
        let out = child.wait_with_output().expect("writer process");
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{text}\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let line = text
            .lines()
            .find_map(|l| l.split_once("COUNTERS ").map(|(_, c)| c))
            .unwrap_or_else(|| panic!("no COUNTERS line: {text}"));
        per_writer.push(line.split(',').map(|c| c.parse::<u32>().unwrap()).collect());
    }
    // Writers whose counters are not one block: they really ran at the same time.
    let interleaved = per_writer
        .iter()
        .filter(|c| c.last().unwrap() - c.first().unwrap() + 1 != ISSUES_EACH)
        .count();
    let all: Vec<u32> = per_writer.concat();
    let wall = t0.elapsed().as_secs_f64();
    let n = writers * ISSUES_EACH;
    let distinct: BTreeSet<u32> = all.iter().copied().collect();
    eprintln!(
        "{PROCESSES} processes + {THREADS} threads: {} counters issued, {} distinct, range {:?}..={:?}, {interleaved} writers interleaved, {wall:.2} s",
        all.len(),
        distinct.len(),
        distinct.first(),
        distinct.last()
    );
    assert!(
        interleaved >= 2,
        "the writers did not overlap: no concurrency tested"
    );
    assert_eq!(all.len() as u32, n);
    assert_eq!(distinct.len(), all.len(), "a counter was issued twice");
    assert_eq!(distinct, (1..=n).collect(), "a gap: an issue was lost");
    let reg = Registry::open(&path).unwrap();
    let h = reg.history(GYRO).unwrap();
    assert_eq!(h.counters.len() as u32, n);
    assert_eq!(h.uploads.len() as u32, n);
    assert!(h.uploads.iter().all(|u| u.result == "committed"));
    assert_eq!(h.seeks.len() as u32, n);
    let seq: BTreeSet<u32> = h.seeks.iter().map(|s| s.sequence).collect();
    assert_eq!(seq, distinct);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `Command::output` without waiting: spawn with piped stdout/stderr.
trait OutputAsync {
    fn output_async(&mut self) -> std::process::Child;
}

impl OutputAsync for Command {
    fn output_async(&mut self) -> std::process::Child {
        self.stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("spawn a writer process")
    }
}
