//! The production recipe side by side (`fogsim demo`): one unit's cold-start seeks from 6 of
//! its own cold starts (2 at each of -40, 20 and +60 degC), calibrated with a type learnt
//! from 10 other units of its design (`unit_recipe`); beside it, the same 6 runs alone, and
//! 96 of its cold starts at the seek's ambient (the calibration that meets the targets
//! without a type); all seek in the same Monte Carlo (same starts, same seeds).
//!
//! The type and the 96-run model are the slow part (tens of seconds). Each is kept in the
//! output directory as an ordinary file (a type file `fogsim train --type` reads, a model
//! file), under a name keyed by the bytes of the running executable and the recipe: the
//! same build and recipe reuse them (same seed, same bytes, so the figures are those of
//! making them afresh), a new build or another seed makes them again and replaces the
//! old files.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, Result};
use serde::Serialize;

use super::own_model::OwnModelPlan;
use super::targets::{seek_targets, verdict_words, SeekTargets, DECIDED_SE};
use super::unit_recipe::{
    chamber_h, default_unit_spread, learn_recipe_type, seeking_unit_params, type_free_model,
    unit_model, RecipeModel, RecipeType, UnitRecipe, RECIPE_AMBIENTS_C,
};
use super::{build_report, run_monte_carlo, MonteCarloConfig};
use crate::io::model::{encode_model, read_model};
use crate::output::reports::Table;
use crate::train::seek_score::{Criterion, SeekGeometry};
use crate::train::type_unit::TypeModel;
use crate::train::InputChoice;

/// Units the demo's type is learnt from, and cold starts of each (2 per recipe ambient).
pub const DEMO_TYPE_UNITS: usize = 10;
pub const DEMO_TYPE_UNIT_RUNS: usize = 6;
/// The unit's own cold starts (2 per recipe ambient).
pub const DEMO_UNIT_RUNS: usize = 6;
/// Cold starts of the calibration without a type, at the seek's ambient (`north-seek`'s
/// own model).
pub const CHAMBER_RUNS: usize = 96;
/// File-name prefixes of the kept type and 96-run model in the output directory.
const TYPE_PREFIX: &str = "fleet-type-";
const MODEL_PREFIX: &str = "unit-96-runs-";

/// One recipe's seeks.
#[derive(Clone, Debug, Serialize)]
pub struct RecipeRow {
    pub recipe: String,
    pub unit_runs: usize,
    pub unit_chamber_h: f64,
    /// Chamber hours of the type (all its units); 0 without one.
    pub type_chamber_h: f64,
    pub compensated_std_deg: f64,
    pub noise_floor_deg: f64,
    pub targets: Option<SeekTargets>,
}

/// The recipes compared, and whether the type came from the kept file.
#[derive(Clone, Debug, Serialize)]
pub struct RecipeComparison {
    pub ambient_c: f64,
    pub starts: usize,
    pub seeks_per_start: usize,
    pub rows: Vec<RecipeRow>,
    /// Where the type is kept, and whether it was read from there: printed, not in the
    /// JSON (its name changes with the build, and a report is the same bytes either way).
    #[serde(skip)]
    pub type_file: String,
    #[serde(skip)]
    pub type_reused: bool,
}

/// Seeks with both recipes at `cfg`'s ambient, seed and starts; the type is kept in (and
/// read from) `keep_dir`.
pub fn compare_recipes(cfg: &MonteCarloConfig, keep_dir: &Path) -> Result<RecipeComparison> {
    let recipe = UnitRecipe {
        type_units: DEMO_TYPE_UNITS,
        type_unit_runs: DEMO_TYPE_UNIT_RUNS,
        type_ambients_c: RECIPE_AMBIENTS_C.to_vec(),
        unit_runs: DEMO_UNIT_RUNS,
        unit_ambients_c: RECIPE_AMBIENTS_C.to_vec(),
        seed: cfg.seed,
        type_shape: Default::default(),
        unit_fit: Default::default(),
        unit_spread: default_unit_spread(),
        unit_terms: None,
        unit_prior_weight: None,
    };
    let plan = OwnModelPlan {
        ambient_c: cfg.ambient_c,
        latitude_deg: cfg.latitude_deg,
        dwell_s: cfg.dwell_s as f64,
        seed: cfg.seed,
        criterion: Criterion::Seek(SeekGeometry {
            symmetric: super::config::scored_as_symmetric(cfg.mode),
            ..SeekGeometry::forward(cfg.dwell_s as f64, cfg.latitude_deg)
        }),
        inputs: InputChoice::Auto,
        seek_timing: Some(MonteCarloConfig {
            restart_above_ambient_c: 0.0,
            ..cfg.clone()
        }),
        rate_clock: Default::default(),
    };
    let key = cache_key(&recipe)?;
    let type_path = keep_dir.join(format!("{TYPE_PREFIX}{key:016x}.json"));
    let (learnt, type_reused) = match read_kept_type(&type_path, &recipe) {
        Some(t) => (t, true),
        None => {
            let t = learn_recipe_type(&recipe, &plan)?;
            keep(&type_path, TYPE_PREFIX, &t.type_model.to_bytes()?)?;
            (t, false)
        }
    };
    let with_type = unit_model(&recipe, learnt, &plan)?;
    let free = type_free_model(&recipe, &plan)?;
    let chamber = UnitRecipe {
        type_units: 0,
        unit_runs: CHAMBER_RUNS,
        unit_ambients_c: vec![cfg.ambient_c],
        ..recipe.clone()
    };
    let model_path = keep_dir.join(format!("{MODEL_PREFIX}{key:016x}.bin"));
    let at_ambient = match read_model(&model_path) {
        Ok(model) => RecipeModel {
            model,
            unit_params: seeking_unit_params(&chamber)?,
            type_model: None,
            calibration: None,
            type_runs: 0,
            type_chamber_h: 0.0,
            unit_chamber_h: chamber_h(CHAMBER_RUNS),
            summary: String::new(),
        },
        Err(_) => {
            let made = type_free_model(&chamber, &plan)?;
            keep(&model_path, MODEL_PREFIX, &encode_model(&made.model)?)?;
            made
        }
    };
    let rows = [
        ("6 own runs + type of 10 units", DEMO_UNIT_RUNS, &with_type),
        ("6 own runs, no type", DEMO_UNIT_RUNS, &free),
        (
            "96 own runs at the seek's ambient",
            CHAMBER_RUNS,
            &at_ambient,
        ),
    ]
    .into_iter()
    .map(|(label, runs, made)| seek_row(label, runs, made, cfg))
    .collect::<Result<Vec<_>>>()?;
    Ok(RecipeComparison {
        ambient_c: cfg.ambient_c,
        starts: cfg.starts,
        seeks_per_start: cfg.seeks_per_start,
        rows,
        type_file: type_path.display().to_string(),
        type_reused,
    })
}

/// One recipe's Monte Carlo with the unit's own parameters.
fn seek_row(
    label: &str,
    unit_runs: usize,
    made: &RecipeModel,
    cfg: &MonteCarloConfig,
) -> Result<RecipeRow> {
    let outcomes = run_monte_carlo(&made.unit_params, cfg, &made.model, &|| {})?;
    let report = build_report(&made.unit_params, cfg, &outcomes, label);
    Ok(RecipeRow {
        recipe: label.to_string(),
        unit_runs,
        unit_chamber_h: made.unit_chamber_h,
        type_chamber_h: made.type_chamber_h,
        compensated_std_deg: report.compensated.std_deg,
        noise_floor_deg: report.noise_floor_deg,
        targets: seek_targets(&report),
    })
}

/// FNV-1a over this executable's bytes and the recipe: a new build or recipe is a new key.
fn cache_key(recipe: &UnitRecipe) -> Result<u64> {
    let exe = std::env::current_exe().map_err(|e| anyhow!("finding this executable: {e}"))?;
    let bytes = std::fs::read(&exe).map_err(|e| anyhow!("reading {}: {e}", exe.display()))?;
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let recipe_text = format!("{recipe:?}");
    for b in bytes.iter().chain(recipe_text.as_bytes()) {
        h = (h ^ u64::from(*b)).wrapping_mul(0x0100_0000_01b3);
    }
    Ok(h)
}

/// The kept type at `path`, if there is one that reads whole and is the recipe's.
fn read_kept_type(path: &Path, recipe: &UnitRecipe) -> Option<RecipeType> {
    let ty = TypeModel::read(path).ok()?;
    (ty.file.units.len() == recipe.type_units).then(|| RecipeType {
        type_runs: ty.runs(),
        summary: format!(
            "type read from {} (kept by an earlier run)\n",
            path.display()
        ),
        type_model: ty,
    })
}

/// Writes `bytes` to `path` (atomically) and removes the files of `prefix` kept beside it
/// by earlier builds or seeds.
fn keep(path: &Path, prefix: &str, bytes: &[u8]) -> Result<()> {
    let dir = path.parent().unwrap_or(Path::new("."));
    if let Ok(entries) = std::fs::read_dir(dir) {
        let stale: Vec<PathBuf> = entries
            .flatten()
            .map(|e| e.path())
            .filter(|p| {
                p.file_name()
                    .and_then(|n| n.to_str())
                    .is_some_and(|n| n.starts_with(prefix))
            })
            .collect();
        for p in stale {
            let _ = std::fs::remove_file(p);
        }
    }
    crate::io::write_atomic(path, bytes).map_err(|e| anyhow!("writing {}: {e}", path.display()))
}

/// The comparison as a table, with the targets' verdicts.
pub fn recipe_table(c: &RecipeComparison) -> String {
    let mut t = Table::new(&[
        "recipe",
        "unit chamber h",
        "type chamber h",
        "all seeks x floor",
        "worst seek 1-3 x floor",
        "worst |mean|/std",
        "targets",
    ]);
    for r in &c.rows {
        let fig = |f: fn(&SeekTargets) -> f64| {
            r.targets
                .as_ref()
                .map_or("-".to_string(), |t| format!("{:.2}", f(t)))
        };
        t.row(&[
            r.recipe.clone(),
            format!("{:.1}", r.unit_chamber_h),
            format!("{:.1}", r.type_chamber_h),
            fig(|t| t.all_over_floor),
            fig(|t| t.worst_first_over_floor),
            fig(|t| t.worst_mean_over_std),
            r.targets
                .as_ref()
                .map_or("no seeks", |t| {
                    verdict_words(t, c.starts, c.seeks_per_start)
                })
                .to_string(),
        ]);
    }
    format!(
        "production recipe: unit U1 of a simulated fleet, {} cold starts x {} seeks at {} degC ({}type {}):\n{}\
         ({} starts: a |mean|/std is known to about +-{:.2}; \"not decided\": a figure within {DECIDED_SE} standard errors of its target; 1,000-start figures over forty fleets: docs/guide/fleet.md)\n",
        c.starts,
        c.seeks_per_start,
        c.ambient_c,
        if c.type_reused { "kept " } else { "" },
        c.type_file,
        t.render(),
        c.starts,
        1.0 / (c.starts.max(1) as f64).sqrt(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn recipe() -> UnitRecipe {
        UnitRecipe {
            type_units: DEMO_TYPE_UNITS,
            type_unit_runs: DEMO_TYPE_UNIT_RUNS,
            type_ambients_c: RECIPE_AMBIENTS_C.to_vec(),
            unit_runs: DEMO_UNIT_RUNS,
            unit_ambients_c: RECIPE_AMBIENTS_C.to_vec(),
            seed: 1,
            type_shape: Default::default(),
            unit_fit: Default::default(),
            unit_spread: default_unit_spread(),
            unit_terms: None,
            unit_prior_weight: None,
        }
    }

    #[test]
    fn a_kept_file_replaces_the_earlier_builds_files_and_nothing_else() {
        let dir = std::env::temp_dir().join(format!("fogsim-keep-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        for name in [
            "fleet-type-0000.json",
            "report.json",
            "unit-96-runs-0000.bin",
        ] {
            std::fs::write(dir.join(name), b"old").unwrap();
        }
        let path = dir.join("fleet-type-1111.json");
        keep(&path, TYPE_PREFIX, b"new").unwrap();
        let mut left: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        left.sort();
        assert_eq!(
            left,
            [
                "fleet-type-1111.json",
                "report.json",
                "unit-96-runs-0000.bin"
            ]
        );
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        // a kept file that does not read whole as a type is not used (it is made again)
        std::fs::write(&path, b"{\"truncated").unwrap();
        assert!(read_kept_type(&path, &recipe()).is_none());
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn the_key_changes_with_the_recipe() {
        let other = UnitRecipe {
            seed: 2,
            type_shape: Default::default(),
            unit_fit: Default::default(),
            unit_spread: default_unit_spread(),
            ..recipe()
        };
        assert_eq!(cache_key(&recipe()).unwrap(), cache_key(&recipe()).unwrap());
        assert_ne!(cache_key(&recipe()).unwrap(), cache_key(&other).unwrap());
    }
}
