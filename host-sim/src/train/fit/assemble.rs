//! Turns the solved selection (bias, linear coefficients, centre weights) into fog-core's
//! `RbfModel`: f32 fields in heapless vectors, RBF inputs first, the trained input range,
//! training metadata; then lets fog-core validate it, so the trainer can only emit models
//! the device will accept.

use crate::train::data::normalize::Normalizer;
use crate::train::error::{Result, TrainError};
use fog_core::model::format::{FeatureSpec, RbfModel, TrainingMeta, MAX_RBF_INPUTS};

/// What a forced (always-present) regressor is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ForcedTerm {
    /// The constant column: the model's `bias_dph`.
    Bias,
    /// Input j's normalised value: the model's `linear[j]`.
    Linear(usize),
    /// Normalised input 0 to the power k (1..=3): the model's `poly[k-1]`.
    Poly(usize),
    /// t times input j's normalised value: the model's `linear_by_t[j]`.
    LinearByT(usize),
}

/// The parts of a trained model in plain f64 form.
pub struct ModelParts<'a> {
    pub specs: &'a [FeatureSpec],
    pub normalizer: &'a Normalizer,
    pub n_rbf_inputs: usize,
    /// Normalised training points, `stride` = number of inputs per point.
    pub points: &'a [f32],
    pub width: f64,
    pub forced: &'a [ForcedTerm],
    /// Candidate index of each centre.
    pub centers: &'a [usize],
    /// One coefficient per forced term, then one per centre.
    pub theta: &'a [f64],
    pub gyro_id: &'a str,
    pub heldout_rms_dph: f64,
    pub n_train: usize,
}

fn capacity(what: &str) -> TrainError {
    TrainError::Model {
        why: format!("{what} exceed the model format's capacity"),
    }
}

/// Sets `v[index] = value`, first growing `v` with zeros to at least `len` entries.
fn set_grown<const N: usize>(
    v: &mut heapless::Vec<f32, N>,
    len: usize,
    index: usize,
    value: f64,
    what: &str,
) -> Result<()> {
    while v.len() < len.max(index + 1) {
        v.push(0.0).map_err(|_| capacity(what))?;
    }
    v[index] = value as f32;
    Ok(())
}

/// Builds and validates the model.
pub fn assemble(parts: &ModelParts<'_>) -> Result<RbfModel> {
    let d = parts.specs.len();
    let nf = parts.forced.len();
    let mut model = RbfModel {
        n_rbf_inputs: parts.n_rbf_inputs as u8,
        bias_dph: 0.0,
        meta: TrainingMeta {
            gyro_id: heapless::String::new(),
            heldout_rms_dph: parts.heldout_rms_dph as f32,
            n_train: parts.n_train as u32,
        },
        ..RbfModel::empty()
    };
    let norm = parts.normalizer;
    for j in 0..d {
        model
            .inputs
            .push(parts.specs[j])
            .map_err(|_| capacity("inputs"))?;
        model
            .input_offset
            .push(norm.offset[j])
            .map_err(|_| capacity("inputs"))?;
        model
            .input_scale
            .push(norm.scale[j])
            .map_err(|_| capacity("inputs"))?;
        model
            .input_min
            .push(norm.min[j])
            .map_err(|_| capacity("inputs"))?;
        model
            .input_max
            .push(norm.max[j])
            .map_err(|_| capacity("inputs"))?;
        model.linear.push(0.0).map_err(|_| capacity("inputs"))?;
    }
    for (term, &coef) in parts.forced.iter().zip(parts.theta) {
        match *term {
            ForcedTerm::Bias => model.bias_dph = coef as f32,
            ForcedTerm::Linear(j) => model.linear[j] = coef as f32,
            ForcedTerm::LinearByT(j) => {
                set_grown(&mut model.linear_by_t, d, j, coef, "inputs")?;
            }
            ForcedTerm::Poly(k) => {
                set_grown(&mut model.poly, k, k - 1, coef, "polynomial terms")?;
            }
        }
    }
    for (&k, &w) in parts.centers.iter().zip(&parts.theta[nf..]) {
        // Only the RBF inputs' coordinates are stored: linear-only ones play no part in
        // the distance (config validation holds their count to `MAX_RBF_INPUTS`).
        let mut c = [0.0f32; MAX_RBF_INPUTS];
        let nr = parts.n_rbf_inputs.min(MAX_RBF_INPUTS);
        c[..nr].copy_from_slice(&parts.points[k * d..k * d + nr]);
        model.centers.push(c).map_err(|_| capacity("centres"))?;
        model
            .widths
            .push(parts.width as f32)
            .map_err(|_| capacity("centres"))?;
        model
            .weights
            .push(w as f32)
            .map_err(|_| capacity("centres"))?;
    }
    model
        .meta
        .gyro_id
        .push_str(parts.gyro_id)
        .map_err(|_| TrainError::BadConfig {
            option: "gyro-id",
            why: "longer than 16 bytes".into(),
        })?;
    model
        .validate()
        .map_err(|e| TrainError::Model { why: e.to_string() })?;
    Ok(model)
}
