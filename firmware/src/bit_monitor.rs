//! Fills fog-core's BIT word from the firmware's real counters, once per BIT period.
//!
//! Exists so that the rule "which counter means which item" is plain host-testable code and
//! not buried in a board's main loop. Inputs per item (docs/explain/northfinder.md, "Built-in test"):
//! gyro link age (clock time since the last decoded sample), frame-error rate (CRC errors
//! over CRC errors + good frames since the previous evaluation), temperature (latest reading)
//! and its rate (difference of consecutive readings over their sample-time distance),
//! inclinometer age (clock time since the last good reading), turntable (the last seek did
//! not end with a turntable driver error within `TABLE_FAULT_HOLD_S`), model (a verified
//! model is in use), flash (both model slots verified at boot).

use fog_core::seeking::bit::{evaluate, BitInputs, BitLimits, BitWord};

/// How long a turntable driver error keeps the turntable item failed, s.
pub const TABLE_FAULT_HOLD_S: f64 = 60.0;

/// What the board measured since power-on (totals; the monitor takes differences).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BitCounters {
    /// Clock now, s.
    pub now_s: f64,
    /// Clock time of the last gyro sample (`None`: none yet).
    pub last_gyro_s: Option<f64>,
    pub frames_ok: u32,
    pub frames_bad: u32,
    /// Latest temperature, degC, and its sample time, s (`None`: none or invalid).
    pub temp: Option<(f64, f32)>,
    /// Clock time of the last good inclinometer reading.
    pub last_tilt_s: Option<f64>,
    /// Clock time of the last turntable driver error.
    pub last_table_error_s: Option<f64>,
    pub model_valid: bool,
    pub flash_ok: bool,
}

/// The monitor: keeps what the rates need between evaluations.
#[derive(Clone, Debug)]
pub struct BitMonitor {
    limits: BitLimits,
    prev_frames: (u32, u32),
    prev_temp: Option<(f64, f32)>,
    temp_rate_cps: f32,
}

impl BitMonitor {
    pub fn new(limits: BitLimits) -> Self {
        Self {
            limits,
            prev_frames: (0, 0),
            prev_temp: None,
            temp_rate_cps: 0.0,
        }
    }

    /// The inputs of this period (updates the rate state).
    pub fn inputs(&mut self, c: &BitCounters) -> BitInputs {
        let ok = c.frames_ok.wrapping_sub(self.prev_frames.0);
        let bad = c.frames_bad.wrapping_sub(self.prev_frames.1);
        self.prev_frames = (c.frames_ok, c.frames_bad);
        if let (Some((t1, v1)), Some((t0, v0))) = (c.temp, self.prev_temp) {
            let dt = t1 - t0;
            if dt > 0.0 {
                self.temp_rate_cps = ((v1 - v0) as f64 / dt) as f32;
            }
        }
        if c.temp.is_some() {
            self.prev_temp = c.temp;
        }
        let age = |t: Option<f64>| t.map_or(f32::INFINITY, |t| (c.now_s - t) as f32);
        BitInputs {
            gyro_silence_s: age(c.last_gyro_s),
            gyro_frames_ok: ok,
            gyro_frames_bad: bad,
            temp_c: c.temp.map_or(f32::NAN, |(_, v)| v),
            temp_rate_cps: self.temp_rate_cps,
            inclinometer_silence_s: age(c.last_tilt_s),
            turntable_answering: c
                .last_table_error_s
                .is_none_or(|t| c.now_s - t > TABLE_FAULT_HOLD_S),
            model_valid: c.model_valid,
            flash_ok: c.flash_ok,
        }
    }

    /// The BIT word of this period.
    pub fn evaluate(&mut self, c: &BitCounters) -> BitWord {
        let inputs = self.inputs(c);
        evaluate(&inputs, &self.limits)
    }
}
