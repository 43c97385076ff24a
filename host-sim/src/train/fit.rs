//! One training at a fixed Gaussian width and polynomial degree: normalise, pick the
//! candidate centres, build the design, add the forced terms (bias, polynomial in the
//! first input, linear inputs), run OLS or Orr selection, and keep the weights of every
//! prefix of the selection path, so validation can score each number of centres from
//! one run. Width, degree and size selection sit on top of this (`validate`).

use super::assemble::{assemble, ForcedTerm, ModelParts};
use super::candidates::grid_candidates;
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

/// What one model shape is: Gaussian width, polynomial degree in input 0, and the
/// number of centres to keep (None: wherever selection stopped).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shape {
    pub width: f64,
    pub degree: usize,
    pub centers: Option<usize>,
}

/// A selection path: the forced terms, the centres in order, and the least-squares
/// coefficients of every prefix (`thetas[m]`: forced terms + first m centres; Orr keeps
/// only its GCV-chosen prefix, shrunk).
pub struct PathFit {
    pub normalizer: Normalizer,
    /// Normalised training points, row-major.
    pub points: Vec<f32>,
    pub forced: Vec<ForcedTerm>,
    /// Training-point index of each selected centre.
    pub centers: Vec<usize>,
    pub thetas: Vec<Option<Vec<f64>>>,
    pub path: PathSummary,
    pub design_bytes: usize,
    pub n_candidates: usize,
    /// Inputs entering the Gaussian distance (the leading ones).
    pub n_rbf_inputs: usize,
}

/// Runs selection at `shape.width` / `shape.degree` on all rows of `ds`.
pub fn fit_path(ds: &Dataset, cfg: &TrainConfig, shape: &Shape) -> Result<PathFit> {
    cfg.check(ds.n_inputs())?;
    let normalizer = Normalizer::fit(ds)?;
    let d = ds.n_inputs();
    let n_rbf = d - cfg.linear_only_inputs;
    let points = normalizer.normalized_rows(ds);
    let candidates = grid_candidates(&points, d, n_rbf, shape.width, cfg.max_candidates);
    let design = GaussianDesign::build(
        &points,
        d,
        n_rbf,
        &candidates,
        shape.width,
        thread_count(cfg.threads),
    );
    let mut sel = Selection::new(&design, &ds.targets_dph, cfg.collinearity_tol);

    let mut forced = Vec::new();
    if sel.add_forced(&vec![1.0; ds.len()]) == Added::Yes {
        forced.push(ForcedTerm::Bias);
    }
    for k in 1..=shape.degree {
        let column: Vec<f64> = points
            .chunks_exact(d)
            .map(|p| f64::from(p[0]).powi(k as i32))
            .collect();
        if sel.add_forced(&column) == Added::Yes {
            forced.push(ForcedTerm::Poly(k));
        }
    }
    let first_linear = if cfg.linear_on_rbf_inputs { 0 } else { n_rbf };
    for j in first_linear..d {
        if j == 0 && shape.degree >= 1 {
            continue; // already the polynomial's first power
        }
        let column: Vec<f64> = points.chunks_exact(d).map(|p| f64::from(p[j])).collect();
        if sel.add_forced(&column) == Added::Yes {
            forced.push(ForcedTerm::Linear(j));
        }
    }

    let max_centers = shape
        .centers
        .unwrap_or(cfg.max_centers)
        .min(cfg.max_centers);
    let path = match cfg.method {
        Method::Ols => select_ols(&mut sel, cfg.rho, cfg.target_dph, max_centers),
        Method::OrrGcv => select_orr(&mut sel, max_centers),
    };
    let nf = forced.len();
    let n_centers = path.terms - nf;
    let thetas = match cfg.method {
        Method::Ols => (0..=n_centers)
            .map(|m| Some(sel.solve(nf + m, &path.shrink)))
            .collect(),
        Method::OrrGcv => {
            let mut t = vec![None; n_centers + 1];
            t[n_centers] = Some(sel.solve(path.terms, &path.shrink));
            t
        }
    };
    let centers = sel.selected()[..n_centers]
        .iter()
        .map(|&k| candidates[k])
        .collect();
    Ok(PathFit {
        normalizer,
        points,
        forced,
        centers,
        thetas,
        path,
        design_bytes: design.bytes(),
        n_candidates: candidates.len(),
        n_rbf_inputs: n_rbf,
    })
}

impl PathFit {
    /// The model with the first `m` centres (m <= the path's length; must have weights).
    pub fn model(&self, ds: &Dataset, cfg: &TrainConfig, width: f64, m: usize) -> Result<RbfModel> {
        let theta = self.thetas.get(m).and_then(Option::as_ref).ok_or_else(|| {
            super::error::TrainError::Model {
                why: format!("no weights for a prefix of {m} centres"),
            }
        })?;
        assemble(&ModelParts {
            specs: &ds.specs,
            normalizer: &self.normalizer,
            n_rbf_inputs: ds.n_inputs() - cfg.linear_only_inputs,
            points: &self.points,
            width,
            forced: &self.forced,
            centers: &self.centers[..m],
            theta,
            gyro_id: &cfg.gyro_id,
            heldout_rms_dph: 0.0,
            n_train: ds.len(),
        })
    }

    /// Largest prefix with weights (the selection's own stop).
    pub fn full_len(&self) -> usize {
        self.centers.len()
    }
}

/// Trains on all rows of `ds` at `shape` (centres: `shape.centers`, else where the
/// selection stopped).
pub fn fit_shape(ds: &Dataset, cfg: &TrainConfig, shape: &Shape) -> Result<Fit> {
    let pf = fit_path(ds, cfg, shape)?;
    let m = shape.centers.unwrap_or(pf.full_len()).min(pf.full_len());
    let m = if pf.thetas.get(m).is_some_and(Option::is_some) {
        m
    } else {
        pf.full_len()
    };
    let model = pf.model(ds, cfg, shape.width, m)?;
    let mut path = pf.path.clone();
    path.center_err.truncate(m);
    Ok(Fit {
        model,
        width: shape.width,
        path,
        design_bytes: pf.design_bytes,
    })
}

/// Trains on all rows of `ds` with Gaussian width `width`, no polynomial base, keeping
/// every centre the selection took.
pub fn fit_width(ds: &Dataset, cfg: &TrainConfig, width: f64) -> Result<Fit> {
    fit_shape(
        ds,
        cfg,
        &Shape {
            width,
            degree: 0,
            centers: None,
        },
    )
}
