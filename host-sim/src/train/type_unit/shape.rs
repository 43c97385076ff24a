//! The form of a type's shared model: the warm-up law as a network's base (`law`) or the
//! trainer's network (`network`), trained the same way by `train --type-out` and
//! `north-seek --type-units`, and chosen from the fleet's own runs (`--type-shape auto`).
//!
//! Why a choice: the law carries a warm-up of two exponential modes with few parameters,
//! and on the simulator's fleets it was the better base; on a fleet whose units warm up
//! otherwise (the independent generator's, whose units differ in their thermal law) the
//! free network carried the type better (docs/record/fleet.md). Which one a design needs
//! is the data's to say: each shape's type is learnt from the other units' runs, each unit
//! left out is calibrated against it from its own runs by the unit step, and the shape is
//! scored by the azimuth error of that unit's first seeks on runs its calibration did not
//! see: as the type will meet a unit it has never seen, after that unit's calibration.
//! (Scored on the shared model alone, without the unit step, the choice took the network
//! on simulator fleets whose law type met every target after the unit step, and the law
//! on independent fleets the network carried: docs/record/fleet.md.) The network is taken
//! only when its pooled error is lower than the law's beyond what the units left out could
//! make of it (the log ratio over its jackknife standard error, each unit left out in turn,
//! above `SHAPE_T_MIN`); otherwise, and when too few units leave no test power, the law:
//! the physical base. The law is the base only where the runs' temperatures follow its
//! exponential modes: where they reject them for a diffusion warm-up (`warmup_clock`'s
//! test on the type's own runs, the clock its network's dT/dt is read in), the network of
//! the lower score is the base and the law is taken only when it is the better beyond the
//! units' scatter. (With the law as the base at a tie, the independent fleet's coil kept it
//! for the time-symmetric seek with 30 units, and that seek then missed every ambient:
//! docs/record/fleet.md.) (A paired test of each unit's log ratio was tried first: it kept the
//! law on independent fleets whose pooled error the network cut by a third, carried by a
//! few units far off the type; docs/record/fleet.md.)

use anyhow::{anyhow, Result};
use fog_core::model::format::RbfModel;

use super::calibrate::{unit_id_of, unit_step_held_out, UnitPlan};
use super::folds::unit_of_runs;
use super::law::{fit_law_network, LawNetwork, LAW_FOLDS};
use super::misfit::Misfit;
use super::terms::Fit;
use super::type_model::{check_type_runs, learn_type, TypeModel, MIN_TYPE_UNITS};
use crate::io::runs::Run;
use crate::train::cold_start::envelope_for;
use crate::train::seek_score::seek_azimuth_first_pairs_per_run;
use crate::train::warmup_clock::{choose_warmup_clock, in_runs_clock, ClockChoice};
use crate::train::{choose_inputs_default, train_model, InputSelection, InputSet, TrainConfig};

/// The form of a type's shared model asked for (`--type-shape`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum TypeShape {
    /// The trainer's network, its inputs chosen by validation (`train`'s defaults).
    Network,
    /// The warm-up law of a two-node thermal model as the base of a network (`law`).
    Law,
    /// Chosen from the fleet's runs by leaving whole units out (`choose_shape`).
    #[default]
    Auto,
}

/// A shared model's form, as trained.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SharedShape {
    /// The trainer's network with the configuration given (`--linear-inputs` among it).
    Network,
    /// The trainer's network with linear terms in its inputs under the Gaussians (a drift
    /// linear in an input, as the Shupe term is in dT/dt, is carried by one term whatever
    /// the unit's warm-up, where Gaussians only approximate it).
    NetworkLinear,
    Law,
}

impl SharedShape {
    pub fn name(self) -> &'static str {
        match self {
            Self::Network => "network",
            Self::NetworkLinear => "network with linear terms",
            Self::Law => "law",
        }
    }
}

/// The shapes `auto` chooses among; the first is the one kept when no other is better
/// beyond the units' scatter.
pub const AUTO_SHAPES: [SharedShape; 3] = [
    SharedShape::Law,
    SharedShape::Network,
    SharedShape::NetworkLinear,
];

/// A trained shared model and what its training chose.
#[derive(Clone, Debug)]
pub enum SharedModel {
    Network {
        model: RbfModel,
        selection: Box<InputSelection>,
        centres: usize,
        inputs: Vec<String>,
        /// The clock its dT/dt is read in, and why (None: the slope, not chosen).
        clock: Option<Box<ClockChoice>>,
    },
    Law(LawNetwork),
}

impl SharedModel {
    pub fn model(&self) -> &RbfModel {
        match self {
            Self::Network { model, .. } => model,
            Self::Law(law) => &law.model,
        }
    }

    /// What it is, in a few lines.
    pub fn describe(&self) -> String {
        match self {
            Self::Network {
                selection,
                centres,
                inputs,
                clock,
                ..
            } => format!(
                "shared model: the network ({centres} centres, inputs {}):\n{}{}",
                inputs.join(", "),
                clock
                    .as_ref()
                    .map_or(String::new(), |c| format!("  {}\n", c.describe())),
                selection.summary(),
            ),
            Self::Law(law) => format!(
                "shared model: the warm-up law (clocks of {:.0} s and {:.0} s, held-out first-seek error {:.4} deg) as the base of a network of {} centres\n{}",
                law.taus_s[0],
                law.taus_s[1],
                law.law_heldout_deg,
                law.model.centers.len(),
                law.grid_edge().map_or(String::new(), |e| format!("  {e}\n")),
            ),
        }
    }
}

/// Trains a shared model of `shape` on `runs`: the law with `cfg.criterion`, or the
/// network as `train` would (inputs from `candidates` by validation, `cfg`'s shape).
pub fn train_shared(
    shape: SharedShape,
    runs: &[Run],
    cfg: &TrainConfig,
    candidates: &[InputSet],
) -> Result<SharedModel> {
    match shape {
        SharedShape::Law => Ok(SharedModel::Law(fit_law_network(
            runs,
            cfg.criterion,
            &cfg.gyro_id,
        )?)),
        SharedShape::Network | SharedShape::NetworkLinear => {
            // the dT/dt input in the clock the runs' warm-up follows (`warmup_clock`),
            // where `--warmup-clock auto` asks for it
            let (clocked, clock) = in_runs_clock(runs, cfg);
            let cfg = &TrainConfig {
                linear_on_rbf_inputs: cfg.linear_on_rbf_inputs
                    || shape == SharedShape::NetworkLinear,
                ..clocked
            };
            let (selection, ds) = choose_inputs_default(runs, candidates, cfg)?;
            let trained = train_model(&ds, cfg)?;
            let mut model = trained.model;
            model.cold_start = envelope_for(runs, &model.inputs)?;
            Ok(SharedModel::Network {
                model,
                selection: Box::new(selection),
                centres: trained.report.n_centers,
                inputs: trained.report.inputs,
                clock: clock.map(Box::new),
            })
        }
    }
}

/// How the shapes are trained and their units left out calibrated when they are scored:
/// as the type will be learnt (`cfg`, `candidates`, the unit terms' `fit`) and its units
/// calibrated (`plan`, the unit step's seeks).
#[derive(Clone, Copy, Debug)]
pub struct ShapeScoring<'a> {
    pub cfg: &'a TrainConfig,
    pub candidates: &'a [InputSet],
    pub fit: Fit,
    pub plan: UnitPlan,
}

impl ShapeScoring<'_> {
    /// The type of `shape` learnt from `runs` as `train --type-out` learns it
    /// (`learn_type` around `train_shared`, the unit terms read with `fit`).
    pub fn learn_type(
        &self,
        shape: SharedShape,
        runs: &[Run],
        type_id: Option<&str>,
    ) -> Result<TypeModel> {
        learn_type(runs, type_id, self.fit, &mut |runs| {
            Ok(train_shared(shape, &runs, self.cfg, self.candidates)?
                .model()
                .clone())
        })
    }
}

/// Seeks from power-on each held-out run is scored on: the six the seek targets judge one
/// by one, as the unit step's score (`calibrate::SCORED_SEEKS`; about the first half hour
/// of a cold start at the default dwells, where the warm-up is).
pub const SHAPE_SEEKS: usize = super::calibrate::SCORED_SEEKS;
/// The network is taken when its pooled held-out error is lower than the law's by more than
/// this many standard errors of the log ratio (jackknife over the held-out units).
pub const SHAPE_T_MIN: f64 = 2.0;
/// Fewest units the choice is made on (fewer: the law, for want of test power): every
/// fold's type needs `MIN_TYPE_UNITS` units left in.
pub const SHAPE_MIN_UNITS: usize = MIN_TYPE_UNITS + 1;

/// How the shape was chosen.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ShapeChoice {
    pub chosen: SharedShape,
    /// Each shape's held-out azimuth rms of the first `SHAPE_SEEKS` seeks, deg, in the
    /// order of `AUTO_SHAPES`; empty when too few units were left to score.
    pub scores_deg: Vec<(SharedShape, f64)>,
    /// The network of the lower score, tested against the law.
    pub challenger: SharedShape,
    /// The diffusion law's margin over the exponential modes on the type's runs where it
    /// refutes them (`warmup_clock::choose_warmup_clock`'s t): the challenger is then the
    /// shape kept when neither is better beyond the units' scatter; None: the law is.
    pub law_refuted_t: Option<f64>,
    /// Held-out units, and those where the challenger's error was the lower.
    pub units: usize,
    pub challenger_better_units: usize,
    /// The log of the law's pooled mean-square error over the challenger's, over its
    /// jackknife standard error (each held-out unit left out in turn).
    pub t_challenger_better: f64,
    /// The type's own units the misfit test finds outside the chosen shape's type their
    /// other units make (each left out of its fold as a new unit): `U6 (warm-up gain 8.2
    /// sigma, critical 3.6)`.
    pub units_outside: Vec<String>,
}

impl ShapeChoice {
    pub fn summary(&self) -> String {
        let base = self.law_refuted_t.map_or(String::new(), |t| {
            format!(
                "shape's base: the {}: the type's runs warm up by diffusion, not by the law's exponential modes (t = {t:.1}); the law is taken only when better beyond the units' scatter\n",
                self.challenger.name()
            )
        });
        if self.scores_deg.is_empty() {
            return format!(
                "{base}shape: {} ({} units: no test power for a choice; a type from at least {SHAPE_MIN_UNITS} units lets its units choose)\n",
                self.chosen.name(),
                self.units
            );
        }
        let scores: Vec<String> = self
            .scores_deg
            .iter()
            .map(|(s, d)| format!("{} {d:.4} deg", s.name()))
            .collect();
        let outside = if self.units_outside.is_empty() {
            format!("type units tested as new units against the type their other units make: none of {} outside its type\n", self.units)
        } else {
            format!(
                "type units outside the type their other units make: {} of {}: {}; a unit's runs shape the type it is tested against: learn the type without them, unless the design's units do differ so\n",
                self.units_outside.len(),
                self.units,
                self.units_outside.join(", ")
            )
        };
        // which way the test runs: the network against the law as the base, or the law
        // against the network
        let rule = if self.law_refuted_t.is_some() {
            format!("the law taken below -{SHAPE_T_MIN}")
        } else {
            format!("taken above {SHAPE_T_MIN}")
        };
        format!(
            "{base}shape: {} (held-out first {SHAPE_SEEKS} seeks of {} units left out: {}; the {} better on {} of {} units, t = {:.1}, {rule})\n{outside}",
            self.chosen.name(),
            self.units,
            scores.join(", "),
            self.challenger.name(),
            self.challenger_better_units,
            self.units,
            self.t_challenger_better,
        )
    }
}

/// `U6 (warm-up gain 8.2 sigma, critical 3.6)`: a unit outside its type, by its term
/// farthest out (|z| over its critical value).
fn outside_line(m: &Misfit) -> Option<String> {
    let worst = m
        .terms
        .iter()
        .filter(|t| t.outside)
        .max_by(|a, b| (a.z.abs() / a.critical).total_cmp(&(b.z.abs() / b.critical)))?;
    Some(format!(
        "{} ({} {:.1} sigma, critical {:.1})",
        m.unit_id,
        worst.name,
        worst.z.abs(),
        worst.critical
    ))
}

/// Chooses the shared model's shape for a type learnt from `runs` (several units'): each of
/// `AUTO_SHAPES` learnt as a type on the runs of the other units, in `LAW_FOLDS` folds of
/// whole units, and scored on the held-out units' first `SHAPE_SEEKS` seeks (the seek of
/// `scoring.cfg.criterion`) after their unit step (`heldout_sse`); the network of the lower
/// score is taken over the law when its pooled error is lower beyond the units' scatter
/// (`jackknife_t` > `SHAPE_T_MIN`); where the runs refute the law's exponential warm-up
/// (`law_refuted`), the law is taken only when its error is the lower beyond it.
pub fn choose_shape(runs: &[Run], scoring: &ShapeScoring) -> Result<ShapeChoice> {
    let unit_of_run = unit_of_runs(runs);
    let units = unit_of_run.iter().max().map_or(0, |m| m + 1);
    let law_refuted_t = law_refuted(runs);
    if units < SHAPE_MIN_UNITS {
        // no test power: the base, the law unless its modes are refuted
        return Ok(ShapeChoice {
            chosen: AUTO_SHAPES[usize::from(law_refuted_t.is_some())],
            law_refuted_t,
            scores_deg: Vec::new(),
            challenger: AUTO_SHAPES[1],
            units,
            challenger_better_units: 0,
            t_challenger_better: 0.0,
            units_outside: Vec::new(),
        });
    }
    // every fold's type and every unit's step need what a type needs
    check_type_runs(runs)?;
    let (sse, mut outside) = heldout_sse(runs, &unit_of_run, units, scoring)?;
    let rms = |k: usize| {
        let (s, n) = sse
            .iter()
            .fold((0.0, 0), |(s, n), u| (s + u[k].0, n + u[k].1));
        (s / n.max(1) as f64).sqrt()
    };
    let scores_deg: Vec<(SharedShape, f64)> = AUTO_SHAPES
        .iter()
        .enumerate()
        .map(|(k, &s)| (s, rms(k)))
        .collect();
    let c = (1..AUTO_SHAPES.len())
        .min_by(|&a, &b| scores_deg[a].1.total_cmp(&scores_deg[b].1))
        .unwrap_or(1);
    let ms = |u: &[(f64, usize)], k: usize| u[k].0 / u[k].1.max(1) as f64;
    let scored: Vec<&UnitSse> = sse.iter().filter(|u| u[0].1 > 0 && u[c].1 > 0).collect();
    let t = jackknife_t(&scored, c);
    let d: Vec<f64> = scored
        .iter()
        .map(|u| ms(&u[..], 0) - ms(&u[..], c))
        .collect();
    let powered = d.len() >= SHAPE_MIN_UNITS;
    let chosen_k = match law_refuted_t {
        None if powered && t > SHAPE_T_MIN => c,
        None => 0,
        Some(_) if powered && t < -SHAPE_T_MIN => 0,
        Some(_) => c,
    };
    Ok(ShapeChoice {
        chosen: AUTO_SHAPES[chosen_k],
        law_refuted_t,
        units_outside: std::mem::take(&mut outside[chosen_k]),
        scores_deg,
        challenger: AUTO_SHAPES[c],
        units: d.len(),
        challenger_better_units: d.iter().filter(|&&x| x > 0.0).count(),
        t_challenger_better: t,
    })
}

/// The diffusion law's margin (t) where the type's runs refute the law's exponential
/// warm-up (`choose_warmup_clock` takes the diffusion clock on them), else None: the test
/// that decides how a network reads dT/dt decides whether the law's modes are the units'
/// physics, whatever clock `--warmup-clock` asks the network to read.
fn law_refuted(runs: &[Run]) -> Option<f64> {
    let clock = choose_warmup_clock(runs);
    clock.is_diffusion().then_some(clock.t).flatten()
}

/// Squared azimuth errors and their count, per shape of `AUTO_SHAPES`, of one unit.
type UnitSse = [(f64, usize); AUTO_SHAPES.len()];

/// Each unit's held-out first-seek errors under each shape: for each shape, the type
/// learnt as `learn_type` learns it (the shape's shared model and the unit terms, `fit`)
/// from the runs of the other folds (`LAW_FOLDS` folds of whole units); each held-out
/// unit calibrated against it by the unit step (`plan`), every run scored after the unit
/// terms fitted on the unit's other runs (`unit_step_held_out`). So a shape is
/// judged by what the seeks of a unit it never saw meet after that unit's own calibration,
/// not by the shared model alone: a shape whose units differ in what the unit terms carry
/// loses nothing by it. With them, per shape, the held-out units the misfit test finds
/// outside the fold's type (`outside_line`).
fn heldout_sse(
    runs: &[Run],
    unit_of_run: &[usize],
    units: usize,
    scoring: &ShapeScoring,
) -> Result<(Vec<UnitSse>, [Vec<String>; AUTO_SHAPES.len()])> {
    let folds = LAW_FOLDS.min(units);
    let geometry = scoring.cfg.criterion.seek_geometry();
    // per unit and shape: squared azimuth errors and their count
    let mut sse = vec![[(0.0, 0usize); AUTO_SHAPES.len()]; units];
    let mut outside: [Vec<String>; AUTO_SHAPES.len()] = Default::default();
    for fold in 0..folds {
        let held = |r: usize| unit_of_run[r] % folds == fold;
        let train: Vec<Run> = (0..runs.len())
            .filter(|&r| !held(r))
            .map(|r| runs[r].clone())
            .collect();
        // the fold's units left out, each with its id and runs
        let held_units = (0..units)
            .filter(|u| u % folds == fold)
            .map(|u| {
                let unit_runs: Vec<Run> = (0..runs.len())
                    .filter(|&r| unit_of_run[r] == u)
                    .map(|r| runs[r].clone())
                    .collect();
                let id = unit_id_of(&unit_runs, &format!("unit {}", u + 1))?;
                Ok((u, id, unit_runs))
            })
            .collect::<Result<Vec<(usize, String, Vec<Run>)>>>()?;
        for (k, shape) in AUTO_SHAPES.into_iter().enumerate() {
            let context = |e: anyhow::Error| {
                anyhow!(
                    "choosing the type's shape, {} on fold {fold}: {e}",
                    shape.name()
                )
            };
            let ty = scoring.learn_type(shape, &train, None).map_err(context)?;
            for (u, id, unit) in &held_units {
                let u = *u;
                let held = unit_step_held_out(&ty, unit, id, &scoring.plan).map_err(context)?;
                let ds = &held.dataset;
                for e in seek_azimuth_first_pairs_per_run(
                    &held.residual,
                    &ds.groups,
                    &ds.t_s,
                    geometry,
                    SHAPE_SEEKS,
                ) {
                    sse[u][k].0 += e.sum_sq_deg2;
                    sse[u][k].1 += e.pairs;
                }
                outside[k].extend(outside_line(&held.misfit));
            }
        }
    }
    Ok((sse, outside))
}

/// The log of the law's pooled mean square (shape 0) over shape `c`'s on the `scored`
/// units, over its jackknife standard error (each unit left out in turn): the pooled
/// error is what the seeks see, and a few units far off the type may carry most of it.
fn jackknife_t(scored: &[&UnitSse], c: usize) -> f64 {
    let log_ratio = |skip: Option<usize>| {
        let (mut l, mut ln, mut ch, mut cn) = (0.0, 0usize, 0.0, 0usize);
        for (_, u) in scored.iter().enumerate().filter(|(i, _)| Some(*i) != skip) {
            l += u[0].0;
            ln += u[0].1;
            ch += u[c].0;
            cn += u[c].1;
        }
        ((l / ln.max(1) as f64) / (ch / cn.max(1) as f64)).ln()
    };
    let n = scored.len();
    let full = log_ratio(None);
    let leave: Vec<f64> = (0..n).map(|i| log_ratio(Some(i))).collect();
    let mean = leave.iter().sum::<f64>() / n.max(1) as f64;
    let se = ((n as f64 - 1.0) / n.max(1) as f64
        * leave.iter().map(|x| (x - mean).powi(2)).sum::<f64>())
    .sqrt();
    if se > 0.0 && full.is_finite() {
        full / se
    } else {
        0.0
    }
}

/// The shape `asked` resolves to on `runs`: itself when fixed, else `choose_shape`'s
/// choice (and the choice, to report).
pub fn resolve_shape(
    asked: TypeShape,
    runs: &[Run],
    scoring: &ShapeScoring,
) -> Result<(SharedShape, Option<ShapeChoice>)> {
    match asked {
        TypeShape::Law => Ok((SharedShape::Law, None)),
        TypeShape::Network => Ok((SharedShape::Network, None)),
        TypeShape::Auto => {
            let choice = choose_shape(runs, scoring)?;
            Ok((choice.chosen, Some(choice)))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::law::tests::{fleet, fleet_of_units, law_of_two_node, seek, two_node};
    use super::*;
    use crate::train::seek_score::Criterion;
    use crate::train::InputSet;

    fn cfg() -> TrainConfig {
        TrainConfig {
            gyro_id: "test".into(),
            criterion: Criterion::Seek(seek()),
            ..TrainConfig::default()
        }
    }

    /// `runs` as `fogsim train` reads a 1 Hz log (`io::read_binned`): the means of 10 s
    /// windows, the rows every shape is trained and scored on in use.
    fn as_read(runs: &[Run]) -> Vec<Run> {
        runs.iter()
            .map(|run| {
                let t = run.columns.iter().position(|c| c == "t_s").unwrap();
                let mut binner = crate::io::WindowBinner::new(run.columns.len(), t);
                for i in 0..run.data[t].len() {
                    binner.push(&run.data.iter().map(|c| c[i]).collect::<Vec<f64>>());
                }
                let mut read = run.clone();
                read.data = binner.finish();
                read
            })
            .collect()
    }

    fn choose(runs: &[Run]) -> ShapeChoice {
        let scoring = ShapeScoring {
            cfg: &cfg(),
            candidates: &[InputSet::TempRate],
            fit: Fit::default(),
            // two 50 s dwells and a turn
            plan: UnitPlan {
                seek_period_s: 120.0,
                ..UnitPlan::chosen()
            },
        };
        choose_shape(&as_read(runs), &scoring).unwrap()
    }

    #[test]
    fn units_whose_warm_up_is_no_law_of_modes_take_the_network() {
        // the twin of another law: a coil heated from one face (diffusion: a stretched
        // exponential, no exponential modes) whose time constant runs from 250 to 850 s
        // over the units, and a Shupe drift in dT/dt: no pair of clocks carries every
        // unit, and the network on T and dT/dt carries all of them
        let rise = |t: f64, _: f64, u: usize| {
            let tau_s = 250.0 + 100.0 * (u as f64 - 1.0);
            7.0 * (1.0 - (-(t.max(0.0) / tau_s).sqrt()).exp())
        };
        let shupe = |_: f64, _: f64, rate: f64, _: f64| 9.0 * rate;
        // measured on the 10 s means: the network with linear terms, t = 5.5
        let got = choose(&fleet_of_units(7, &rise, &shupe));
        assert_ne!(got.chosen, SharedShape::Law, "{}", got.summary());
        assert!(got.law_refuted_t.is_some(), "{}", got.summary());
        assert!(got.summary().contains("warm up by diffusion"));
        // three such units leave no test power for the choice, but their runs still
        // refute the law's modes: the network, not the law
        let three = choose(&fleet_of_units(3, &rise, &shupe));
        assert_eq!(three.chosen, SharedShape::Network, "{}", three.summary());
        assert!(three.summary().contains("no test power"));
    }

    /// `runs` with each unit's warm-up drift (`law_of_two_node`) scaled by its own gain:
    /// 0.6, 0.8, ... for U1, U2, ...
    fn with_unit_gains(mut runs: Vec<Run>) -> Vec<Run> {
        for run in &mut runs {
            let u: f64 = run.meta_value("unit_id").unwrap()[1..].parse().unwrap();
            let gain = 0.4 + 0.2 * u;
            let col = |name: &str| run.columns.iter().position(|c| c == name).unwrap();
            let (rate, temp) = (col("rate_dph"), col("temp_c"));
            let t = run.t_s().to_vec();
            for (i, t) in t.into_iter().enumerate() {
                let extra = (gain - 1.0) * law_of_two_node(t, run.data[temp][i], 0.0);
                run.data[rate][i] += extra;
            }
        }
        runs
    }

    #[test]
    fn a_fleet_of_the_law_keeps_it_and_so_do_units_that_differ_in_what_the_unit_step_fits() {
        // units 3 % apart in dissipation, the drift the law's own: the network gains
        // nothing beyond the units' scatter.
        // The same fleet with every unit's warm-up 0.6 to 1.4 times the type's: the unit
        // step's terms carry most of it, so the law stays the shape. Measured on the 10 s
        // means (`as_read`): the law's held-out error 0.0036 deg after the unit step (t -3.1
        // for the network), 0.0017 with identical units (t -6.5); scored on the type alone
        // (the choice before the unit step was in its loop) the law read 0.0333 deg and the
        // network was taken at t = 3.0, failing both of its assertions below (docs/record/fleet.md
        // has the same comparison on the 1 Hz rows: 0.0069, 0.0018; 0.0338, t = 8.2).
        let same = choose(&fleet(&two_node, &law_of_two_node));
        assert_eq!(same.chosen, SharedShape::Law, "{}", same.summary());
        let differ = choose(&with_unit_gains(fleet(&two_node, &law_of_two_node)));
        let law = |c: &ShapeChoice| c.scores_deg[0].1;
        assert!(
            law(&differ) < 5.0 * law(&same),
            "{}{}",
            same.summary(),
            differ.summary()
        );
        assert_eq!(differ.chosen, SharedShape::Law, "{}", differ.summary());
    }

    #[test]
    fn without_a_warm_up_drift_the_choice_stays_with_the_law() {
        // the null twin: a drift of T alone, which both shapes carry (measured: t = 0.9)
        let got = choose(&fleet(&two_node, &|_, temp, _| 0.001 * temp));
        assert_eq!(got.chosen, SharedShape::Law, "{}", got.summary());
    }

    #[test]
    fn two_units_leave_no_test_power() {
        let runs: Vec<Run> = fleet(&two_node, &law_of_two_node)
            .into_iter()
            .filter(|r| matches!(r.meta_value("unit_id"), Some("U1" | "U2")))
            .collect();
        let got = choose(&runs);
        assert_eq!(got.chosen, SharedShape::Law);
        assert_eq!(got.law_refuted_t, None, "{}", got.summary());
        assert!(got.scores_deg.is_empty());
        assert!(got.summary().contains("no test power"), "{}", got.summary());
    }
}
