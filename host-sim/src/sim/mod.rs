//! The FOG physics simulator (seeded, deterministic): two-node thermal model after
//! power-on, temperature sensor, drift physics (temperature bias, Shupe rate term,
//! gradient-rate term, turn-on bias, pluggable extra terms), IEEE Std 952 noise, and
//! an indexing turntable. See `docs/explain/simulator.md` for the calibration to the paper.

mod checks;
pub mod error;
pub mod gyro;
pub mod instrument;
pub mod noise;
pub mod params;
pub mod run;
pub mod spec;
pub mod terms;
pub mod thermal;
pub mod tripod;
pub mod turntable;

pub use error::SimError;
pub use gyro::{RawSample, SimGyro};
pub use instrument::SeekInstrument;
pub use params::{
    DriftParams, GyroParams, NoiseParams, RunVariation, SensorParams, SensorPlacement,
    ThermalParams,
};
pub use run::{rig, simulate_run, MEAN_WINDOW_S};
pub use spec::{RunSpec, StartState, DEFAULT_LATITUDE_DEG};
pub use terms::{AuxSource, AuxTransform, DriftTerm};
pub use tripod::{BaseMotion, Disturbance};
pub use turntable::{SimTurntable, TurntableError, TurntableParams};
