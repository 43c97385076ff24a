//! The terminal tables: per model its ambients, seeks and targets, then paper vs this project.

use super::results::*;
use crate::output::reports::{drift_cells, fmt_minutes, Table, DRIFT_COLUMNS};
use crate::pipeline::compensate::compensate_table;
use crate::pipeline::north_seek::seek_table;
use crate::stats::SPEC_DPH;

pub(super) fn compare(models: &[ModelResult], room_c: f64) -> Vec<Comparison> {
    let row = |q: String, p: &str, us: Vec<String>| Comparison {
        quantity: q,
        paper: p.into(),
        this_project: us.join(" | "),
    };
    let f4 = |v: f64| format!("{v:.4}");
    let each =
        |f: &dyn Fn(&ModelResult) -> String| -> Vec<String> { models.iter().map(f).collect() };
    let room = |m: &ModelResult| -> AmbientResult {
        m.per_ambient
            .iter()
            .find(|a| a.ambient_c == room_c)
            .or(m.per_ambient.first())
            .cloned()
            .expect("at least one ambient")
    };
    let at = format!(" ({room_c} degC, held out)");
    let ns = |m: &ModelResult| m.north_seek.clone();
    vec![
        row(
            format!("uncompensated largest startup deviation, deg/h{at}"),
            "0.17",
            each(&|m| f4(room(m).before.max_dev_dph)),
        ),
        row(
            format!("uncompensated time until 10 s std within spec{at}"),
            "15 min",
            each(&|m| fmt_minutes(room(m).before.time_to_spec_s)),
        ),
        row(
            format!("compensated startup drift 1 sigma, deg/h{at}"),
            "0.020 / 0.021",
            each(&|m| f4(room(m).after.std_dph)),
        ),
        row(
            format!("compensated largest startup deviation, deg/h{at}"),
            "-",
            each(&|m| f4(room(m).after.max_dev_dph)),
        ),
        row(
            format!("compensated time until within spec{at}"),
            "~0",
            each(&|m| fmt_minutes(room(m).after.time_to_spec_s)),
        ),
        row(
            "worst held-out compensated 1 sigma over all ambients, deg/h".into(),
            "(20 degC only)",
            each(&|m| f4(m.targets.worst_heldout_after_std_dph)),
        ),
        row(
            "neurons selected by OLS".into(),
            "35 / 37",
            each(&|m| m.training.n_centers.to_string()),
        ),
        row(
            "north seek: cold starts x seeks".into(),
            "1 x 6",
            each(&|m| format!("{} x {}", ns(m).starts, ns(m).seeks_per_start)),
        ),
        row(
            "north seek time per seek (longest), s".into(),
            "296",
            each(&|m| format!("{:.0}", ns(m).max_seek_duration_s)),
        ),
        row(
            "azimuth std over a start's 6 seeks, uncompensated, deg".into(),
            "0.034",
            each(&|m| f4(ns(m).uncompensated.mean_within_start_std_deg)),
        ),
        row(
            "azimuth std over a start's 6 seeks, compensated, deg".into(),
            "0.013",
            each(&|m| f4(ns(m).compensated.mean_within_start_std_deg)),
        ),
        row(
            "azimuth max - min of a start, uncompensated, deg".into(),
            "0.097",
            each(&|m| f4(ns(m).uncompensated.mean_range_deg)),
        ),
        row(
            "azimuth max - min of a start, compensated, deg".into(),
            "0.04",
            each(&|m| f4(ns(m).compensated.mean_range_deg)),
        ),
        row(
            "azimuth std of all seeks, uncompensated, deg".into(),
            "-",
            each(&|m| f4(ns(m).uncompensated.std_deg)),
        ),
        row(
            "azimuth std of all seeks, compensated, deg".into(),
            "-",
            each(&|m| f4(ns(m).compensated.std_deg)),
        ),
        row(
            "white-noise floor of the azimuth, deg".into(),
            "-",
            each(&|m| f4(ns(m).noise_floor_deg)),
        ),
    ]
}

/// The human-readable summary of one model variant.
pub(super) fn model_summary(m: &ModelResult) -> String {
    let mut amb = Table::new(&[&["ambient", "held-out runs"][..], &DRIFT_COLUMNS].concat());
    for a in &m.per_ambient {
        let label = [
            format!("{:+.0} degC", a.ambient_c),
            a.heldout_runs.to_string(),
        ];
        amb.row(&[&label[..], &drift_cells(&a.before, &a.after)].concat());
    }
    let t = &m.targets;
    let ok = |b: bool| if b { "MET" } else { "MISSED" };
    format!(
        "=== {}: {} centres, width {:.2}, cross-validated rms {:.4} deg/h\n{}\
         held-out drift of 10 s means, deg/h (spec {SPEC_DPH}):\n{}\nnorth seek at {} degC:\n{}{}\
         targets:\n\
         - held-out compensated std <= {SPEC_DPH} deg/h at every ambient: worst {:.4} -> {}\n\
         - time to spec: worst before {}, worst after {}\n\
         - compensated azimuth std within 1.2x the noise floor: {:.2}x -> {}\n\
         - uncompensated / compensated rms error of seeks 1, 2: {}\n\
         - seek time <= 296 s: {}\n\n",
        m.label,
        m.training.n_centers,
        m.training.width,
        m.training.heldout_rms_dph,
        m.recipe.as_deref().unwrap_or(""),
        amb.render(),
        m.north_seek.ambient_c,
        seek_table(&m.north_seek),
        m.north_seek_other_ambients
            .iter()
            .map(|r| format!("north seek at {} degC:\n{}", r.ambient_c, seek_table(r)))
            .collect::<String>(),
        t.worst_heldout_after_std_dph,
        ok(t.heldout_std_within_spec_everywhere),
        fmt_minutes(t.worst_time_to_spec_before_s),
        fmt_minutes(t.worst_time_to_spec_after_s),
        t.azimuth_std_over_floor,
        ok(t.azimuth_within_1_2x_floor),
        t.first_seeks_uncomp_over_comp
            .iter()
            .map(|v| format!("{v:.2}x"))
            .collect::<Vec<_>>()
            .join(", "),
        ok(t.seek_time_within_paper),
    )
}

/// The human-readable summary: per model variant the per-ambient table, the seek table and
/// the targets; then paper vs this project.
pub fn summary(r: &ReproduceReport) -> String {
    let mut cmp = Table::new(&[
        "quantity",
        "paper",
        &r.models
            .iter()
            .map(|m| m.label.as_str())
            .collect::<Vec<_>>()
            .join(" | "),
    ]);
    for c in &r.paper_vs_us {
        cmp.row(&[&c.quantity, &c.paper, &c.this_project]);
    }
    format!(
        "campaign: {} temperatures x {} runs x {} min (seed {}); models trained on runs 1-{} of each temperature\n\n{}\
         paper vs this project:\n{}",
        r.ambients_c.len(),
        r.runs_per_ambient,
        r.minutes,
        r.seed,
        r.train_runs_per_ambient,
        r.models.iter().map(model_summary).collect::<String>(),
        cmp.render(),
    )
}

/// The per-run held-out tables of every model variant (`reproduce` prints them in full).
pub fn validation_tables(r: &ReproduceReport) -> String {
    r.models
        .iter()
        .map(|m| {
            format!(
                "held-out runs, {}:\n{}\n",
                m.label,
                compensate_table(&m.validation)
            )
        })
        .collect()
}
