//! The wire formats of the device's sensor and rig links, shared by the firmware (which
//! decodes them), the host's rig and simulators (which encode them) and the tests, so
//! every side reads the one definition of a frame:
//! - `framing`: sync marker, fixed-length body, CRC-16; the resynchronising decoder;
//! - `gyro_frame`: the FOG's sample frame (angle increment, coil temperature, status);
//! - `tilt_frame`: the inclinometer's frame (pitch and roll of the base);
//! - `table_line`: the indexing turntable's ASCII command and reply lines.
//!
//! The host port (model upload, north-finder messages) is a different link: [`crate::link`].

pub mod framing;
pub mod gyro_frame;
pub mod table_line;
pub mod tilt_frame;
