//! Generators and judges shared by several test modules.

pub mod aging;
pub mod field_gyro;
pub mod fleet_independent;
pub mod fleet_judge;
pub mod independent;
pub mod level;
pub mod novel;
pub mod peer;
pub mod peer_library;
pub mod peer_subset;
pub mod planted;
pub mod seeds;
pub mod seek_judge;
pub mod single_record;
pub mod soaked;
