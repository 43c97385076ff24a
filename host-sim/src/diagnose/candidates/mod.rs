//! Stage 3, the candidate library: every feature a column or metadata key can offer
//! (values, smooth functions, derivatives, memory, levels, products with the base's
//! inputs; `generic`) and what the device can compute of it causally.

pub mod causal;
pub mod generic;
pub mod transforms;
