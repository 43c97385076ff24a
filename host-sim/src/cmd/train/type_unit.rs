//! `fogsim train --type-out TYPE` (learn a gyro type from several units' runs) and
//! `fogsim train --type TYPE` (calibrate one unit from its own runs with the type as the
//! prior): the two steps of `train::type_unit`, with `train`'s outputs, locks and
//! staging, and the calibration registry as the factory's record of both.

use std::path::Path;

use anyhow::{anyhow, bail, Result};
use fog_core::model::format::RbfModel;

use super::args::Args;
use super::finish::{field_refined, stage};
use crate::io::model::encode_model;
use crate::io::runs::Run;
use crate::io::StagedFiles;
use crate::registry::{Registry, UnitCalibrationRecord};
use crate::train::type_unit::calibrate::DEFAULT_SEEK_PERIOD_S;
use crate::train::type_unit::type_model::learn_type;
use crate::train::type_unit::{
    calibrate_unit, choose_own, ordinary_model, resolve_shape, train_shared, unit_id_of,
    MisfitPolicy, ShapeScoring, SharedModel, TypeModel, TypeShape, UnitPlan,
};
use crate::train::{InputSet, TrainConfig};

/// `model` for the device `gyro_id` (written into its metadata).
fn for_gyro(model: &RbfModel, gyro_id: &str) -> Result<RbfModel> {
    let mut m = model.clone();
    m.meta.gyro_id.clear();
    m.meta
        .gyro_id
        .push_str(gyro_id)
        .map_err(|_| anyhow!("--gyro-id {gyro_id}: at most 16 bytes"))?;
    Ok(m)
}

/// The model's encoding for the device `gyro_id`, and its CRC-32.
fn encoded(model: &RbfModel, gyro_id: &str) -> Result<(Vec<u8>, u32)> {
    let bytes = encode_model(&for_gyro(model, gyro_id)?)?;
    let crc = fog_core::model::crc::crc32(&bytes);
    Ok((bytes, crc))
}

/// The unit step's plan from the flags: `--unit-terms`, `--unit-prior-weight`,
/// `--seek-period-s` and the seek sequence.
fn unit_plan(args: &Args) -> UnitPlan {
    UnitPlan {
        terms: args.unit_terms,
        prior_weight: args.unit_prior_weight,
        seek_period_s: args.seek_period_s.unwrap_or(DEFAULT_SEEK_PERIOD_S),
        symmetric_seeks: args.seek_geometry().symmetric,
    }
}

/// `--type-out`: learns the type, writes it, the shared model (`--out`) and `--json` (the
/// type file's content), and records it when `--registry` is given.
pub(super) fn learn(
    args: &Args,
    cfg: &TrainConfig,
    candidates: &[InputSet],
    type_path: &Path,
    runs: &[Run],
) -> Result<()> {
    let ignored = args.network_shape_flags();
    if args.type_shape != TypeShape::Network && !ignored.is_empty() {
        bail!(
            "{}: a network's shape options; --type-shape law and auto (the default) choose \
             their own shape: drop them or use --type-shape network",
            ignored.join(", ")
        );
    }
    // the shapes scored by what the unit step makes of units left out (`--seek-period-s`)
    let scoring = ShapeScoring {
        cfg,
        candidates,
        fit: args.unit_fit,
        plan: unit_plan(args),
    };
    let (shape, choice) = resolve_shape(args.type_shape, runs, &scoring)?;
    if let Some(c) = &choice {
        print!("{}", c.summary());
    }
    // what the law's clock choices said of their grid, once each whatever the rounds; and
    // the clock the network's dT/dt is read in (`warmup_clock`: the runs decide it, the
    // same in every round)
    let mut edges: Vec<String> = Vec::new();
    let mut rate_clock: Option<String> = None;
    let mut train = |runs: Vec<Run>| -> Result<RbfModel> {
        let shared = train_shared(shape, &runs, cfg, candidates)?;
        match &shared {
            SharedModel::Law(law) => {
                if let Some(e) = law.grid_edge().filter(|e| !edges.contains(e)) {
                    edges.push(e);
                }
            }
            SharedModel::Network {
                clock: Some(clock), ..
            } => rate_clock = Some(clock.describe()),
            SharedModel::Network { .. } => {}
        }
        Ok(shared.model().clone())
    };
    let ty = learn_type(runs, None, args.unit_fit, &mut train)?;
    if let Some(c) = &rate_clock {
        println!("{c}");
    }
    for e in &edges {
        eprintln!("fogsim train: warning: {e}");
    }
    let (model_bytes, crc) = encoded(&ty.model, &cfg.gyro_id)?;
    let type_bytes = ty.to_bytes()?;
    let mut staged = StagedFiles::default();
    stage(&mut staged, &args.out, &model_bytes)?;
    stage(&mut staged, type_path, &type_bytes)?;
    if let Some(j) = &args.json {
        stage(&mut staged, j, &type_bytes)?;
    }
    if let Some(db) = &args.registry {
        let unit_runs: Vec<(String, String)> = runs
            .iter()
            .map(|r| {
                (
                    r.meta_value("unit_id").unwrap_or("").trim().to_string(),
                    r.name(),
                )
            })
            .collect();
        let json = String::from_utf8(type_bytes.clone())?;
        Registry::open(db)?.record_type(
            &ty.file.type_id,
            ty.file.units.len(),
            crc,
            &json,
            &unit_runs,
        )?;
    }
    staged.commit()?;
    print!("{}", ty.summary());
    println!(
        "wrote type {} to {} and its shared model (CRC-32 {crc:08x}) to {}",
        ty.file.type_id,
        type_path.display(),
        args.out.display()
    );
    Ok(())
}

/// What `--type` leaves to the caller.
pub(super) enum Calibrated {
    /// Done: the unit's model written (or nothing to write) and recorded.
    Done,
    /// The unit is outside its type and `--misfit own` asks for the ordinary training on
    /// its runs alone; the record is written once that model is (with its CRC).
    Own(UnitCalibrationRecord),
}

/// `--type`: calibrates the unit. `min_own_runs`: the run count the ordinary training
/// needs, checked before anything is recorded when `--misfit own` falls back to it. The
/// unit's own model (the ordinary training, `cfg` over `candidates`) is compared with the
/// calibration first (`type_unit::own`; not when `--unit-terms` or `--unit-prior-weight`
/// fix the calibration): where its own runs say more than its type, it leaves the type, as
/// with `--misfit own`.
pub(super) fn calibrate(
    args: &Args,
    cfg: &TrainConfig,
    candidates: &[InputSet],
    type_path: &Path,
    runs: &[Run],
    min_own_runs: usize,
) -> Result<Calibrated> {
    let ty = TypeModel::read(type_path)?;
    let unit = unit_id_of(runs, &args.gyro_id)?;
    let plan = unit_plan(args);
    let cal = calibrate_unit(&ty, runs, &unit, &plan)?;
    print!("{}", cal.summary());
    let policy = args.misfit.unwrap_or(MisfitPolicy::Refuse);
    let misfit = cal.misfit.outside();
    if !misfit && plan.terms.is_none() && plan.prior_weight.is_none() {
        let own = choose_own(&cal, runs, &plan, min_own_runs, &mut |subset| {
            ordinary_model(subset, candidates, cfg)
        })?;
        print!("{}", own.summary());
        if own.taken {
            println!("unit {unit}: trained on its own runs alone");
            return Ok(Calibrated::Own(UnitCalibrationRecord {
                unit_id: unit.clone(),
                type_id: ty.file.type_id.clone(),
                runs: cal.runs,
                terms: String::new(),
                prior_weight: cal.prior_weight,
                misfit: String::new(),
                outcome: "own model (its runs say more than its type)".into(),
                model_crc32: None,
            }));
        }
    }
    // the device's model (its gyro id in it) is what field records were measured under
    let device_model = for_gyro(&cal.model, &args.gyro_id)?;
    let model = match misfit {
        true => device_model,
        false => field_refined(args, &device_model)?,
    };
    let (bytes, crc) = encoded(&model, &args.gyro_id)?;
    let mut record = UnitCalibrationRecord {
        unit_id: unit.clone(),
        type_id: ty.file.type_id.clone(),
        runs: cal.runs,
        terms: cal.term_names[..cal.terms].join(", "),
        prior_weight: cal.prior_weight,
        misfit: cal.misfit.lines().join("; "),
        outcome: "calibrated".into(),
        model_crc32: Some(crc),
    };
    if misfit {
        record.model_crc32 = None;
        let type_id = &ty.file.type_id;
        match policy {
            MisfitPolicy::Refuse => {
                record.outcome = "refused (misfit)".into();
                record_unit(args, &record, runs)?;
                bail!(
                    "unit {unit}: outside its type {type_id} (above); nothing written (`--misfit own` trains it on its own runs alone)"
                );
            }
            MisfitPolicy::Own if runs.len() < min_own_runs => {
                record.outcome = "refused (misfit, too few runs of its own)".into();
                record_unit(args, &record, runs)?;
                bail!(
                    "unit {unit}: outside its type {type_id} (above), and {} run(s) are too few to train it on its own (`--misfit own` needs at least {min_own_runs}); nothing written",
                    runs.len()
                );
            }
            MisfitPolicy::Own => {
                record.outcome = "own model (misfit)".into();
                println!(
                    "unit {unit}: outside its type: trained on its own runs alone (--misfit own)"
                );
                return Ok(Calibrated::Own(record));
            }
        }
    }
    record_unit(args, &record, runs)?;
    let mut staged = StagedFiles::default();
    stage(&mut staged, &args.out, &bytes)?;
    if let Some(j) = &args.json {
        stage(&mut staged, j, &serde_json::to_vec_pretty(&cal)?)?;
    }
    staged.commit()?;
    println!(
        "wrote unit {unit}'s model (CRC-32 {crc:08x}, gyro id {}) to {}",
        args.gyro_id,
        args.out.display()
    );
    Ok(Calibrated::Done)
}

/// `--misfit own`: records the unit's own model (`record`) once it is written, with the
/// CRC-32 of the bytes written.
pub(super) fn record_own(
    args: &Args,
    mut record: UnitCalibrationRecord,
    runs: &[Run],
    model_bytes: &[u8],
) -> Result<()> {
    record.model_crc32 = Some(fog_core::model::crc::crc32(model_bytes));
    record_unit(args, &record, runs)
}

/// Records one unit calibration's outcome and its runs in `--registry`, if given.
fn record_unit(args: &Args, record: &UnitCalibrationRecord, runs: &[Run]) -> Result<()> {
    if let Some(db) = &args.registry {
        let names: Vec<String> = runs.iter().map(Run::name).collect();
        Registry::open(db)?.record_unit_calibration(record, &names)?;
    }
    Ok(())
}
