//! Worst error of the f32 and fixed-point evaluation paths against the f64 reference over a
//! model's whole trained input box: the measurement behind the fixed-point accuracy claim,
//! usable on any model (synthetic in the tests, trained ones via `examples/fixed_error.rs`).

use crate::model::fixed::{FixedError, FixedModel};
use crate::model::format::{RbfModel, MAX_INPUTS};
use crate::model::rbf::{predict_f32, predict_f64};
use crate::model::synthetic::SplitMix64;

/// Result of `worst_errors`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorReport {
    /// max |fixed - f64| over the points, deg/h.
    pub worst_fixed_dph: f64,
    /// max |f32 - f64| over the points, deg/h.
    pub worst_f32_dph: f64,
    /// Raw inputs where the fixed-point error was largest.
    pub worst_fixed_at: [f32; MAX_INPUTS],
    /// Largest |drift| seen, deg/h (scale of the model's output).
    pub max_abs_drift_dph: f64,
    /// Points evaluated.
    pub n_points: u32,
}

/// Evaluate on a regular grid of about `n_grid` points spanning the trained range of every
/// input, plus `n_random` uniform random points in it (seeded). Both paths get the same f32
/// inputs; the reference evaluates exactly those.
pub fn worst_errors(
    model: &RbfModel,
    n_grid: u32,
    n_random: u32,
    seed: u64,
) -> Result<ErrorReport, FixedError> {
    let fixed = FixedModel::from_model(model)?;
    let n = model.inputs.len();
    let mut rep = ErrorReport {
        worst_fixed_dph: 0.0,
        worst_f32_dph: 0.0,
        worst_fixed_at: [0.0; MAX_INPUTS],
        max_abs_drift_dph: 0.0,
        n_points: 0,
    };
    let check = |u: &[f64; MAX_INPUTS], rep: &mut ErrorReport| {
        let mut x32 = [0.0f32; MAX_INPUTS];
        let mut x64 = [0.0f64; MAX_INPUTS];
        for j in 0..n {
            let (lo, hi) = (model.input_min[j] as f64, model.input_max[j] as f64);
            x32[j] = (lo + u[j] * (hi - lo)) as f32;
            x64[j] = x32[j] as f64;
        }
        let (Ok(r), Ok(q), Ok(f)) = (
            predict_f64(model, &x64[..n]),
            fixed.predict(&x32[..n]),
            predict_f32(model, &x32[..n]),
        ) else {
            return;
        };
        let e = libm::fabs(q as f64 - r);
        if e > rep.worst_fixed_dph {
            rep.worst_fixed_dph = e;
            rep.worst_fixed_at = x32;
        }
        rep.worst_f32_dph = rep.worst_f32_dph.max(libm::fabs(f as f64 - r));
        rep.max_abs_drift_dph = rep.max_abs_drift_dph.max(libm::fabs(r));
        rep.n_points += 1;
    };
    // Grid: steps per input so that steps^n is about n_grid.
    let steps = (libm::pow(n_grid.max(1) as f64, 1.0 / n as f64) as u64).max(2);
    let total = steps.pow(n as u32);
    for idx in 0..total {
        let mut u = [0.0f64; MAX_INPUTS];
        let mut rest = idx;
        for uj in u.iter_mut().take(n) {
            *uj = (rest % steps) as f64 / (steps - 1) as f64;
            rest /= steps;
        }
        check(&u, &mut rep);
    }
    let mut rng = SplitMix64::new(seed);
    for _ in 0..n_random {
        let mut u = [0.0f64; MAX_INPUTS];
        for uj in u.iter_mut().take(n) {
            *uj = rng.unit();
        }
        check(&u, &mut rep);
    }
    Ok(rep)
}
