//! Stage 6, back to the simulator: its physics calibrated to the record and the named cause
//! mapped onto its drift terms.

pub mod calibrate;
pub mod drift_terms;
pub mod thermal;

use crate::diagnose::baseline::models::Stacked;
use crate::diagnose::error::DiagnoseError;
use crate::diagnose::input::Campaign;
use crate::diagnose::memprobe;
use crate::diagnose::selection::screen::Step;
use crate::diagnose::validation::folds::Folds;

/// The simulator's physics calibrated to the campaign , with its design
/// (the uncertainty stage refits on it).
pub fn calibrate_stage(
    campaign: &Campaign,
    folds: &Folds,
    st: &Stacked,
    named: Option<&Step>,
) -> Result<(calibrate::SimDesign, calibrate::SimCalibration), DiagnoseError> {
    let sim_design = calibrate::SimDesign::new(campaign);
    memprobe::stage("SimDesign::new");
    let sim = calibrate::calibrate(
        &sim_design,
        &folds.run_rows,
        &st.y,
        named.map(|s| s.cols.as_slice()),
    )?;
    memprobe::stage("simulator::calibrate");
    Ok((sim_design, sim))
}
