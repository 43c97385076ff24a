//! `fogsim campaign`: simulate the paper's test campaign into a directory of fog-runs
//! v1 files (one per power-on, 10 s means, Earth rate in `earth_dph`).

use crate::pipeline::campaign::{
    simulate_campaign, write_campaign, CampaignSpec, PAPER_AMBIENTS_C, PAPER_MINUTES, PAPER_RUNS,
};
use crate::sim::{GyroParams, DEFAULT_LATITUDE_DEG};
use anyhow::bail;
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
        })
    }
}

/// Runs the subcommand.
pub fn run(args: Args) -> anyhow::Result<()> {
    let spec = args.to_spec()?;
    let runs = simulate_campaign(&GyroParams::paper_default(), &spec)?;
    let files = write_campaign(&args.out, &runs)?;
    println!(
        "fogsim campaign: wrote {} runs ({} ambients x {} power-ons, {} min, seed {}) to {}",
        files.len(),
        spec.ambients_c.len(),
        spec.runs_per_ambient,
        spec.minutes,
        spec.seed,
        args.out.display()
    );
    Ok(())
}
