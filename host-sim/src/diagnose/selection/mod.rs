//! Stage 4, selection and tests: candidates ranked by held-out gain, the family-wise
//! significance test, the power check when nothing is named, the named cause and the
//! test that separates it from competing explanations.

pub mod cause;
pub mod parsimony;
pub mod power;
pub mod scored;
pub mod screen;
pub mod separate;
