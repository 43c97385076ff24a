//! The field correction of a chamber model (`fogsim train --field`): what the device
//! learnt from its own seeks, folded back into its model.
//!
//! - `refine`: a weighted ridge fit of the field records' residual biases on the
//!   temperature state, its weight chosen by held-out field seeks, folded into the model's
//!   bias and linear terms; it runs `terms` (which terms the field can carry, coverage),
//!   `weight` (the held-out choice of the weight and the terms kept) and `fit` (the
//!   observations, the ridge fit and its fold), and re-exports their public items;
//! - this module: which records belong to the model (its CRC-32, or a heading-calibrated
//!   variant the registry knows), the fit on them, and the lines `train` prints.
//!
//! The records' file format is `io::field_records`; the pull from a device is
//! `device::field_pull`; their table in the registry is `registry::field_records`.

mod fit;
pub mod refine;
mod terms;
#[cfg(test)]
mod test_fixtures;
mod weight;

use std::path::Path;

use anyhow::{bail, Result};
use fog_core::model::format::RbfModel;

use crate::io::field_records::{self, StoredRecord};
use crate::io::model::model_crc32;
use crate::train::seek_score::SeekGeometry;
use refine::{FieldObservation, WeightChoice};

/// What `train --field` did with the field records.
pub struct FieldRefinement {
    pub model: RbfModel,
    pub used: usize,
    /// Of `used`, records measured under a heading-calibrated variant of the model.
    pub used_variant: usize,
    /// The variants' CRC-32s that were accepted (from the registry).
    pub variants: Vec<u32>,
    /// Records measured under another model (their residual is not this model's).
    pub other_model: usize,
    pub choice: WeightChoice,
    pub correction: refine::Correction,
}

/// Refines `model` with the records in `dir` measured under it or under one of
/// `variants` (heading-calibrated variants of it, `registry::variants_of`).
pub fn refine_with_dir(
    model: &RbfModel,
    dir: &Path,
    variants: &[u32],
    weight: Option<f64>,
    seek: SeekGeometry,
) -> Result<FieldRefinement> {
    let records = field_records::read_dir_records(dir)?;
    if records.is_empty() {
        bail!(
            "--field {}: no {} there (run `fogsim field pull` first)",
            dir.display(),
            field_records::JSON_NAME
        );
    }
    refine_with_records(model, &records, variants, weight, seek)
        .map_err(|e| anyhow::anyhow!("--field {}: {e}", dir.display()))
}

/// Refines `model` with those of `records` measured under it (same model CRC-32) or under
/// one of `variants`: what `train --field` does once the records are read (the aging
/// measurement calls it directly).
pub fn refine_with_records(
    model: &RbfModel,
    records: &[StoredRecord],
    variants: &[u32],
    weight: Option<f64>,
    seek: SeekGeometry,
) -> Result<FieldRefinement> {
    let crc = model_crc32(model)?;
    let is_variant = |r: &&StoredRecord| r.model_crc32.is_some_and(|c| variants.contains(&c));
    let used_variant = records.iter().filter(is_variant).count();
    let mut used: Vec<&StoredRecord> = records
        .iter()
        .filter(|r| r.model_crc32 == Some(crc) || is_variant(r))
        .collect();
    used.sort_by(|a, b| (&a.gyro_id, a.sequence).cmp(&(&b.gyro_id, b.sequence)));
    let clock: Vec<(&str, f64)> = used
        .iter()
        .map(|r| (r.gyro_id.as_str(), f64::from(r.t_since_power_on_s)))
        .collect();
    let obs: Vec<FieldObservation> = used
        .iter()
        .zip(refine::power_ons(&clock))
        .map(|(r, power_on)| FieldObservation {
            temp_c: f64::from(r.temp_c),
            temp_rate_cps: f64::from(r.temp_rate_cps),
            temp_accel_cps2: f64::from(r.temp_accel_cps2),
            residual_bias_dph: f64::from(r.residual_bias_dph),
            power_on,
            t_since_power_on_s: f64::from(r.t_since_power_on_s),
        })
        .collect();
    if obs.is_empty() {
        bail!(
            "none of its {} records was measured under this chamber model (CRC-32 {crc:08x}) \
             or a heading-calibrated variant the registry knows ({}); their residuals belong \
             to another model",
            records.len(),
            crc_list(variants)
        );
    }
    let (model, correction, choice) = refine::refine(model, &obs, weight, seek)?;
    Ok(FieldRefinement {
        model,
        used: obs.len(),
        used_variant,
        variants: variants.to_vec(),
        other_model: records.len() - obs.len(),
        choice,
        correction,
    })
}

/// `[0x0123abcd, ...]` (`none` if empty).
fn crc_list(crcs: &[u32]) -> String {
    if crcs.is_empty() {
        return "none".into();
    }
    let list: Vec<String> = crcs.iter().map(|c| format!("{c:08x}")).collect();
    format!("[{}]", list.join(", "))
}

impl FieldRefinement {
    /// Names of the first `k` identifiable terms (T, then dT/dt, as the model has them).
    fn correction_term_names(&self, k: usize) -> impl Iterator<Item = &'static str> + '_ {
        self.choice
            .kinds
            .iter()
            .take(k)
            .map(|&kind| refine::kind_name(kind))
    }

    /// The lines `train` prints.
    pub fn summary(&self) -> String {
        let variants = if self.variants.is_empty() {
            String::new()
        } else {
            format!(
                "{} of them under heading-calibrated variants {} (registry); ",
                self.used_variant,
                crc_list(&self.variants)
            )
        };
        let mut s = format!(
            "field refinement: {} field seeks used ({variants}{} measured under another model, \
             not used)\n",
            self.used, self.other_model
        );
        if self.used_variant > 0 {
            s += "field refinement: the refined model carries no heading calibration: attach \
                  it again (`fogsim heading-cal`) before uploading\n";
        }
        for line in &self.correction.coverage {
            s += &format!("field range: {line}\n");
        }
        for line in &self.correction.coverage_refused {
            s += &format!("field coverage: {line}\n");
        }
        if let Some(v) = &self.choice.verdict {
            s += &format!("field refinement: {v}\n");
            return s;
        }
        s += &format!(
            "terms  field weight W  leave-one-power-on-out: rms of the residual bias, dph; azimuth \
             score, deg ({} power-ons; the best W per terms by the residual bias, then the \
             fewest terms within one standard error by the {})\n",
            self.choice.power_ons,
            self.choice.criterion.name()
        );
        let names = |k: usize| {
            std::iter::once("1")
                .chain(self.correction_term_names(k))
                .collect::<Vec<_>>()
                .join("+")
        };
        for c in &self.choice.candidates {
            let mark = if c.weight == self.choice.weight && c.terms == self.choice.terms_kept {
                " <- used"
            } else {
                ""
            };
            s += &format!(
                "{:<10} {:>14}  {:>10.5}  {:>8.5}{mark}\n",
                names(c.terms),
                c.weight,
                c.rms_dph,
                c.az_rms_deg
            );
        }
        s += &format!(
            "field terms: the residual bias chooses {}, the azimuth score {}; used: the {}\n",
            names(self.choice.terms_by_half_sum),
            names(self.choice.terms_by_azimuth),
            self.choice.criterion.name()
        );
        s += &format!(
            "field correction: constant {:+.5} dph, terms {:?} coefficients {:?} dph per field std\n",
            self.correction.coef_dph[0],
            self.correction
                .terms
                .iter()
                .map(|t| refine::kind_name(t.kind))
                .collect::<Vec<_>>(),
            &self.correction.coef_dph[1..]
        );
        for note in &self.correction.not_fitted {
            s += &format!("field correction: not fitted: {note}\n");
        }
        s
    }
}
