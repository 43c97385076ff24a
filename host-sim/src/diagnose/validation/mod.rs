//! Ground floor: held-out validation shared by every stage, importing none of them: the
//! layouts (`folds`: whole runs, or buffered time blocks of single records), the ridge
//! fits on them (`cv`), the buffer rule (`buffer`), the design rows (`design`; held in
//! memory within a fixed budget by `row_cache`), the per-unit scores of a term (`score`),
//! the sums of per-unit systems that every fit starts from (`unit_sums`) and the sign-flip
//! test that respects run offsets (`signflip`).

pub mod buffer;
pub mod cv;
pub mod design;
pub mod folds;
pub mod row_cache;
pub mod score;
pub mod signflip;
pub mod unit_sums;
