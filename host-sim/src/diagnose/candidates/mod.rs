//! Stage 3, the candidate library: every feature a column or metadata key can offer
//! (values, smooth functions, derivatives, memory, levels, products with the base's
//! inputs; `generic`), metadata of every type as run-constant columns (`metadata`) and
//! what the device can compute of it causally; event clocks (`events`), products of two
//! extra columns screened against the base (`pairs`), rate-independent memory
//! (`hysteresis`) and the operator families the report counts and checks per family
//! (`families`).

pub mod causal;
pub mod events;
pub mod families;
pub mod generic;
pub mod hysteresis;
pub mod metadata;
pub mod pairs;
pub mod transforms;

use crate::diagnose::baseline::choice::BaseFit;
use crate::diagnose::baseline::models::Stacked;
use crate::diagnose::input::Campaign;
use crate::diagnose::memprobe;
use crate::diagnose::validation::folds::Folds;

/// The generic library and, if the cap left candidates out, a note saying so (the
/// candidate's label and the reason, as the selection lists skipped candidates).
/// Products with dT/dt use the base's window (`st`); the pairwise products are screened
/// against `base` on `folds` (`pairs`).
pub fn library_of(
    campaign: &Campaign,
    meta: &[metadata::MetaColumn],
    st: &Stacked,
    folds: &Folds,
    base: &BaseFit,
) -> (generic::Built, Option<(String, String)>) {
    let keep_pairs = |p| pairs::screened(campaign, folds, base, p);
    let library = generic::enumerate(
        campaign,
        meta,
        st.temp_rate_half_s,
        &folds.unit_rows,
        &keep_pairs,
    );
    let left_out = library.cut_by_cap.len();
    memprobe::stage("library");
    let note = (left_out > 0).then(|| {
        (
            format!("{left_out} candidates"),
            format!("library capped at {} candidates", generic::MAX_CANDIDATES),
        )
    });
    (library, note)
}
