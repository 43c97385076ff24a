//! The models `reproduce` compares: the paper's inputs and the global model's, chosen by
//! validation, and the file each is written to.

use std::path::Path;

use anyhow::{anyhow, Result};

use crate::io::runs::Run;
use crate::train::{choose_inputs_default, InputSelection, InputSet, TrainConfig};
use fog_core::model::format::FeatureSpec;

/// The model inputs compared: the paper's (T, dT/dt), and the global model's, chosen from
/// the training runs by `train`'s defaults (`choose_inputs_default` over every `InputSet`),
/// with that choice.
pub fn input_variants(train_runs: &[&Run]) -> Result<Vec<InputVariant>> {
    let owned: Vec<Run> = train_runs.iter().map(|r| (*r).clone()).collect();
    let cfg = TrainConfig::default();
    let (selection, _) = choose_inputs_default(&owned, &InputSet::ALL, &cfg)
        .map_err(|e| anyhow!("choosing the global model's inputs: {e}"))?;
    let chosen = selection.chosen;
    Ok(vec![
        InputVariant {
            label: "paper inputs (T, dT/dt)".into(),
            specs: InputSet::TempRate.specs(),
            selection: None,
        },
        InputVariant {
            label: format!(
                "global model, inputs chosen by validation ({})",
                chosen.name()
            ),
            specs: chosen.specs(),
            selection: Some(selection),
        },
    ])
}

/// One model `reproduce` trains: its label, inputs and how they were chosen (None: fixed).
pub struct InputVariant {
    pub label: String,
    pub specs: Vec<FeatureSpec>,
    pub selection: Option<InputSelection>,
}

/// File name of a variant's deployable model (written beside its plots).
pub fn model_file_name(specs: &[FeatureSpec]) -> String {
    let set = InputSet::NAMED
        .into_iter()
        .find(|s| s.specs() == specs)
        .map_or("custom", InputSet::name);
    format!("model_{}.bin", set.replace(',', "_"))
}

/// Writes a model in fog-core's encoding (what `fogsim upload` sends), atomically.
pub fn write_model_file(path: &Path, model: &fog_core::model::format::RbfModel) -> Result<()> {
    crate::io::write_atomic(path, &crate::io::model::encode_model(model)?)
        .map_err(|e| anyhow!("writing {}: {e}", path.display()))
}
