//! `fogsim campaign`: simulate the paper's test campaign into a directory of fog-runs
//! v1 files (one per power-on, 10 s means, Earth rate in `earth_dph`), for one gyro or
//! for a fleet of units of its type (`--units`).

use super::check_output_file;
use crate::io::logger_csv::write_logger_csv;
use crate::io::read_bounded;
use crate::io::run_format::excerpt;
use crate::io::OutputGuard;
use crate::pipeline::campaign::{
    simulate_campaign, write_campaign, CampaignSpec, PAPER_AMBIENTS_C, PAPER_MINUTES, PAPER_RUNS,
};
use crate::pipeline::fleet::{simulate_fleet, FleetType, MAX_UNITS};
use crate::pipeline::heading_campaign::{check_headings, simulate_heading_campaign};
use crate::sim::unit_spread::MAX_SPREAD_FILE_BYTES;
use crate::sim::{GyroParams, TypeSpread, DEFAULT_LATITUDE_DEG};
use anyhow::{anyhow, bail, Context};
use std::path::{Path, PathBuf};

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
    /// Make a fleet: this many units of the gyro type (1..=999), each with every power-on
    /// above and its physical parameters drawn about the type's by --unit-spread. Files
    /// are prefixed by the unit (`u001_`), with `unit_id` and `type_id` metadata. Without
    /// it: one gyro, the type itself.
    #[arg(long)]
    pub units: Option<usize>,
    /// How the units differ (needs --units): `default` (docs/explain/simulator.md,
    /// "Fleets"), `none` (units differ only in their runs' noise, turn-on bias and soak)
    /// or a spread file of `parameter: spread` lines (docs/reference/formats.md)
    /// [default: default].
    #[arg(long)]
    pub unit_spread: Option<PathBuf>,
    /// Seed the units are drawn from (needs --units): the same type seed gives the same
    /// units whatever --seed, which seeds their runs [default: 1].
    #[arg(long)]
    pub type_seed: Option<u64>,
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

impl Args {
    /// The fleet of `--units`, `--unit-spread` and `--type-seed` (None: one gyro).
    fn fleet(&self) -> anyhow::Result<Option<(FleetType, usize)>> {
        let Some(units) = self.units else {
            // checked here, not by clap: its message would name --units, not the flag given
            if let Some(p) = &self.unit_spread {
                bail!("--unit-spread {}: needs --units", p.display());
            }
            if let Some(s) = self.type_seed {
                bail!("--type-seed {s}: needs --units");
            }
            return Ok(None);
        };
        if !(1..=MAX_UNITS).contains(&units) {
            bail!("--units {units}: must be within 1..={MAX_UNITS}");
        }
        let (spread, label) = spread_of(self.unit_spread.as_deref())?;
        let mut fleet = FleetType::paper(spread, &label, self.type_seed.unwrap_or(1));
        fleet.params = fleet.params.with_heading_bias(self.heading_bias_dph);
        Ok(Some((fleet, units)))
    }
}

/// `--unit-spread`'s spread and its label (`default`, `none` or `file NAME`).
pub(crate) fn spread_of(arg: Option<&Path>) -> anyhow::Result<(TypeSpread, String)> {
    Ok(match arg {
        None => (TypeSpread::default_spread(), "default".to_string()),
        Some(p) if p.as_os_str() == "default" => {
            (TypeSpread::default_spread(), "default".to_string())
        }
        Some(p) if p.as_os_str() == "none" => (TypeSpread::none(), "none".to_string()),
        Some(p) => (read_spread_file(p)?, spread_file_label(p)),
    })
}

/// A spread file (`--unit-spread FILE`), read whole within its size limit.
fn read_spread_file(path: &Path) -> anyhow::Result<TypeSpread> {
    let at = || format!("--unit-spread {}", path.display());
    let bytes = read_bounded(path, MAX_SPREAD_FILE_BYTES).map_err(|e| anyhow!("{}: {e}", at()))?;
    let text = std::str::from_utf8(&bytes).map_err(|_| anyhow!("{}: not UTF-8 text", at()))?;
    TypeSpread::parse(text).map_err(|e| anyhow!("{}: {e}", at()))
}

/// The `unit_spread` metadata of a spread file: `file NAME` (its name, not its path).
fn spread_file_label(path: &Path) -> String {
    let name = path.file_name().unwrap_or(path.as_os_str());
    format!("file {}", excerpt(&name.to_string_lossy()))
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
    if let Some(h) = &args.headings_deg {
        check_headings(h).map_err(|e| anyhow!("--headings-deg: {e}"))?;
    }
    let fleet = args.fleet()?;
    let runs = match (&fleet, &args.headings_deg) {
        (Some((fleet, units)), h) => simulate_fleet(fleet, *units, &spec, h.as_deref())?,
        (None, Some(h)) => {
            let params = GyroParams::paper_default().with_heading_bias(args.heading_bias_dph);
            simulate_heading_campaign(&params, &spec, h)?
        }
        (None, None) => simulate_campaign(&GyroParams::paper_default(), &spec)?,
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
    let units = fleet.as_ref().map_or(String::new(), |(f, n)| {
        format!(
            "{n} units of {} (type seed {}, spread {}) x ",
            f.type_id, f.type_seed, f.spread_label
        )
    });
    println!(
        "fogsim campaign: wrote {} runs ({units}{} ambients x {}{} power-ons, {} min, seed {}) to {}",
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
