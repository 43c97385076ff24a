//! Type and unit calibration (`fogsim train --type-out` / `--type`, `train::type_unit`):
//! end to end on the simulator's fleet (outputs, reports and the registry's record; the
//! same commands give the same bytes); on an independent fleet (`common::fleet_independent`)
//! a unit outside its type is flagged and one inside it is not, its null twin flags no
//! unit, and the unit calibration does no worse on held-out seeks than the type alone; the
//! CLI refuses an odd unit by default and trains it alone with `--misfit own`, and trains a
//! unit alone when its own runs say more than its type; bad input gets one line and writes
//! nothing.

use crate::app_support;
use crate::common::fleet_independent::{fleet, FleetLaw};

use fog_core::model::format::{FeatureKind, RbfModel};
use fog_sim::io::model::read_model;
use fog_sim::io::runs::{write_run, Run};
use fog_sim::registry::Registry;
use fog_sim::train::type_unit::terms::Fit;
use fog_sim::train::type_unit::type_model::learn_type;
use fog_sim::train::type_unit::{calibrate_unit, TypeModel, UnitCalibration, UnitPlan};
use fog_sim::train::{dataset_from_runs, default_specs, train_model, TrainConfig};
use std::path::{Path, PathBuf};
use std::process::Output;
use std::time::Instant;

/// `fogsim ARGS` in `dir` (paths relative to it).
fn fogsim(dir: &Path, args: &[&str]) -> Output {
    app_support::fogsim(dir, args)
}

/// `fogsim ARGS` in `dir`, which must succeed; its stdout.
fn fogsim_ok(dir: &Path, args: &[&str]) -> String {
    let o = fogsim(dir, args);
    assert!(
        o.status.success(),
        "fogsim {args:?}: {}",
        app_support::stderr(&o)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// `fogsim campaign` of `units` units into `dir/fleet` (20 min cold starts at 10 Hz, every
/// unit at every ambient `runs` times).
fn sim_fleet(dir: &Path, units: usize, ambients_c: &str, runs: usize) {
    fogsim_ok(
        dir,
        &[
            "campaign",
            "--out",
            "fleet",
            "--units",
            &units.to_string(),
            "--ambient-c",
            ambients_c,
            "--runs",
            &runs.to_string(),
            "--duration-min",
            "20",
            "--raw-rate-hz",
            "10",
            "--seed",
            "3",
            "--type-seed",
            "5",
        ],
    );
}

/// The files of `dir/sub` whose names start with `prefix`, as `sub/name`, in name order.
fn files(dir: &Path, sub: &str, prefix: &str) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir.join(sub))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(prefix))
        .map(|n| format!("{sub}/{n}"))
        .collect();
    v.sort();
    v
}

/// The runs of units `units` (1-based) of the simulator's fleet in `dir/fleet`.
fn unit_files(dir: &Path, units: &[usize]) -> Vec<String> {
    units
        .iter()
        .flat_map(|u| files(dir, "fleet", &format!("u{u:03}_")))
        .collect()
}

/// A fleet of 4 units, one cold start each at -40, 20 and +60 degC: the runs of units 1-3
/// (a type's) and of unit 4 (a unit to calibrate).
fn three_units_and_a_fourth(dir: &Path) -> (Vec<String>, Vec<String>) {
    sim_fleet(dir, 4, "-40,20,60", 1);
    (unit_files(dir, &[1, 2, 3]), unit_files(dir, &[4]))
}

/// `fogsim train RUNS EXTRA...` as arguments.
fn train_args<'a>(runs: &'a [String], extra: &[&'a str]) -> Vec<&'a str> {
    let mut a = vec!["train"];
    a.extend(runs.iter().map(String::as_str));
    a.extend_from_slice(extra);
    a
}

#[test]
fn the_cli_learns_a_type_from_three_units_and_calibrates_a_fourth_with_reports_and_registry() {
    let t0 = Instant::now();
    let dir = app_support::scratch_dir("type-cli");
    let (type_runs, unit_runs) = three_units_and_a_fourth(&dir);
    assert_eq!((type_runs.len(), unit_runs.len()), (9, 3));
    let learnt = fogsim_ok(
        &dir,
        &train_args(
            &type_runs,
            &[
                "--type-out",
                "type.json",
                "--out",
                "shared.model",
                "--registry",
                "reg.sqlite",
                "--json",
                "type_report.json",
            ],
        ),
    );
    assert!(
        learnt.contains("wrote type paper_default to type.json"),
        "{learnt}"
    );
    let calibrated = fogsim_ok(
        &dir,
        &train_args(
            &unit_runs,
            &[
                "--type",
                "type.json",
                "--out",
                "u4.model",
                "--gyro-id",
                "U4",
                "--registry",
                "reg.sqlite",
                "--json",
                "u4.json",
            ],
        ),
    );
    assert!(calibrated.contains("wrote unit U4's model"), "{calibrated}");
    // three runs, three folds of the ordinary training: none can be left out to compare
    assert!(
        calibrated.contains("unit's own model: not compared (3 runs are too few"),
        "{calibrated}"
    );

    // the type: three units of three runs, its shared model the one written beside it
    let ty = TypeModel::read(&dir.join("type.json")).unwrap();
    assert_eq!(ty.file.type_id, "paper_default");
    let units: Vec<(&str, usize)> = ty
        .file
        .units
        .iter()
        .map(|u| (u.unit_id.as_str(), u.runs))
        .collect();
    assert_eq!(units, [("U1", 3), ("U2", 3), ("U3", 3)]);
    let shared = read_model(&dir.join("shared.model")).unwrap();
    assert_eq!(shared, ty.model);
    // `--json` of `--type-out` is the type file's content
    assert_eq!(
        std::fs::read(dir.join("type_report.json")).unwrap(),
        std::fs::read(dir.join("type.json")).unwrap()
    );
    // the unit's model: an ordinary model of the type's inputs, with its gyro id
    let unit_bytes = std::fs::read(dir.join("u4.model")).unwrap();
    let unit = read_model(&dir.join("u4.model")).unwrap();
    assert_eq!(unit.meta.gyro_id.as_str(), "U4");
    assert_eq!(unit.inputs, ty.model.inputs);
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("u4.json")).unwrap()).unwrap();
    assert_eq!(report["unit_id"], "U4");
    assert_eq!(report["type_id"], "paper_default");
    assert_eq!(report["runs"], 3);
    assert_eq!(
        report["misfit"]["terms"].as_array().unwrap().len(),
        ty.file.terms.len()
    );
    let chosen_drift_dph = report["chosen_drift_dph"].as_f64().unwrap();
    let type_alone_drift_dph = report["type_alone_drift_dph"].as_f64().unwrap();
    assert!(chosen_drift_dph <= type_alone_drift_dph, "{report}");

    // the registry: the type's units and runs, and the unit's calibration by its model's CRC
    let reg = Registry::open(&dir.join("reg.sqlite")).unwrap();
    assert_eq!(
        reg.type_units("paper_default").unwrap(),
        [("U1".to_string(), 3), ("U2".into(), 3), ("U3".into(), 3)]
    );
    let cals = reg.unit_calibrations("U4").unwrap();
    assert_eq!(cals.len(), 1, "{cals:?}");
    assert_eq!(cals[0].type_id, "paper_default");
    assert_eq!(cals[0].runs, 3);
    assert_eq!(cals[0].outcome, "calibrated");
    assert_eq!(
        cals[0].model_crc32,
        Some(fog_core::model::crc::crc32(&unit_bytes))
    );
    assert!(reg.unit_calibrations("U1").unwrap().is_empty());
    drop(reg);
    println!(
        "type from 3 units x 3 runs, unit U4 on 3 runs: held-out drift {chosen_drift_dph:.4} deg/h \
         ({type_alone_drift_dph:.4} with the type alone); {:.1} s",
        t0.elapsed().as_secs_f64()
    );
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn the_law_shape_learns_a_type_whose_unit_calibration_is_an_ordinary_model() {
    let dir = app_support::scratch_dir("type-law");
    let (type_runs, unit_runs) = three_units_and_a_fourth(&dir);
    let learnt = fogsim_ok(
        &dir,
        &train_args(
            &type_runs,
            &[
                "--type-out",
                "type.json",
                "--type-shape",
                "law",
                "--out",
                "shared.model",
            ],
        ),
    );
    fogsim_ok(
        &dir,
        &train_args(&unit_runs, &["--type", "type.json", "--out", "u4.model"]),
    );
    // the shared model: T and the rise since power-on, then two power-on clocks of the
    // grid (fast before slow) and their stretches, their products with T among the unit
    // terms
    let ty = TypeModel::read(&dir.join("type.json")).unwrap();
    let labels: Vec<String> = ty
        .model
        .inputs
        .iter()
        .map(fog_sim::train::feature_name)
        .collect();
    assert_eq!(labels[..2], ["temp_c:value", "temp_c:rise"], "{labels:?}");
    let taus: Vec<f32> = ty.model.inputs[2..].iter().map(|s| s.tau_s).collect();
    assert!(
        taus.len() == 4 && taus[0] < taus[1] && taus[2..] == taus[..2],
        "{labels:?}"
    );
    let kinds: Vec<FeatureKind> = ty.model.inputs[2..].iter().map(|s| s.kind).collect();
    assert_eq!(
        kinds,
        [
            FeatureKind::PowerOnDecay,
            FeatureKind::PowerOnDecay,
            FeatureKind::PowerOnDecayStretch,
            FeatureKind::PowerOnDecayStretch
        ]
    );
    assert!(
        ty.file
            .terms
            .iter()
            .any(|t| t.term.starts_with("linear_by_t:")),
        "{learnt}"
    );
    assert_eq!(read_model(&dir.join("shared.model")).unwrap(), ty.model);
    let unit = read_model(&dir.join("u4.model")).unwrap();
    assert_eq!(unit.inputs, ty.model.inputs);
    assert!(
        unit.cold_start.is_some(),
        "a clocked model checks cold starts"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn the_same_commands_write_the_same_type_and_unit_model_bytes() {
    let t0 = Instant::now();
    let dir = app_support::scratch_dir("type-bytes");
    // the smallest fleet a type and a unit calibration take: 3 + 1 units of 2 runs
    sim_fleet(&dir, 4, "20", 2);
    let type_runs = unit_files(&dir, &[1, 2, 3]);
    let unit_runs = unit_files(&dir, &[4]);
    let outputs = ["type.json", "shared.model", "unit.model", "unit.json"];
    let mut bytes: Vec<Vec<Vec<u8>>> = Vec::new();
    for round in ["a", "b"] {
        std::fs::create_dir_all(dir.join(round)).unwrap();
        let p = |name: &str| format!("{round}/{name}");
        let (ty, shared, model, json) =
            (p(outputs[0]), p(outputs[1]), p(outputs[2]), p(outputs[3]));
        fogsim_ok(
            &dir,
            &train_args(&type_runs, &["--type-out", &ty, "--out", &shared]),
        );
        fogsim_ok(
            &dir,
            &train_args(
                &unit_runs,
                &["--type", &ty, "--out", &model, "--json", &json],
            ),
        );
        bytes.push(
            outputs
                .iter()
                .map(|o| std::fs::read(dir.join(round).join(o)).unwrap())
                .collect(),
        );
    }
    for (k, name) in outputs.iter().enumerate() {
        assert!(!bytes[0][k].is_empty(), "{name} is empty");
        assert!(
            bytes[0][k] == bytes[1][k],
            "{name} differs between two runs"
        );
    }
    println!("same bytes twice: {:.1} s", t0.elapsed().as_secs_f64());
    std::fs::remove_dir_all(dir).unwrap();
}

// ---- the independent fleet, library level ----

/// The independent fleets' size for the misfit decisions: 6 units (the type from 5), each
/// with 2 cold starts of 30 min at -10 and at +30 degC (two ambients, so that temperature
/// and dT/dt terms are told apart).
const UNITS: usize = 6;
const AMBIENTS_C: [f64; 2] = [-10.0, 30.0];
const RUNS_PER_AMBIENT: usize = 2;
const MINUTES: usize = 30;

/// The shared model's trainer: the paper's inputs with linear terms (fixed, so that the
/// type's unit terms are offset, warm-up gain, temperature and Shupe coefficients).
fn train_shared(runs: Vec<Run>) -> anyhow::Result<RbfModel> {
    let cfg = TrainConfig {
        linear_on_rbf_inputs: true,
        ..Default::default()
    };
    let ds = dataset_from_runs(&runs, &default_specs())?;
    Ok(train_model(&ds, &cfg)?.model)
}

/// Unit `unit` (1-based) of the independent fleet `law` (seed `seed`): the type learnt from
/// every other unit, the unit's runs and its id.
fn type_and_unit(law: FleetLaw, seed: u64, unit: usize) -> (TypeModel, Vec<Run>, String) {
    let f = fleet(law, UNITS, &AMBIENTS_C, RUNS_PER_AMBIENT, MINUTES, seed);
    let id = format!("U{unit}");
    let (own, others): (Vec<Run>, Vec<Run>) = f
        .runs
        .into_iter()
        .partition(|r| r.meta_value("unit_id") == Some(id.as_str()));
    let ty = learn_type(
        &others,
        Some("independent"),
        Fit::default(),
        &mut train_shared,
    )
    .unwrap();
    (ty, own, id)
}

/// That unit calibrated against that type, its choice made by leave-one-run-out.
fn calibrated(law: FleetLaw, seed: u64, unit: usize) -> (TypeModel, UnitCalibration) {
    let (ty, own, id) = type_and_unit(law, seed, unit);
    let cal = calibrate_unit(&ty, &own, &id, &UnitPlan::chosen()).unwrap();
    (ty, cal)
}

/// The largest |z| / critical over the unit's terms (> 1: outside its type).
fn worst_ratio(cal: &UnitCalibration) -> f64 {
    cal.misfit
        .terms
        .iter()
        .map(|t| t.z.abs() / t.critical)
        .fold(0.0, f64::max)
}

/// Measured at this size, seeds 1..=12 (2026-12-05, every term tested at once): the odd
/// unit's largest |z| / critical was 2.3 to 8.2 (largest |z| 12 to 39 against critical
/// values of 4.6 to 8; the flagged terms mostly the warm-up gain, the offset and the
/// temperature coefficient, which take up the reversed Shupe term with it); the normal last
/// unit's 0.08 to 0.72, and its held-out seek rms 0.0089 to 0.0133 deg against 0.0089 to
/// 0.0262 with the type alone. Smaller fleets were not robust (measured with the trainer on
/// one thread): with 4 units of 2 runs (the type from 3) the odd unit was missed at 1 seed
/// of 12 (0.94), with 8 units of 1 run per ambient at 5 of 12. Since 2026-12-06 the terms
/// the runs cannot resolve are held at the type's mean (`calibrate::misfit_of`): seeds 1-3
/// odd 4.10 / 6.37 / 14.15, normal 0.09 / 0.35 / 1.14 (seed 3's normal unit flagged, one
/// of the 2 of 108 of the qualification below, the test's 1 % level), so the normal units
/// are held to that level here: at most the 99 % binomial quantile of 1 % of 3 units.
#[test]
fn an_independent_odd_unit_is_outside_its_type_and_a_normal_unit_is_within_it() {
    let t0 = Instant::now();
    let mut normal_flagged = Vec::new();
    for seed in 1..=3 {
        let (ty, odd) = calibrated(FleetLaw::OddUnit, seed, UNITS);
        let lines = odd.misfit.lines();
        println!(
            "seed {seed}: odd unit: worst |z|/critical {:.2}: {lines:?}",
            worst_ratio(&odd)
        );
        assert!(odd.misfit.outside(), "seed {seed}: {lines:?}");
        let names: Vec<&str> = ty.file.terms.iter().map(|t| t.name.as_str()).collect();
        let flagged: Vec<&String> = lines
            .iter()
            .filter(|l| l.contains("sigma outside the type"))
            .collect();
        assert!(!flagged.is_empty(), "seed {seed}: {lines:?}");
        for l in flagged {
            assert!(
                l.starts_with(&format!("unit U{UNITS}: "))
                    && names.iter().any(|n| l.contains(&format!(": {n} "))),
                "seed {seed}: `{l}` names no term of {names:?}"
            );
        }

        let (_, normal) = calibrated(FleetLaw::Type, seed, UNITS);
        println!(
            "seed {seed}: normal unit: worst |z|/critical {:.2}; held-out drift {:.4} deg/h \
             ({:.4} with the type alone), {} unit terms",
            worst_ratio(&normal),
            normal.chosen_drift_dph,
            normal.type_alone_drift_dph,
            normal.terms
        );
        if normal.misfit.outside() {
            normal_flagged.push(format!("seed {seed}: {:?}", normal.misfit.lines()));
        }
        assert!(
            normal.chosen_drift_dph <= normal.type_alone_drift_dph,
            "seed {seed}: {} > {}",
            normal.chosen_drift_dph,
            normal.type_alone_drift_dph
        );
    }
    let allowed = crate::common::level::binomial_upper(
        3,
        fog_sim::train::type_unit::misfit::FAMILY_ALPHA,
        0.99,
    );
    assert!(
        normal_flagged.len() <= allowed,
        "{} of 3 normal units flagged (allowed {allowed}): {normal_flagged:?}",
        normal_flagged.len()
    );
    println!("{:.1} s", t0.elapsed().as_secs_f64());
}

/// A fixed choice (`--unit-terms`, `--unit-prior-weight`) is what is fitted, and is still
/// scored beside the type alone, so the summary can compare the two.
#[test]
fn a_fixed_unit_step_fits_what_it_is_told_and_reports_the_type_alone_beside_it() {
    let (ty, own, id) = type_and_unit(FleetLaw::Type, 1, UNITS);
    let plan = UnitPlan {
        terms: Some(2),
        prior_weight: Some(0.3),
        ..UnitPlan::chosen()
    };
    let cal = calibrate_unit(&ty, &own, &id, &plan).unwrap();
    let summary = cal.summary();
    println!("{summary}");
    assert_eq!((cal.terms, cal.prior_weight), (2, 0.3));
    assert!(cal.type_alone_drift_dph.is_finite(), "{summary}");
    assert!(
        summary.contains("chosen by --unit-terms and --unit-prior-weight (fixed)"),
        "{summary}"
    );
    // the weight fixed alone: every count tried at that weight
    let weight_only = UnitPlan {
        terms: None,
        ..plan
    };
    let cal = calibrate_unit(&ty, &own, &id, &weight_only).unwrap();
    assert!(cal
        .candidates
        .iter()
        .all(|c| c.terms == 0 || c.prior_weight == 0.3));
}

/// Measured (seeds 1..=18, every unit in turn): the null twin's largest |z| / critical was
/// at most 0.71 (|z| at most 3.6); seed 1 here: at most 0.34.
#[test]
fn the_independent_null_twin_flags_no_unit() {
    let t0 = Instant::now();
    for unit in 1..=UNITS {
        let (_, cal) = calibrated(FleetLaw::Identical, 1, unit);
        println!("unit U{unit}: worst |z|/critical {:.2}", worst_ratio(&cal));
        assert!(!cal.misfit.outside(), "U{unit}: {:?}", cal.misfit.lines());
    }
    println!("{:.1} s", t0.elapsed().as_secs_f64());
}

// ---- the CLI on the independent fleet ----

/// Writes the independent fleet `law` (seed 1) into `dir/indep/` as fog-runs files with
/// `type_id` metadata.
fn write_independent(dir: &Path, law: FleetLaw, units: usize, runs_per_ambient: usize) {
    let f = fleet(law, units, &AMBIENTS_C, runs_per_ambient, MINUTES, 1);
    std::fs::create_dir_all(dir.join("indep")).unwrap();
    for mut run in f.runs {
        run.meta.push(("type_id".into(), "independent".into()));
        write_run(dir.join("indep").join(run.name()), &run).unwrap();
    }
}

/// The runs of unit `u` of the independent fleet in `dir/indep`.
fn indep_files(dir: &Path, units: &[usize]) -> Vec<String> {
    units
        .iter()
        .flat_map(|u| files(dir, "indep", &format!("fleet1_u{u:03}_")))
        .collect()
}

/// Learns `type.json` from `type_runs` (units 1-5 of the odd fleet in `dir`; dT/dt in the
/// clock their runs choose, the default): none of its units is outside the type its other
/// units make; and a type from units 2-6, which names the odd U6 so before its runs shape
/// a type.
fn learn_types_with_and_without_the_odd_unit(dir: &Path, type_runs: &[String]) {
    let learnt = fogsim_ok(
        dir,
        &train_args(
            type_runs,
            &["--type-out", "type.json", "--out", "shared.model"],
        ),
    );
    // its own units, each tested as a new unit against the type the others make: none out
    assert!(
        learnt.contains("against the type their other units make: none of 5 outside"),
        "{learnt}"
    );
    // with the odd unit among them, it is named before its runs shape a type
    let with_odd = fogsim_ok(
        dir,
        &train_args(
            &indep_files(dir, &[2, 3, 4, 5, UNITS]),
            &["--type-out", "type-odd.json", "--out", "shared-odd.model"],
        ),
    );
    for l in learnt.lines().chain(with_odd.lines()) {
        if l.starts_with("type units") || l.starts_with("shape:") {
            println!("{l}");
        }
    }
    assert!(
        with_odd
            .lines()
            .any(|l| l
                .starts_with("type units outside the type their other units make: 1 of 5: U6 (")),
        "{with_odd}"
    );
}

#[test]
fn the_cli_refuses_an_odd_unit_by_default_and_trains_it_alone_with_misfit_own() {
    let t0 = Instant::now();
    let dir = app_support::scratch_dir("type-odd");
    write_independent(&dir, FleetLaw::OddUnit, UNITS, RUNS_PER_AMBIENT);
    let type_runs = indep_files(&dir, &[1, 2, 3, 4, 5]);
    let odd_runs = indep_files(&dir, &[UNITS]);
    learn_types_with_and_without_the_odd_unit(&dir, &type_runs);
    // With the type's network reading dT/dt in the diffusion clock its runs choose, the
    // unit terms warm-up gain and Shupe coefficient are nearly collinear on these 4 runs;
    // the misfit test holds the unresolved terms at the type's mean and finds the warm-up
    // gain 15.0 sigma out (critical 4.2); all at once it had no power (Shupe coefficient
    // -0.042 against 0.049 +- 0.018, z 4.5, critical 5.8).
    let unit = |extra: &[&str]| {
        let mut a = vec!["--out", "u6.model"];
        a.extend_from_slice(extra);
        unit_runs_cmd(&dir, &odd_runs, &a)
    };
    let refused = unit(&[]);
    let out = String::from_utf8_lossy(&refused.stdout);
    let err = app_support::stderr(&refused);
    assert!(!refused.status.success(), "{out}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(
        err.contains("unit U6: outside its type independent") && err.contains("nothing written"),
        "{err}"
    );
    assert!(
        out.lines()
            .any(|l| l.starts_with("unit U6: ") && l.contains(" sigma outside the type")),
        "{out}"
    );
    assert!(!dir.join("u6.model").exists());

    let own = unit(&["--misfit", "own"]);
    let out = String::from_utf8_lossy(&own.stdout);
    assert!(own.status.success(), "{}", app_support::stderr(&own));
    assert!(
        out.contains("unit U6: outside its type: trained on its own runs alone"),
        "{out}"
    );
    read_model(&dir.join("u6.model")).unwrap();

    // Fewer runs than the ordinary training's folds: refused before anything is trained,
    // said in one line, recorded as such. (Its four runs at two ambients are the fewest in
    // which the misfit test sees this unit: with two or three it says it has no test power,
    // as the clocks' stretches are nearly collinear with their amplitudes within a run.)
    let few = unit_runs_cmd(
        &dir,
        &odd_runs,
        &["--misfit", "own", "--folds", "5", "--out", "u6b.model"],
    );
    let err = app_support::stderr(&few);
    assert!(
        !few.status.success(),
        "{}",
        String::from_utf8_lossy(&few.stdout)
    );
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(
        err.contains("4 run(s) are too few to train it on its own")
            && err.contains("nothing written"),
        "{err}"
    );
    assert!(!dir.join("u6b.model").exists());

    let records = Registry::open(&dir.join("reg.sqlite"))
        .unwrap()
        .unit_calibrations("U6")
        .unwrap();
    let outcomes: Vec<&str> = records.iter().map(|c| c.outcome.as_str()).collect();
    assert_eq!(
        outcomes,
        [
            "refused (misfit)",
            "own model (misfit)",
            "refused (misfit, too few runs of its own)"
        ]
    );
    // the own model's record carries the CRC of the model written
    let written = std::fs::read(dir.join("u6.model")).unwrap();
    assert_eq!(
        records[1].model_crc32,
        Some(fog_core::model::crc::crc32(&written))
    );
    assert_eq!(
        (records[0].model_crc32, records[2].model_crc32),
        (None, None)
    );
    println!("{:.1} s", t0.elapsed().as_secs_f64());
    std::fs::remove_dir_all(dir).unwrap();
}

/// `train --type` compares the unit's own model with its calibration: a unit of the
/// independent fleet whose units differ in what the type's terms cannot carry, with 48 of
/// its cold starts (16 at each of -40, 20, +60 degC), leaves its type (seek_independent's
/// library figures: t 4.7-6.7 over seeds 1-3) and is trained on its own runs, recorded as
/// such; the same unit with its 6 fleet runs keeps the calibration. The type reads dT/dt
/// as the slope (`--warmup-clock slope`): in the clock its runs choose (the default) it
/// carries this unit, and 48 runs stay with it (0.0099 against 0.0099 deg/h, t = -0.8).
#[test]
fn the_cli_trains_a_unit_on_its_own_when_its_runs_say_more_than_its_type() {
    use crate::common::fleet_independent::extra_cold_starts;
    use rand::SeedableRng;
    const AMBIENTS: [f64; 3] = [-40.0, 20.0, 60.0];
    let dir = app_support::scratch_dir("type-own");
    std::fs::create_dir_all(dir.join("indep")).unwrap();
    let f = fleet(FleetLaw::Type, 11, &AMBIENTS, 2, 45, 1);
    let truth = f.units[10];
    let mut runs = f.runs;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0x0417_0001);
    runs.extend(extra_cold_starts(
        &truth,
        "U11",
        &AMBIENTS,
        6..48,
        45,
        "fleet1_u011_extra_",
        &mut rng,
    ));
    for mut run in runs {
        run.meta.push(("type_id".into(), "independent".into()));
        write_run(dir.join("indep").join(run.name()), &run).unwrap();
    }
    let type_runs = indep_files(&dir, &(1..=10).collect::<Vec<_>>());
    let unit48 = indep_files(&dir, &[11]);
    assert_eq!(unit48.len(), 48);
    let six: Vec<String> = unit48
        .iter()
        .filter(|f| !f.contains("extra"))
        .cloned()
        .collect();
    assert_eq!(six.len(), 6);
    let tm = ["--seek-sequence", "thue-morse"];
    let mut a = vec![
        "--type-out",
        "type.json",
        "--out",
        "shared.model",
        "--warmup-clock",
        "slope",
    ];
    a.extend(tm);
    fogsim_ok(&dir, &train_args(&type_runs, &a));
    let unit = |runs: &[String], out: &str| {
        let mut a = vec!["--out", out, "--gyro-id", "U11"];
        a.extend(tm);
        let o = unit_runs_cmd(&dir, runs, &a);
        assert!(o.status.success(), "{}", app_support::stderr(&o));
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    let many = unit(&unit48, "u11_48.model");
    assert!(
        many.contains("its own runs say more than its type: the unit's own model")
            && many.contains("unit U11: trained on its own runs alone"),
        "{many}"
    );
    let few = unit(&six, "u11_6.model");
    assert!(
        few.contains("over 6 runs (6 folds)")
            && few.contains("the unit calibration\n")
            && few.contains("wrote unit U11's model"),
        "{few}"
    );
    let outcomes: Vec<String> = Registry::open(&dir.join("reg.sqlite"))
        .unwrap()
        .unit_calibrations("U11")
        .unwrap()
        .into_iter()
        .map(|c| c.outcome)
        .collect();
    assert_eq!(
        outcomes,
        ["own model (its runs say more than its type)", "calibrated"]
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// `fogsim train RUNS --type type.json --registry reg.sqlite EXTRA` in `dir`.
fn unit_runs_cmd<'a>(dir: &Path, runs: &'a [String], extra: &[&'a str]) -> std::process::Output {
    let mut a = vec!["--type", "type.json"];
    a.extend_from_slice(extra);
    a.extend(["--registry", "reg.sqlite"]);
    fogsim(dir, &train_args(runs, &a))
}

/// Copies `runs` (relative to `dir`) into `dir/sub/` with their `# type_id:` line set to
/// `type_id`.
fn with_type_id(dir: &Path, runs: &[String], sub: &str, type_id: &str) {
    std::fs::create_dir_all(dir.join(sub)).unwrap();
    let (from, to) = (
        "\n# type_id: independent\n",
        format!("\n# type_id: {type_id}\n"),
    );
    for r in runs {
        let text = std::fs::read_to_string(dir.join(r)).unwrap();
        assert!(text.contains(from), "{r}");
        let name = Path::new(r).file_name().unwrap();
        std::fs::write(dir.join(sub).join(name), text.replace(from, &to)).unwrap();
    }
}

/// The bad-input fleet in `dir/indep/`: 5 independent units of 2 runs (one per ambient), of
/// type `independent`; copies of U3's and U4's runs of type `other_design` in `dir/other/`.
fn bad_input_fleet(dir: &Path) {
    write_independent(dir, FleetLaw::Type, 5, 1);
    with_type_id(dir, &indep_files(dir, &[3, 4]), "other", "other_design");
}

/// The runs a bad-input case names: `U1+U2` (units), `U3'` (U3 of `other_design`), `U4[0]`
/// (U4's first run), joined by `+`.
fn case_runs(dir: &Path, key: &str) -> Vec<String> {
    key.split('+')
        .flat_map(|k| match k {
            "U3'" | "U4'" => {
                let u = &k[1..2];
                files(dir, "other", &format!("fleet1_u00{u}_"))
            }
            "U4[0]" => indep_files(dir, &[4])[..1].to_vec(),
            _ => indep_files(dir, &[k[1..].parse().unwrap()]),
        })
        .collect()
}

/// Runs every `(runs, options, what the line must say)` of `cases` as `fogsim train`
/// (`TERMS+1`: one more than the type's unit terms), each refused by `check_refused`.
fn refuse_all(dir: &Path, cases: &[(&str, &str, &str)], terms: usize) {
    for (runs, options, needle) in cases {
        let runs = case_runs(dir, runs);
        let options = options.replace("TERMS+1", &(terms + 1).to_string());
        let options: Vec<&str> = options.split_whitespace().collect();
        let needle = needle.replace("TERMS+1", &(terms + 1).to_string());
        let needle = needle.replace("TERMS", &terms.to_string());
        check_refused(dir, &train_args(&runs, &options), &needle);
    }
}

#[test]
fn bad_type_learning_inputs_fail_with_one_line_and_write_nothing() {
    let t0 = Instant::now();
    let dir = app_support::scratch_dir("type-bad-learn");
    bad_input_fleet(&dir);
    let learn = "--type-out out.type.json --out out.model";
    let cases = [
        (
            "U1+U2+U3'",
            learn,
            "runs of 2 types mixed: independent (4 runs), other_design (2 runs)",
        ),
        (
            "U1+U2",
            learn,
            "2 unit(s): a type's unit-to-unit spread needs at least 3 units",
        ),
        (
            "U1+U2+U3",
            "--type-out out.type.json --out out.model --type type.json",
            "--type",
        ),
        (
            "U1+U2+U3",
            "--type-out out.type.json --out out.model --max-centers 5 --rho 0.01",
            "--max-centers, --rho: a network's shape options; --type-shape law and auto",
        ),
        (
            "U4",
            "--out out.model --misfit own",
            "--misfit: needs --type TYPE",
        ),
        (
            "U4",
            "--out out.model --unit-terms 1",
            "--unit-terms: needs --type TYPE",
        ),
        (
            "U4",
            "--out out.model --unit-prior-weight 1",
            "--unit-prior-weight: needs --type TYPE",
        ),
        (
            "U4",
            "--out out.model --registry out.sqlite",
            "--registry: needs --field, --type-out or --type",
        ),
    ];
    refuse_all(&dir, &cases, 0);
    println!(
        "{} bad invocations: {:.1} s",
        cases.len(),
        t0.elapsed().as_secs_f64()
    );
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn bad_unit_calibration_inputs_fail_with_one_line_and_write_nothing() {
    let t0 = Instant::now();
    let dir = app_support::scratch_dir("type-bad-unit");
    bad_input_fleet(&dir);
    let type_runs = indep_files(&dir, &[1, 2, 3]);
    let learn = ["--type-out", "type.json", "--out", "shared.model"];
    fogsim_ok(&dir, &train_args(&type_runs, &learn));
    // a truncated type file, and one whose model is not hex
    let type_text = std::fs::read_to_string(dir.join("type.json")).unwrap();
    let half = &type_text[..type_text.len() / 2];
    std::fs::write(dir.join("truncated.json"), half).unwrap();
    let mut file: serde_json::Value = serde_json::from_str(&type_text).unwrap();
    let hex = file["model_hex"].as_str().unwrap().to_string();
    file["model_hex"] = format!("zz{}", &hex[2..]).into();
    std::fs::write(dir.join("not-hex.json"), file.to_string()).unwrap();
    let terms = file["terms"].as_array().unwrap().len();
    let cal = "--type type.json --out out.model";
    let cases = [
        (
            "U4[0]",
            cal,
            "1 run file(s): a unit calibration holds out one run at a time",
        ),
        ("U1", cal, "unit U1 is one the type was learnt from"),
        (
            "U4",
            "--type type.json --out out.model --unit-terms 3",
            "unit U4: 2 runs for 3 unit terms (--unit-terms)",
        ),
        (
            "U4",
            "--type type.json --out out.model --unit-terms TERMS+1",
            "--unit-terms TERMS+1: the type has TERMS unit terms",
        ),
        (
            "U4",
            "--type type.json --out out.model --unit-prior-weight -1",
            "--unit-prior-weight -1: a weight in runs, finite and >= 0",
        ),
        (
            "U4'",
            cal,
            "a unit of type `other_design`, the type model is `independent`",
        ),
        (
            "U4+U5",
            cal,
            "runs of 2 units (U4, U5): a unit calibration is one unit's",
        ),
        (
            "U4",
            "--type truncated.json --out out.model",
            "truncated.json: not a type file",
        ),
        (
            "U4",
            "--type not-hex.json --out out.model",
            "not-hex.json: its model is not hex",
        ),
        (
            "U4",
            "--type shared.model --out out.model",
            "shared.model: not a type file",
        ),
    ];
    refuse_all(&dir, &cases, terms);
    let seek_refusals = north_seek_recipe_refusals(&dir);
    // the faults, not the rest, made them fail: U4 is calibrated without them
    let u4 = indep_files(&dir, &[4]);
    let good: Vec<&str> = cal.split_whitespace().collect();
    fogsim_ok(&dir, &train_args(&u4, &good));
    assert!(dir.join("out.model").exists());
    println!(
        "{} bad invocations: {:.1} s",
        cases.len() + seek_refusals,
        t0.elapsed().as_secs_f64()
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// `north-seek`'s unit recipe refused in `dir` (which holds `type.json` and
/// `shared.model`): a type file as a model, a recipe option without the recipe, too few runs
/// for the type-free recipe, a warm-up clock without a type. Returns how many were tried.
fn north_seek_recipe_refusals(dir: &Path) -> usize {
    let seek = ["--starts", "1", "--seeks", "1", "--json", "out.json"];
    // a type file where a model is expected
    check_refused(
        dir,
        &[&["north-seek", "--model", "type.json"], &seek[..]].concat(),
        "--model type.json: more than 2048 bytes, a model is at most 2048 bytes",
    );
    // a unit recipe's option without the recipe, named (not only the missing flag)
    check_refused(
        dir,
        &[
            &["north-seek", "--model", "shared.model", "--unit-runs", "3"],
            &seek[..],
        ]
        .concat(),
        "--unit-runs: needs --type-units",
    );
    // the type-free recipe trains the unit's runs as any model: too few for its folds
    check_refused(
        dir,
        &[
            &["north-seek", "--type-units", "0", "--unit-runs", "2"],
            &seek[..],
        ]
        .concat(),
        "--unit-runs 2: --type-units 0 trains the unit on its own runs alone",
    );
    // the clock is a trained model's: a model given is not trained
    check_refused(
        dir,
        &[
            &[
                "north-seek",
                "--model",
                "shared.model",
                "--warmup-clock",
                "auto",
            ],
            &seek[..],
        ]
        .concat(),
        "--warmup-clock is for the model north-seek trains; --model shared.model is given",
    );
    4
}

/// `fogsim ARGS` in `dir` must fail with one line on stderr containing `needle`, and leave
/// no `out.*` behind.
fn check_refused(dir: &Path, args: &[&str], needle: &str) {
    let o = fogsim(dir, args);
    let err = app_support::stderr(&o);
    assert!(!o.status.success(), "{args:?} accepted");
    assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
    assert!(err.contains(needle), "{args:?}: `{err}` lacks `{needle}`");
    let left: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.file_name().unwrap().to_string_lossy().starts_with("out."))
        .collect();
    assert!(left.is_empty(), "{args:?} left {left:?}");
}

/// The misfit test's false alarms on normal units (the independent `Type` fleet, every unit
/// in turn against the type of the others, `MISFIT_SEEDS` seeds, 18 by default: 108 units)
/// stay within the family-wise level: at most the 99 % binomial quantile of 1 % of them
/// (4 of 108). Measured: 5 of 108 (largest |z| / critical 1.56) when the z ignored the type
/// mean's own error, 4 of 108 (1.34) with it: at the bound, not inside it with a margin.
/// What is left is likely the unit's jackknife standard error from 6 runs (not measured).
/// With the units read within runs (the default since 2026-12-03): 4 of 108 (1.73), other
/// units than before. With the unresolved terms held at the type's mean and each fitted
/// term tested against the same combination of the type's units (2026-12-06): 2 of 108
/// (seed 3 U6 1.14, seed 11 U3 1.32).
#[test]
#[ignore = "slow suite: 108 unit calibrations (cargo test -- --include-ignored)"]
fn qualification_normal_units_are_flagged_at_the_misfit_tests_level() {
    let seeds: u64 = std::env::var("MISFIT_SEEDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(18);
    let mut flagged = Vec::new();
    let mut tested = 0usize;
    for seed in 1..=seeds {
        for unit in 1..=UNITS {
            let (_, cal) = calibrated(FleetLaw::Type, seed, unit);
            tested += 1;
            let r = worst_ratio(&cal);
            if cal.misfit.outside() {
                flagged.push(format!("seed {seed} U{unit}: {r:.2}"));
            }
        }
    }
    let allowed = crate::common::level::binomial_upper(
        tested,
        fog_sim::train::type_unit::misfit::FAMILY_ALPHA,
        0.99,
    );
    println!(
        "{} of {tested} normal units flagged (allowed {allowed}): {flagged:?}",
        flagged.len()
    );
    assert!(
        flagged.len() <= allowed,
        "{} of {tested} flagged (allowed {allowed}): {flagged:?}",
        flagged.len()
    );
}

// ---- self-check on the simulator's own fleet ----

/// `fogsim campaign` of 11 units with `spread` (a spread file's text, or `none`), 2 cold
/// starts at each of -40, 20 and +60 degC, seed 3, then `fogsim train --type-out` on units
/// 1-10; the type's terms (name, raw spread) and the drawn parameter `key` of those units.
fn cli_type_of_simulated_fleet(
    tag: &str,
    spread: &str,
    key: &str,
) -> (Vec<(String, f64)>, Vec<f64>) {
    use fog_sim::sim::TypeSpread;
    let dir = app_support::scratch_dir(&format!("selfcheck_{tag}"));
    let spread_arg = if spread == "none" {
        "none".to_string()
    } else {
        let f = dir.join("spread.txt");
        std::fs::write(&f, spread).unwrap();
        f.display().to_string()
    };
    let fleet_dir = dir.join("fleet");
    let fd = fleet_dir.to_str().unwrap();
    let o = app_support::fogsim(
        &dir,
        &[
            "campaign",
            "--out",
            fd,
            "--units",
            "11",
            "--ambient-c",
            "-40,20,60",
            "--runs",
            "2",
            "--seed",
            "3",
            "--unit-spread",
            &spread_arg,
        ],
    );
    assert!(o.status.success(), "{}", app_support::stderr(&o));
    let mut files: Vec<String> = std::fs::read_dir(&fleet_dir)
        .unwrap()
        .map(|e| e.unwrap().path().display().to_string())
        .filter(|p| !p.contains("/u011_"))
        .collect();
    files.sort();
    let ty = dir.join("type.json");
    let mut args = vec!["train".to_string()];
    args.extend(files);
    args.extend([
        "--type-out".into(),
        ty.display().to_string(),
        // the network shape, whose unit terms name the Shupe and temperature coefficients
        // the check reads (the law shape's are clock amplitudes)
        "--type-shape".into(),
        "network".into(),
        // the runs as measured: a unit's temperature coefficient shows between runs
        "--unit-fit".into(),
        "pooled".into(),
        "--out".into(),
        dir.join("type.fogm").display().to_string(),
    ]);
    let o = app_support::fogsim(&dir, &args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(o.status.success(), "{}", app_support::stderr(&o));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&ty).unwrap()).unwrap();
    let terms = json["terms"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| {
            (
                t["name"].as_str().unwrap().to_string(),
                t["raw_spread"].as_f64().unwrap(),
            )
        })
        .collect();
    let spread = if spread == "none" {
        TypeSpread::none()
    } else {
        TypeSpread::parse(spread).unwrap()
    };
    let fleet = fog_sim::pipeline::fleet::FleetType::paper(spread, "paper_default", 1);
    let drawn = (0..10)
        .map(|u| {
            let mut p = fleet.unit(u).unwrap();
            let e = fog_sim::sim::unit_spread::SPREAD_ENTRIES
                .iter()
                .find(|e| e.key == key)
                .unwrap();
            *(e.field)(&mut p)
        })
        .collect();
    (terms, drawn)
}

fn spread_of(terms: &[(String, f64)], name: &str) -> f64 {
    terms
        .iter()
        .find(|(n, _)| n == name)
        .map(|(_, s)| *s)
        .expect(name)
}

/// Self-check: a type learnt (as a user learns it, `fogsim train --type-out`) from the
/// simulator's own fleet whose units differ only in their Shupe coefficient (10 %) reads
/// that spread in its Shupe term, against the drawn coefficients of the same 10 units; its
/// twin whose units differ only in the bias temperature coefficient reads that one in its
/// temperature coefficient and not in the Shupe term; its null twin reads neither.
/// Measured (one fleet, seed 3; type spread / the drawn units' spread): the Shupe fleet's
/// Shupe term 0.92 (1.08 against 1.17 deg/h per degC/s), the tempco fleet's temperature
/// coefficient 1.00 and its Shupe term 0.22, the null twin's Shupe term 0.28 (the floor its
/// 10 units' estimation noise allows) and temperature coefficient 0.02. The bounds (0.6-1.5x,
/// below 0.5x) are that noise's: the spread is the units' scatter less their noise, with 10
/// units about +-35 %. With the default spread every parameter varies and the Shupe term
/// reads 4.9x the Shupe coefficient's own spread: it is an effective term that takes up the
/// thermal and sensor-lag differences too.
#[test]
fn the_type_reads_the_simulators_own_unit_spread() {
    let (shupe, drawn_k) = cli_type_of_simulated_fleet(
        "shupe",
        "drift.shupe_dph_per_cps: 10%\n",
        "drift.shupe_dph_per_cps",
    );
    let (tempco, drawn_c) = cli_type_of_simulated_fleet(
        "tempco",
        "drift.bias_dph_per_c: 0.001\n",
        "drift.bias_dph_per_c",
    );
    let (none, _) = cli_type_of_simulated_fleet("none", "none", "drift.shupe_dph_per_cps");
    let (sd_k, sd_c) = (
        crate::common::fleet_judge::std_dev(&drawn_k),
        crate::common::fleet_judge::std_dev(&drawn_c),
    );
    let ratios = [
        spread_of(&shupe, "Shupe coefficient") / sd_k,
        spread_of(&tempco, "temperature coefficient") / sd_c,
        spread_of(&tempco, "Shupe coefficient") / sd_k,
        spread_of(&none, "Shupe coefficient") / sd_k,
        spread_of(&none, "temperature coefficient") / sd_c,
    ];
    println!(
        "type spread / drawn spread: Shupe fleet's Shupe {:.2}; tempco fleet's tempco {:.2}, its Shupe {:.2}; null fleet's Shupe {:.2}, tempco {:.2}",
        ratios[0], ratios[1], ratios[2], ratios[3], ratios[4]
    );
    for (what, r) in [
        ("Shupe fleet's Shupe", ratios[0]),
        ("tempco fleet's tempco", ratios[1]),
    ] {
        assert!(
            (0.6..=1.5).contains(&r),
            "{what}: type spread {r:.2} x the drawn units'"
        );
    }
    for (what, r) in [
        ("tempco fleet's Shupe", ratios[2]),
        ("null fleet's Shupe", ratios[3]),
        ("null fleet's tempco", ratios[4]),
    ] {
        assert!(
            r < 0.5,
            "{what}: type spread {r:.2} x the drawn Shupe / tempco spread"
        );
    }
}

/// By default (`--warmup-clock auto`) a type whose runs warm up by diffusion (the
/// independent fleet) reads the network's dT/dt in that clock, says so, and writes model
/// format 7; the unit calibrated against it is an ordinary model of the same inputs. With
/// `--warmup-clock slope` the slope stays (format 6, no such line). The type-free `train`
/// of one unit's runs chooses alike; beside `--type` the flag is refused in one line,
/// nothing written.
#[test]
fn the_cli_reads_dt_dt_in_the_clock_a_type_chooses() {
    let dir = app_support::scratch_dir("type-clock");
    write_independent(&dir, FleetLaw::Type, 5, 1);
    let type_runs = indep_files(&dir, &[1, 2, 3, 4]);
    let shape = ["--type-shape", "network"];
    let auto = fogsim_ok(
        &dir,
        &train_args(
            &type_runs,
            &[
                &shape[..],
                &["--type-out", "type.json", "--out", "shared.model"],
            ]
            .concat(),
        ),
    );
    let said: Vec<&str> = auto
        .lines()
        .filter(|l| l.starts_with("dT/dt read as"))
        .collect();
    assert_eq!(said.len(), 1, "{auto}");
    assert!(
        said[0].starts_with("dT/dt read as the diffusion clock ("),
        "{}",
        said[0]
    );
    let bytes = std::fs::read(dir.join("shared.model")).unwrap();
    assert_eq!(bytes[5], 7, "format version byte: {:?}", &bytes[..8]);
    let m = read_model(&dir.join("shared.model")).unwrap();
    assert!(m
        .inputs
        .iter()
        .any(|s| s.kind == fog_core::model::format::FeatureKind::TempRateDiffusionCps));
    // the unit step against it: an ordinary model with the type's inputs
    let unit = unit_runs_cmd(&dir, &indep_files(&dir, &[5]), &["--out", "u5.model"]);
    assert!(unit.status.success(), "{}", app_support::stderr(&unit));
    assert_eq!(read_model(&dir.join("u5.model")).unwrap().inputs, m.inputs);

    let slope = fogsim_ok(
        &dir,
        &train_args(
            &type_runs,
            &[
                &shape[..],
                &[
                    "--type-out",
                    "type-s.json",
                    "--out",
                    "shared-s.model",
                    "--warmup-clock",
                    "slope",
                ],
            ]
            .concat(),
        ),
    );
    assert!(!slope.contains("dT/dt read as"), "{slope}");
    assert_eq!(std::fs::read(dir.join("shared-s.model")).unwrap()[5], 6);

    // the type-free `train` chooses the same way: two units' runs read in the diffusion
    // clock by default, the slope kept with `--warmup-clock slope`
    let unit5 = indep_files(&dir, &[5]);
    let two = indep_files(&dir, &[4, 5]);
    let alone = fogsim_ok(&dir, &train_args(&two, &["--out", "alone.model"]));
    assert!(
        alone
            .lines()
            .any(|l| l.starts_with("dT/dt read as the diffusion clock (")),
        "{alone}"
    );
    let m = read_model(&dir.join("alone.model")).unwrap();
    assert!(m
        .inputs
        .iter()
        .any(|s| s.kind == fog_core::model::format::FeatureKind::TempRateDiffusionCps));
    let alone_s = fogsim_ok(
        &dir,
        &train_args(&two, &["--out", "alone-s.model", "--warmup-clock", "slope"]),
    );
    assert!(!alone_s.contains("dT/dt read as"), "{alone_s}");
    assert_eq!(std::fs::read(dir.join("alone-s.model")).unwrap()[5], 6);

    // a unit calibration reads its type's clock: the flag beside --type is refused
    let refused = unit_runs_cmd(
        &dir,
        &unit5,
        &["--out", "u5-s.model", "--warmup-clock", "slope"],
    );
    let err = app_support::stderr(&refused);
    assert!(!refused.status.success());
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(
        err.contains(
            "--warmup-clock: a unit calibrated with --type reads dT/dt in its type's clock"
        ),
        "{err}"
    );
    assert!(!dir.join("u5-s.model").exists());
}
