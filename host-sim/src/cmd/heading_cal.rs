//! `fogsim heading-cal --model IN --out OUT (--a-dph A --b-dph B --sigma-dph S
//! --n-headings N | --from-diagnose D.json | --from-runs DIR)`: attaches a heading
//! calibration to a model. `--from-runs` fits a and b with their 1-sigma from runs at
//! several headings (`fog_sim::pipeline::heading_fit`).
//!
//! Exists because the heading harmonic of the bias, a cos(alpha) + b sin(alpha) of the
//! input axis azimuth alpha, is the same harmonic as Earth rate (no seek can remove it) and
//! has to travel to the device in a form nobody can alter unseen: inside the model bytes
//! (format version 3), under the model's CRC and, once `fogsim upload` signs it, the
//! upload signature. There is no separate, unsigned way to put it on a device.
//!
//! From `diagnose --json`: `between_run.heading` gives amplitude A (deg/h) and the phase
//! (deg, the azimuth of largest bias), so a = A cos(phase), b = A sin(phase), the
//! convention of `fog_core::model::heading::HeadingHarmonic` (phase = atan2(b, a)). The
//! 1-sigma of a and b is the leave-one-run-out rms of the run offsets with the harmonic
//! times sqrt(2 / runs) (least squares over runs spread round the circle), unless
//! `--sigma-dph` is given.

use std::io::BufReader;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use fog_core::model::format::MAX_ENCODED_LEN;
use fog_core::model::heading::HeadingHarmonic;
use serde::Deserialize;

use super::check_output_file;
use crate::io::model::read_model;
use crate::io::{write_atomic, OutputGuard};
use crate::pipeline::heading_fit::{fit_from_runs, short_number};
use fog_core::model::format::MAX_HEADING_HARMONIC_DPH;
use std::io::Read;

/// The diagnose column that is the input axis azimuth (`diagnose::sim_fit::drift_terms`).
const AZIMUTH_COLUMN: &str = "heading_deg";

/// Options of `fogsim heading-cal`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The model to extend (`fogsim train --out`); never overwritten.
    #[arg(long)]
    pub model: PathBuf,
    /// Where the model with the heading calibration goes (must not be an input).
    #[arg(long)]
    pub out: PathBuf,
    /// a of a cos(alpha) + b sin(alpha), deg/h (alpha: input axis azimuth).
    #[arg(long, allow_hyphen_values = true, requires_all = ["b_dph", "n_headings", "sigma_dph"], conflicts_with = "from_diagnose")]
    pub a_dph: Option<f32>,
    /// b of a cos(alpha) + b sin(alpha), deg/h.
    #[arg(long, allow_hyphen_values = true, requires = "a_dph")]
    pub b_dph: Option<f32>,
    /// 1-sigma of a and of b, deg/h (with --from-diagnose: overrides the one from the runs).
    #[arg(long)]
    pub sigma_dph: Option<f32>,
    /// Headings (or runs) the calibration used (with --from-diagnose: its run count).
    #[arg(long, requires = "a_dph")]
    pub n_headings: Option<u16>,
    /// `fogsim diagnose --json` output whose between-run heading harmonic to attach.
    #[arg(long, required_unless_present_any = ["a_dph", "from_runs"], conflicts_with = "from_runs")]
    pub from_diagnose: Option<PathBuf>,
    /// fog-runs files (or directories) recorded at several headings (`heading_deg`
    /// column, `latitude_deg` metadata): a and b are fitted from them, compensated with
    /// --model (e.g. `fogsim campaign --headings-deg 0,45,...`).
    #[arg(long, num_args = 1.., conflicts_with = "a_dph")]
    pub from_runs: Option<Vec<PathBuf>>,
}

/// Largest diagnose report read, bytes (a report of 10 000 runs is a few MB).
pub const MAX_DIAGNOSE_JSON_BYTES: u64 = 64 << 20;

/// The parts of diagnose's JSON this command reads (the rest is skipped while parsing).
#[derive(Deserialize)]
struct DiagnoseJson {
    campaign: CampaignJson,
    between_run: BetweenJson,
}

#[derive(Deserialize)]
struct CampaignJson {
    runs: usize,
}

#[derive(Deserialize)]
struct BetweenJson {
    heading: Option<HeadingJson>,
    rows: Vec<RowJson>,
}

#[derive(Deserialize)]
struct HeadingJson {
    column: String,
    amplitude_dph: f64,
    phase_deg: f64,
}

#[derive(Deserialize)]
struct RowJson {
    label: String,
    heldout_offset_rms_dph: f64,
}

/// Runs the subcommand.
pub fn run(args: Args) -> anyhow::Result<()> {
    let mut inputs = vec![args.model.clone()];
    inputs.extend(args.from_diagnose.clone());
    inputs.extend(args.from_runs.clone().unwrap_or_default());
    let guard = OutputGuard::new(&inputs);
    check_output_file(&guard, Some(&args.out), "--out")?;
    let harmonic = match (&args.from_diagnose, args.a_dph, args.b_dph, args.n_headings) {
        (None, None, None, None) if args.from_runs.is_some() => {
            from_runs(args.from_runs.as_deref().unwrap_or_default(), &args.model)?
        }
        (Some(path), None, None, None) => from_diagnose(path, args.sigma_dph)?,
        (None, Some(a), Some(b), Some(n)) => {
            let sigma = args
                .sigma_dph
                .context("--sigma-dph is required with --a-dph")?;
            for (flag, v) in [("--a-dph", a), ("--b-dph", b), ("--sigma-dph", sigma)] {
                if !v.is_finite() {
                    bail!("{flag} {v}: not a finite number of deg/h");
                }
            }
            HeadingHarmonic {
                cos_dph: a,
                sin_dph: b,
                cos_sigma_dph: sigma,
                sin_sigma_dph: sigma,
                correlation: 0.0,
                n_headings: n,
            }
        }
        _ => bail!(
            "give --from-runs DIR, --from-diagnose FILE, or --a-dph, --b-dph, --sigma-dph and --n-headings"
        ),
    };
    let mut model = read_model(&args.model)?;
    model.heading = Some(harmonic);
    let mut buf = [0u8; MAX_ENCODED_LEN];
    let len = model
        .encode(&mut buf)
        .map_err(|e| anyhow::anyhow!("heading calibration refused: {e}"))?;
    write_atomic(&args.out, &buf[..len])
        .with_context(|| format!("writing {}", args.out.display()))?;
    println!(
        "heading calibration a = {:+.5} deg/h, b = {:+.5} deg/h (1-sigma {:.5} / {:.5}), \
         amplitude {:.5} deg/h, largest at {:.1} deg, {} headings",
        harmonic.cos_dph,
        harmonic.sin_dph,
        harmonic.cos_sigma_dph,
        harmonic.sin_sigma_dph,
        harmonic.amplitude_dph(),
        harmonic.phase_deg().rem_euclid(360.0),
        harmonic.n_headings
    );
    println!(
        "wrote {} ({len} bytes, model format v{}); sign and install it with `fogsim upload`",
        args.out.display(),
        model.format_version()
    );
    Ok(())
}

/// The heading harmonic fitted from runs at several headings, printed dwell by dwell.
fn from_runs(paths: &[PathBuf], model: &Path) -> anyhow::Result<HeadingHarmonic> {
    let runs = crate::io::read_runs_binned(paths)?;
    let model = read_model(model)?;
    let fit = fit_from_runs(&runs, &model).context("--from-runs")?;
    println!(
        "{} runs at latitude {} deg; mean compensated rate per run (Earth rate included):",
        fit.dwells.len(),
        fit.latitude_deg
    );
    for d in &fit.dwells {
        println!(
            "  heading {:>7.2} deg  {:+.5} +- {:.5} deg/h  ({} windows)  {}",
            d.heading_deg, d.mean_rate_dph, d.sigma_dph, d.windows, d.file
        );
    }
    println!("constant bias b0 {:+.5} deg/h", fit.bias_dph);
    Ok(fit.harmonic)
}

/// The between-run heading harmonic of a diagnose report as a `HeadingHarmonic`.
fn from_diagnose(path: &Path, sigma_dph: Option<f32>) -> anyhow::Result<HeadingHarmonic> {
    let len = std::fs::metadata(path)
        .with_context(|| format!("--from-diagnose {}", path.display()))?
        .len();
    if len > MAX_DIAGNOSE_JSON_BYTES {
        bail!(
            "--from-diagnose {}: {len} bytes, more than the {MAX_DIAGNOSE_JSON_BYTES} a diagnose report can be",
            path.display()
        );
    }
    let file =
        std::fs::File::open(path).with_context(|| format!("--from-diagnose {}", path.display()))?;
    let d: DiagnoseJson = serde_json::from_reader(BufReader::new(file).take(len + 1))
        .with_context(|| {
            format!(
                "--from-diagnose {}: not a `fogsim diagnose --json` report",
                path.display()
            )
        })?;
    harmonic_from_report(&d, sigma_dph)
        .with_context(|| format!("--from-diagnose {}", path.display()))
}

fn harmonic_from_report(
    d: &DiagnoseJson,
    sigma_dph: Option<f32>,
) -> anyhow::Result<HeadingHarmonic> {
    let Some(h) = &d.between_run.heading else {
        bail!("diagnose named no heading harmonic between runs (between_run.heading is null): nothing to attach");
    };
    if h.column != AZIMUTH_COLUMN {
        bail!(
            "the harmonic is in column `{}`, not the input axis azimuth `{AZIMUTH_COLUMN}`: \
             the device cannot apply it",
            h.column
        );
    }
    if !(h.amplitude_dph.is_finite()
        && h.amplitude_dph >= 0.0
        && h.amplitude_dph <= f64::from(MAX_HEADING_HARMONIC_DPH)
        && h.phase_deg.is_finite())
    {
        bail!(
            "between_run.heading has amplitude {} deg/h, phase {} deg: not usable (amplitude must be within 0..={MAX_HEADING_HARMONIC_DPH})",
            short_number(h.amplitude_dph),
            short_number(h.phase_deg)
        );
    }
    let n_headings = u16::try_from(d.campaign.runs).unwrap_or(u16::MAX);
    let sigma = match sigma_dph {
        Some(s) => s,
        None => {
            let label = format!("{AZIMUTH_COLUMN}:run_harmonic");
            let row = d
                .between_run
                .rows
                .iter()
                .find(|r| r.label == label)
                .with_context(|| {
                    format!(
                        "no between_run row `{label}` to take the 1-sigma from: give --sigma-dph"
                    )
                })?;
            (row.heldout_offset_rms_dph * (2.0 / d.campaign.runs.max(1) as f64).sqrt()) as f32
        }
    };
    let phase = h.phase_deg.to_radians();
    Ok(HeadingHarmonic {
        cos_dph: (h.amplitude_dph * phase.cos()) as f32,
        sin_dph: (h.amplitude_dph * phase.sin()) as f32,
        cos_sigma_dph: sigma,
        sin_sigma_dph: sigma,
        correlation: 0.0,
        n_headings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(amplitude_dph: f64, phase_deg: f64, column: &str) -> DiagnoseJson {
        DiagnoseJson {
            campaign: CampaignJson { runs: 8 },
            between_run: BetweenJson {
                heading: Some(HeadingJson {
                    column: column.into(),
                    amplitude_dph,
                    phase_deg,
                }),
                rows: vec![RowJson {
                    label: "heading_deg:run_harmonic".into(),
                    heldout_offset_rms_dph: 0.004,
                }],
            },
        }
    }

    /// diagnose's (amplitude, phase of largest bias) and heading_cal's (a, b) describe the
    /// same bias at every azimuth, in every quadrant.
    #[test]
    fn amplitude_and_phase_become_a_and_b_with_heading_cals_signs() {
        for (amp, phase) in [
            (0.05, 0.0),
            (0.05, 63.0),
            (0.02, 150.0),
            (0.08, 241.0),
            (0.03, 333.0),
        ] {
            let h = harmonic_from_report(&report(amp, phase, "heading_deg"), None).unwrap();
            assert!((h.phase_deg().rem_euclid(360.0) as f64 - phase).abs() < 1e-3);
            assert!((h.amplitude_dph() as f64 - amp).abs() < 1e-6);
            for alpha in (0..360).step_by(15) {
                let alpha = alpha as f64;
                let diagnose_bias = amp * (alpha - phase).to_radians().cos();
                assert!(
                    (h.bias_dph(alpha) - diagnose_bias).abs() < 1e-6,
                    "{amp} {phase} {alpha}"
                );
            }
            assert_eq!(h.n_headings, 8);
            assert!((h.cos_sigma_dph - 0.002).abs() < 1e-6, "0.004 sqrt(2/8)");
        }
    }

    #[test]
    fn a_harmonic_of_another_column_or_none_is_refused_with_the_reason() {
        let e = harmonic_from_report(&report(0.05, 10.0, "mag_deg"), None).unwrap_err();
        assert!(e.to_string().contains("mag_deg"), "{e}");
        let mut none = report(0.05, 10.0, "heading_deg");
        none.between_run.heading = None;
        let e = harmonic_from_report(&none, None).unwrap_err();
        assert!(e.to_string().contains("between_run.heading is null"), "{e}");
        let e = harmonic_from_report(&report(f64::NAN, 10.0, "heading_deg"), None).unwrap_err();
        assert!(e.to_string().contains("not usable"), "{e}");
    }
}
