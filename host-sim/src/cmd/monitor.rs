//! `fogsim monitor --port PORT [--registry DB] [--csv FILE]`: live status of the north
//! finder, every seek result stored in the calibration registry (and appended to a CSV if
//! asked; see `crate::device::monitor`). On a terminal a progress bar; otherwise (a pipe, a
//! script) one `key=value` line per status and per result, so a script can follow it.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Duration;

use anyhow::{bail, Result};
use fog_core::link::messages::{Command, SeekFailureReport, Status};
use indicatif::{ProgressBar, ProgressStyle};

use super::upload::LinkArgs;
use crate::device::monitor::{
    monitor, CsvAppend, Event, MonitorOptions, MonitorSummary, ResultLog,
};
use crate::device::upload::device_gyro_id;
use crate::io::utc::now_utc;
use crate::registry::{self, Registry, SeekRecord};

/// Options of `fogsim monitor`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub link: LinkArgs,
    /// Calibration registry (SQLite) the results are stored in. Default:
    /// $XDG_DATA_HOME/fogsim/registry.sqlite (~/.local/share/fogsim/registry.sqlite).
    #[arg(long)]
    pub registry: Option<PathBuf>,
    /// Also append each result to this CSV (created with a header; locked per append).
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// Send the site latitude first, deg.
    #[arg(
        long = "latitude-deg",
        alias = "latitude",
        allow_negative_numbers = true
    )]
    pub latitude: Option<f32>,
    /// Start a seek with this many table positions (2 or 4). The session then fails if
    /// the seek stops without a result (with the device's reason) or its results do not
    /// come within --duration-s.
    #[arg(long = "positions", alias = "start", value_name = "POSITIONS")]
    pub start: Option<u8>,
    /// Stop after this many results.
    #[arg(long, default_value_t = 1)]
    pub results: usize,
    /// Stop after this many seconds in any case.
    #[arg(long, default_value_t = 900)]
    pub duration_s: u64,
}

/// Runs the subcommand.
pub fn run(a: Args) -> Result<()> {
    let commands = commands(&a)?;
    let csv = a.csv.as_deref().map(CsvAppend::open).transpose()?;
    let reg = Registry::open(&registry::resolve(a.registry.as_deref())?)?;
    let reg_path = reg.path().to_path_buf();
    let mut link = a.link.open()?;
    // The gyro id the results are filed under: the device's own (upload `Hello`).
    let gyro_id = device_gyro_id(&mut link)?;
    let mut log = ResultLog::new(reg, csv, &gyro_id);
    let opts = MonitorOptions {
        max_results: a.results,
        max_duration: Duration::from_secs(a.duration_s),
        commands,
    };
    let tty = std::io::stdout().is_terminal();
    let bar = if tty {
        let bar = ProgressBar::new(1000);
        bar.set_style(
            ProgressStyle::with_template("{bar:40} {percent:>3}% {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        bar
    } else {
        ProgressBar::hidden()
    };
    let sum = monitor(&mut link, &mut log, &opts, |e| {
        let line = match e {
            Event::Status(s) if tty => {
                bar.set_position((s.progress.clamp(0.0, 1.0) * 1000.0) as u64);
                bar.set_message(status_text(s));
                return;
            }
            Event::Status(s) => format!("status utc={} {}", now_utc(), status_line(s)),
            Event::Result(_, r) => result_line(r),
            Event::Failed(f) => format!("failed utc={} {}", now_utc(), failure_line(f)),
        };
        if tty {
            bar.println(line);
        } else {
            println!("{line}");
        }
    })?;
    bar.finish_and_clear();
    println!(
        "summary statuses={} results={} failed={} bad_frames={} seek_retries={} gyro={gyro_id} registry={}{}",
        sum.statuses,
        sum.results,
        sum.failures.len(),
        sum.bad_frames,
        sum.start_retries,
        reg_path.display(),
        a.csv
            .as_ref()
            .map_or(String::new(), |c| format!(" csv={}", c.display()))
    );
    if log.csv_repairs > 0 {
        eprintln!(
            "fogsim monitor: ended {} torn last line(s) of the CSV before appending",
            log.csv_repairs
        );
    }
    for r in &sum.refusals {
        println!("refused command={r}");
    }
    if a.start.is_some() {
        outcome_of_own_seek(&sum, a.results, a.duration_s)?;
    }
    Ok(())
}

/// A session that started a seek fails unless it got its results: the seek stopped
/// without one (the device's reason), or the time ran out (the last status said).
fn outcome_of_own_seek(sum: &MonitorSummary, results: usize, duration_s: u64) -> Result<()> {
    if let Some(f) = sum.failures.last() {
        bail!(
            "the seek stopped without a result at t={:.1} s since power-on: {} ({} restarts{})",
            f.t_s,
            f.error,
            f.restarts,
            f.last_restart
                .map_or(String::new(), |r| format!(", the last for {r:?}"))
        );
    }
    if sum.results < results {
        bail!(
            "{} of the {} results asked for (--results) within --duration-s {}; the last status: {}",
            sum.results,
            results,
            duration_s,
            sum.last_status
                .as_ref()
                .map_or("none".to_string(), status_line)
        );
    }
    Ok(())
}

/// One seek failure as `key=value` fields (no spaces inside a value).
pub fn failure_line(f: &SeekFailureReport) -> String {
    format!(
        "t_s={:.1} error={} restarts={} last_restart={}",
        f.t_s,
        field_value(&f.error),
        f.restarts,
        f.last_restart.as_ref().map_or("none".into(), field_value)
    )
}

/// A value's Debug form without spaces, for one `key=value` field.
fn field_value(v: &impl std::fmt::Debug) -> String {
    format!("{v:?}").replace(' ', "")
}

/// The commands to send first, checked.
fn commands(a: &Args) -> Result<Vec<Command>> {
    let mut commands = Vec::new();
    if let Some(p) = a.start {
        if p != 2 && p != 4 {
            bail!("--positions {p}: must be 2 or 4");
        }
    }
    if let Some(l) = a.latitude {
        if !(l.is_finite() && l.abs() < 85.0) {
            bail!("--latitude-deg {l}: must be within -85..85 deg");
        }
        commands.push(Command::SetLatitude { latitude_deg: l });
    }
    if let Some(p) = a.start {
        commands.push(Command::StartSeek { positions: p });
    }
    commands.push(Command::GetStatus);
    Ok(commands)
}

fn bit_text(s: &Status) -> String {
    match s.bit.seek_permission() {
        Ok(()) => "ok".to_string(),
        Err(item) => item.name().to_string(),
    }
}

/// The progress bar's message.
fn status_text(s: &Status) -> String {
    format!(
        "{:?} | predicted 1-sigma {:.4} deg | {:.2} degC | tilt {:.2}/{:.2} deg | restarts {} | BIT {} | {}{}",
        s.state,
        s.predicted_sigma_deg,
        s.temp_c,
        s.tilt.pitch_deg,
        s.tilt.roll_deg,
        s.restarts,
        bit_text(s),
        if s.heading_cal {
            "heading cal"
        } else {
            "no heading cal"
        },
        fault_text(&s.faults)
    )
}

/// One status as `key=value` fields (no spaces inside a value).
pub fn status_line(s: &Status) -> String {
    format!(
        "t_s={:.1} state={} progress={:.3} predicted_sigma_deg={:.4} temp_c={:.2} latitude_deg={:.4} \
         pitch_deg={:.3} roll_deg={:.3} restarts={} last_restart={} bit={} model_crc32={} \
         heading_cal={} faults_in_a_row={} safe_mode={}",
        s.t_s,
        field_value(&s.state),
        s.progress,
        s.predicted_sigma_deg,
        s.temp_c,
        s.latitude_deg,
        s.tilt.pitch_deg,
        s.tilt.roll_deg,
        s.restarts,
        s.last_restart.as_ref().map_or("none".into(), field_value),
        bit_text(s),
        s.model_crc32
            .map_or("none".to_string(), |c| format!("0x{c:08X}")),
        s.heading_cal,
        s.faults.faults_in_a_row,
        s.faults.safe_mode
    )
}

/// One result as `key=value` fields, as stored in the registry.
pub fn result_line(r: &SeekRecord) -> String {
    let opt = |v: Option<f64>, prec: usize| v.map_or("none".to_string(), |v| format!("{v:.prec$}"));
    format!(
        "result utc={} gyro={} sequence={} azimuth_deg={:.4} sigma_deg={:.4} verdict={}{} \
         model_crc32={} temp_c={} latitude_deg={} pitch_deg={:.3} roll_deg={:.3} positions={} \
         duration_s={:.1} t_end_s={:.1}",
        r.received_utc,
        r.gyro_id,
        r.sequence,
        r.azimuth_deg,
        r.sigma_deg,
        r.verdict,
        r.observed_latitude_deg
            .map_or(String::new(), |l| format!(" observed_latitude_deg={l:.3}")),
        r.model_crc32
            .map_or("none".to_string(), |c| format!("0x{c:08X}")),
        opt(r.temp_c, 2),
        opt(r.latitude_deg, 4),
        r.pitch_deg,
        r.roll_deg,
        r.positions,
        r.duration_s,
        r.t_end_s
    )
}

/// The status line's fault part: empty without faults in a row, else the count, the
/// last cause and whether the device is in safe mode.
fn fault_text(f: &fog_core::link::messages::FaultState) -> String {
    match (f.safe_mode, f.faults_in_a_row) {
        (false, 0) => String::new(),
        (safe, n) => format!(
            " | {}{n} faults in a row, last {:?} (detail {})",
            if safe { "SAFE MODE: " } else { "" },
            f.last_cause,
            f.last_detail
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fog_core::seeking::quality::{MotionReason, QualityError};

    #[test]
    fn a_session_that_started_a_seek_fails_without_its_results_and_says_why() {
        let mut sum = MonitorSummary {
            results: 1,
            ..MonitorSummary::default()
        };
        assert!(outcome_of_own_seek(&sum, 1, 300).is_ok());
        sum.results = 0;
        let e = outcome_of_own_seek(&sum, 1, 300).unwrap_err().to_string();
        assert_eq!(
            e,
            "0 of the 1 results asked for (--results) within --duration-s 300; the last status: none"
        );
        let stall = MotionReason::GyroStall { gap_ms: 4000 };
        sum.failures.push(SeekFailureReport {
            error: QualityError::TooMuchMotion(stall),
            t_s: 95.0,
            restarts: 3,
            last_restart: Some(stall),
        });
        let e = outcome_of_own_seek(&sum, 1, 300).unwrap_err().to_string();
        assert_eq!(
            e,
            "the seek stopped without a result at t=95.0 s since power-on: seek stopped: base \
             keeps moving (GyroStall { gap_ms: 4000 }) (3 restarts, the last for GyroStall { \
             gap_ms: 4000 })"
        );
        assert_eq!(
            failure_line(&sum.failures[0]),
            "t_s=95.0 error=TooMuchMotion(GyroStall{gap_ms:4000}) restarts=3 \
             last_restart=GyroStall{gap_ms:4000}"
        );
    }
}
