//! fog-app's fixed numbers: the gyro rate, the UARTs' baud rates, the loop's budgets and
//! periods, and the verifying key and gyro id chosen at build time.

/// Gyro output rate, Hz.
pub(crate) const GYRO_RATE_HZ: u32 = 2000;
/// Host link and turntable baud rates; the gyro link runs at 460,800 baud.
pub(crate) const HOST_BAUD: u32 = 115_200;
pub(crate) const GYRO_BAUD: u32 = 460_800;
pub(crate) const TABLE_BAUD: u32 = 115_200;
pub(crate) const INCL_BAUD: u32 = 115_200;
/// Watchdog deadline between feeds, ms.
pub(crate) const WATCHDOG_TIMEOUT_MS: u32 = 500;
/// Host bytes handled per main-loop pass (the gyro ring is drained in between).
pub(crate) const HOST_BYTES_PER_PASS: usize = 64;
/// Reply bytes waiting for the host UART.
pub(crate) const TX_QUEUE_LEN: usize = 512;
/// No gyro sample for this long marks the gyro silent (a fault in the window), s.
pub(crate) const GYRO_SILENCE_S: f64 = 0.1;
/// Status period on the host port and BIT evaluation period, s (clock time).
pub(crate) const STATUS_PERIOD_S: f64 = 1.0;
/// Inclinometer reading period, s of sample time.
pub(crate) const TILT_PERIOD_S: f64 = 1.0;
/// Seed of the simulated inclinometer's noise.
pub(crate) const TILT_NOISE_SEED: u64 = 0x5C13_3000;

/// The model-verifying public key and the gyro id, chosen at build time (build.rs).
pub(crate) const VERIFY_KEY: [u8; 32] =
    *include_bytes!(concat!(env!("OUT_DIR"), "/verify_key.bin"));
pub(crate) const GYRO_ID: &str = include_str!(concat!(env!("OUT_DIR"), "/gyro_id.txt"));
