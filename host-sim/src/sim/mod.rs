//! The FOG physics simulator (seeded, deterministic): two-node thermal model after
//! power-on, temperature sensor, drift physics (temperature bias, Shupe rate term,
//! gradient-rate term, turn-on bias, pluggable extra terms), IEEE Std 952 noise, an
//! indexing turntable, the units of one gyro type (`unit_spread`, `fleet`), and its random
//! parts one at a time switched off (`quiet`). See
//! `docs/explain/simulator.md` for the calibration to the paper and the fleet's spreads.

mod checks;
pub mod error;
pub mod fleet;
pub mod gyro;
pub mod instrument;
pub mod noise;
pub mod params;
pub mod quiet;
pub mod run;
pub mod spec;
pub mod terms;
pub mod thermal;
pub mod tripod;
pub mod turntable;
pub mod unit_spread;

pub use error::SimError;
pub use fleet::unit_params;
pub use gyro::{RawSample, SimGyro};
pub use instrument::SeekInstrument;
pub use params::{
    DriftParams, GyroParams, NoiseParams, RunVariation, SensorParams, SensorPlacement,
    ThermalParams,
};
pub use quiet::RandomPart;
pub use run::{rig, simulate_run, MEAN_WINDOW_S};
pub use spec::{RunSpec, StartState, DEFAULT_LATITUDE_DEG};
pub use terms::{AuxSource, AuxTransform, DriftTerm};
pub use tripod::{BaseMotion, Disturbance};
pub use turntable::{SimTurntable, TurntableError, TurntableParams};
pub use unit_spread::{SpreadLaw, TypeSpread};
