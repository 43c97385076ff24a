//! The seek sequences and the type + unit recipe on the independent fleet
//! (`common::fleet_independent`: a stretched-exponential warm-up, a drift in T and the
//! true dT/dt, a uniform unit-to-unit law; nothing shared with the simulator), judged by
//! issue 37's targets on held-out cold starts of a unit the type never saw.
//!
//! The type is learnt from 10 units of 6 cold starts (2 at each of -40, 20, +60 degC;
//! `INDEP_TYPE_UNIT_RUNS` for more, `INDEP_TYPE_UNITS` for more or fewer units) as
//! `train --type-out` learns it (`INDEP_SHAPES`: `law`, `network`, `auto`, the default,
//! which chooses by the first seeks of the type's units left out; default `law,auto`),
//! scored with the sequence's seek geometry; the 11th unit is calibrated
//! from its own 6 (`calibrate_unit`: its terms and prior chosen by leave-one-run-out in the
//! sequence's seek windows; `INDEP_UNIT_RUNS` for more); the type-free recipe is `fogsim
//! train`'s default trainer on those runs alone. Each held-out cold start of the 11th unit
//! (its own physics, fresh noise and turn-on offset) is read as each seek reads its drift:
//! the residual (drift less the model) averaged over the device's own position spans
//! (`pipeline::north_seek::schedule`: the simulator's turntable and firmware timing at the
//! sequence's default dwell), the opposite positions differenced, turned into azimuth
//! error at the site latitude. The floor is the generator's white noise through the same
//! rows. Per ambient and seek: the rms over the floor and |mean| / std over the held-out
//! starts, `north-seek`'s targets.
//!
//! Twins (`FleetLaw`): identical units (null), an odd unit (a Shupe term of the other sign:
//! refused by the misfit test, not scored), and single-effect fleets whose units differ
//! only in the Shupe coefficient or only in the thermal time constant and rise.
//!
//! The CI size (`INDEP_SEEK_STARTS` unset, `at_ci_size`: 200 held-out starts per ambient,
//! seed 1, the type fleet and its null twin, the Thue-Morse seek alone, the law type on
//! the null twin only as `auto` keeps it) guards the judge (white noise at its floor) and
//! the recipe where the type carries the unit; the measurement over seeds and twins is run with
//! `INDEP_SEEK_STARTS=1000 INDEP_SEEK_SEEDS=1,2,3,4,5 INDEP_SEEK_FLEETS=type,identical,shupe,thermal`
//! (docs/record/fleet.md, "The type and unit recipe on the independent fleet").

use crate::common::fleet_independent::{
    cold_start, cold_start_rows, extra_cold_starts, fleet, FleetLaw, UnitTruth, NOISE_10S_DPH,
};
use crate::common::seek_judge::residual_dph;

use fog_core::model::format::RbfModel;
use fog_core::seeking::northfinder::SeekMode;
use fog_sim::io::runs::Run;
use fog_sim::pipeline::north_seek::schedule::seek_schedule;
use fog_sim::pipeline::north_seek::{default_dwell_s, scored_as_symmetric, MonteCarloConfig};
use fog_sim::sim::GyroParams;
use fog_sim::train::seek_refit::SeekSchedule;
use fog_sim::train::seek_score::{Criterion, SeekGeometry};
use fog_sim::train::type_unit::terms::Fit;
use fog_sim::train::type_unit::{
    calibrate_unit, choose_own, ordinary_model, resolve_shape, OwnChoice, ShapeChoice,
    ShapeScoring, SharedShape, TypeModel, TypeShape, UnitPlan,
};
use fog_sim::train::warmup_clock::RateClock;
use fog_sim::train::{feature_name, InputChoice, InputSet, TrainConfig};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::time::Instant;

const TYPE_UNITS: usize = 10;
const AMBIENTS_C: [f64; 3] = [-40.0, 20.0, 60.0];
const MINUTES: usize = 45;
const SEEKS: usize = 6;
const SEQUENCES: [SeekMode; 3] = [
    SeekMode::TwoPosition,
    SeekMode::TwoPositionSymmetric,
    SeekMode::TwoPositionThueMorse,
];

/// True at the CI size (`INDEP_SEEK_STARTS` unset); a measurement sets it, and every
/// command docs/record/fleet.md records does.
fn at_ci_size() -> bool {
    std::env::var("INDEP_SEEK_STARTS").is_err()
}

/// The seek sequences measured: all three in a measurement; at the CI size the Thue-Morse
/// seek alone, the one every assertion of the recipe test reads (the type is learnt, and
/// its shape chosen, once per sequence: most of its time).
fn sequences() -> &'static [SeekMode] {
    if at_ci_size() {
        &SEQUENCES[2..]
    } else {
        &SEQUENCES
    }
}

/// Held-out cold starts per ambient.
fn heldout_starts() -> usize {
    std::env::var("INDEP_SEEK_STARTS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(200)
}

fn sequence_name(mode: SeekMode) -> &'static str {
    match mode {
        SeekMode::TwoPosition => "forward",
        SeekMode::TwoPositionSymmetric => "time-symmetric",
        SeekMode::TwoPositionThueMorse => "Thue-Morse",
        _ => "other",
    }
}

/// The device's seeks of `mode` at its default dwell: their position spans.
fn schedule(mode: SeekMode) -> SeekSchedule {
    let cfg = MonteCarloConfig {
        mode,
        dwell_s: default_dwell_s(mode),
        starts: 1,
        threads: 1,
        ..MonteCarloConfig::paper(1)
    };
    seek_schedule(&GyroParams::paper_default(), &cfg, None).unwrap()
}

/// Each seek's weights on a run's rows (10 s means ending at `t_s`): +1/(pairs x rows)
/// on the first position's rows, -1/(pairs x rows) on the second's, so that the weighted
/// sum of the residual is the seek's drift difference, deg/h.
fn seek_weights(sched: &SeekSchedule, t_s: &[f64]) -> Vec<Vec<(usize, f64)>> {
    sched
        .seeks
        .iter()
        .take(SEEKS)
        .map(|pairs| {
            let mut w = vec![0.0; t_s.len()];
            let rows = |(a, b): (f64, f64)| -> Vec<usize> {
                (0..t_s.len())
                    .filter(|&i| t_s[i] - 5.0 >= a && t_s[i] - 5.0 < b)
                    .collect()
            };
            let p = pairs.len() as f64;
            for pair in pairs {
                for (span, sign) in [(pair.first_s, 1.0), (pair.second_s, -1.0)] {
                    let r = rows(span);
                    assert!(!r.is_empty(), "a position span holds no row: {span:?}");
                    for &i in &r {
                        w[i] += sign / (p * r.len() as f64);
                    }
                }
            }
            w.into_iter()
                .enumerate()
                .filter(|&(_, v)| v != 0.0)
                .collect()
        })
        .collect()
}

/// Each seek's azimuth error, deg, of the residual `res` (deg/h, rows ending at `t_s`),
/// and each seek's white-noise floor (the generator's 10 s noise through the same rows).
fn seek_errors_deg(
    sched: &SeekSchedule,
    t_s: &[f64],
    res: &[f64],
    geometry: SeekGeometry,
) -> (Vec<f64>, Vec<f64>) {
    seek_weights(sched, t_s)
        .iter()
        .map(|w| {
            let e: f64 = w.iter().map(|&(i, v)| v * res[i]).sum();
            let ss: f64 = w.iter().map(|(_, v)| v * v).sum();
            (
                geometry.azimuth_deg(e),
                geometry.azimuth_deg(NOISE_10S_DPH * ss.sqrt()),
            )
        })
        .unzip()
}

/// A recipe's model for one sequence, with how it reads the held-out starts.
struct Judged {
    recipe: &'static str,
    mode: SeekMode,
    model: RbfModel,
    sched: SeekSchedule,
    /// Azimuth errors, deg: [ambient][seek] over held-out starts.
    errors_deg: Vec<Vec<Vec<f64>>>,
    floor_deg: Vec<f64>,
}

impl Judged {
    fn new(recipe: &'static str, mode: SeekMode, model: RbfModel, sched: SeekSchedule) -> Self {
        Judged {
            recipe,
            mode,
            model,
            sched,
            errors_deg: vec![vec![Vec::new(); SEEKS]; AMBIENTS_C.len()],
            floor_deg: Vec::new(),
        }
    }

    fn read(&mut self, ambient: usize, run: &Run, geometry: SeekGeometry) {
        let (ds, res) = residual_dph(&self.model, std::slice::from_ref(run), &self.model.inputs);
        let (errors, floors) = seek_errors_deg(&self.sched, &ds.t_s, &res, geometry);
        if self.floor_deg.is_empty() {
            self.floor_deg = floors;
        }
        for (k, e) in errors.into_iter().enumerate() {
            self.errors_deg[ambient][k].push(e);
        }
    }

    /// Per ambient: all seeks' rms over the floor, the worst of seeks 1-3 over its floor,
    /// the worst |mean| / std over the six seeks (with its seek).
    fn figures(&self) -> Vec<(f64, f64, f64, usize)> {
        self.errors_deg
            .iter()
            .map(|seeks| {
                let mut all = (0.0, 0.0);
                let mut worst13: f64 = 0.0;
                let mut bias = (0.0, 0);
                for (k, e) in seeks.iter().enumerate() {
                    let n = e.len() as f64;
                    let mean = e.iter().sum::<f64>() / n;
                    let ms = e.iter().map(|x| x * x).sum::<f64>() / n;
                    let std = (ms - mean * mean).max(0.0).sqrt();
                    all.0 += ms;
                    all.1 += self.floor_deg[k].powi(2);
                    if k < 3 {
                        worst13 = worst13.max(ms.sqrt() / self.floor_deg[k]);
                    }
                    if mean.abs() / std > bias.0 {
                        bias = (mean.abs() / std, k + 1);
                    }
                }
                ((all.0 / all.1).sqrt(), worst13, bias.0, bias.1)
            })
            .collect()
    }
}

fn met((all, worst13, bias, _): (f64, f64, f64, usize)) -> bool {
    all <= 1.1 && worst13 <= 1.15 && bias <= 0.3
}

/// The type-free recipe: `fogsim train`'s default trainer on the unit's runs alone (T and
/// dT/dt, dT/dt in the clock the runs choose, `--warmup-clock auto`; `INDEP_ALONE_CLOCK`
/// as `INDEP_RATE_CLOCK`), scored with the sequence's seek geometry.
fn train_alone(runs: &[Run], criterion: Criterion) -> RbfModel {
    let cfg = TrainConfig {
        criterion,
        rate_clock: clock_from_env("INDEP_ALONE_CLOCK"),
        ..TrainConfig::default()
    };
    ordinary_model(runs, &[InputSet::TempRate], &cfg).unwrap()
}

/// The type of shape `shape` learnt from `runs` as `train --type-out` learns it (`train`'s
/// inputs and configuration for the network; `auto` chosen once on all the runs), the
/// shape it took, and the choice when one was made.
fn learn_independent_type(
    runs: &[Run],
    shape: TypeShape,
    criterion: Criterion,
    plan: UnitPlan,
    clock: RateClock,
) -> (TypeModel, SharedShape, Option<ShapeChoice>) {
    with_scoring(criterion, plan, clock, |scoring| {
        let (shared, choice) = resolve_shape(shape, runs, scoring).unwrap();
        let ty = scoring
            .learn_type(shared, runs, Some("independent"))
            .unwrap();
        (ty, shared, choice)
    })
}

/// `f` given the scoring `train --type-out` learns a type with (`train`'s inputs and
/// configuration for the network, `criterion`, the unit step's `plan`, the dT/dt `clock`).
fn with_scoring<R>(
    criterion: Criterion,
    plan: UnitPlan,
    clock: RateClock,
    f: impl FnOnce(&ShapeScoring) -> R,
) -> R {
    let cfg = TrainConfig {
        gyro_id: "independent".into(),
        criterion,
        rate_clock: clock,
        ..TrainConfig::default()
    };
    let candidates = InputChoice::Auto.candidates();
    f(&ShapeScoring {
        cfg: &cfg,
        candidates: &candidates,
        fit: Fit::default(),
        plan,
    })
}

/// How the type's network reads dT/dt (`INDEP_RATE_CLOCK=auto|slope`, default `train
/// --warmup-clock`'s).
fn rate_clock() -> RateClock {
    clock_from_env("INDEP_RATE_CLOCK")
}

/// The clock the variable `var` names (`auto|slope`; unset: `train --warmup-clock`'s default).
fn clock_from_env(var: &str) -> RateClock {
    match std::env::var(var).as_deref() {
        Ok("auto") => RateClock::Auto,
        Ok("slope") => RateClock::Slope,
        Err(_) => RateClock::default(),
        Ok(other) => panic!("{var}: unknown clock {other}"),
    }
}

/// Shapes measured (`INDEP_SHAPES`, default `law,auto`).
fn shapes() -> Vec<TypeShape> {
    std::env::var("INDEP_SHAPES")
        .unwrap_or_else(|_| "law,auto".into())
        .split(',')
        .map(|s| match s.trim() {
            "law" => TypeShape::Law,
            "network" => TypeShape::Network,
            "auto" => TypeShape::Auto,
            other => panic!("INDEP_SHAPES: unknown shape {other}"),
        })
        .collect()
}

/// What `measure` read: each recipe per sequence, whether the misfit test refused unit 11
/// (then only the type-free rows are read), and the shape each sequence's type took.
struct Measured {
    judged: Vec<Judged>,
    refused: bool,
    shapes: Vec<(SeekMode, SharedShape)>,
}

/// The seek criterion the type is learnt with for `mode` (its default dwell, the site).
fn criterion_of(mode: SeekMode) -> Criterion {
    let lat = fog_sim::sim::DEFAULT_LATITUDE_DEG;
    Criterion::parse("seek", default_dwell_s(mode) as f64, lat)
        .unwrap()
        .with_symmetric_seeks(scored_as_symmetric(mode))
}

/// The unit step's plan for `mode`'s seeks (their period on `sched`).
fn plan_of(sched: &SeekSchedule, mode: SeekMode) -> UnitPlan {
    UnitPlan {
        seek_period_s: sched.period_s,
        symmetric_seeks: scored_as_symmetric(mode),
        ..UnitPlan::chosen()
    }
}

/// The unit's own model against its calibration for the fleet `law` (seed `seed`, the
/// Thue-Morse seek, a type of shape `shape` whose network reads dT/dt as the slope), as
/// `train --type` compares them, for each count of the unit's runs in `unit_runs` (the
/// type's runs do not depend on it: the type is learnt once).
fn own_choices(
    law: FleetLaw,
    seed: u64,
    shape: SharedShape,
    unit_runs: &[usize],
) -> Vec<OwnChoice> {
    let mode = SeekMode::TwoPositionThueMorse;
    let criterion = criterion_of(mode);
    let plan = plan_of(&schedule(mode), mode);
    let mut ty = None;
    let mut choices = Vec::new();
    for &runs in unit_runs {
        let sp = split(law, seed, runs);
        let ty = ty.get_or_insert_with(|| {
            with_scoring(criterion, plan, RateClock::Slope, |scoring| {
                scoring
                    .learn_type(shape, &sp.type_runs, Some("independent"))
                    .unwrap()
            })
        });
        let cal = calibrate_unit(ty, &sp.own, &sp.unit_id, &plan).unwrap();
        let min_train = TrainConfig::default().folds;
        choices.push(
            choose_own(&cal, &sp.own, &plan, min_train, &mut |r| {
                Ok(train_alone(r, criterion))
            })
            .unwrap(),
        );
    }
    choices
}

/// The fleet `law`'s unit 11: its truth, id and `unit_runs` cold starts (2 per ambient
/// from the fleet, more spread evenly over the ambients), and units 1-10's runs (2 per
/// ambient from the fleet, more to `type_unit_runs`).
struct Split {
    truth: UnitTruth,
    unit_id: String,
    own: Vec<Run>,
    type_runs: Vec<Run>,
}

fn split(law: FleetLaw, seed: u64, unit_runs: usize) -> Split {
    // units past the 11th are drawn after it, so units 1-11 are the same whatever the count
    let n_type = type_units();
    assert!(
        n_type == TYPE_UNITS || law != FleetLaw::OddUnit,
        "INDEP_TYPE_UNITS: the odd twin's odd unit is its fleet's last, so only {TYPE_UNITS} type units"
    );
    let f = fleet(
        law,
        n_type.max(TYPE_UNITS) + 1,
        &AMBIENTS_C,
        2,
        MINUTES,
        seed,
    );
    let unit_id = format!("U{}", TYPE_UNITS + 1);
    let truth = f.units[TYPE_UNITS];
    let type_ids: Vec<String> = (1..=n_type.max(TYPE_UNITS) + 1)
        .filter(|&u| u != TYPE_UNITS + 1)
        .take(n_type)
        .map(|u| format!("U{u}"))
        .collect();
    let (mut own, mut type_runs): (Vec<Run>, Vec<Run>) = f
        .runs
        .into_iter()
        .filter(|r| {
            r.meta_value("unit_id")
                .is_some_and(|u| u == unit_id || type_ids.iter().any(|t| t == u))
        })
        .partition(|r| r.meta_value("unit_id") == Some(unit_id.as_str()));
    let mut more = ChaCha8Rng::seed_from_u64(seed ^ 0x0418_0000);
    for (u, truth) in f.units.iter().enumerate() {
        if !type_ids.contains(&format!("U{}", u + 1)) {
            continue;
        }
        type_runs.extend(extra_cold_starts(
            truth,
            &format!("U{}", u + 1),
            &AMBIENTS_C,
            2 * AMBIENTS_C.len()..type_unit_runs(),
            MINUTES,
            &format!("extra_u{:03}_", u + 1),
            &mut more,
        ));
    }
    let mut extra = ChaCha8Rng::seed_from_u64(seed ^ 0x0417_0000);
    own.extend(extra_cold_starts(
        &truth,
        &unit_id,
        &AMBIENTS_C,
        own.len()..unit_runs,
        MINUTES,
        "extra_u011_",
        &mut extra,
    ));
    Split {
        truth,
        unit_id,
        own,
        type_runs,
    }
}

/// The fleet `law`: the type from units 1-10, unit 11 calibrated from its own 6 runs
/// (`INDEP_UNIT_RUNS`) and, for each sequence, read on `starts` held-out cold starts per
/// ambient.
fn measure(law: FleetLaw, shape: TypeShape, seed: u64, starts: usize) -> Measured {
    let Split {
        truth,
        unit_id,
        own,
        type_runs,
    } = split(law, seed, unit_runs());
    let lat = fog_sim::sim::DEFAULT_LATITUDE_DEG;
    let mut judged = Vec::new();
    let mut refused = false;
    let mut shapes = Vec::new();
    for &mode in sequences() {
        let criterion = criterion_of(mode);
        let sched = schedule(mode);
        let plan = plan_of(&sched, mode);
        let (ty, took, choice) =
            learn_independent_type(&type_runs, shape, criterion, plan, rate_clock());
        if let Some(c) = &choice {
            print!(
                "{law:?} seed {seed}, {}: {}",
                sequence_name(mode),
                c.summary()
            );
            // the null twin's units, each tested against the type the others make: none
            // outside (0 of 150 over seeds 1-5 and the three seeks; docs/record/fleet.md)
            assert!(
                law != FleetLaw::Identical || c.units_outside.is_empty(),
                "the null twin's type units {:?} outside the type their others make",
                c.units_outside
            );
        }
        shapes.push((mode, took));
        let cal = calibrate_unit(&ty, &own, &unit_id, &plan).unwrap();
        let own_model = train_alone(&own, criterion);
        if cal.misfit.outside() {
            // refused, as `train --type` refuses it by default (`--misfit own`: the unit's
            // runs alone, the type-free rows)
            println!(
                "{law:?} seed {seed}, {shape:?} type, {}: {}",
                sequence_name(mode),
                cal.misfit.lines().join("; ")
            );
            refused = true;
            judged.push(Judged::new("unit runs alone", mode, own_model, sched));
            continue;
        }
        println!(
            "{law:?} seed {seed}, {shape:?} type, {}: inputs {}; {} unit terms, prior weight {}; type terms: {}; {}",
            sequence_name(mode),
            ty.model.inputs.iter().map(feature_name).collect::<Vec<_>>().join(", "),
            cal.terms,
            cal.prior_weight,
            ty.file.terms.iter().map(|t| t.name.as_str()).collect::<Vec<_>>().join(", "),
            cal.misfit.lines().join("; ")
        );
        // the unit's own model beside it, as `train --type` compares them
        let min_train = TrainConfig::default().folds;
        let own_choice = choose_own(&cal, &own, &plan, min_train, &mut |r| {
            Ok(train_alone(r, criterion))
        })
        .unwrap();
        print!(
            "{law:?} seed {seed}, {shape:?} type, {}: {}",
            sequence_name(mode),
            own_choice.summary()
        );
        judged.push(Judged::new(
            "type + unit runs",
            mode,
            if own_choice.taken {
                own_model.clone()
            } else {
                cal.model
            },
            sched.clone(),
        ));
        judged.push(Judged::new("unit runs alone", mode, own_model, sched));
    }
    let geometry = SeekGeometry::forward(0.0, lat);
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5EE4_0000);
    for (a, &amb) in AMBIENTS_C.iter().enumerate() {
        for _ in 0..starts {
            let run = cold_start(&truth, amb, MINUTES, &mut rng);
            for j in judged.iter_mut() {
                j.read(a, &run, geometry);
            }
        }
    }
    Measured {
        judged,
        refused,
        shapes,
    }
}

fn print_table(law: FleetLaw, shape: TypeShape, judged: &[Judged], starts: usize) {
    println!(
        "{law:?} fleet, {shape:?} type: {starts} held-out cold starts per ambient (-40 | 20 | +60 degC): \
         all seeks / worst of 1-3 x floor / worst |mean|/std (seek)"
    );
    for j in judged {
        let cells: Vec<String> = j
            .figures()
            .into_iter()
            .map(|f| {
                format!(
                    "{:.3} / {:.3} / {:.2} (seek {}) {}",
                    f.0,
                    f.1,
                    f.2,
                    f.3,
                    if met(f) { "met" } else { "missed" }
                )
            })
            .collect();
        println!(
            "  {:15} {:18} floor {:.4} deg | {}",
            sequence_name(j.mode),
            j.recipe,
            j.floor_deg[0],
            cells.join(" | ")
        );
    }
}

/// The unit's calibration runs (`INDEP_UNIT_RUNS`; default 6, two at each ambient).
fn unit_runs() -> usize {
    std::env::var("INDEP_UNIT_RUNS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(6)
}

/// Each type unit's cold starts (`INDEP_TYPE_UNIT_RUNS`; default 6, two at each ambient;
/// more are spread evenly over the ambients, the first six unchanged).
/// Units the type is learnt from (`INDEP_TYPE_UNITS`, default 10: units 1-10; more are
/// units 12 on, fewer the first of 1-10; the calibrated unit is always unit 11).
fn type_units() -> usize {
    std::env::var("INDEP_TYPE_UNITS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(TYPE_UNITS)
}

fn type_unit_runs() -> usize {
    std::env::var("INDEP_TYPE_UNIT_RUNS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(6)
}

/// The fleets measured (`INDEP_SEEK_FLEETS=type,identical,shupe,thermal,odd`; default the
/// type fleet and its null twin).
fn fleets() -> Vec<FleetLaw> {
    let names = std::env::var("INDEP_SEEK_FLEETS").unwrap_or_else(|_| "type,identical".into());
    names
        .split(',')
        .map(|n| match n.trim() {
            "type" => FleetLaw::Type,
            "identical" => FleetLaw::Identical,
            "shupe" => FleetLaw::OnlyShupe,
            "thermal" => FleetLaw::OnlyThermal,
            "odd" => FleetLaw::OddUnit,
            other => panic!("INDEP_SEEK_FLEETS: unknown fleet {other}"),
        })
        .collect()
}

/// The seeds of the measurement (`INDEP_SEEK_SEEDS=1,2,3`; default 1).
fn seeds() -> Vec<u64> {
    std::env::var("INDEP_SEEK_SEEDS")
        .ok()
        .map(|v| v.split(',').map(|x| x.trim().parse().unwrap()).collect())
        .unwrap_or_else(|| vec![1])
}

/// The cells `recipe` with `mode` meets, of the three ambients.
fn cells_met(judged: &[Judged], recipe: &str, mode: SeekMode) -> usize {
    let j = judged
        .iter()
        .find(|j| j.recipe == recipe && j.mode == mode)
        .unwrap();
    j.figures().into_iter().filter(|&f| met(f)).count()
}

/// The judge reads the generator's 10 s means, as the device reads its windows; a logger
/// writes 1 Hz rows, which `fogsim train` reads through `io::bin` into the same windows.
/// Written as a 1 Hz file and read by `train`'s reader, a cold start is its 10 s means
/// exactly, at every ambient, so the recipe's figures here hold for 1 Hz logs too.
#[test]
fn one_hz_rows_read_by_train_are_the_10_s_means_the_judge_reads() {
    let dir = crate::app_support::scratch_dir("indep_1hz");
    for (k, amb) in AMBIENTS_C.into_iter().enumerate() {
        let truth = fleet(FleetLaw::Type, 1, &[amb], 1, 1, k as u64).units[0];
        let means = cold_start(&truth, amb, MINUTES, &mut ChaCha8Rng::seed_from_u64(7));
        let rows = cold_start_rows(&truth, amb, MINUTES, &mut ChaCha8Rng::seed_from_u64(7), 1);
        assert_eq!(rows.len(), 10 * means.len());
        let path = dir.join(format!("cold_start_{amb}.csv"));
        fog_sim::io::runs::write_run(&path, &rows).unwrap();
        let binned = fog_sim::io::read_binned(&path).unwrap();
        for col in ["t_s", "rate_dph", "temp_c"] {
            assert_eq!(binned.column(col), means.column(col), "{col} at {amb} degC");
        }
    }
}

/// The judge's self-check: a residual of the generator's white noise alone (what a model
/// equal to the unit's drift leaves, its turn-on offset included) reads at its floor with
/// no bias, for every sequence; a constant (the turn-on offset) cancels.
#[test]
fn the_judge_reads_white_noise_at_its_floor_and_cancels_a_constant() {
    use rand_distr::{Distribution, Normal};
    let geometry = SeekGeometry::forward(0.0, fog_sim::sim::DEFAULT_LATITUDE_DEG);
    let t_s: Vec<f64> = (1..=MINUTES * 6).map(|k| 10.0 * k as f64).collect();
    let noise = Normal::new(0.0, NOISE_10S_DPH).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for mode in SEQUENCES {
        let sched = schedule(mode);
        let (constant, _) = seek_errors_deg(&sched, &t_s, &vec![0.3; t_s.len()], geometry);
        assert!(constant.iter().all(|e| e.abs() < 1e-12), "{constant:?}");
        let mut sums = [(0.0, 0.0); SEEKS];
        let mut floors = Vec::new();
        let n = 2000;
        for _ in 0..n {
            let res: Vec<f64> = t_s.iter().map(|_| 0.3 + noise.sample(&mut rng)).collect();
            let (e, f) = seek_errors_deg(&sched, &t_s, &res, geometry);
            for (s, x) in sums.iter_mut().zip(e) {
                s.0 += x;
                s.1 += x * x;
            }
            floors = f;
        }
        for (k, (sum, ss)) in sums.iter().enumerate() {
            let mean = sum / n as f64;
            let rms = (ss / n as f64).sqrt();
            // 2000 draws: the rms within 5 % (3.5 standard errors), the mean within 0.1 std
            assert!(
                (rms / floors[k] - 1.0).abs() < 0.05,
                "{mode:?} seek {}: {rms} vs {}",
                k + 1,
                floors[k]
            );
            assert!(
                mean.abs() < 0.1 * rms,
                "{mode:?} seek {}: mean {mean}",
                k + 1
            );
        }
    }
}

/// Cells met per (fleet, shape, sequence, recipe) over the seeds run, and the refusals.
#[derive(Default)]
struct Tally {
    rows: Vec<(String, usize, usize)>,
}

impl Tally {
    fn add(&mut self, law: FleetLaw, shape: TypeShape, judged: &[Judged]) {
        for j in judged {
            let key = format!(
                "{law:?} fleet, {shape:?} type, {}, {}",
                sequence_name(j.mode),
                j.recipe
            );
            let met = j.figures().into_iter().filter(|&f| met(f)).count();
            match self.rows.iter_mut().find(|r| r.0 == key) {
                Some(r) => {
                    r.1 += met;
                    r.2 += AMBIENTS_C.len();
                }
                None => self.rows.push((key, met, AMBIENTS_C.len())),
            }
        }
    }
}

/// The unit's own model beside its calibration (`type_unit::own`), seed 1, Thue-Morse,
/// with a type whose network reads dT/dt as the slope (`--warmup-clock slope`), which
/// cannot carry these units' warm-up (docs/record/fleet.md): 24 of the unit's runs take it
/// out of its type (measured t 5.0, critical 2.5; the own model read in the runs' clock,
/// as `train` reads it since 2026-12-06: 4.9 with the slope); with 6 runs they do not (t
/// -1.0, critical 3.4; -1.6), nor do the same 24 runs of the null twin, whose type carries
/// the unit (t -3.4 with its type in the network with linear terms, which `auto` takes
/// there since the twenty-sixth stop; with the law it took before, -4.4; -4.0). (With 48 runs every seed 1-3 leaves, and the recipe meets 6 of 9 cells as the
/// unit's runs alone, against 2 of 9: docs/record/fleet.md.) With the clock the type
/// chooses (the default) it carries the unit and 24 runs stay with it (t -2.3).
///
/// Each type is learnt in the shape `--type-shape auto` takes on its fleet with this clock,
/// given here rather than chosen again (the choice was 2/3 of this test's time and none of
/// its assertions): the network with linear terms on the type fleet (t 2.7 against the law)
/// and on the null twin (t 0.2, the law's modes refuted by its runs' diffusion warm-up,
/// t 56.9: the network the base; the law there until 2026-12-06, twenty-sixth stop);
/// learnt so, the type fleet's was the one `auto` gave, field for field (measured
/// 2026-12-06). The choice itself is asserted by
/// `the_type_and_unit_recipe_on_the_independent_fleet_and_its_twins` and the shape unit tests.
#[test]
fn a_unit_leaves_its_type_when_its_own_runs_say_more_and_only_then() {
    let show = |law: FleetLaw, shape: SharedShape, runs: &[usize]| -> Vec<bool> {
        let choices = own_choices(law, 1, shape, runs);
        for (c, n) in choices.iter().zip(runs) {
            print!("{law:?}, {n} unit runs: {}", c.summary());
        }
        choices.iter().map(|c| c.taken).collect()
    };
    let differ = show(FleetLaw::Type, SharedShape::NetworkLinear, &[24, 6]);
    assert!(differ[0], "24 runs of a unit its type cannot carry");
    assert!(
        !show(FleetLaw::Identical, SharedShape::NetworkLinear, &[24])[0],
        "the null twin left its type"
    );
    assert!(!differ[1], "6 runs left the type");
}

/// Measured at 200 starts, seed 1 (the CI size): the fleet's and its null twin's runs warm
/// up by diffusion, which refutes the law's exponential modes, so `auto` takes a network
/// for the Thue-Morse seek on both (the law only when better beyond the units' scatter);
/// with identical units the type + unit recipe then meets every target at every ambient;
/// where units differ the network's worst first-seek bias is a fraction of the law type's
/// (0.70 of a std against 5.80); the odd twin's unit is refused. Over seeds 1-5 at 1,000 starts
/// (docs/record/fleet.md): the single-effect twins put the law type's misses in the units'
/// thermal differences, which its clocks do not carry on this law.
#[test]
fn the_type_and_unit_recipe_on_the_independent_fleet_and_its_twins() {
    let t0 = Instant::now();
    let starts = heldout_starts();
    let mut tally = Tally::default();
    // the Thue-Morse seek's worst |mean| / std over the ambients, type + unit runs, by shape
    let mut tm_bias: Vec<(TypeShape, f64)> = Vec::new();
    let shapes = shapes();
    for seed in seeds() {
        for &shape in &shapes {
            for law in fleets() {
                // At the CI size the law type on identical units is not measured: the null
                // twin's assertions are on the type `auto` takes there.
                if at_ci_size()
                    && shape == TypeShape::Law
                    && law == FleetLaw::Identical
                    && shapes.contains(&TypeShape::Auto)
                    && type_unit_runs() == 6
                {
                    continue;
                }
                let m = measure(law, shape, seed, starts);
                print_table(law, shape, &m.judged, starts);
                tally.add(law, shape, &m.judged);
                let tm = SeekMode::TwoPositionThueMorse;
                let tm_shape = m.shapes.iter().find(|s| s.0 == tm).map(|s| s.1);
                if at_ci_size() && seed == 1 && shape == TypeShape::Auto {
                    if law == FleetLaw::Identical {
                        assert!(!m.refused, "the null twin's U11 refused");
                        let met = cells_met(&m.judged, "type + unit runs", tm);
                        assert_eq!(met, 3, "the null twin's Thue-Morse cells met");
                    }
                    assert!(
                        tm_shape.is_some_and(|s| s != SharedShape::Law),
                        "{law:?}: auto took {tm_shape:?} on runs that warm up by diffusion"
                    );
                }
                if seed == 1 && law == FleetLaw::Type {
                    if let Some(j) = m
                        .judged
                        .iter()
                        .find(|j| j.recipe == "type + unit runs" && j.mode == tm)
                    {
                        let worst = j.figures().iter().fold(0.0f64, |w, f| w.max(f.2));
                        tm_bias.push((shape, worst));
                    }
                }
            }
        }
        // the odd twin's odd unit is its fleet's last: only with the default type units
        if type_units() == TYPE_UNITS {
            assert!(
                measure(FleetLaw::OddUnit, TypeShape::Law, seed, 0).refused,
                "seed {seed}: the odd twin's unit passed its type's misfit test"
            );
        }
    }
    for (key, met, cells) in &tally.rows {
        println!("{key}: {met} of {cells} cells met");
    }
    let bias = |s: TypeShape| tm_bias.iter().find(|b| b.0 == s).map(|b| b.1);
    if let (Some(law), Some(auto)) = (bias(TypeShape::Law), bias(TypeShape::Auto)) {
        assert!(
            auto < 0.5 * law,
            "units that differ, Thue-Morse: auto's worst bias {auto:.2} std, the law's {law:.2}"
        );
    }
    println!("{:.1} s", t0.elapsed().as_secs_f64());
}
