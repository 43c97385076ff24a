//! The `RbfModel` struct as stored and sent, its training metadata, and the plain
//! operations on it: an empty placeholder, an in-place copy, sizes and output bounds.

use super::inputs::FeatureSpec;
use super::limits::{MAX_CENTERS, MAX_INPUTS, MAX_POLY_DEGREE, MAX_RBF_INPUTS, XN_CLAMP};
use crate::model::cold_start::ColdStartEnvelope;
use crate::model::heading::HeadingHarmonic;
use heapless::{String, Vec};
use serde::{Deserialize, Serialize};

/// Where the model came from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrainingMeta {
    pub gyro_id: String<16>,
    /// Held-out rms of the compensated 10 s drift, deg/h.
    pub heldout_rms_dph: f32,
    /// Number of training samples (candidate centres).
    pub n_train: u32,
}

/// A validated RBF drift model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RbfModel {
    /// How many of `inputs` (the leading ones) enter the RBF distance; the rest are linear-only.
    pub n_rbf_inputs: u8,
    pub inputs: Vec<FeatureSpec, MAX_INPUTS>,
    pub input_offset: Vec<f32, MAX_INPUTS>,
    pub input_scale: Vec<f32, MAX_INPUTS>,
    /// Trained range of each input, raw units (inclusive).
    pub input_min: Vec<f32, MAX_INPUTS>,
    pub input_max: Vec<f32, MAX_INPUTS>,
    /// Linear terms on the normalised inputs, deg/h per unit (zeros for a pure RBF).
    pub linear: Vec<f32, MAX_INPUTS>,
    /// Centres in normalised input space; each has `n_rbf_inputs` used entries.
    pub centers: Vec<[f32; MAX_RBF_INPUTS], MAX_CENTERS>,
    /// Gaussian widths (sigma) in normalised space, > 0.
    pub widths: Vec<f32, MAX_CENTERS>,
    /// Output weights, deg/h.
    pub weights: Vec<f32, MAX_CENTERS>,
    pub bias_dph: f32,
    pub meta: TrainingMeta,
    /// Polynomial base (format version 2): coefficient k-1 multiplies t^k, deg/h, with
    /// t = normalised input 0 held to its trained range; at most `MAX_POLY_DEGREE` terms.
    pub poly: Vec<f32, MAX_POLY_DEGREE>,
    /// Heading harmonic of the bias (format version 3), applied by the north finder while
    /// this model is active; `None`: no heading calibration (also for v1/v2 models).
    pub heading: Option<HeadingHarmonic>,
    /// Temperature-coupled linear terms (format version 4): coefficient j multiplies
    /// t * xn_j, deg/h per unit^2, t as for `poly` (normalised input 0 held to its trained
    /// range), so input j's linear coefficient is linear[j] + linear_by_t[j] t. Empty
    /// (none, also for v1-v3 models) or one per input.
    pub linear_by_t: Vec<f32, MAX_INPUTS>,
    /// The training cold starts' least temperature rise since power-on (format version 5):
    /// the compensator flags a power-on that rises less as not a cold start. `None`: no
    /// check (also for v1-v4 models).
    pub cold_start: Option<ColdStartEnvelope>,
}

impl RbfModel {
    /// A placeholder with no inputs (fails `validate`): the initial value of model storage
    /// that lives in a `static` or is overwritten in place with `copy_from`.
    pub const fn empty() -> Self {
        RbfModel {
            n_rbf_inputs: 0,
            inputs: Vec::new(),
            input_offset: Vec::new(),
            input_scale: Vec::new(),
            input_min: Vec::new(),
            input_max: Vec::new(),
            linear: Vec::new(),
            centers: Vec::new(),
            widths: Vec::new(),
            weights: Vec::new(),
            bias_dph: 0.0,
            meta: TrainingMeta {
                gyro_id: String::new(),
                heldout_rms_dph: 0.0,
                n_train: 0,
            },
            poly: Vec::new(),
            heading: None,
            linear_by_t: Vec::new(),
            cold_start: None,
        }
    }

    /// Make `self` equal to `src`, field by field in place (`*self = src.clone()` would
    /// build the ~1.7 KB model as a temporary on the stack first).
    pub fn copy_from(&mut self, src: &RbfModel) {
        fn copy<T: Copy, const N: usize>(dst: &mut Vec<T, N>, src: &Vec<T, N>) {
            dst.clear();
            // Same capacity on both sides: cannot fail.
            let _ = dst.extend_from_slice(src);
        }
        self.n_rbf_inputs = src.n_rbf_inputs;
        copy(&mut self.inputs, &src.inputs);
        copy(&mut self.input_offset, &src.input_offset);
        copy(&mut self.input_scale, &src.input_scale);
        copy(&mut self.input_min, &src.input_min);
        copy(&mut self.input_max, &src.input_max);
        copy(&mut self.linear, &src.linear);
        copy(&mut self.centers, &src.centers);
        copy(&mut self.widths, &src.widths);
        copy(&mut self.weights, &src.weights);
        copy(&mut self.poly, &src.poly);
        copy(&mut self.linear_by_t, &src.linear_by_t);
        self.heading = src.heading;
        self.cold_start.clone_from(&src.cold_start);
        self.bias_dph = src.bias_dph;
        self.meta.gyro_id.clear();
        let _ = self.meta.gyro_id.push_str(&src.meta.gyro_id);
        self.meta.heldout_rms_dph = src.meta.heldout_rms_dph;
        self.meta.n_train = src.meta.n_train;
    }

    /// Number of inputs.
    pub fn n_inputs(&self) -> usize {
        self.inputs.len()
    }

    /// Number of RBF centres.
    pub fn n_centers(&self) -> usize {
        self.centers.len()
    }

    /// Trained range of input 0 in normalised units (the polynomial's domain), f32 as the
    /// evaluator computes it.
    pub fn poly_domain(&self) -> (f32, f32) {
        let first = |v: &Vec<f32, MAX_INPUTS>| v.first().copied();
        match (
            first(&self.input_min),
            first(&self.input_max),
            first(&self.input_offset),
            first(&self.input_scale),
        ) {
            (Some(lo), Some(hi), Some(off), Some(scale)) => {
                let norm = |v: f32| ((v - off) / scale).clamp(-XN_CLAMP, XN_CLAMP);
                (norm(lo), norm(hi))
            }
            _ => (0.0, 0.0),
        }
    }

    /// Upper bound of |drift| over all inputs, deg/h (f64, from the stored f32 values).
    pub fn worst_case_output_dph(&self) -> f64 {
        let (lo, hi) = self.poly_domain();
        let t = libm::fmax(libm::fabs(lo as f64), libm::fabs(hi as f64));
        let abs = |v: &f32| libm::fabs(*v as f64);
        let linear: f64 = self.linear.iter().map(abs).sum::<f64>() * XN_CLAMP as f64
            + self.linear_by_t.iter().map(abs).sum::<f64>() * XN_CLAMP as f64 * t;
        let mut power = 1.0;
        let mut poly = 0.0;
        for p in &self.poly {
            power *= t;
            poly += abs(p) * power;
        }
        abs(&self.bias_dph) + linear + poly + self.weights.iter().map(abs).sum::<f64>()
    }
}
