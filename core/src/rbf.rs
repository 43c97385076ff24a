//! Gaussian RBF evaluation in f32 (`libm::expf`).
