//! One training at a fixed Gaussian width and polynomial degree: normalise, pick the
//! candidate centres, accumulate the Gram matrix of the extended design (`gram`), add
//! the forced terms (bias, polynomial in the first input, linear inputs), run OLS or Orr
//! selection on it, and keep the weights of every prefix of the selection path, so
//! validation can score each number of centres from one run. `WidthDesign` and
//! `select_path` are shared with validation (`validate`), which runs them per fold.

use crate::fanout::thread_count;
use crate::train::data::dataset::Dataset;
use crate::train::data::normalize::Normalizer;
use crate::train::error::Result;
use crate::train::fit::assemble::{assemble, ForcedTerm, ModelParts};
use crate::train::fit::candidates::grid_candidates;
use crate::train::fit::config::{Method, TrainConfig};
use crate::train::fit::design::GaussianDesign;
use crate::train::fit::gram::{FoldGrams, ForcedColumn, GramView, Layout};
use crate::train::fit::ols::select_ols;
use crate::train::fit::orr::select_orr;
use crate::train::fit::path::PathSummary;
use crate::train::fit::select::{Added, Selection};
use fog_core::model::format::RbfModel;

/// A model trained at one width, with what its selection did.
#[derive(Clone, Debug)]
pub struct Fit {
    pub model: RbfModel,
    pub width: f64,
    pub path: PathSummary,
    /// Size this fit's n x K design would have as f32, bytes (streamed, never held).
    pub design_bytes: usize,
    /// Bytes of the Gram matrices this fit held.
    pub gram_bytes: usize,
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
    /// Size of the n x K design as f32, bytes (streamed into the Gram, never held).
    pub design_bytes: usize,
    /// Bytes of the Gram matrices the fit held.
    pub gram_bytes: usize,
    pub n_candidates: usize,
    /// Inputs entering the Gaussian distance (the leading ones).
    pub n_rbf_inputs: usize,
}

/// Runs selection at `shape.width` / `shape.degree` on all rows of `ds`.
pub fn fit_path(ds: &Dataset, cfg: &TrainConfig, shape: &Shape) -> Result<PathFit> {
    cfg.check(ds.n_inputs())?;
    let normalizer = Normalizer::fit(ds)?;
    let points = normalizer.normalized_rows(ds);
    let width_design = WidthDesign::new(ds, cfg, &points, shape.width, shape.degree);
    let grams = width_design.grams_of(
        ds,
        &points,
        &vec![0; ds.len()],
        1,
        thread_count(cfg.threads),
    );
    Ok(path_on_gram(
        ds,
        cfg,
        (normalizer, points),
        &width_design,
        &grams,
        shape,
    ))
}

/// Runs selection at `shape` on the Gram of all rows of an already accumulated design
/// (`grams.all()`: validation's per-fold Grams summed, so the final fit costs no pass
/// over the rows). `normalized`: the normaliser and the points it made.
pub(super) fn path_on_gram(
    ds: &Dataset,
    cfg: &TrainConfig,
    normalized: (Normalizer, Vec<f32>),
    width_design: &WidthDesign,
    grams: &FoldGrams,
    shape: &Shape,
) -> PathFit {
    let (normalizer, points) = normalized;
    let path = select_path(grams.all(), width_design, cfg, shape);
    let centers = path
        .selected
        .iter()
        .map(|&k| width_design.candidates[k])
        .collect();
    PathFit {
        normalizer,
        points,
        forced: path.forced,
        centers,
        thetas: path.thetas,
        path: path.summary,
        design_bytes: GaussianDesign::bytes_for(ds.len(), width_design.candidates.len()),
        gram_bytes: grams.bytes(),
        n_candidates: width_design.candidates.len(),
        n_rbf_inputs: width_design.n_rbf,
    }
}

/// The extended design of one width: candidate centres and the forced columns of every
/// polynomial degree up to the largest asked for.
pub(super) struct WidthDesign {
    pub width: f64,
    pub candidates: Vec<usize>,
    pub columns: Vec<ForcedColumn>,
    pub n_rbf: usize,
    first_linear: usize,
}

impl WidthDesign {
    /// Candidates by the grid over `points` (normalised rows of `ds`), forced columns
    /// for degrees up to `max_degree`.
    pub fn new(
        ds: &Dataset,
        cfg: &TrainConfig,
        points: &[f32],
        width: f64,
        max_degree: usize,
    ) -> Self {
        let d = ds.n_inputs();
        let n_rbf = d - cfg.linear_only_inputs;
        let candidates = grid_candidates(points, d, n_rbf, width, cfg.max_candidates);
        let first_linear = if cfg.linear_on_rbf_inputs { 0 } else { n_rbf };
        let powers = max_degree.max(usize::from(first_linear == 0));
        let mut columns = vec![ForcedColumn::Bias];
        columns.extend((1..=powers).map(ForcedColumn::Power));
        columns.extend((first_linear.max(1)..d).map(ForcedColumn::Input));
        if cfg.linear_by_t {
            columns.extend((first_linear.max(1)..d).map(ForcedColumn::InputByT));
        }
        Self {
            width,
            candidates,
            columns,
            n_rbf,
            first_linear,
        }
    }

    /// Per-fold Gram matrices of this design over the rows of `ds` (normalised `points`).
    pub fn grams_of(
        &self,
        ds: &Dataset,
        points: &[f32],
        fold: &[usize],
        folds: usize,
        threads: usize,
    ) -> FoldGrams {
        FoldGrams::build(
            &Layout {
                points,
                stride: ds.n_inputs(),
                rbf_dims: self.n_rbf,
                candidates: &self.candidates,
                width: self.width,
                forced: &self.columns,
                targets: &ds.targets_dph,
            },
            fold,
            folds,
            threads,
        )
    }

    /// The forced terms of a model of polynomial `degree`, each with its Gram column:
    /// bias, T^1..T^degree, then the linear inputs (input 0's linear term is T^1), then
    /// their temperature-coupled twins (t x input j) when the design has them.
    pub fn forced_terms(&self, degree: usize, n_inputs: usize) -> Vec<(ForcedTerm, usize)> {
        let col = |c: ForcedColumn| self.columns.iter().position(|&x| x == c);
        let mut terms = vec![(ForcedTerm::Bias, 0)];
        for k in 1..=degree {
            terms.extend(col(ForcedColumn::Power(k)).map(|c| (ForcedTerm::Poly(k), c)));
        }
        for j in self.first_linear..n_inputs {
            if j == 0 && degree >= 1 {
                continue; // already the polynomial's first power
            }
            let c = if j == 0 {
                ForcedColumn::Power(1)
            } else {
                ForcedColumn::Input(j)
            };
            terms.extend(col(c).map(|c| (ForcedTerm::Linear(j), c)));
        }
        for j in 1..n_inputs {
            terms.extend(col(ForcedColumn::InputByT(j)).map(|c| (ForcedTerm::LinearByT(j), c)));
        }
        terms
    }
}

/// One selection path on a Gram matrix.
pub(super) struct SelectedPath {
    pub forced: Vec<ForcedTerm>,
    /// Gram column of every kept term (forced terms, then centres in order).
    pub columns: Vec<usize>,
    /// Candidate number of each selected centre.
    pub selected: Vec<usize>,
    pub thetas: Vec<Option<Vec<f64>>>,
    pub summary: PathSummary,
}

/// Adds the forced terms of `shape.degree`, then selects centres by `cfg.method`, and
/// solves for the coefficients of every prefix (Orr: of its GCV-chosen prefix only).
pub(super) fn select_path(
    gram: GramView<'_>,
    design: &WidthDesign,
    cfg: &TrainConfig,
    shape: &Shape,
) -> SelectedPath {
    let mut sel = Selection::new(gram, cfg.collinearity_tol);
    let n_inputs = design.n_rbf + cfg.linear_only_inputs;
    let mut forced = Vec::new();
    for (term, column) in design.forced_terms(shape.degree, n_inputs) {
        if sel.add_forced(column) == Added::Yes {
            forced.push(term);
        }
    }
    let max_centers = shape
        .centers
        .unwrap_or(cfg.max_centers)
        .min(cfg.max_centers);
    let summary = match cfg.method {
        Method::Ols => select_ols(&mut sel, cfg.rho, cfg.target_dph, max_centers),
        Method::OrrGcv => select_orr(&mut sel, max_centers),
    };
    let nf = forced.len();
    let n_centers = summary.terms - nf;
    let thetas = match cfg.method {
        Method::Ols => (0..=n_centers)
            .map(|m| Some(sel.solve(nf + m, &summary.shrink)))
            .collect(),
        Method::OrrGcv => {
            let mut t = vec![None; n_centers + 1];
            t[n_centers] = Some(sel.solve(summary.terms, &summary.shrink));
            t
        }
    };
    SelectedPath {
        forced,
        columns: sel.columns()[..summary.terms].to_vec(),
        selected: sel.selected()[..n_centers].to_vec(),
        thetas,
        summary,
    }
}

impl PathFit {
    /// The model with the first `m` centres (m <= the path's length; must have weights).
    pub fn model(&self, ds: &Dataset, cfg: &TrainConfig, width: f64, m: usize) -> Result<RbfModel> {
        let theta = self.thetas.get(m).and_then(Option::as_ref).ok_or_else(|| {
            crate::train::error::TrainError::Model {
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
    fit_from_path(&fit_path(ds, cfg, shape)?, ds, cfg, shape)
}

/// The model of a selection path at `shape` (centres: `shape.centers`, else where the
/// selection stopped).
pub fn fit_from_path(pf: &PathFit, ds: &Dataset, cfg: &TrainConfig, shape: &Shape) -> Result<Fit> {
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
        gram_bytes: pf.gram_bytes,
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
