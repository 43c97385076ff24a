//! The fit itself: the design (`design`, `candidates`), one Gram matrix per fold of whole
//! runs (`gram`, `assemble`), forward centre selection (`select`: Chen-Cowan-Grant OLS in
//! `ols`, Orr's regularised selection in `orr`, along a `path`), the shape search over
//! widths and polynomial degrees (`shape`), held-out validation (`validate`) and batch
//! prediction with fog-core's deployed maths (`predict`); configured by `config`.

pub mod assemble;
pub mod candidates;
pub mod config;
pub mod design;
pub mod gram;
pub mod ols;
pub mod orr;
pub mod path;
pub mod predict;
pub mod select;
pub mod shape;
pub mod validate;
