//! Per-window drift compensation.
