//! Effects that live between runs: a bias constant within a run but different from run to
//! run (a heading-dependent magnetic bias when each run has its own heading; a
//! dependence on the chamber ambient or on a column's run mean). Within-run screening
//! cannot see them: the free run offset absorbs them. Here the run offsets left by the
//! chosen base (the turn-on biases) are the data: each candidate (run-level features) is
//! validated leaving one run out against the offsets' own mean (the turn-on
//! repeatability), and its per-run held-out gains are scaled by the run's point count so
//! they are drops in held-out squared error like the within-run gains. They then enter
//! a Westfall-Young sign-flip max-T test over the run-level library, Bonferroni with the
//! within-run sequence; the selection is stepwise like the within-run one (`selection::
//! screen`: after a run-level cause is named, the rest are scored conditional on it,
//! until nothing passes; the steps are gated, so no split over them). A run-level permutation test (features
//! shuffled across runs) is reported next to each candidate as a check. The run-level
//! library: the run mean (angles: circular-mean harmonic) of every extra column, the
//! ambient, and every metadata key that varies between runs (numbers as values,
//! categories as levels; `candidates::generic::metadata`).

use crate::diagnose::baseline::choice::BaseFit;
use crate::diagnose::baseline::models::Stacked;
use crate::diagnose::candidates::generic::MetaColumn;
use crate::diagnose::input::Campaign;
use crate::diagnose::linalg::solve_spd;
use crate::diagnose::selection::scored::ALPHA;
use crate::diagnose::selection::screen::MIN_GAIN_PCT;
use crate::diagnose::validation::folds::Folds;
use crate::diagnose::validation::signflip::{max_t_pvalues, FLIP_SEED};
use fog_core::consts::EARTH_RATE_DPH;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

/// Run-level permutations for the check p-value.
pub const PERMUTATIONS: usize = 4_000;
/// Seed of the permutations (results are deterministic).
pub const PERM_SEED: u64 = 0xBE7_3EE2;

/// One run-level candidate: `features[r]` holds run r's feature values.
#[derive(Clone, Debug)]
pub struct RunCandidate {
    pub label: String,
    pub column: String,
    pub harmonic: bool,
    pub features: Vec<Vec<f64>>,
}

/// One scored run-level candidate, for the report.
#[derive(Clone, Debug, Serialize)]
pub struct RunRow {
    pub label: String,
    /// Leave-one-run-out rms of the run offsets with the candidate, deg/h.
    pub heldout_offset_rms_dph: f64,
    /// Gain on the turn-on repeatability, %.
    pub gain_pct: f64,
    /// Family-wise p (shared with the within-run candidates).
    pub p_value: f64,
    /// Run-level permutation p (candidate alone).
    pub permutation_p: f64,
    pub significant: bool,
    /// Fitted coefficients on all runs (intercept first), deg/h per unit.
    pub coef: Vec<f64>,
}

/// A named heading harmonic in north-seeking terms.
#[derive(Clone, Debug, Serialize)]
pub struct HeadingEffect {
    pub column: String,
    pub amplitude_dph: f64,
    /// Heading of maximum bias, deg.
    pub phase_deg: f64,
    pub latitude_deg: f64,
    /// Two-position seek at psi = 90 deg: bias difference 2 A cos(psi - phase) over
    /// 2 Omega_H sin psi, deg.
    pub azimuth_error_at_90_deg: f64,
    /// Largest over the seek headings where |sin psi| >= 0.5 (A / (Omega_H / 2)), deg.
    pub azimuth_error_bound_deg: f64,
}

/// The between-run analysis.
#[derive(Clone, Debug, Serialize)]
pub struct BetweenRun {
    /// Turn-on repeatability, deg/h: the run-level variance component of the law shared
    /// across runs when that law holds (`levels`), else the rms of the free run offsets
    /// about their leave-one-out mean.
    pub turn_on_repeatability_dph: f64,
    /// rms of the offsets the chosen law leaves about their leave-one-out mean, deg/h.
    pub offsets_heldout_rms_dph: f64,
    /// What the offsets are left by: the chosen base and level treatment.
    pub offsets_from: String,
    pub rows: Vec<RunRow>,
    /// Label of the first named run-level effect, if any.
    pub named: Option<String>,
    /// Every named run-level effect, in the order named, with its conditional gain.
    pub named_steps: Vec<RunRow>,
    pub heading: Option<HeadingEffect>,
    /// Why the analysis was not run, if it was not.
    pub note: Option<String>,
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// Run offsets left by the base fitted on every run: mean over the run of drift minus
/// the base's prediction (the base itself carries no offset).
pub fn run_offsets(folds: &Folds, st: &Stacked, base: &BaseFit) -> Vec<f64> {
    let design = base.raw_design();
    let w = base
        .prepared
        .fit_all(folds, &[])
        .map(|(w, _)| w)
        .unwrap_or_default();
    let mut row = vec![0.0; design.width()];
    folds
        .run_rows
        .iter()
        .map(|r| {
            let resid: Vec<f64> = r
                .clone()
                .map(|i| {
                    design.row(i, &mut row);
                    st.y[i] - row.iter().zip(&w).map(|(c, wj)| c * wj).sum::<f64>()
                })
                .collect();
            mean(&resid)
        })
        .collect()
}

/// Run-level candidates: the harmonic (cos, sin of the run's circular mean) of every
/// `*_deg` column, the run mean of every other extra column, the ambient, and every
/// metadata key (value, or indicators of all but its commonest level).
pub fn enumerate(c: &Campaign, meta: &[MetaColumn]) -> Vec<RunCandidate> {
    let mut out = Vec::new();
    for (j, name) in c.extra_names.iter().enumerate() {
        if name.ends_with("_deg") {
            let f = c
                .runs
                .iter()
                .map(|s| {
                    let cs = mean(
                        &s.extras[j]
                            .iter()
                            .map(|a| a.to_radians().cos())
                            .collect::<Vec<_>>(),
                    );
                    let sn = mean(
                        &s.extras[j]
                            .iter()
                            .map(|a| a.to_radians().sin())
                            .collect::<Vec<_>>(),
                    );
                    let ang = sn.atan2(cs);
                    vec![ang.cos(), ang.sin()]
                })
                .collect();
            out.push(RunCandidate {
                label: format!("{name}:run_harmonic"),
                column: name.clone(),
                harmonic: true,
                features: f,
            });
        } else {
            out.push(RunCandidate {
                label: format!("{name}:run_mean"),
                column: name.clone(),
                harmonic: false,
                features: c.runs.iter().map(|s| vec![mean(&s.extras[j])]).collect(),
            });
        }
    }
    if c.runs.iter().all(|s| s.ambient_c.is_some()) {
        out.push(RunCandidate {
            label: "ambient_c:run_value".into(),
            column: "ambient_c".into(),
            harmonic: false,
            features: c
                .runs
                .iter()
                .map(|s| vec![s.ambient_c.unwrap_or(0.0)])
                .collect(),
        });
    }
    for m in meta.iter().filter(|m| m.run_values.len() == c.runs.len()) {
        let levels = m
            .categorical
            .then(|| crate::diagnose::candidates::generic::few_levels(m.run_values.iter().copied()))
            .flatten();
        let (label, features) = match levels {
            Some(l) => {
                let count = |v: f64| m.run_values.iter().filter(|x| **x == v).count();
                let reference = l.iter().copied().max_by_key(|v| count(*v)).unwrap_or(0.0);
                let shown: Vec<f64> = l.into_iter().filter(|v| *v != reference).collect();
                (
                    format!("# {}:levels", m.key),
                    m.run_values
                        .iter()
                        .map(|x| shown.iter().map(|v| f64::from(u8::from(x == v))).collect())
                        .collect(),
                )
            }
            None => (
                format!("# {}:run_value", m.key),
                m.run_values.iter().map(|x| vec![*x]).collect(),
            ),
        };
        out.push(RunCandidate {
            label,
            column: m.key.clone(),
            harmonic: false,
            features,
        });
    }
    out.retain(|c| varies(&c.features));
    out
}

fn varies(f: &[Vec<f64>]) -> bool {
    let k = f.first().map_or(0, Vec::len);
    (0..k).any(|j| {
        let v: Vec<f64> = f.iter().map(|x| x[j]).collect();
        let m = mean(&v);
        v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() > 1e-12 * (1.0 + m * m) * v.len() as f64
    })
}

/// Least squares o = a + b . f over `rows` (small ridge for stability).
fn fit(o: &[f64], f: &[Vec<f64>], rows: &[usize]) -> Option<Vec<f64>> {
    let q = 1 + f.first().map_or(0, Vec::len);
    let mut a = vec![0.0; q * q];
    let mut b = vec![0.0; q];
    for &r in rows {
        let x: Vec<f64> = std::iter::once(1.0).chain(f[r].iter().copied()).collect();
        for i in 0..q {
            b[i] += x[i] * o[r];
            for j in 0..q {
                a[i * q + j] += x[i] * x[j];
            }
        }
    }
    for i in 0..q {
        a[i * q + i] += 1e-9 * (1.0 + a[i * q + i]);
    }
    solve_spd(&mut a, &mut b, q).ok()?;
    Some(b)
}

fn predict(coef: &[f64], f: &[f64]) -> f64 {
    coef[0] + coef[1..].iter().zip(f).map(|(c, x)| c * x).sum::<f64>()
}

/// Leave-one-run-out errors of the offsets under o = a + b . f (f empty: the mean).
fn loo_errors(o: &[f64], f: &[Vec<f64>]) -> Option<Vec<f64>> {
    let n = o.len();
    (0..n)
        .map(|r| {
            let rows: Vec<usize> = (0..n).filter(|&i| i != r).collect();
            let coef = fit(o, f, &rows)?;
            Some(o[r] - predict(&coef, &f[r]))
        })
        .collect()
}

/// Per-run held-out gains (run's points x drop in squared offset error, leave one run
/// out), the leave-one-out rms without and with the candidate.
pub fn loo_gains(o: &[f64], lens: &[usize], f: &[Vec<f64>]) -> Option<(Vec<f64>, f64, f64)> {
    let n = o.len();
    let mut gains = Vec::with_capacity(n);
    let (mut ss0, mut ss1) = (0.0, 0.0);
    for r in 0..n {
        let rows: Vec<usize> = (0..n).filter(|&i| i != r).collect();
        let m = rows.iter().map(|&i| o[i]).sum::<f64>() / rows.len() as f64;
        let coef = fit(o, f, &rows)?;
        let e0 = o[r] - m;
        let e1 = o[r] - predict(&coef, &f[r]);
        ss0 += e0 * e0;
        ss1 += e1 * e1;
        gains.push(lens[r] as f64 * (e0 * e0 - e1 * e1));
    }
    Some((gains, (ss0 / n as f64).sqrt(), (ss1 / n as f64).sqrt()))
}

/// Run-level permutation p of the total gain (features shuffled across runs).
pub fn permutation_p(o: &[f64], lens: &[usize], f: &[Vec<f64>]) -> f64 {
    let Some((g, _, _)) = loo_gains(o, lens, f) else {
        return 1.0;
    };
    let obs: f64 = g.iter().sum();
    let mut rng = ChaCha8Rng::seed_from_u64(PERM_SEED);
    let mut perm: Vec<Vec<f64>> = f.to_vec();
    let mut hits = 1usize;
    for _ in 0..PERMUTATIONS {
        perm.shuffle(&mut rng);
        if let Some((gp, _, _)) = loo_gains(o, lens, &perm) {
            if gp.iter().sum::<f64>() >= obs - 1e-12 * obs.abs() {
                hits += 1;
            }
        }
    }
    hits as f64 / (PERMUTATIONS + 1) as f64
}

/// A heading harmonic's amplitude, phase and two-position azimuth error.
pub fn heading_effect(column: &str, coef: &[f64], latitude_deg: f64) -> HeadingEffect {
    let (a, b) = (
        coef.get(1).copied().unwrap_or(0.0),
        coef.get(2).copied().unwrap_or(0.0),
    );
    let amp = a.hypot(b);
    let phase = b.atan2(a);
    let omega_h = (EARTH_RATE_DPH * latitude_deg.to_radians().cos())
        .abs()
        .max(1e-9);
    // at psi = 90 deg: 2 A cos(90 deg - phase) / (2 Omega_H sin 90 deg)
    let at_90 = (amp * phase.sin() / omega_h).atan().to_degrees();
    HeadingEffect {
        column: column.to_owned(),
        amplitude_dph: amp,
        phase_deg: phase.to_degrees().rem_euclid(360.0),
        latitude_deg,
        azimuth_error_at_90_deg: at_90,
        azimuth_error_bound_deg: (amp / (0.5 * omega_h)).atan().to_degrees(),
    }
}

/// The run levels the between-run stage explains: the offsets the chosen base leaves
/// under free offsets, or the shared law's levels (refitted with the run features).
pub enum LevelModel {
    Free(Vec<f64>),
    Shared(
        std::sync::Arc<crate::diagnose::baseline::levels::LevelSystems>,
        f64,
    ),
}

impl LevelModel {
    /// Leave-one-run-out level errors with run features `f` (per run; may be empty).
    fn errors(&self, f: &[Vec<f64>]) -> Option<Vec<f64>> {
        match self {
            Self::Free(o) => loo_errors(o, f),
            Self::Shared(lv, th) => lv.with_run_features(f).heldout_level_errors(*th),
        }
    }

    /// Coefficients fitted on every run: intercept, then the last `k` features'.
    fn coef(&self, f: &[Vec<f64>], k: usize) -> Vec<f64> {
        let all = match self {
            Self::Free(o) => fit(o, f, &(0..o.len()).collect::<Vec<_>>()),
            Self::Shared(lv, th) => {
                let with = lv.with_run_features(f);
                with.solve_shared(&vec![1.0; lv.runs()], *th).map(|w| w.w)
            }
        };
        let Some(w) = all else {
            return vec![];
        };
        let mut coef = vec![w[0]];
        coef.extend_from_slice(&w[w.len().saturating_sub(k)..]);
        coef
    }
}

/// Offsets, the level model, the run-level library and step 1's rows (p-values filled
/// in by `finish`).
pub struct Prepared {
    pub offsets: Vec<f64>,
    pub offsets_from: String,
    pub offsets_rms_dph: f64,
    pub model: LevelModel,
    pub lens: Vec<usize>,
    pub cands: Vec<RunCandidate>,
    pub repeatability_dph: f64,
}

/// Whether the layout holds runs out whole (the between-run stage needs it).
pub fn runs_held_out_whole(folds: &Folds) -> bool {
    folds.offsets == crate::diagnose::validation::folds::Offsets::PerUnit
}

/// Offsets, level model and candidates; `Err` (with the reason) when runs are too few.
pub fn prepare(
    c: &Campaign,
    meta: &[MetaColumn],
    folds: &Folds,
    st: &Stacked,
    base: &BaseFit,
    levels: Option<&crate::diagnose::baseline::choice::LevelChoice>,
) -> Result<Prepared, String> {
    if !runs_held_out_whole(folds) {
        return Err("between-run effects need >= 4 runs held out whole".into());
    }
    let (offsets, offsets_from) = match levels {
        Some(l) => (
            l.offsets_left.clone(),
            format!(
                "{} ({})",
                l.base,
                crate::diagnose::baseline::choice::law_name(l.law)
            ),
        ),
        None => (
            run_offsets(folds, st, base),
            format!("{} (free run offsets)", base.spec.name),
        ),
    };
    let lens: Vec<usize> = folds.run_rows.iter().map(|r| r.len()).collect();
    let offsets_rms_dph =
        loo_gains(&offsets, &lens, &vec![vec![]; offsets.len()]).map_or(f64::NAN, |(_, r0, _)| r0);
    let shared = levels
        .filter(|l| l.law == crate::diagnose::baseline::levels::Law::Shared)
        .and_then(|l| Some((l.systems.clone()?, l.theta)));
    let model = match shared {
        Some((lv, th)) if lv.heldout_level_errors(th).is_some() => LevelModel::Shared(lv, th),
        _ => LevelModel::Free(offsets.clone()),
    };
    Ok(Prepared {
        repeatability_dph: levels.map_or(offsets_rms_dph, |l| l.repeatability_dph),
        offsets_rms_dph,
        offsets_from,
        model,
        cands: enumerate(c, meta),
        lens,
        offsets,
    })
}

/// Per run, `given`'s features followed by `cand`'s.
fn joined(given: &[Vec<f64>], cand: &[Vec<f64>]) -> Vec<Vec<f64>> {
    given
        .iter()
        .zip(cand)
        .map(|(g, c)| g.iter().chain(c).copied().collect())
        .collect()
}

fn rms(e: &[f64]) -> f64 {
    (e.iter().map(|v| v * v).sum::<f64>() / e.len().max(1) as f64).sqrt()
}

/// Step-wise selection of run-level causes (see the module header); `groups` sequences
/// share alpha (Bonferroni).
pub fn finish(p: Prepared, groups: f64, latitude_deg: f64) -> BetweenRun {
    let runs = p.offsets.len();
    let mut given: Vec<Vec<f64>> = vec![vec![]; runs];
    let mut named_steps: Vec<RunRow> = Vec::new();
    let mut named_idx: Vec<usize> = Vec::new();
    let mut first_rows = Vec::new();
    let mut e0 = p.model.errors(&given);
    for k in 1..=crate::diagnose::selection::screen::MAX_STEPS {
        let Some(before) = e0.clone() else { break };
        let mut rows = Vec::new();
        let mut gains = Vec::new();
        let mut idx = Vec::new();
        for (i, cand) in p.cands.iter().enumerate() {
            if named_idx.contains(&i) {
                continue;
            }
            let f = joined(&given, &cand.features);
            if f[0].len() + 2 >= runs {
                continue;
            }
            let Some(after) = p.model.errors(&f) else {
                continue;
            };
            gains.push(
                p.lens
                    .iter()
                    .zip(before.iter().zip(&after))
                    .map(|(&n, (a, b))| n as f64 * (a * a - b * b))
                    .collect::<Vec<f64>>(),
            );
            rows.push(RunRow {
                label: cand.label.clone(),
                heldout_offset_rms_dph: rms(&after),
                gain_pct: 100.0 * (1.0 - rms(&after) / rms(&before).max(1e-300)),
                p_value: 1.0,
                permutation_p: if k == 1 {
                    permutation_p(&p.offsets, &p.lens, &cand.features)
                } else {
                    f64::NAN
                },
                significant: false,
                coef: p.model.coef(&f, cand.features[0].len()),
            });
            idx.push(i);
        }
        for (r, fp) in rows.iter_mut().zip(max_t_pvalues(&gains, FLIP_SEED)) {
            r.p_value = (fp * groups).min(1.0);
            r.significant = r.p_value < ALPHA && r.gain_pct > MIN_GAIN_PCT;
        }
        let best = rows
            .iter()
            .enumerate()
            .filter(|(_, r)| r.significant)
            .max_by(|a, b| a.1.gain_pct.total_cmp(&b.1.gain_pct))
            .map(|(j, _)| j);
        if let Some(j) = best {
            named_steps.push(rows[j].clone());
            named_idx.push(idx[j]);
            given = joined(&given, &p.cands[idx[j]].features);
            e0 = p.model.errors(&given);
        }
        if k == 1 {
            first_rows = rows;
        }
        if best.is_none() {
            break;
        }
    }
    let heading = named_idx
        .iter()
        .zip(&named_steps)
        .find(|(i, _)| p.cands[**i].harmonic)
        .map(|(i, r)| heading_effect(&p.cands[*i].column, &r.coef, latitude_deg));
    first_rows.sort_by(|a, b| b.gain_pct.total_cmp(&a.gain_pct));
    BetweenRun {
        turn_on_repeatability_dph: p.repeatability_dph,
        offsets_heldout_rms_dph: p.offsets_rms_dph,
        offsets_from: p.offsets_from,
        rows: first_rows,
        named: named_steps.first().map(|r| r.label.clone()),
        named_steps,
        heading,
        note: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_heading_harmonic_in_the_offsets_is_recovered() {
        let n = 12;
        let lens = vec![100; n];
        let f: Vec<Vec<f64>> = (0..n)
            .map(|r| {
                let h = (r as f64 * 97.0).to_radians();
                vec![h.cos(), h.sin()]
            })
            .collect();
        let jitter = |r: usize| 0.002 * ((r as f64 * 12.9898).sin() * 43_758.5).fract();
        let o: Vec<f64> = (0..n)
            .map(|r| 0.5 + 0.03 * f[r][0] - 0.01 * f[r][1] + jitter(r))
            .collect();
        let (g, rms0, rms1) = loo_gains(&o, &lens, &f).unwrap();
        assert!(rms1 < 0.2 * rms0, "{rms0} -> {rms1}");
        assert!(g.iter().sum::<f64>() > 0.0);
        assert!(permutation_p(&o, &lens, &f) < 0.01);
        let all: Vec<usize> = (0..n).collect();
        let e = heading_effect("heading_deg", &fit(&o, &f, &all).unwrap(), 40.0);
        assert!((e.amplitude_dph - 0.0316).abs() < 0.002, "{e:?}");
        assert!((e.phase_deg - 341.6).abs() < 3.0, "{e:?}");
        let unrelated: Vec<Vec<f64>> = (0..n).map(|r| vec![((r * 5) % 7) as f64]).collect();
        let flat: Vec<f64> = (0..n).map(jitter).collect();
        assert!(permutation_p(&flat, &lens, &unrelated) > 0.01);
    }
}
