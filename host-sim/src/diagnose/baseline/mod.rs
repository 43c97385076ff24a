//! Stage 2, the base model: the paper's RBF and its rivals on the record's own inputs, with one
//! temperature law across runs or free run levels, chosen on held-out runs.

pub mod choice;
pub mod layout;
pub mod levels;
pub mod models;
pub mod rbf_basis;
