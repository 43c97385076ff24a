//! `fogsim campaign`: simulate the paper's test campaign into a directory of fog-runs
//! v1 files (one per power-on, 10 s means, Earth rate in `earth_dph`).

use super::check_output_file;
use crate::io::logger_csv::write_logger_csv;
use crate::io::OutputGuard;
use crate::pipeline::campaign::{
    simulate_campaign, write_campaign, CampaignSpec, PAPER_AMBIENTS_C, PAPER_MINUTES, PAPER_RUNS,
};
use crate::pipeline::heading_campaign::{check_headings, simulate_heading_campaign};
use crate::sim::{GyroParams, DEFAULT_LATITUDE_DEG};
use anyhow::{bail, Context};
use std::path::PathBuf;

/// Options of `fogsim campaign`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Output directory (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// Chamber temperatures, degC, comma separated.
    #[arg(long = "ambient-c", alias = "ambient", value_delimiter = ',', allow_hyphen_values = true,
          default_values_t = PAPER_AMBIENTS_C.to_vec())]
    pub ambient: Vec<f64>,
    /// Power-ons per temperature.
    #[arg(long, default_value_t = PAPER_RUNS)]
    pub runs: usize,
    /// Record length from power-on, min.
    #[arg(long = "duration-min", alias = "minutes", default_value_t = PAPER_MINUTES, allow_hyphen_values = true)]
    pub minutes: f64,
    /// Seed; the same seed gives the same bytes.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Site latitude, deg.
    #[arg(long = "latitude-deg", alias = "latitude", default_value_t = DEFAULT_LATITUDE_DEG, allow_hyphen_values = true)]
    pub latitude: f64,
    /// Raw gyro sample rate, Hz.
    #[arg(long, default_value_t = 100.0)]
    pub raw_rate_hz: f64,
    /// Input axis horizontal at each of these azimuths, deg (comma separated): every
    /// power-on is repeated at every heading (for `fogsim heading-cal --from-runs`).
    /// Without it the input axis is vertical, as in the paper.
    #[arg(long, visible_alias = "headings", value_delimiter = ',')]
    pub headings_deg: Option<Vec<f64>>,
    /// Plant a heading-dependent bias A cos(input axis azimuth), deg/h (needs
    /// --headings-deg; -1..=1).
    #[arg(
        long,
        default_value_t = 0.0,
        allow_hyphen_values = true,
        requires = "headings_deg"
    )]
    pub heading_bias_dph: f64,
    /// Also write every run into this one file as a lab logger would log them
    /// (semicolon, decimal comma, ISO time, deg/s, degF; `io::logger_csv`): the input of
    /// `fogsim import` in docs/workflow.md.
    #[arg(long)]
    pub logger_csv: Option<PathBuf>,
}

impl Args {
    /// Checks the options and turns them into a campaign specification.
    pub fn to_spec(&self) -> anyhow::Result<CampaignSpec> {
        let ambients = self.ambient.clone();
        if ambients.is_empty() {
            bail!("--ambient-c: empty list");
        }
        if let Some(a) = ambients.iter().find(|a| !(-60.0..=100.0).contains(*a)) {
            bail!("--ambient-c {a}: must be within -60..=100 degC");
        }
        if !(1..=1000).contains(&self.runs) {
            bail!("--runs {}: must be within 1..=1000", self.runs);
        }
        if !(self.minutes.is_finite() && (10.0 / 60.0..=24.0 * 60.0).contains(&self.minutes)) {
            bail!(
                "--duration-min {}: must be within 1/6 (one 10 s mean) ..= 1440",
                self.minutes
            );
        }
        if !(-90.0..=90.0).contains(&self.latitude) {
            bail!(
                "--latitude-deg {}: must be within -90..=90 deg",
                self.latitude
            );
        }
        let per_window = self.raw_rate_hz * 10.0;
        if !(0.1..=20_000.0).contains(&self.raw_rate_hz)
            || (per_window - per_window.round()).abs() > 1e-9
        {
            bail!(
                "--raw-rate-hz {}: must be within 0.1..=20000 Hz and give whole samples per 10 s",
                self.raw_rate_hz
            );
        }
        Ok(CampaignSpec {
            ambients_c: ambients,
            runs_per_ambient: self.runs,
            minutes: self.minutes,
            seed: self.seed,
            latitude_deg: self.latitude,
            raw_rate_hz: self.raw_rate_hz,
            warm_restarts: None,
        })
    }
}

/// Runs the subcommand.
pub fn run(args: Args) -> anyhow::Result<()> {
    let spec = args.to_spec()?;
    check_output_file(
        &OutputGuard::default(),
        args.logger_csv.as_deref(),
        "--logger-csv",
    )?;
    if !(args.heading_bias_dph.is_finite() && args.heading_bias_dph.abs() <= 1.0) {
        bail!(
            "--heading-bias-dph {:.4e}: must be within -1..=1 deg/h",
            args.heading_bias_dph
        );
    }
    let runs = match &args.headings_deg {
        Some(h) => {
            check_headings(h).map_err(|e| anyhow::anyhow!("--headings-deg: {e}"))?;
            let params = GyroParams::paper_default().with_heading_bias(args.heading_bias_dph);
            simulate_heading_campaign(&params, &spec, h)?
        }
        None => simulate_campaign(&GyroParams::paper_default(), &spec)?,
    };
    let files = write_campaign(&args.out, &runs)?;
    if let Some(log) = &args.logger_csv {
        let all: Vec<_> = runs.iter().map(|r| &r.run).collect();
        write_logger_csv(log, &all).with_context(|| format!("--logger-csv {}", log.display()))?;
        println!(
            "fogsim campaign: logged the {} runs one after another in {} (timestamp;rate_dps;coil_temp_f)",
            all.len(),
            log.display()
        );
    }
    println!(
        "fogsim campaign: wrote {} runs ({} ambients x {}{} power-ons, {} min, seed {}) to {}",
        files.len(),
        spec.ambients_c.len(),
        args.headings_deg
            .as_ref()
            .map_or(String::new(), |h| format!("{} headings x ", h.len())),
        spec.runs_per_ambient,
        spec.minutes,
        spec.seed,
        args.out.display()
    );
    Ok(())
}
