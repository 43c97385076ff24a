//! The device-facing clients: everything that talks to a gyro (or the simulated one) over
//! its links. `upload` sends a signed model (and holds the polled link reader the others
//! share), `monitor` receives status and seek results into the registry, `field_pull`
//! fetches the device's field records, and `rig` serves a simulated gyro and turntable on
//! the device's own links for tests and the lab.

pub mod field_pull;
pub mod monitor;
pub mod rig;
pub mod upload;
