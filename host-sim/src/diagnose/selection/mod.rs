//! Stage 4, selection and tests: candidates ranked by held-out gain, the family-wise
//! significance test, the power check when nothing is named, and the named cause.

pub mod cause;
pub mod power;
pub mod screen;
