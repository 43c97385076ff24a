//! Upload protocol messages shared by `fogsim upload` and the firmware.
