//! Stage 3, the candidate library: every feature a column can offer (values, derivatives,
//! memory) and what the device can compute of it causally.

pub mod causal;
pub mod derivatives;
pub mod transforms;
