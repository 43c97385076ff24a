//! `fogsim monitor --port PORT [--registry DB] [--csv FILE]`: live status of the north
//! finder, every seek result stored in the calibration registry (and appended to a CSV if
//! asked; see `crate::device::monitor`). On a terminal a progress bar; otherwise (a pipe, a
//! script) one `key=value` line per status and per result, so a script can follow it.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Duration;

use anyhow::{bail, Result};
use fog_core::link::messages::{Command, Status};
use indicatif::{ProgressBar, ProgressStyle};

use super::upload::LinkArgs;
use crate::device::monitor::{monitor, CsvAppend, MonitorOptions, ResultLog};
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
    /// Start a seek with this many table positions (2 or 4).
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
    let sum = monitor(
        &mut link,
        &mut log,
        &opts,
        |s| {
            if tty {
                bar.set_position((s.progress.clamp(0.0, 1.0) * 1000.0) as u64);
                bar.set_message(status_text(s));
            } else {
                println!("status utc={} {}", now_utc(), status_line(s));
            }
        },
        |_, r| {
            if tty {
                bar.println(result_line(r));
            } else {
                println!("{}", result_line(r));
            }
        },
    )?;
    bar.finish_and_clear();
    println!(
        "summary statuses={} results={} bad_frames={} seek_retries={} gyro={gyro_id} registry={}{}",
        sum.statuses,
        sum.results,
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
    Ok(())
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
         pitch_deg={:.3} roll_deg={:.3} restarts={} bit={} model_crc32={} heading_cal={} \
         faults_in_a_row={} safe_mode={}",
        s.t_s,
        format!("{:?}", s.state).replace(' ', ""),
        s.progress,
        s.predicted_sigma_deg,
        s.temp_c,
        s.latitude_deg,
        s.tilt.pitch_deg,
        s.tilt.roll_deg,
        s.restarts,
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
