//! The project's figures, built from its data: startup drift (paper Fig. 4/5) and coil
//! temperature after power-on (runs coloured by ambient), the Allan analysis (confidence
//! band, error bars, fitted IEEE 952 lines) and the north-seek azimuth scatter.

pub mod allan;
pub mod azimuth;
pub mod runs;
