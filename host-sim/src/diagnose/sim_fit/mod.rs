//! Stage 6, back to the simulator: its physics calibrated to the record and the named cause
//! mapped onto its drift terms.

pub mod calibrate;
pub mod drift_terms;
pub mod thermal;
