//! `fogsim registry show GYRO` / `fogsim registry export --csv FILE`: read the calibration
//! registry (`crate::registry`): a gyro's counters, models, uploads and seek results, or
//! every seek result as a CSV (written atomically; the registry itself is never an output).

use std::path::PathBuf;

use anyhow::{bail, Result};

use super::check_output_file;
use crate::io::OutputGuard;
use crate::registry::{self, write_results_csv, History, Registry};

/// Options of `fogsim registry`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Calibration registry (SQLite). Default: $XDG_DATA_HOME/fogsim/registry.sqlite
    /// (~/.local/share/fogsim/registry.sqlite).
    #[arg(long, global = true)]
    pub registry: Option<PathBuf>,
    #[command(subcommand)]
    pub action: Action,
}

#[derive(clap::Subcommand, Debug)]
pub enum Action {
    /// Print one gyro's history: counters issued, models, uploads, seek results.
    Show {
        /// The gyro id (as the device reports it).
        gyro: String,
    },
    /// Write the seek results as a CSV.
    Export {
        /// Output CSV (replaced atomically).
        #[arg(long)]
        csv: PathBuf,
        /// Only this gyro's results.
        #[arg(long)]
        gyro: Option<String>,
    },
}

/// Runs the subcommand.
pub fn run(a: Args) -> Result<()> {
    let path = registry::resolve(a.registry.as_deref())?;
    if !path.is_file() {
        bail!(
            "registry {}: does not exist (upload and monitor create it)",
            path.display()
        );
    }
    let reg = Registry::open(&path)?;
    match a.action {
        Action::Show { gyro } => {
            let h = reg.history(&gyro)?;
            if h == History::default() {
                bail!(
                    "registry {}: nothing about gyro {gyro:?} (gyros known: {})",
                    path.display(),
                    reg.gyros()?.join(", ")
                );
            }
            print!("{}", show(&gyro, &h));
            Ok(())
        }
        Action::Export { csv, gyro } => {
            check_output_file(&OutputGuard::new(&[&path]), Some(&csv), "--csv")?;
            let results = reg.seeks(gyro.as_deref())?;
            write_results_csv(&csv, &results)
                .map_err(|e| anyhow::anyhow!("--csv {}: cannot write: {e}", csv.display()))?;
            println!("{} results written to {}", results.len(), csv.display());
            Ok(())
        }
    }
}

/// The history as text.
fn show(gyro: &str, h: &History) -> String {
    let mut out = format!("gyro {gyro}\n");
    let last = h
        .counters
        .last()
        .map_or("none".to_string(), |c| c.0.to_string());
    out += &format!(
        "security counters issued: {} (last {last})\n",
        h.counters.len()
    );
    for (c, utc, crc) in &h.counters {
        out += &format!("  counter {c:>4}  {utc}  model 0x{crc:08X}\n");
    }
    out += &format!("models: {}\n", h.models.len());
    for (utc, m) in &h.models {
        let heading = m
            .heading
            .map_or("no heading calibration".to_string(), |(v, n)| {
                format!(
                    "heading a={:.4}+-{:.4} b={:.4}+-{:.4} deg/h ({n} headings)",
                    v[0], v[2], v[1], v[3]
                )
            });
        out += &format!(
            "  0x{:08X}  {utc}  {} bytes, inputs {}, {} centres, held-out rms {:.4} deg/h, {heading}\n",
            m.model_crc32, m.model_len, m.inputs, m.n_centers, m.heldout_rms_dph
        );
    }
    out += &format!("uploads: {}\n", h.uploads.len());
    for u in &h.uploads {
        out += &format!(
            "  {}  counter {:>4}  model 0x{:08X}  {}\n",
            u.started_utc, u.counter, u.model_crc32, u.result
        );
    }
    out += &format!("seek results: {}\n", h.seeks.len());
    for s in &h.seeks {
        out += &format!(
            "  {}  seq {}  azimuth {:.4} deg +- {:.4}  {}  {} positions  T {}  lat {}  tilt {:.3}/{:.3} deg\n",
            s.received_utc,
            s.sequence,
            s.azimuth_deg,
            s.sigma_deg,
            s.verdict,
            s.positions,
            s.temp_c.map_or("-".to_string(), |t| format!("{t:.2} degC")),
            s.latitude_deg.map_or("-".to_string(), |l| format!("{l:.4} deg")),
            s.pitch_deg,
            s.roll_deg
        );
    }
    out
}
