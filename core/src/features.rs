//! 10 s window averaging and temperature-rate estimation.
