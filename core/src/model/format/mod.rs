//! The RBF drift model as stored in flash and sent over the wire.
//!
//! CONTRACT (shared by trainer, diagnose, firmware): the struct layout below is
//! the one every crate builds against. Encoding is postcard of `WireModel`
//! (magic, version, body, CRC-32 of the body bytes); decoding (`model::in_place`, above
//! this folder) validates sizes, finiteness, positive widths and ranges and returns a
//! `ModelError` (`model::error`, below it, with the stored sub-records `model::heading` and
//! `model::cold_start` and the CRC `model::crc`).
//!
//! drift_dph = bias_dph + sum_j (linear[j] + linear_by_t[j] * t) * xn_j + sum_k poly[k-1] * t^k
//!             + sum_i weights[i] * exp(-||xn - c_i||^2 / (2 widths[i]^2))
//! with xn_j = (x_j - input_offset[j]) / input_scale[j] (normalised inputs, each held to
//! +-`XN_CLAMP`) and t = xn_0 held to the trained range of input 0 (a polynomial is not
//! extrapolated). Only the first `n_rbf_inputs` inputs enter the Gaussian distance; inputs
//! after them are linear-only terms (diagnose may add a cause that way).
//!
//! Format versions: 1 has no `poly` (decoded with an empty one), 2 appends `poly` after
//! `meta`, 3 appends `heading` after `poly`: the optional heading harmonic of the bias
//! (`model::heading`, fitted by `seeking::heading_cal`), stored inside the model bytes so that the model's CRC and the upload
//! signature cover it (v1 and v2 decode with none), 4 appends `linear_by_t` after
//! `heading`: linear terms whose coefficients change with temperature (a Shupe coefficient
//! k_S(T) = k_0 + k_1 T makes the drift k_0 dT/dt + k_1 T dT/dt; v1-v3 decode with none), 5
//! appends `cold_start` after `linear_by_t`: the optional envelope of the training cold
//! starts' temperature rise (`model::cold_start`; v1-v4 decode with none), 6 keeps 5's layout
//! and allows up to six inputs (four of them at most in the Gaussians, so a centre stays
//! four wide) and the warm-up clock's stretch as an input kind: a v6 file a v5 build
//! refuses by its version, not as malformed. Validation bounds every parameter's magnitude so that any model that decodes
//! gives a finite drift below `MAX_OUTPUT_DPH` at any finite input.
//!
//! One file a job, importing one way: `limits` (the format's constants and bounds, with the
//! `ModelError` messages that quote them) -> `inputs` (what a model input is) -> `model`
//! (the `RbfModel` struct and its plain accessors) -> `validate` (the invariants) and
//! `encode` (the postcard/CRC wire bytes).

mod encode;
mod inputs;
mod limits;
mod model;
mod validate;

pub(crate) use encode::{BodyCounts, WireModel};
pub use inputs::{FeatureKind, FeatureSpec, PAPER_INPUTS};
pub use limits::{
    INPUT_SCALE_RANGE, MAX_ABS_CENTER, MAX_ABS_RAW_INPUT, MAX_AUX, MAX_CENTERS, MAX_ENCODED_LEN,
    MAX_HEADING_HARMONIC_DPH, MAX_HEADING_SIGMA_DPH, MAX_INPUTS, MAX_OUTPUT_DPH, MAX_POLY_DEGREE,
    MAX_RBF_INPUTS, MODEL_MAGIC, MODEL_VERSION, MODEL_VERSION_BASE, MODEL_VERSION_OLDEST,
    WIDTH_RANGE, XN_CLAMP,
};
pub use model::{RbfModel, TrainingMeta};
