//! `fogsim allan FILE... [--column C] [--taus octave|decade|all] [--kind adev|mdev|hdev|tdev|totdev]
//! [--json FILE] [--plot FILE.svg]`: an Allan-family deviation of one column of fog-runs
//! files with 1-sigma confidence intervals, and the IEEE Std 952 noise terms.

use super::{check_distinct_outputs, check_output_file};
use crate::io::OutputGuard;
use crate::output::plots::{allan_chart, write_svg};
use crate::output::reports::write_json;
use crate::pipeline::allan::{allan_of_files, AllanReport, DRIFT_COLUMN};
use crate::stats::allan::{Kind, TauSpacing};
use std::fmt::Write;
use std::path::PathBuf;

/// Options of `fogsim allan`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// fog-runs v1 files or directories (read in name order; each file its own segment).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Column to analyse; `drift` = rate_dph - earth_dph.
    #[arg(long, default_value = DRIFT_COLUMN)]
    pub column: String,
    /// Tau spacing: octave, decade (1, 2, 4 x 10^k) or all.
    #[arg(long, default_value = "octave")]
    pub taus: TauSpacing,
    /// Deviation: adev (overlapping), mdev, hdev (overlapping), tdev, totdev.
    #[arg(long, default_value = "adev")]
    pub kind: Kind,
    /// Write the curve and the noise terms as JSON here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write the plot (SVG) here.
    #[arg(long)]
    pub plot: Option<PathBuf>,
}

/// Runs the subcommand.
pub fn run(args: Args) -> anyhow::Result<()> {
    let guard = OutputGuard::new(&args.files);
    check_output_file(&guard, args.json.as_deref(), "--json")?;
    check_output_file(&guard, args.plot.as_deref(), "--plot")?;
    check_distinct_outputs(&[
        ("--json", args.json.as_deref()),
        ("--plot", args.plot.as_deref()),
    ])?;
    let report = allan_of_files(&args.files, &args.column, args.kind, args.taus)?;
    print!("{}", render_text(&report));
    if let Some(path) = &args.json {
        write_json(path, &report)?;
        println!("JSON written to {}", path.display());
    }
    if let Some(path) = &args.plot {
        let title = format!(
            "{} of {} ({} file{})",
            report.analysis.curve.kind,
            report.column,
            report.files.len(),
            if report.files.len() == 1 { "" } else { "s" }
        );
        write_svg(path, &allan_chart(&title, &report.analysis))?;
        println!("plot written to {}", path.display());
    }
    Ok(())
}

/// The curve table and the noise-term table.
pub fn render_text(r: &AllanReport) -> String {
    let a = &r.analysis;
    let c = &a.curve;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{} of '{}': {} rows in {} file(s), row period {} s, {} segment(s) ({} gap(s) in t_s){}",
        c.kind.name(),
        r.column,
        r.rows,
        r.files.len(),
        r.row_period_s,
        c.segments,
        r.gaps,
        if c.decimation > 1 {
            format!(
                "; averaged {} rows per sample to bound memory (tau0 {} s)",
                c.decimation, c.tau0_s
            )
        } else {
            String::new()
        }
    );
    let _ = writeln!(
        s,
        "{:>12} {:>9} {:>12} {:>12} {:>12} {:>9} {:>6} {:>10}",
        "tau_s",
        "m",
        c.kind.to_string(),
        "lo_1sigma",
        "hi_1sigma",
        "edf",
        "alpha",
        "terms"
    );
    for p in &c.points {
        let _ = writeln!(
            s,
            "{:>12.4} {:>9} {:>12.4e} {:>12.4e} {:>12.4e} {:>9.1} {:>5}{} {:>10}",
            p.tau_s,
            p.m,
            p.dev,
            p.dev_lo,
            p.dev_hi,
            p.edf,
            p.alpha,
            if p.alpha_identified { " " } else { "*" },
            p.terms
        );
    }
    let _ = writeln!(
        s,
        "  unit {}; interval: chi-squared with Greenhall's EDF for noise exponent alpha (lag-1 autocorrelation; * = carried from a shorter tau)",
        c.unit
    );
    let _ =
        writeln!(
        s,
        "IEEE Std 952 noise terms (fitted to the octave ADEV, {} points, reduced chi2 {:.2}){}:",
        a.noise.points_used,
        a.noise.reduced_chi2,
        if a.noise.note.is_empty() { String::new() } else { format!(" - {}", a.noise.note) }
    );
    if !r.column.ends_with("_dph") && r.column != DRIFT_COLUMN {
        let _ = writeln!(
            s,
            "  (column '{}' is not a rate in deg/h: the units below do not apply)",
            r.column
        );
    }
    for t in &a.noise.terms {
        let range = match (t.tau_from_s, t.tau_to_s) {
            (Some(lo), Some(hi)) => format!("tau {lo:.4}..{hi:.4} s"),
            _ => "-".into(),
        };
        let _ = if t.detected {
            writeln!(
                s,
                "  {:?} {:<18} {:.4e} +/- {:.2e} {:<14} read from {range}",
                t.term, t.name, t.value, t.sigma, t.unit
            )
        } else if t.in_fit {
            writeln!(s, "  {:?} {:<18} not significant: {:.2e} +/- {:.2e} {} (below 2 sigma in variance; strongest at {range})", t.term, t.name, t.value, t.sigma, t.unit)
        } else {
            writeln!(
                s,
                "  {:?} {:<18} not in the best fit (1-sigma upper bound {:.2e} {})",
                t.term, t.name, t.sigma, t.unit
            )
        };
    }
    s
}
