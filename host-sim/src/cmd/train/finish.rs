//! The last steps of every trained model, ordinary or unit-calibrated: refinement with
//! field records (`--field`) and staging of each output for the joint commit.

use super::args::Args;
use crate::io::StagedFiles;
use anyhow::Context;
use std::path::Path;

/// The trained model, refined with `--field` records if given (`crate::train::field_correction`).
pub(super) fn field_refined(
    args: &Args,
    model: &fog_core::model::format::RbfModel,
) -> anyhow::Result<fog_core::model::format::RbfModel> {
    let Some(dir) = &args.field else {
        return Ok(model.clone());
    };
    let variants = match (&args.registry, crate::registry::default_path()) {
        (Some(path), _) if !path.is_file() => {
            anyhow::bail!("--registry {}: no such registry file", path.display())
        }
        (Some(path), _) => crate::registry::variants_of(model, path)?,
        (None, Ok(path)) if path.is_file() => crate::registry::variants_of(model, &path)?,
        (None, _) => Vec::new(),
    };
    // The azimuth score's seeks are the ones the trainer's seek criterion scores.
    let seek = args.seek_geometry();
    let refined = crate::train::field_correction::refine_with_dir(
        model,
        dir,
        &variants,
        args.field_weight,
        seek,
    )?;
    print!("{}", refined.summary());
    Ok(refined.model)
}

/// Stages one output (see [`StagedFiles`]), naming it on failure.
pub(super) fn stage(staged: &mut StagedFiles, path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    staged
        .stage(path, bytes)
        .with_context(|| format!("writing {}", path.display()))
}
