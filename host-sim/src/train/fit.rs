//! One training at a fixed Gaussian width: normalise, build the design, add the forced
//! terms (bias, linear inputs), run OLS or Orr selection, solve the triangular system and
//! assemble the model. Width selection and validation sit on top of this (`validate`).

use super::assemble::{assemble, ForcedTerm, ModelParts};
use super::config::{Method, TrainConfig};
use super::dataset::Dataset;
use super::design::{thread_count, GaussianDesign};
use super::error::Result;
use super::normalize::Normalizer;
use super::ols::select_ols;
use super::orr::select_orr;
use super::path::PathSummary;
use super::select::{Added, Selection};
use fog_core::model::RbfModel;

/// A model trained at one width, with what its selection did.
#[derive(Clone, Debug)]
pub struct Fit {
    pub model: RbfModel,
    pub width: f64,
    pub path: PathSummary,
    /// Size of the design matrix this fit held, bytes.
    pub design_bytes: usize,
}

/// Trains on all rows of `ds` with Gaussian width `width` (normalised units).
pub fn fit_width(ds: &Dataset, cfg: &TrainConfig, width: f64) -> Result<Fit> {
    cfg.check(ds.n_inputs())?;
    let normalizer = Normalizer::fit(ds)?;
    let d = ds.n_inputs();
    let n_rbf = d - cfg.linear_only_inputs;
    let points = normalizer.normalized_rows(ds);
    let design = GaussianDesign::build(&points, d, n_rbf, width, thread_count(cfg.threads));
    let mut sel = Selection::new(&design, &ds.targets_dph, cfg.collinearity_tol);

    let mut forced = Vec::new();
    if sel.add_forced(&vec![1.0; ds.len()]) == Added::Yes {
        forced.push(ForcedTerm::Bias);
    }
    let first_linear = if cfg.linear_on_rbf_inputs { 0 } else { n_rbf };
    for j in first_linear..d {
        let column: Vec<f64> = points.chunks_exact(d).map(|p| f64::from(p[j])).collect();
        if sel.add_forced(&column) == Added::Yes {
            forced.push(ForcedTerm::Linear(j));
        }
    }

    let path = match cfg.method {
        Method::Ols => select_ols(&mut sel, cfg.rho, cfg.max_centers),
        Method::OrrGcv => select_orr(&mut sel, cfg.max_centers),
    };
    let theta = sel.solve(path.terms, &path.shrink);
    let n_centers = path.terms - forced.len();
    let model = assemble(&ModelParts {
        specs: &ds.specs,
        normalizer: &normalizer,
        n_rbf_inputs: n_rbf,
        points: &points,
        width,
        forced: &forced,
        centers: &sel.selected()[..n_centers],
        theta: &theta,
        gyro_id: &cfg.gyro_id,
        heldout_rms_dph: 0.0,
        n_train: ds.len(),
    })?;
    Ok(Fit {
        model,
        width,
        path,
        design_bytes: design.bytes(),
    })
}
