//! `fogsim monitor --port PORT --csv FILE`: live status of the north finder with a progress
//! bar, every seek result appended to a CSV (see `crate::monitor`).

use std::path::PathBuf;
use std::time::Duration;

use anyhow::{bail, Result};
use fog_core::link::messages::Command;
use indicatif::{ProgressBar, ProgressStyle};

use super::upload::LinkArgs;
use crate::monitor::{monitor, MonitorOptions, ResultLog};

/// Options of `fogsim monitor`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub link: LinkArgs,
    /// Results CSV, appended to (created with a header).
    #[arg(long)]
    pub csv: PathBuf,
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
    if let Some(p) = a.start {
        if p != 2 && p != 4 {
            bail!("--positions {p}: must be 2 or 4");
        }
    }
    let mut commands = Vec::new();
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
    let mut log = ResultLog::open(&a.csv)?;
    let mut link = a.link.open()?;
    let bar = ProgressBar::new(1000);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {percent:>3}% {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let opts = MonitorOptions {
        max_results: a.results,
        max_duration: Duration::from_secs(a.duration_s),
        commands,
    };
    let sum = monitor(
        &mut link,
        &mut log,
        &opts,
        |s| {
            bar.set_position((s.progress.clamp(0.0, 1.0) * 1000.0) as u64);
            let bit = match s.bit.seek_permission() {
                Ok(()) => "BIT ok".to_string(),
                Err(item) => format!("BIT: {}", item.name()),
            };
            bar.set_message(format!(
                "{:?} | predicted 1-sigma {:.4} deg | {:.2} degC | tilt {:.2}/{:.2} deg | restarts {} | {bit}",
                s.state, s.predicted_sigma_deg, s.temp_c, s.tilt.pitch_deg, s.tilt.roll_deg, s.restarts
            ));
        },
        |r| {
            bar.println(format!(
                "seek {}: azimuth {:.4} deg +- {:.4} ({:?})",
                r.sequence, r.azimuth_deg, r.sigma_deg, r.validity
            ))
        },
    )?;
    bar.finish_and_clear();
    println!(
        "{} status messages, {} results appended to {}, {} bad frames",
        sum.statuses,
        sum.results,
        a.csv.display(),
        sum.bad_frames
    );
    for r in &sum.refusals {
        println!("device refused a command: {r}");
    }
    Ok(())
}
