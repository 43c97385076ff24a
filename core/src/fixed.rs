//! Integer-only RBF evaluation for FPU-less parts.
