//! `fogsim import LOG... --out DIR`: foreign recordings to fog-runs v1. Any logger's CSV
//! through `--time`, `--rate`, `--temp` (with units) and friends (`fog_sim::io::import::
//! logger`), or the PAN thermal-vacuum MEMS log as a preset (`--preset pan`, also chosen
//! when no column mapping is given).

use super::prepare_output_dir;
use crate::io::import::logger::{import_logs, LoggerSpec};
use crate::io::import::{import_pan, mapping, Heading};
use crate::io::OutputGuard;
use std::path::PathBuf;

/// Options of `fogsim import`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The logs (CSV); for the PAN preset `TVCtest3_7_20.csv` or the directory holding it.
    #[arg(required = true)]
    pub input: Vec<PathBuf>,
    /// Directory for the fog-runs files (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// A known layout instead of a column mapping: `pan` (the PAN TVAC MEMS log).
    #[arg(long, conflicts_with_all = ["time", "rate", "temp"])]
    pub preset: Option<String>,
    /// PAN preset: which gyro axis becomes a run: x, y, z or all.
    #[arg(long, default_value = "all")]
    pub axis: String,
    /// Time column and unit: COL[:s|ms|us|iso] (s when not given).
    #[arg(long, requires_all = ["rate", "temp"])]
    pub time: Option<String>,
    /// Gyro rate column and unit: COL:dph|dps|rps, optionally *SCALE (counts x SCALE in
    /// the unit), e.g. `gyro_cnt:dps*0.0001`.
    #[arg(long, requires = "time")]
    pub rate: Option<String>,
    /// Gyro temperature column and unit: COL:c|f|k.
    #[arg(long, requires = "time")]
    pub temp: Option<String>,
    /// Further columns to copy (numeric), by name; repeat or separate with commas.
    #[arg(long, value_delimiter = ',')]
    pub keep: Vec<String>,
    /// Column names of a header-less file (its first line is data).
    #[arg(long, value_delimiter = ',')]
    pub columns: Option<Vec<String>>,
    /// Site latitude, deg (written as `latitude_deg` metadata).
    #[arg(long, allow_hyphen_values = true)]
    pub latitude_deg: Option<f64>,
    /// Earth rate along the gyro's input axis, deg/h (e.g. 15.041 sin(latitude) for a
    /// vertical axis), written as `earth_dph` metadata: training and diagnosis then see
    /// the drift (rate - earth), as in simulated runs, and runs of other gyros recorded so
    /// can share one type (`train --type-out`). Without it the records' drift includes it.
    #[arg(long, allow_hyphen_values = true)]
    pub earth_dph: Option<f64>,
    /// Gyro id (written as `gyro` metadata).
    #[arg(long)]
    pub gyro_id: Option<String>,
    /// Column holding the input axis azimuth, deg (becomes `heading_deg`).
    #[arg(long, conflicts_with = "heading_deg")]
    pub heading_col: Option<String>,
    /// Input axis azimuth of the whole log, deg (becomes a `heading_deg` column).
    #[arg(long, allow_hyphen_values = true)]
    pub heading_deg: Option<f64>,
    /// A time step longer than this starts a new run, s [default: ten median sample
    /// spacings of the log, at least 60 s].
    #[arg(long)]
    pub split_gap_s: Option<f64>,
}

impl Args {
    /// The logger mapping these options give (None: no `--time`, the PAN preset).
    fn logger_spec(&self) -> anyhow::Result<Option<LoggerSpec>> {
        let (Some(time), Some(rate), Some(temp)) = (&self.time, &self.rate, &self.temp) else {
            return Ok(None);
        };
        let heading = match (&self.heading_col, self.heading_deg) {
            (Some(c), _) => Heading::Column(c.clone()),
            (None, Some(d)) if d.is_finite() => Heading::Fixed(d),
            (None, Some(d)) => anyhow::bail!("--heading-deg {d}: not a finite angle"),
            (None, None) => Heading::Unknown,
        };
        if let Some(l) = self.latitude_deg {
            if !(-90.0..=90.0).contains(&l) {
                anyhow::bail!("--latitude-deg {l:.4e}: outside -90..90");
            }
        }
        Ok(Some(LoggerSpec {
            time: mapping::TimeColumn::parse(time).map_err(anyhow::Error::msg)?,
            rate: mapping::RateColumn::parse(rate).map_err(anyhow::Error::msg)?,
            temp: mapping::TempColumn::parse(temp).map_err(anyhow::Error::msg)?,
            keep: self.keep.clone(),
            columns: self.columns.clone(),
            latitude_deg: self.latitude_deg,
            earth_dph: match self.earth_dph {
                Some(e) if !(e.is_finite() && e.abs() <= fog_core::consts::EARTH_RATE_DPH) => {
                    anyhow::bail!("--earth-dph {e}: must be within +-15.041 deg/h (Earth rate)")
                }
                e => e,
            },
            gyro_id: self.gyro_id.clone(),
            heading,
            split_gap_s: self.split_gap_s,
        }))
    }
}

/// Runs the subcommand.
pub fn run(args: Args) -> anyhow::Result<()> {
    // Checked whatever the layout: a bad flag is never ignored.
    if !["x", "y", "z", "all"].contains(&args.axis.as_str()) {
        anyhow::bail!("--axis {}: expected x, y, z or all", args.axis);
    }
    if args.columns.iter().flatten().any(|c| c.trim().is_empty()) {
        anyhow::bail!("--columns: an empty column name");
    }
    match (args.logger_spec()?, args.preset.as_deref()) {
        (Some(spec), _) => {
            let guard = OutputGuard::new(&args.input);
            prepare_output_dir(&guard, Some(&args.out), "--out")?;
            let done = import_logs(&spec, &args.input, &args.out, &guard)?;
            print!("{}", done.summary());
            Ok(())
        }
        (None, None | Some("pan")) => run_pan(&args),
        (None, Some(other)) => anyhow::bail!("--preset {other}: the known preset is `pan`"),
    }
}

fn run_pan(args: &Args) -> anyhow::Result<()> {
    let axes: Vec<usize> = match args.axis.as_str() {
        "x" => vec![0],
        "y" => vec![1],
        "z" => vec![2],
        "all" => vec![0, 1, 2],
        other => anyhow::bail!("--axis {other}: expected x, y, z or all"),
    };
    if args.earth_dph.is_some() {
        anyhow::bail!("--earth-dph: for a logger's mapping (--time, --rate, --temp); the PAN preset writes its own (0: its axes are not levelled)");
    }
    let [input] = &args.input[..] else {
        anyhow::bail!(
            "the PAN preset reads one recording; for other logs give --time, --rate and --temp"
        );
    };
    let file = if input.is_dir() {
        input.join("TVCtest3_7_20.csv")
    } else {
        input.clone()
    };
    let guard = OutputGuard::new(&[input, &file]);
    prepare_output_dir(&guard, Some(&args.out), "--out")?;
    let imp = import_pan(&file, &axes)?;
    let mut staged = crate::io::StagedFiles::default();
    for run in &imp.runs {
        let path = args.out.join(run.name());
        super::check_output_file(&guard, Some(&path), "--out")?;
        let mut w = staged.create(&path)?;
        crate::io::runs::write_run_text(run, &mut w)?;
        crate::io::StagedFiles::close(w)?;
    }
    staged.commit()?;
    for run in &imp.runs {
        println!(
            "wrote {} ({} rows)",
            args.out.join(run.name()).display(),
            run.len()
        );
    }
    println!(
        "{} samples in {} bursts -> one row per burst; {} outlier sample(s) dropped",
        imp.samples, imp.bursts, imp.outliers_dropped
    );
    Ok(())
}
