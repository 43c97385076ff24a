//! Every invariant the evaluators rely on: counts, lengths, finiteness, ranges, the stored
//! heading harmonic and the magnitude bounds that keep any valid model's drift finite.

use super::limits::{
    INPUT_SCALE_RANGE, MAX_ABS_CENTER, MAX_ABS_RAW_INPUT, MAX_AUX, MAX_HEADING_HARMONIC_DPH,
    MAX_HEADING_SIGMA_DPH, MAX_OUTPUT_DPH, MAX_POLY_DEGREE, MAX_RBF_INPUTS, WIDTH_RANGE,
};
use super::model::RbfModel;
use crate::model::error::{check_finite, check_len, ModelError, ModelField};
use crate::model::heading::MIN_HEADINGS;

impl RbfModel {
    /// Check every invariant the evaluators rely on.
    pub fn validate(&self) -> Result<(), ModelError> {
        let n = self.inputs.len();
        if n == 0 {
            return Err(ModelError::NoInputs);
        }
        let nr = self.n_rbf_inputs as usize;
        if nr > n || nr > MAX_RBF_INPUTS || (nr == 0 && !self.centers.is_empty()) {
            return Err(ModelError::BadRbfInputCount {
                n_rbf_inputs: self.n_rbf_inputs,
                n_inputs: n as u8,
            });
        }
        check_len(ModelField::InputOffset, n, self.input_offset.len())?;
        check_len(ModelField::InputScale, n, self.input_scale.len())?;
        check_len(ModelField::InputMin, n, self.input_min.len())?;
        check_len(ModelField::InputMax, n, self.input_max.len())?;
        check_len(ModelField::Linear, n, self.linear.len())?;
        let m = self.centers.len();
        check_len(ModelField::Widths, m, self.widths.len())?;
        check_len(ModelField::Weights, m, self.weights.len())?;
        for (i, spec) in self.inputs.iter().enumerate() {
            let tau_ok = spec.tau_s.is_finite()
                && if spec.kind.needs_time_constant() {
                    spec.tau_s > 0.0
                } else {
                    spec.tau_s >= 0.0
                };
            if !tau_ok {
                return Err(ModelError::BadTimeConstant { input: i as u8 });
            }
            if let Some(ch) = spec.kind.aux_channel() {
                if ch as usize >= MAX_AUX {
                    return Err(ModelError::BadAuxChannel {
                        input: i as u8,
                        channel: ch,
                    });
                }
            }
        }
        check_finite(ModelField::InputOffset, &self.input_offset)?;
        check_finite(ModelField::InputScale, &self.input_scale)?;
        check_finite(ModelField::InputMin, &self.input_min)?;
        check_finite(ModelField::InputMax, &self.input_max)?;
        check_finite(ModelField::Linear, &self.linear)?;
        if !self.linear_by_t.is_empty() {
            check_len(ModelField::LinearByT, n, self.linear_by_t.len())?;
        }
        check_finite(ModelField::LinearByT, &self.linear_by_t)?;
        if let Some(c) = &self.cold_start {
            c.validate()?;
        }
        if let Some(i) = self.input_scale.iter().position(|&s| s <= 0.0) {
            return Err(ModelError::NonPositiveScale { input: i as u8 });
        }
        if let Some(i) = (0..n).find(|&i| self.input_min[i] > self.input_max[i]) {
            return Err(ModelError::BadRange { input: i as u8 });
        }
        for (i, c) in self.centers.iter().enumerate() {
            if c.iter().any(|v| !v.is_finite()) {
                return Err(ModelError::NonFinite {
                    field: ModelField::Centers,
                    index: i as u16,
                });
            }
        }
        check_finite(ModelField::Widths, &self.widths)?;
        if let Some(i) = self.widths.iter().position(|&w| w <= 0.0) {
            return Err(ModelError::NonPositiveWidth { center: i as u16 });
        }
        check_finite(ModelField::Weights, &self.weights)?;
        check_finite(ModelField::Bias, &[self.bias_dph])?;
        check_finite(ModelField::HeldoutRms, &[self.meta.heldout_rms_dph])?;
        check_finite(ModelField::Poly, &self.poly)?;
        if self.poly.len() > MAX_POLY_DEGREE {
            return Err(ModelError::OutOfBounds {
                field: ModelField::Poly,
                index: self.poly.len() as u16,
            });
        }
        self.check_heading()?;
        self.check_bounds()
    }

    /// The heading harmonic, if any: finite, |a|, |b| <= `MAX_HEADING_HARMONIC_DPH`,
    /// sigmas in [0, `MAX_HEADING_SIGMA_DPH`], |correlation| <= 1, at least `MIN_HEADINGS`.
    fn check_heading(&self) -> Result<(), ModelError> {
        let Some(h) = &self.heading else {
            return Ok(());
        };
        let values = [
            h.cos_dph,
            h.sin_dph,
            h.cos_sigma_dph,
            h.sin_sigma_dph,
            h.correlation,
        ];
        check_finite(ModelField::Heading, &values)?;
        let limits = [
            (-MAX_HEADING_HARMONIC_DPH, MAX_HEADING_HARMONIC_DPH),
            (-MAX_HEADING_HARMONIC_DPH, MAX_HEADING_HARMONIC_DPH),
            (0.0, MAX_HEADING_SIGMA_DPH),
            (0.0, MAX_HEADING_SIGMA_DPH),
            (-1.0, 1.0),
        ];
        if let Some(i) =
            (0..values.len()).find(|&i| !(limits[i].0..=limits[i].1).contains(&values[i]))
        {
            return Err(ModelError::OutOfBounds {
                field: ModelField::Heading,
                index: i as u16,
            });
        }
        if (h.n_headings as usize) < MIN_HEADINGS {
            return Err(ModelError::OutOfBounds {
                field: ModelField::Heading,
                index: 5,
            });
        }
        Ok(())
    }

    /// Magnitude bounds: every intermediate of the evaluators stays finite and the
    /// drift stays below `MAX_OUTPUT_DPH` whatever the (finite) inputs.
    fn check_bounds(&self) -> Result<(), ModelError> {
        let out = |field, index: usize| {
            Err(ModelError::OutOfBounds {
                field,
                index: index as u16,
            })
        };
        let raw_ok = |v: &f32| v.abs() <= MAX_ABS_RAW_INPUT;
        for (field, values) in [
            (ModelField::InputOffset, &self.input_offset),
            (ModelField::InputMin, &self.input_min),
            (ModelField::InputMax, &self.input_max),
        ] {
            if let Some(i) = values.iter().position(|v| !raw_ok(v)) {
                return out(field, i);
            }
        }
        let (s_lo, s_hi) = INPUT_SCALE_RANGE;
        if let Some(i) = self
            .input_scale
            .iter()
            .position(|&s| !(s_lo..=s_hi).contains(&s))
        {
            return out(ModelField::InputScale, i);
        }
        let nr = self.n_rbf_inputs as usize;
        if let Some(i) = self
            .centers
            .iter()
            .position(|c| c.iter().take(nr).any(|v| v.abs() > MAX_ABS_CENTER))
        {
            return out(ModelField::Centers, i);
        }
        let (w_lo, w_hi) = WIDTH_RANGE;
        if let Some(i) = self
            .widths
            .iter()
            .position(|&w| !(w_lo..=w_hi).contains(&w))
        {
            return out(ModelField::Widths, i);
        }
        let worst = self.worst_case_output_dph();
        if worst.is_nan() || worst > MAX_OUTPUT_DPH {
            return Err(ModelError::OutputUnbounded {
                worst_dph: if worst < u32::MAX as f64 {
                    worst as u32
                } else {
                    u32::MAX
                },
            });
        }
        Ok(())
    }
}
