//! The training set: one row of model inputs (raw units) per 10 s point, its target
//! drift (deg/h) and the id of the run (group) it came from, so validation can hold
//! out whole runs. Validation happens here once, so the fitting code can trust it.

use crate::train::error::{Result, TrainError};
use fog_core::model::format::{FeatureSpec, MAX_INPUTS};

/// Rows of model inputs with their targets and run ids.
#[derive(Clone, Debug, PartialEq)]
pub struct Dataset {
    /// What each input column is (fog-core feature kinds, so the device computes the same).
    pub specs: Vec<FeatureSpec>,
    /// Human-readable name of each input column, e.g. `temp_c:value`.
    pub input_names: Vec<String>,
    /// Row-major inputs, `len() * n_inputs()` values, raw units.
    inputs: Vec<f64>,
    /// Target drift per row, deg/h (rate_dph - earth_dph).
    pub targets_dph: Vec<f64>,
    /// Group (run) id per row; rows of one group are never split by validation.
    pub groups: Vec<u32>,
    /// Time since power-on of each row, s (for reports and plots; not a model input).
    pub t_s: Vec<f64>,
    /// Name of each group id (e.g. the run's file name), indexed by id.
    pub group_names: Vec<String>,
    /// Ambient (chamber) temperature of each group, degC, when the run says it: runs at
    /// one ambient are replicates for the declared input range (`declared_range`).
    pub group_ambient_c: Vec<Option<f64>>,
}

impl Dataset {
    /// An empty dataset with these input columns.
    pub fn with_specs(specs: Vec<FeatureSpec>, input_names: Vec<String>) -> Result<Self> {
        if specs.is_empty() {
            return Err(TrainError::BadConfig {
                option: "inputs",
                why: "at least one model input is needed".into(),
            });
        }
        if specs.len() > MAX_INPUTS {
            return Err(TrainError::TooManyInputs {
                found: specs.len(),
                max: MAX_INPUTS,
            });
        }
        if input_names.len() != specs.len() {
            return Err(TrainError::InputCount {
                expected: specs.len(),
                found: input_names.len(),
                row: 0,
            });
        }
        Ok(Self {
            specs,
            input_names,
            inputs: Vec::new(),
            targets_dph: Vec::new(),
            groups: Vec::new(),
            t_s: Vec::new(),
            group_names: Vec::new(),
            group_ambient_c: Vec::new(),
        })
    }

    /// Appends one group (run): rows of inputs, targets and times; returns its group id.
    /// The whole group is checked first and nothing is added if any value is bad.
    pub fn push_group(
        &mut self,
        name: &str,
        rows: &[Vec<f64>],
        targets_dph: &[f64],
        t_s: &[f64],
    ) -> Result<u32> {
        if rows.len() != targets_dph.len() || rows.len() != t_s.len() {
            return Err(TrainError::LengthMismatch {
                rows: rows.len(),
                targets: targets_dph.len(),
                groups: t_s.len(),
            });
        }
        let base = self.len();
        for (i, (row, &y)) in rows.iter().zip(targets_dph).enumerate() {
            if row.len() != self.n_inputs() {
                return Err(TrainError::InputCount {
                    expected: self.n_inputs(),
                    found: row.len(),
                    row: base + i,
                });
            }
            if let Some(j) = row.iter().position(|v| !v.is_finite()) {
                return Err(TrainError::NonFinite {
                    what: "model input",
                    row: base + i,
                    input: j,
                });
            }
            if !y.is_finite() {
                return Err(TrainError::NonFinite {
                    what: "target drift",
                    row: base + i,
                    input: 0,
                });
            }
        }
        let id = self.group_names.len() as u32;
        self.group_names.push(name.to_string());
        self.group_ambient_c.push(None);
        for ((row, &y), &t) in rows.iter().zip(targets_dph).zip(t_s) {
            self.inputs.extend_from_slice(row);
            self.targets_dph.push(y);
            self.groups.push(id);
            self.t_s.push(t);
        }
        Ok(id)
    }

    /// Sets the ambient of group `id` (ignored for an unknown id).
    pub fn set_group_ambient(&mut self, id: u32, ambient_c: Option<f64>) {
        if let Some(a) = self.group_ambient_c.get_mut(id as usize) {
            *a = ambient_c.filter(|v| v.is_finite());
        }
    }

    /// Number of rows (10 s points).
    pub fn len(&self) -> usize {
        self.targets_dph.len()
    }

    /// True when there are no rows.
    pub fn is_empty(&self) -> bool {
        self.targets_dph.is_empty()
    }

    /// Number of input columns.
    pub fn n_inputs(&self) -> usize {
        self.specs.len()
    }

    /// Number of groups (runs).
    pub fn n_groups(&self) -> usize {
        self.group_names.len()
    }

    /// Inputs of row `i`, raw units, in `specs` order.
    pub fn row(&self, i: usize) -> &[f64] {
        let d = self.n_inputs();
        &self.inputs[i * d..(i + 1) * d]
    }

    /// Iterator over all input rows.
    pub fn rows(&self) -> impl Iterator<Item = &[f64]> {
        self.inputs.chunks_exact(self.n_inputs())
    }

    /// The rows whose indices are listed (group ids and names are kept as they are).
    pub fn subset(&self, indices: &[usize]) -> Self {
        let mut out = Self {
            specs: self.specs.clone(),
            input_names: self.input_names.clone(),
            inputs: Vec::with_capacity(indices.len() * self.n_inputs()),
            targets_dph: Vec::with_capacity(indices.len()),
            groups: Vec::with_capacity(indices.len()),
            t_s: Vec::with_capacity(indices.len()),
            group_names: self.group_names.clone(),
            group_ambient_c: self.group_ambient_c.clone(),
        };
        for &i in indices {
            out.inputs.extend_from_slice(self.row(i));
            out.targets_dph.push(self.targets_dph[i]);
            out.groups.push(self.groups[i]);
            out.t_s.push(self.t_s[i]);
        }
        out
    }

    /// Row indices of the groups for which `keep(group_id)` is true.
    pub fn indices_where(&self, keep: impl Fn(u32) -> bool) -> Vec<usize> {
        (0..self.len()).filter(|&i| keep(self.groups[i])).collect()
    }
}
