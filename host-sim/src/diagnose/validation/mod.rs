//! Held-out validation shared by every stage: folds over whole runs (or buffered time
//! blocks of single records) and the sign-flip test that respects run offsets.

pub mod buffer;
pub mod cv;
pub mod design;
pub mod folds;
pub mod signflip;
