//! The trainer's data: 10 s drift rows from runs (`dataset`, with the model's input
//! columns built by `features`), the inputs' normalisation (`normalize`) and the range a
//! model declares valid (`declared_range`).

pub mod dataset;
pub mod declared_range;
pub mod features;
pub mod normalize;
