//! The unit terms of a type model: what may differ from one unit of a gyro type to the
//! next, written as corrections to the type's shared drift model that fold exactly into an
//! ordinary device model.
//!
//! A unit's drift is the type's prediction p(x) corrected by
//!
//!   c(x) = offset + gain (p(x) - bias) + sum_j l_j xn_j      (xn_j: the model's normalised input j)
//!
//! The offset is the unit's own constant bias (deg/h), the gain scales the type's whole
//! warm-up shape (a unit whose Shupe or gradient coefficients are all a few % larger), and
//! each l_j is a linear term in one of the type's inputs: in T it is the unit's own
//! temperature coefficient, in dT/dt its own Shupe coefficient, in the warm-up clock its own
//! warm-up amplitude. These are the parameters physics says vary between units of one
//! design; they are also exactly what fog-core's model format carries (bias, the output
//! weights and the linear terms), so a calibrated unit is an ordinary model, read by every
//! firmware that reads the type's.
//!
//! Every column of the design is evaluated with fog-core's own prediction (a model that has
//! only that term), so whatever the device does to an input (normalisation, clamping) the
//! fit sees too, and `fold` is exact up to the f32 rounding of the stored coefficients.

use anyhow::{bail, Result};
use fog_core::model::format::{FeatureKind, RbfModel};

use crate::train::{predict_batch, Dataset};

/// How a type's units and a unit's rows are fitted (`solve`'s module notes; `--unit-fit`, a type's
/// `unit_fit`).
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "snake_case")]
pub enum Fit {
    /// Over all the unit's runs as measured (every type before 2026-12-03).
    Pooled,
    /// To each run's deviation from its own mean: the default, from the Monte Carlo over
    /// 20 simulated fleets (docs/record/fleet.md).
    #[default]
    WithinRuns,
}

/// One unit term of a type model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnitTerm {
    /// A constant, deg/h.
    Offset,
    /// A factor on the type's prediction less its bias: 0 is the type's shape.
    Gain,
    /// A linear term in the model's normalised input j, deg/h per normalised unit.
    Linear(usize),
    /// A term in t xn_j (t: normalised T): how the unit's input-j coefficient changes with
    /// temperature, e.g. its own Shupe coefficient's cold gain. Offered only on a type model
    /// whose shared model has such terms (`linear_by_t`).
    LinearByT(usize),
}

/// Every unit term a model can carry when fitted `fit`: the offset (pooled only: within
/// runs each run's constant is taken out), the gain (only when the model predicts more
/// than its bias: a gain on nothing is a term no unit can show), then one linear term per
/// input.
pub fn unit_terms(model: &RbfModel, fit: Fit) -> Vec<UnitTerm> {
    let mut t = match fit {
        Fit::Pooled => vec![UnitTerm::Offset],
        Fit::WithinRuns => vec![],
    };
    if predicts_beyond_bias(model) {
        t.push(UnitTerm::Gain);
    }
    t.extend((0..model.inputs.len()).map(UnitTerm::Linear));
    t.extend(
        (0..model.linear_by_t.len().min(model.inputs.len()))
            .filter(|&j| model.linear_by_t[j] != 0.0)
            .map(UnitTerm::LinearByT),
    );
    t
}

/// Whether `model`'s prediction less its bias can be other than zero: a weighted centre, a
/// polynomial or linear coefficient, or a heading harmonic. (Validation may keep none of
/// them: on some simulated fleets the trainer's network kept no centre, the units' own
/// linear terms carrying their drift.)
fn predicts_beyond_bias(model: &RbfModel) -> bool {
    let any = |v: &[f32]| v.iter().any(|&x| x != 0.0);
    any(&model.weights)
        || any(&model.poly)
        || any(&model.linear)
        || any(&model.linear_by_t)
        || model.heading.is_some()
}

/// The term's name in reports and files, in the physics' words where they fit.
pub fn term_name(model: &RbfModel, term: UnitTerm) -> String {
    match term {
        UnitTerm::Offset => "offset".into(),
        UnitTerm::Gain => "warm-up gain".into(),
        UnitTerm::Linear(j) => match model.inputs.get(j).map(|s| s.kind) {
            Some(FeatureKind::TempC) => "temperature coefficient".into(),
            Some(FeatureKind::TempRateCps | FeatureKind::TempRateDiffusionCps) => {
                "Shupe coefficient".into()
            }
            Some(FeatureKind::TempAccelCps2 | FeatureKind::TempAccelFlatStartCps2) => {
                "gradient (d2T/dt2) coefficient".into()
            }
            Some(FeatureKind::TempRiseC) => "rise coefficient".into(),
            // a type of the law shape has two clocks: named by their time constants
            Some(FeatureKind::PowerOnDecay) => {
                format!("warm-up clock amplitude ({:.0} s)", model.inputs[j].tau_s)
            }
            Some(FeatureKind::PowerOnDecayStretch) => {
                format!("warm-up clock stretch ({:.0} s)", model.inputs[j].tau_s)
            }
            Some(FeatureKind::TempLagC) => "lagged-temperature coefficient".into(),
            _ => format!("input {j} coefficient"),
        },
        UnitTerm::LinearByT(j) => format!(
            "{} x T",
            term_name(model, UnitTerm::Linear(j)).replace(" coefficient", "")
        ),
    }
}

/// The term's coefficient in raw units, and that unit: a linear term per unit of its input
/// (deg/h per degC for T, per degC/s for dT/dt, ...), the offset in deg/h, the gain as is.
pub fn raw_coefficient(model: &RbfModel, term: UnitTerm, coef: f64) -> (f64, &'static str) {
    match term {
        UnitTerm::Offset => (coef, "deg/h"),
        UnitTerm::Gain => (coef, "(factor)"),
        UnitTerm::Linear(j) => {
            let scale = model.input_scale.get(j).map_or(1.0, |s| f64::from(*s));
            let unit = match model.inputs.get(j).map(|s| s.kind) {
                Some(FeatureKind::TempC | FeatureKind::TempRiseC | FeatureKind::TempLagC) => {
                    "deg/h per degC"
                }
                Some(FeatureKind::TempRateCps | FeatureKind::TempRateDiffusionCps) => {
                    "deg/h per degC/s"
                }
                Some(FeatureKind::TempAccelCps2 | FeatureKind::TempAccelFlatStartCps2) => {
                    "deg/h per degC/s^2"
                }
                _ => "deg/h per unit",
            };
            (coef / scale, unit)
        }
        UnitTerm::LinearByT(j) => {
            let scale = |k: usize| model.input_scale.get(k).map_or(1.0, |s| f64::from(*s));
            (coef / (scale(j) * scale(0)), "deg/h per unit per degC")
        }
    }
}

/// The type's prediction and one design column per term (row order of `ds`), each
/// evaluated with fog-core's maths.
pub fn design(model: &RbfModel, terms: &[UnitTerm], ds: &Dataset) -> Result<Design> {
    let pred = predict_batch(model, ds.rows())?;
    let bias = f64::from(model.bias_dph);
    let mut columns = Vec::with_capacity(terms.len());
    for &t in terms {
        columns.push(match t {
            UnitTerm::Offset => vec![1.0; ds.len()],
            UnitTerm::Gain => pred.iter().map(|p| p - bias).collect(),
            UnitTerm::Linear(j) => predict_batch(&only_linear(model, j, false), ds.rows())?,
            UnitTerm::LinearByT(j) => predict_batch(&only_linear(model, j, true), ds.rows())?,
        });
    }
    Ok(Design { pred, columns })
}

/// A model's prediction and the unit terms' design columns on some rows.
#[derive(Clone, Debug)]
pub struct Design {
    pub pred: Vec<f64>,
    /// `columns[k][i]`: term k's regressor on row i.
    pub columns: Vec<Vec<f64>>,
}

/// `model` with every term zero but a coefficient of 1 on input j's linear term (or, with
/// `by_t`, on its `linear_by_t` term).
fn only_linear(model: &RbfModel, j: usize, by_t: bool) -> RbfModel {
    let mut m = model.clone();
    m.bias_dph = 0.0;
    m.weights.iter_mut().for_each(|w| *w = 0.0);
    m.poly.iter_mut().for_each(|p| *p = 0.0);
    m.linear_by_t.iter_mut().for_each(|p| *p = 0.0);
    m.linear.iter_mut().for_each(|p| *p = 0.0);
    let target = if by_t {
        &mut m.linear_by_t
    } else {
        &mut m.linear
    };
    if let Some(l) = target.get_mut(j) {
        *l = 1.0;
    }
    m
}

/// The type model with the unit terms' coefficients folded in: an ordinary device model.
pub fn fold(model: &RbfModel, terms: &[UnitTerm], coef: &[f64]) -> Result<RbfModel> {
    let mut out = model.clone();
    let gain = terms
        .iter()
        .zip(coef)
        .find(|(t, _)| **t == UnitTerm::Gain)
        .map_or(0.0, |(_, c)| *c);
    let factor = 1.0 + gain;
    let scale = |v: &mut f32| *v = (f64::from(*v) * factor) as f32;
    out.weights.iter_mut().for_each(scale);
    out.poly.iter_mut().for_each(scale);
    out.linear.iter_mut().for_each(scale);
    out.linear_by_t.iter_mut().for_each(scale);
    for (&t, &c) in terms.iter().zip(coef) {
        match t {
            UnitTerm::Offset => out.bias_dph = (f64::from(out.bias_dph) + c) as f32,
            UnitTerm::Gain => {}
            UnitTerm::Linear(j) => match out.linear.get_mut(j) {
                Some(l) => *l = (f64::from(*l) + c) as f32,
                None => bail!("unit term on input {j}: the model has no such input"),
            },
            UnitTerm::LinearByT(j) => match out.linear_by_t.get_mut(j) {
                Some(l) => *l = (f64::from(*l) + c) as f32,
                None => bail!("unit term on T x input {j}: the model has no such term"),
            },
        }
    }
    let finite = out.bias_dph.is_finite()
        && out.weights.iter().chain(&out.poly).all(|v| v.is_finite())
        && out
            .linear
            .iter()
            .chain(&out.linear_by_t)
            .all(|v| v.is_finite());
    if !finite {
        bail!("the unit terms make the model not finite: not folded");
    }
    Ok(out)
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use fog_core::model::format::FeatureSpec;

    /// T and dT/dt with linear terms and a T polynomial, no Gaussians.
    pub(in crate::train::type_unit) fn model() -> RbfModel {
        let mut m = RbfModel::empty();
        m.n_rbf_inputs = 0;
        for (k, off, scale, lin) in [
            (FeatureKind::TempC, 25.0f32, 10.0f32, 0.02f32),
            (FeatureKind::TempRateCps, 0.0, 0.01, 0.15),
        ] {
            m.inputs.push(FeatureSpec::plain(k)).unwrap();
            m.input_offset.push(off).unwrap();
            m.input_scale.push(scale).unwrap();
            m.input_min.push(-40.0).unwrap();
            m.input_max.push(80.0).unwrap();
            m.linear.push(lin).unwrap();
        }
        m.poly.push(0.004).unwrap();
        m.bias_dph = 0.3;
        m
    }

    fn dataset(m: &RbfModel) -> Dataset {
        let specs: Vec<FeatureSpec> = m.inputs.iter().copied().collect();
        let mut ds = Dataset::with_specs(specs, vec!["t".into(), "rate".into()]).unwrap();
        let rows: Vec<Vec<f64>> = (0..50)
            .map(|i| vec![-30.0 + 1.7 * i as f64, 0.012 * (-(i as f64) / 9.0).exp()])
            .collect();
        let t: Vec<f64> = (0..50).map(|i| 10.0 * i as f64).collect();
        ds.push_group("r", &rows, &vec![0.0; 50], &t).unwrap();
        ds
    }

    #[test]
    fn a_model_of_its_bias_alone_offers_no_gain() {
        // validation may keep nothing but the bias (seen on simulated fleets with the
        // trainer's network): the gain's column is zero, no unit can show it, and the type
        // must not carry a term it cannot estimate
        let mut m = model();
        m.weights.iter_mut().for_each(|w| *w = 0.0);
        m.poly.iter_mut().for_each(|p| *p = 0.0);
        m.linear.iter_mut().for_each(|l| *l = 0.0);
        m.linear_by_t.iter_mut().for_each(|l| *l = 0.0);
        m.heading = None;
        let terms = unit_terms(&m, Fit::WithinRuns);
        assert_eq!(terms, [UnitTerm::Linear(0), UnitTerm::Linear(1)]);
        assert!(unit_terms(&model(), Fit::WithinRuns).contains(&UnitTerm::Gain));
    }

    #[test]
    fn folded_terms_predict_what_the_design_says() {
        let m = model();
        let ds = dataset(&m);
        let terms = unit_terms(&m, Fit::Pooled);
        assert_eq!(terms.len(), 4);
        let coef = [0.011, -0.07, 0.004, -0.02];
        let d = design(&m, &terms, &ds).unwrap();
        let folded = fold(&m, &terms, &coef).unwrap();
        let after = predict_batch(&folded, ds.rows()).unwrap();
        for (i, a) in after.iter().enumerate() {
            let want = d.pred[i]
                + d.columns
                    .iter()
                    .zip(&coef)
                    .map(|(c, b)| c[i] * b)
                    .sum::<f64>();
            assert!(
                (a - want).abs() < 2e-6 * (1.0 + want.abs()),
                "row {i}: {a} vs {want}"
            );
        }
        // the gain scales the shape and leaves the bias: a pure offset changes only it
        let only_offset = fold(&m, &terms, &[0.05, 0.0, 0.0, 0.0]).unwrap();
        assert_eq!(only_offset.linear, m.linear);
        assert!((only_offset.bias_dph - 0.35).abs() < 1e-6);
    }

    #[test]
    fn a_temperature_coupled_term_is_offered_and_folds_exactly_where_the_type_has_one() {
        let mut m = model();
        assert!(!unit_terms(&m, Fit::Pooled).contains(&UnitTerm::LinearByT(1)));
        m.linear_by_t.push(0.0).unwrap();
        m.linear_by_t.push(0.03).unwrap();
        let terms = unit_terms(&m, Fit::Pooled);
        assert_eq!(terms.last(), Some(&UnitTerm::LinearByT(1)));
        assert_eq!(term_name(&m, UnitTerm::LinearByT(1)), "Shupe x T");
        let ds = dataset(&m);
        let coef = [0.0, 0.1, 0.0, 0.0, 0.02];
        let d = design(&m, &terms, &ds).unwrap();
        let after = predict_batch(&fold(&m, &terms, &coef).unwrap(), ds.rows()).unwrap();
        for (i, a) in after.iter().enumerate() {
            let want = d.pred[i] + 0.1 * d.columns[1][i] + 0.02 * d.columns[4][i];
            assert!(
                (a - want).abs() < 2e-6 * (1.0 + want.abs()),
                "row {i}: {a} vs {want}"
            );
        }
    }

    #[test]
    fn a_term_that_makes_the_model_not_finite_is_refused() {
        let m = model();
        let terms = unit_terms(&m, Fit::Pooled);
        assert!(fold(&m, &terms, &[0.0, 0.0, f64::INFINITY, 0.0]).is_err());
    }
}
