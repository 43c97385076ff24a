//! The type model: what the units of one gyro design share, and how they differ.
//!
//! It is learnt once per design from the cold starts of several units (`fogsim train
//! FLEET_RUNS --type-out TYPE.json`): the shared drift model is trained on every unit's
//! runs together, and then each unit's own unit terms (`terms`: warm-up gain, a
//! linear term per input; an offset too when read `Pooled`) are fitted to its runs against
//! that shared model, within each run by default (`terms::Fit`). Their mean over
//! the units is the type's value of each term and their scatter over the units, less what
//! the units' own estimation noise (jackknife over their runs) explains, is the type's
//! unit-to-unit spread: the prior of every later unit calibration.
//!
//! The terms are put in the order in which the fleet resolves them best (spread against
//! estimation noise, largest first): the unit calibration tries them in that order, so the
//! first term a unit pays a parameter for is the one in which units are most distinctly
//! different.
//!
//! The file is JSON (`TypeFile`), with the shared model's fog-core encoding in hex, so a
//! type is one self-contained file to keep, diff and record in the registry.

use anyhow::{anyhow, bail, Context, Result};
use fog_core::model::format::{RbfModel, MAX_ENCODED_LEN};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

use super::solve::{own_estimate, UnitRows};
use super::terms::Fit;
use super::terms::{raw_coefficient, term_name, unit_terms, UnitTerm};
use crate::io::runs::Run;
use crate::train::dataset_from_runs;

/// Fewest units a type is learnt from: a spread needs units to scatter, and with two
/// there is one degree of freedom, too few to test a third unit against.
pub const MIN_TYPE_UNITS: usize = 3;
/// Fewest runs per unit: the jackknife over a unit's runs needs two.
pub const MIN_RUNS_PER_UNIT: usize = 2;
/// The type file's format tag.
pub const TYPE_FORMAT: &str = "fogsim-type 1";
/// Most bytes of a type file read (1,000 units of a few hundred bytes each and the model).
pub const MAX_TYPE_FILE_BYTES: u64 = 4 * 1024 * 1024;

/// One unit term of the type: its value and spread over the units.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TypeTerm {
    /// `offset`, `gain` or `linear:J` (input J of the model).
    pub term: String,
    /// In the physics' words (`Shupe coefficient`, ...).
    pub name: String,
    /// Mean over the units, model units (deg/h, or per normalised input).
    pub mean: f64,
    /// Unit-to-unit spread (1 sigma) with the units' estimation noise removed, model units.
    pub spread: f64,
    /// Scatter of the units' estimates (1 sigma), model units.
    pub scatter: f64,
    /// rms of the units' own jackknife standard errors, model units.
    pub noise: f64,
    /// Mean and spread in raw units, and that unit (`deg/h per degC/s`, ...).
    pub raw_mean: f64,
    pub raw_spread: f64,
    pub raw_unit: String,
}

/// One unit the type was learnt from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TypeUnit {
    pub unit_id: String,
    pub runs: usize,
    /// Its own estimate of every term and the jackknife standard error, model units.
    pub estimate: Vec<f64>,
    pub se: Vec<f64>,
}

/// A type model (the file `--type-out` writes and `--type` reads).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TypeFile {
    pub format: String,
    pub type_id: String,
    pub units: Vec<TypeUnit>,
    /// Every unit term, in the model's order (`terms::unit_terms`).
    pub terms: Vec<TypeTerm>,
    /// Indices into `terms`, best resolved by the fleet first: the unit calibration's order.
    pub order: Vec<usize>,
    /// rms of the units' rows after each unit's own terms, deg/h: how well shared model
    /// and unit terms together fit the fleet (what the backfitting rounds lower).
    pub unit_residual_rms_dph: f64,
    /// That rms after each round of `learn_type` (the first: the model trained on the
    /// runs as measured).
    pub rounds_rms_dph: Vec<f64>,
    /// The shared model, fog-core encoding, hex.
    pub model_hex: String,
    /// How the units were fitted, and every unit calibrated against this type is
    /// (`within_runs` or `pooled`; absent in types before 2026-12-03: `pooled`).
    #[serde(default = "pooled")]
    pub unit_fit: Fit,
}

fn pooled() -> Fit {
    Fit::Pooled
}

/// A type model in memory: the file's fields with the model decoded.
#[derive(Clone, Debug)]
pub struct TypeModel {
    pub file: TypeFile,
    pub model: RbfModel,
}

impl TypeModel {
    pub fn terms(&self) -> Vec<UnitTerm> {
        unit_terms(&self.model, self.file.unit_fit)
    }
    pub fn mean(&self) -> Vec<f64> {
        self.file.terms.iter().map(|t| t.mean).collect()
    }
    pub fn spread(&self) -> Vec<f64> {
        self.file.terms.iter().map(|t| t.spread).collect()
    }
    pub fn runs(&self) -> usize {
        self.file.units.iter().map(|u| u.runs).sum()
    }

    /// One line per term and the units, for people.
    pub fn summary(&self) -> String {
        let f = &self.file;
        let mut s = format!(
            "type {}: {} units, {} runs, read {}; unit terms, best resolved first (value and unit-to-unit spread, raw units):\n",
            f.type_id,
            f.units.len(),
            self.runs(),
            match f.unit_fit {
                Fit::WithinRuns => "within runs",
                Fit::Pooled => "pooled over runs",
            }
        );
        if !f.rounds_rms_dph.is_empty() {
            let r: Vec<String> = f.rounds_rms_dph.iter().map(|v| format!("{v:.4}")).collect();
            s += &format!(
                "  shared model and unit terms fitted in turn: units' residual rms {} deg/h by round (kept {:.4})\n",
                r.join(" -> "),
                f.unit_residual_rms_dph
            );
        }
        for &k in &f.order {
            let t = &f.terms[k];
            s += &format!(
                "  {:<32} {:+.4e} +- {:.4e} {} (units scatter {:.3e}, estimation noise {:.3e}, model units)\n",
                t.name, t.raw_mean, t.raw_spread, t.raw_unit, t.scatter, t.noise
            );
        }
        s
    }

    /// Reads a type file (size-bounded), checks it whole.
    pub fn read(path: &Path) -> Result<Self> {
        let bytes = crate::io::bounded::read_bounded(path, MAX_TYPE_FILE_BYTES)
            .map_err(|e| anyhow!("{}: {e}", path.display()))?;
        let file: TypeFile = serde_json::from_slice(&bytes)
            .map_err(|e| anyhow!("{}: not a type file ({e})", path.display()))?;
        Self::from_file(file).with_context(|| format!("{}", path.display()))
    }

    /// Checks a parsed type file and decodes its model.
    pub fn from_file(file: TypeFile) -> Result<Self> {
        if file.format != TYPE_FORMAT {
            bail!("format `{}`: this build reads `{TYPE_FORMAT}`", file.format);
        }
        let bytes = from_hex(&file.model_hex)?;
        let model = RbfModel::decode(&bytes).map_err(|e| anyhow!("its model: {e}"))?;
        let p = unit_terms(&model, file.unit_fit).len();
        if file.terms.len() != p {
            bail!("{} terms for a model with {p} unit terms", file.terms.len());
        }
        let mut seen = file.order.clone();
        seen.sort_unstable();
        if seen != (0..p).collect::<Vec<_>>() {
            bail!("its term order is not a permutation of the {p} terms");
        }
        for t in &file.terms {
            if !(t.mean.is_finite() && t.spread.is_finite() && t.spread > 0.0) {
                bail!(
                    "term `{}`: mean and spread must be finite, spread > 0",
                    t.name
                );
            }
        }
        if let Some(u) = file
            .units
            .iter()
            .find(|u| u.estimate.len() != p || u.se.len() != p)
        {
            bail!(
                "unit {}: {} estimates for {p} unit terms",
                u.unit_id,
                u.estimate.len()
            );
        }
        if file.units.len() < MIN_TYPE_UNITS {
            bail!(
                "{} units: a type needs at least {MIN_TYPE_UNITS}",
                file.units.len()
            );
        }
        Ok(Self { file, model })
    }

    /// The file's bytes (pretty JSON, newline-terminated).
    pub fn to_bytes(&self) -> Result<Vec<u8>> {
        let mut v = serde_json::to_vec_pretty(&self.file)?;
        v.push(b'\n');
        Ok(v)
    }
}

/// Each unit's id and the indices of its runs.
pub type UnitRuns = Vec<(String, Vec<usize>)>;

/// The runs of each unit (its `unit_id` metadata), in order of first appearance, after
/// checking they are one type's: every run names its unit, and no two `type_id`s mix.
pub fn runs_by_unit(runs: &[Run]) -> Result<(String, UnitRuns)> {
    let mut types: BTreeMap<String, usize> = BTreeMap::new();
    let mut units: Vec<(String, Vec<usize>)> = Vec::new();
    for (i, r) in runs.iter().enumerate() {
        let Some(u) = r
            .meta_value("unit_id")
            .map(str::trim)
            .filter(|u| !u.is_empty())
        else {
            bail!(
                "{}: no `unit_id` metadata; a type is learnt from the runs of named units",
                r.name()
            );
        };
        if let Some(t) = r.meta_value("type_id").map(str::trim) {
            *types.entry(t.to_string()).or_default() += 1;
        }
        match units.iter_mut().find(|(id, _)| id == u) {
            Some((_, v)) => v.push(i),
            None => units.push((u.to_string(), vec![i])),
        }
    }
    if types.len() > 1 {
        let list: Vec<String> = types
            .iter()
            .map(|(t, n)| format!("{t} ({n} runs)"))
            .collect();
        bail!(
            "runs of {} types mixed: {}; a type model is one design's",
            types.len(),
            list.join(", ")
        );
    }
    let type_id = types.into_keys().next().unwrap_or_else(|| "unnamed".into());
    Ok((type_id, units))
}

/// The runs of each unit after checking they can make a type: one type, at least
/// `MIN_TYPE_UNITS` units of at least `MIN_RUNS_PER_UNIT` runs (checked before any
/// training, so bad input is refused at once).
pub fn check_type_runs(runs: &[Run]) -> Result<(String, UnitRuns)> {
    let (type_id, units) = runs_by_unit(runs)?;
    if units.len() < MIN_TYPE_UNITS {
        bail!(
            "{} unit(s): a type's unit-to-unit spread needs at least {MIN_TYPE_UNITS} units to be tested",
            units.len()
        );
    }
    if let Some((u, v)) = units.iter().find(|(_, v)| v.len() < MIN_RUNS_PER_UNIT) {
        bail!(
            "unit {u}: {} run(s); each unit of a type needs at least {MIN_RUNS_PER_UNIT} (its estimate's error is measured by leaving one out)",
            v.len()
        );
    }
    Ok((type_id, units))
}

/// Learns the type from `runs` (several units' cold starts) against `model`, the shared
/// model trained on those runs.
pub fn fit_type(
    model: &RbfModel,
    runs: &[Run],
    type_id_override: Option<&str>,
    fit: Fit,
) -> Result<TypeModel> {
    let (type_id, units) = check_type_runs(runs)?;
    let type_id = type_id_override.map_or(type_id, str::to_string);
    let terms = unit_terms(model, fit);
    let p = terms.len();
    let mut fitted = Vec::with_capacity(units.len());
    let (mut ss, mut rows_n) = (0.0, 0usize);
    for (u, idx) in &units {
        let unit_runs: Vec<Run> = idx.iter().map(|&i| runs[i].clone()).collect();
        let ds =
            dataset_from_runs(&unit_runs, &model.inputs).map_err(|e| anyhow!("unit {u}: {e}"))?;
        let rows = UnitRows::new(model, &terms, &ds, fit)?;
        let (estimate, se) = own_estimate(&rows).map_err(|e| anyhow!("unit {u}: {e}"))?;
        let res = rows.corrected(0..rows.residual.len(), &estimate);
        ss += res.iter().map(|r| r * r).sum::<f64>();
        rows_n += res.len();
        fitted.push(TypeUnit {
            unit_id: u.clone(),
            runs: idx.len(),
            estimate,
            se,
        });
    }
    let n = fitted.len() as f64;
    let mut type_terms = Vec::with_capacity(p);
    for (k, &t) in terms.iter().enumerate() {
        let mean = fitted.iter().map(|u| u.estimate[k]).sum::<f64>() / n;
        let var = fitted
            .iter()
            .map(|u| (u.estimate[k] - mean).powi(2))
            .sum::<f64>()
            / (n - 1.0);
        let noise2 = fitted.iter().map(|u| u.se[k] * u.se[k]).sum::<f64>() / n;
        // What the scatter shows beyond the units' own noise; where it shows nothing, the
        // spread is the mean's own uncertainty (noise / sqrt(units)), never zero: a prior
        // of zero width would forbid what the fleet could not rule out.
        let spread = (var - noise2).max(noise2 / n).sqrt().max(1e-12);
        let (raw_mean, raw_unit) = raw_coefficient(model, t, mean);
        let (raw_spread, _) = raw_coefficient(model, t, spread);
        type_terms.push(TypeTerm {
            term: match t {
                UnitTerm::Offset => "offset".into(),
                UnitTerm::Gain => "gain".into(),
                UnitTerm::Linear(j) => format!("linear:{j}"),
                UnitTerm::LinearByT(j) => format!("linear_by_t:{j}"),
            },
            name: term_name(model, t),
            mean,
            spread,
            scatter: var.sqrt(),
            noise: noise2.sqrt(),
            raw_mean,
            raw_spread: raw_spread.abs(),
            raw_unit: raw_unit.into(),
        });
    }
    let mut order: Vec<usize> = (0..p).collect();
    let resolution = |k: usize| {
        let t = &type_terms[k];
        t.spread * t.spread / (t.noise * t.noise).max(f64::MIN_POSITIVE)
    };
    order.sort_by(|&a, &b| resolution(b).total_cmp(&resolution(a)).then(a.cmp(&b)));
    let mut buf = [0u8; MAX_ENCODED_LEN];
    let len = model
        .encode(&mut buf)
        .map_err(|e| anyhow!("encoding the shared model: {e}"))?;
    TypeModel::from_file(TypeFile {
        format: TYPE_FORMAT.into(),
        type_id,
        units: fitted,
        terms: type_terms,
        order,
        unit_residual_rms_dph: (ss / rows_n.max(1) as f64).sqrt(),
        rounds_rms_dph: Vec::new(),
        model_hex: to_hex(&buf[..len]),
        unit_fit: fit,
    })
}

/// Most backfitting rounds of `learn_type`.
pub const MAX_ROUNDS: usize = 4;
/// A round is kept only if it lowers the units' residual rms by more than this fraction.
pub const ROUND_GAIN: f64 = 0.01;

/// Learns a type from several units' `runs`, training its shared model with `train`: the
/// shared model and the unit terms are fitted in turn (backfitting). A model trained on
/// the runs as measured must carry every unit's own offset, temperature coefficient and
/// Shupe coefficient as scatter it cannot fit (measured on the simulator's fleet: the
/// held-out rms of 10 units' runs was 5x a single unit's, and validation chose one centre);
/// so after the unit terms are fitted, each unit's deviation from the type (shrunk by its
/// estimation noise: spread^2 / (spread^2 + se^2)) is taken out of its runs and the shared
/// model trained again, until the units' residual stops falling by `ROUND_GAIN`.
pub fn learn_type(
    runs: &[Run],
    type_id: Option<&str>,
    fit: Fit,
    train: &mut dyn FnMut(Vec<Run>) -> Result<RbfModel>,
) -> Result<TypeModel> {
    check_type_runs(runs)?;
    let shared = train(runs.to_vec())?;
    let mut ty = fit_type(&shared, runs, type_id, fit)?;
    let mut history = vec![ty.file.unit_residual_rms_dph];
    for _ in 1..MAX_ROUNDS {
        let shared = train(corrected_runs(&ty, runs)?)?;
        let next = fit_type(&shared, runs, type_id, fit)?;
        let rms = next.file.unit_residual_rms_dph;
        history.push(rms);
        if rms >= (1.0 - ROUND_GAIN) * ty.file.unit_residual_rms_dph {
            break;
        }
        ty = next;
    }
    ty.file.rounds_rms_dph = history;
    Ok(ty)
}

/// `runs` with each unit's deviation from the type (its own estimates less the type's mean,
/// shrunk by spread^2 / (spread^2 + se^2)) taken out of `rate_dph`: what the shared model
/// should learn from. The correction is computed on the model's 10 s rows and
/// interpolated in time onto the run's rows.
pub fn corrected_runs(ty: &TypeModel, runs: &[Run]) -> Result<Vec<Run>> {
    let model = &ty.model;
    let terms = ty.terms();
    let mut out = runs.to_vec();
    for u in &ty.file.units {
        let delta: Vec<f64> = ty
            .file
            .terms
            .iter()
            .enumerate()
            .map(|(k, t)| {
                let s2 = t.spread * t.spread;
                let e2 = u.se[k] * u.se[k];
                let shrink = if e2.is_finite() { s2 / (s2 + e2) } else { 0.0 };
                (u.estimate[k] - t.mean) * shrink
            })
            .collect();
        for run in out
            .iter_mut()
            .filter(|r| r.meta_value("unit_id").map(str::trim) == Some(u.unit_id.as_str()))
        {
            let ds = dataset_from_runs(std::slice::from_ref(run), &model.inputs)
                .map_err(|e| anyhow!("{}: {e}", run.name()))?;
            let d = super::terms::design(model, &terms, &ds)?;
            let c: Vec<f64> = (0..ds.len())
                .map(|i| {
                    d.columns
                        .iter()
                        .zip(&delta)
                        .map(|(col, b)| col[i] * b)
                        .sum()
                })
                .collect();
            let t = run.t_s().to_vec();
            let Some(col) = run.columns.iter().position(|c| c == "rate_dph") else {
                bail!("{}: no rate_dph column", run.name());
            };
            for (i, ti) in t.iter().enumerate() {
                run.data[col][i] -= interpolate(&ds.t_s, &c, *ti);
            }
        }
    }
    Ok(out)
}

/// Piecewise-linear `y(x)` at `at`, held at the ends (`x` increasing, non-empty).
fn interpolate(x: &[f64], y: &[f64], at: f64) -> f64 {
    match x.partition_point(|&v| v < at) {
        0 => y.first().copied().unwrap_or(0.0),
        k if k >= x.len() => y.last().copied().unwrap_or(0.0),
        k => {
            let f = (at - x[k - 1]) / (x[k] - x[k - 1]);
            y[k - 1] + f * (y[k] - y[k - 1])
        }
    }
}

fn to_hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

fn from_hex(s: &str) -> Result<Vec<u8>> {
    if !s.len().is_multiple_of(2) || s.len() > 2 * MAX_ENCODED_LEN {
        bail!("its model is not hex of at most {MAX_ENCODED_LEN} bytes");
    }
    (0..s.len())
        .step_by(2)
        .map(|i| {
            u8::from_str_radix(s.get(i..i + 2).unwrap_or("zz"), 16)
                .map_err(|_| anyhow!("its model is not hex (at character {i})"))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use fog_core::model::format::{FeatureKind, FeatureSpec};

    /// A model on T and dT/dt of linear terms `linear` alone (no centres).
    fn linear_model(linear: f32) -> RbfModel {
        let mut m = RbfModel::empty();
        m.n_rbf_inputs = 0;
        for k in [FeatureKind::TempC, FeatureKind::TempRateCps] {
            m.inputs.push(FeatureSpec::plain(k)).unwrap();
            m.input_offset.push(0.0).unwrap();
            m.input_scale.push(1.0).unwrap();
            m.input_min.push(-40.0).unwrap();
            m.input_max.push(80.0).unwrap();
            m.linear.push(linear).unwrap();
        }
        m
    }

    #[test]
    fn a_shared_model_of_its_bias_alone_makes_a_type_of_the_units_linear_terms() {
        // the trainer's network kept no centre on some simulated fleets (the units' own
        // linear terms carry their drift): the type is learnt without a warm-up gain,
        // which no unit could show, and reads back
        let runs = super::super::law::tests::fleet(
            &super::super::law::tests::two_node,
            &|_, temp, rate| 0.001 * temp + 9.0 * rate,
        );
        let ty = fit_type(&linear_model(0.0), &runs, None, Fit::WithinRuns).unwrap();
        let names: Vec<&str> = ty.file.terms.iter().map(|t| t.name.as_str()).collect();
        assert_eq!(names, ["temperature coefficient", "Shupe coefficient"]);
        TypeModel::from_file(ty.file.clone()).unwrap();
    }

    /// The JSON of a type read pooled (before `unit_fit` existed: no such key) of a model on
    /// T and dT/dt: terms offset, gain, linear:0, linear:1; 3 units.
    fn pooled_type_json() -> serde_json::Value {
        let m = linear_model(0.01);
        let mut buf = [0u8; MAX_ENCODED_LEN];
        let len = m.encode(&mut buf).unwrap();
        let terms = unit_terms(&m, Fit::Pooled);
        let file = TypeFile {
            format: TYPE_FORMAT.into(),
            type_id: "t".into(),
            units: (0..3)
                .map(|u| TypeUnit {
                    unit_id: format!("U{u}"),
                    runs: 2,
                    estimate: vec![0.0; terms.len()],
                    se: vec![0.01; terms.len()],
                })
                .collect(),
            terms: terms
                .iter()
                .map(|&t| TypeTerm {
                    term: format!("{t:?}"),
                    name: term_name(&m, t),
                    mean: 0.0,
                    spread: 0.1,
                    scatter: 0.1,
                    noise: 0.01,
                    raw_mean: 0.0,
                    raw_spread: 0.1,
                    raw_unit: String::new(),
                })
                .collect(),
            order: (0..terms.len()).collect(),
            unit_residual_rms_dph: 0.01,
            rounds_rms_dph: Vec::new(),
            model_hex: to_hex(&buf[..len]),
            unit_fit: Fit::Pooled,
        };
        let mut v = serde_json::to_value(&file).unwrap();
        v.as_object_mut().unwrap().remove("unit_fit");
        v
    }

    #[test]
    fn a_type_file_without_unit_fit_reads_pooled_and_a_mismatch_is_refused() {
        let old: TypeFile = serde_json::from_value(pooled_type_json()).unwrap();
        let ty = TypeModel::from_file(old).unwrap();
        assert_eq!(ty.file.unit_fit, Fit::Pooled);
        assert_eq!(ty.terms()[0], UnitTerm::Offset);
        // the same terms said to be read within runs: one term too many (no offset there)
        let mut v = pooled_type_json();
        v["unit_fit"] = "within_runs".into();
        let err = TypeModel::from_file(serde_json::from_value(v).unwrap()).unwrap_err();
        assert_eq!(err.to_string(), "4 terms for a model with 3 unit terms");
    }
}
