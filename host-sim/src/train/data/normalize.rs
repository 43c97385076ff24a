//! Input normalisation: each input is shifted by its training mean and divided by its
//! training standard deviation, so one Gaussian width means the same in every
//! direction. The offsets and scales are rounded to f32 exactly as the model stores
//! them, so the trainer sees the same normalised inputs as the device.

use crate::train::data::dataset::Dataset;
use crate::train::error::{Result, TrainError};

/// Per-input offset and scale, plus the raw range seen in training.
#[derive(Clone, Debug, PartialEq)]
pub struct Normalizer {
    pub offset: Vec<f32>,
    pub scale: Vec<f32>,
    pub min: Vec<f32>,
    pub max: Vec<f32>,
}

/// Relative spread below which an input counts as constant.
const MIN_RELATIVE_STD: f64 = 1e-9;

impl Normalizer {
    /// Mean/std normalisation fitted on the dataset's rows.
    pub fn fit(ds: &Dataset) -> Result<Self> {
        if ds.is_empty() {
            return Err(TrainError::EmptyDataset);
        }
        let d = ds.n_inputs();
        let n = ds.len() as f64;
        let mut out = Self {
            offset: Vec::with_capacity(d),
            scale: Vec::with_capacity(d),
            min: Vec::with_capacity(d),
            max: Vec::with_capacity(d),
        };
        for j in 0..d {
            let col = || ds.rows().map(move |r| r[j]);
            let mean = col().sum::<f64>() / n;
            let var = col().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n;
            let std = var.sqrt();
            let lo = col().fold(f64::INFINITY, f64::min);
            let hi = col().fold(f64::NEG_INFINITY, f64::max);
            let spread_ok = std > MIN_RELATIVE_STD * mean.abs().max(1e-30) && (std as f32) > 0.0;
            if !spread_ok {
                return Err(TrainError::ConstantInput { input: j });
            }
            out.offset.push(mean as f32);
            out.scale.push(std as f32);
            out.min.push(lo as f32);
            out.max.push(hi as f32);
        }
        Ok(out)
    }

    /// Normalised value of input `j`.
    pub fn apply(&self, j: usize, raw: f64) -> f64 {
        (raw - f64::from(self.offset[j])) / f64::from(self.scale[j])
    }

    /// All rows normalised and rounded to f32 (the precision of stored centres).
    pub fn normalized_rows(&self, ds: &Dataset) -> Vec<f32> {
        ds.rows()
            .flat_map(|r| r.iter().enumerate().map(|(j, &v)| self.apply(j, v) as f32))
            .collect()
    }
}
