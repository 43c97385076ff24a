//! What one completed two-position seek teaches about the gyro in the field: the residual
//! bias it measured (after the drift model) at the temperature state it ran in.
//!
//! A two-position seek differences headings 0 and 180 deg for the azimuth; the half-sum of
//! the two positions' compensated rates is the bias the model left, at the seek's mean
//! temperature, dT/dt, d2T/dt2 (the mean of the model's own window input) and time since
//! power-on. The device keeps these records in
//! a flash ring (`fog_firmware::field_log`), sends them on request (`link::messages`), and
//! `fogsim train --field` refines the model with them. This module is the one definition
//! both ends build against: the record, its fixed 36-byte flash encoding with its own
//! CRC-32, and the temperature state averaged over a seek's windows.
//!
//! Flash encoding (little-endian):
//!
//! | offset | bytes | field |
//! |---|---|---|
//! | 0 | 2 | magic `"FR"` (0x5246) |
//! | 2 | 1 | encoding version (1) |
//! | 3 | 1 | flags: bit 0 = a model was active (`model_crc32` valid) |
//! | 4 | 4 | sequence number (u32, never 0xFFFF_FFFF) |
//! | 8 | 4 | temperature, degC (f32) |
//! | 12 | 4 | dT/dt, degC/s (f32) |
//! | 16 | 4 | d2T/dt2, degC/s^2 (f32) |
//! | 20 | 4 | time since power-on at the seek's end, s (f32) |
//! | 24 | 4 | residual bias, deg/h (f32) |
//! | 28 | 4 | CRC-32 of the active model (0 without one) |
//! | 32 | 4 | CRC-32 (ISO-HDLC, as the link) of bytes 0..32 |
//!
//! An erased slot reads all 0xFF and is `Empty`; anything else that fails the magic,
//! version, CRC or range checks is `Corrupt` (a torn write), never a record.

use serde::{Deserialize, Serialize};

use crate::compensation::compensator::WindowResult;
use crate::model::crc::CRC32;
use crate::model::format::{FeatureKind, RbfModel};

/// Bytes of one encoded record (a multiple of every supported flash word: 1, 2, 4 bytes).
pub const FIELD_RECORD_LEN: usize = 36;
/// Magic "FR".
const RECORD_MAGIC: u16 = 0x5246;
/// Encoding version.
const RECORD_VERSION: u8 = 1;
/// Flag: a model was active.
const FLAG_MODEL: u8 = 1;
/// Bytes covered by the record CRC.
const CRC_SPAN: usize = 32;
/// Largest |residual bias| a record may carry, deg/h (a navigation-grade FOG's residual
/// is < 1 deg/h; beyond this the seek was not a measurement of bias).
pub const MAX_ABS_RESIDUAL_DPH: f32 = 1000.0;
/// Largest |temperature| a record may carry, degC.
pub const MAX_ABS_TEMP_C: f32 = 200.0;

/// One completed two-position seek's residual bias at its temperature state.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FieldRecord {
    /// Ring sequence number (assigned at append; increases across power cycles).
    pub sequence: u32,
    /// Mean gyro temperature over the seek's windows, degC.
    pub temp_c: f32,
    /// Mean dT/dt over the seek's windows, degC/s.
    pub temp_rate_cps: f32,
    /// Mean over the seek's windows of the model's own d2T/dt2 input (its 10 s window
    /// estimate), degC/s^2; 0 when the model has no plain d2T/dt2 input.
    pub temp_accel_cps2: f32,
    /// Seconds since power-on at the seek's end.
    pub t_since_power_on_s: f32,
    /// Half-sum of the two positions' compensated rates, deg/h.
    pub residual_bias_dph: f32,
    /// CRC-32 of the drift model that compensated the seek (`None`: uncompensated).
    pub model_crc32: Option<u32>,
}

/// Why bytes are not a record.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RecordDefect {
    /// All 0xFF: an erased slot (not a fault).
    Empty,
    /// Wrong magic, version, CRC, or a value out of range: a torn or decayed write.
    Corrupt,
}

impl FieldRecord {
    /// An all-zero record (array filler of a reply; never sent as a record).
    pub const ZERO: Self = Self {
        sequence: 0,
        temp_c: 0.0,
        temp_rate_cps: 0.0,
        temp_accel_cps2: 0.0,
        t_since_power_on_s: 0.0,
        residual_bias_dph: 0.0,
        model_crc32: None,
    };

    /// `true` if every value is finite and in range and the sequence is not the erased
    /// pattern (what `to_bytes` may write and `from_bytes` accepts).
    pub fn is_plausible(&self) -> bool {
        let finite = [
            self.temp_c,
            self.temp_rate_cps,
            self.temp_accel_cps2,
            self.t_since_power_on_s,
            self.residual_bias_dph,
        ]
        .iter()
        .all(|v| v.is_finite());
        finite
            && self.sequence != u32::MAX
            && libm::fabsf(self.temp_c) <= MAX_ABS_TEMP_C
            && libm::fabsf(self.residual_bias_dph) <= MAX_ABS_RESIDUAL_DPH
            && self.t_since_power_on_s >= 0.0
    }

    /// The fixed flash encoding (table above).
    pub fn to_bytes(&self) -> [u8; FIELD_RECORD_LEN] {
        let mut b = [0u8; FIELD_RECORD_LEN];
        b[0..2].copy_from_slice(&RECORD_MAGIC.to_le_bytes());
        b[2] = RECORD_VERSION;
        b[3] = if self.model_crc32.is_some() {
            FLAG_MODEL
        } else {
            0
        };
        b[4..8].copy_from_slice(&self.sequence.to_le_bytes());
        b[8..12].copy_from_slice(&self.temp_c.to_le_bytes());
        b[12..16].copy_from_slice(&self.temp_rate_cps.to_le_bytes());
        b[16..20].copy_from_slice(&self.temp_accel_cps2.to_le_bytes());
        b[20..24].copy_from_slice(&self.t_since_power_on_s.to_le_bytes());
        b[24..28].copy_from_slice(&self.residual_bias_dph.to_le_bytes());
        b[28..32].copy_from_slice(&self.model_crc32.unwrap_or(0).to_le_bytes());
        let crc = CRC32.checksum(&b[..CRC_SPAN]);
        b[32..36].copy_from_slice(&crc.to_le_bytes());
        b
    }

    /// Decodes and checks one slot's bytes.
    pub fn from_bytes(b: &[u8; FIELD_RECORD_LEN]) -> Result<Self, RecordDefect> {
        if b.iter().all(|&x| x == 0xFF) {
            return Err(RecordDefect::Empty);
        }
        let word = |at: usize| u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]]);
        let float = |at: usize| f32::from_bits(word(at));
        let header_ok = u16::from_le_bytes([b[0], b[1]]) == RECORD_MAGIC
            && b[2] == RECORD_VERSION
            && b[3] & !FLAG_MODEL == 0
            && CRC32.checksum(&b[..CRC_SPAN]) == word(32);
        if !header_ok {
            return Err(RecordDefect::Corrupt);
        }
        let record = Self {
            sequence: word(4),
            temp_c: float(8),
            temp_rate_cps: float(12),
            temp_accel_cps2: float(16),
            t_since_power_on_s: float(20),
            residual_bias_dph: float(24),
            model_crc32: (b[3] & FLAG_MODEL != 0).then(|| word(28)),
        };
        if record.is_plausible() {
            Ok(record)
        } else {
            Err(RecordDefect::Corrupt)
        }
    }
}

/// The temperature state averaged over a seek's windows: mean T, mean dT/dt, and the mean
/// of the model's own d2T/dt2 input (its 10 s window estimate, the value the model saw and
/// a linear correction in it averages over; 0 when the model has none). The seek's bias is
/// an average over the same windows, so its state is too. Reset at each seek start; no
/// allocation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SeekTempState {
    n: u32,
    sum_temp: f64,
    sum_rate: f64,
    n_accel: u32,
    sum_accel: f64,
}

/// The averaged state of a seek, what a record carries besides the bias.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TempState {
    pub temp_c: f32,
    pub temp_rate_cps: f32,
    pub temp_accel_cps2: f32,
}

/// Index of the model's d2T/dt2 input (`TempAccelCps2` or its flat-start estimator
/// `TempAccelFlatStartCps2`, default span), if it has one: the input whose window values
/// a record averages.
pub fn accel_input_index(model: &RbfModel) -> Option<usize> {
    model.inputs.iter().position(|s| {
        matches!(
            s.kind,
            FeatureKind::TempAccelCps2 | FeatureKind::TempAccelFlatStartCps2
        ) && s.tau_s == 0.0
    })
}

impl SeekTempState {
    pub const fn new() -> Self {
        Self {
            n: 0,
            sum_temp: 0.0,
            sum_rate: 0.0,
            n_accel: 0,
            sum_accel: 0.0,
        }
    }

    /// Forgets everything (a seek starts).
    pub fn reset(&mut self) {
        *self = Self::new();
    }

    /// Adds one window: its mean temperature, dT/dt and, when `model` (the model that
    /// compensated it) has a plain d2T/dt2 input, that input's value in this window.
    /// Non-finite values are skipped (a window without temperature does not move the state).
    pub fn push_window(&mut self, w: &WindowResult, model: Option<&RbfModel>) {
        if !(w.temp_c.is_finite() && w.temp_rate_cps.is_finite()) {
            return;
        }
        self.n += 1;
        self.sum_temp += f64::from(w.temp_c);
        self.sum_rate += f64::from(w.temp_rate_cps);
        let accel = model
            .and_then(accel_input_index)
            .filter(|&j| j < usize::from(w.n_inputs))
            .and_then(|j| w.inputs.get(j).copied())
            .filter(|a| a.is_finite());
        if let Some(a) = accel {
            self.n_accel += 1;
            self.sum_accel += f64::from(a);
        }
    }

    /// Windows averaged so far.
    pub fn windows(&self) -> u32 {
        self.n
    }

    /// The averaged state (`None` before the first window); d2T/dt2 is 0 if no window
    /// carried the model's d2T/dt2 input.
    pub fn state(&self) -> Option<TempState> {
        if self.n == 0 {
            return None;
        }
        let n = f64::from(self.n);
        let accel = if self.n_accel > 0 {
            self.sum_accel / f64::from(self.n_accel)
        } else {
            0.0
        };
        Some(TempState {
            temp_c: (self.sum_temp / n) as f32,
            temp_rate_cps: (self.sum_rate / n) as f32,
            temp_accel_cps2: accel as f32,
        })
    }
}

/// The residual bias of a completed two-position seek: the half-sum of its two main
/// positions' compensated rates (headings 0 and 180 deg apart; the short ambiguity dwell
/// at +90 deg is not used), deg/h. `None` for a four-position seek (its bias is its own
/// estimate, not recorded here) or if the two main positions are not opposite. A
/// time-symmetric two-position seek counts: its positions average both visits, so the
/// half-sum is the bias at the seek's mean time, as for the forward seek.
pub fn two_position_residual_dph(result: &crate::seeking::northfinder::SeekResult) -> Option<f64> {
    use crate::seeking::northfinder::SeekMode;
    if result.mode.forward() != SeekMode::TwoPosition || result.n_positions < 2 {
        return None;
    }
    let (a, b) = (&result.positions[0], &result.positions[1]);
    let apart_deg = libm::fabsf(libm::remainderf(b.heading_deg - a.heading_deg, 360.0));
    if libm::fabsf(apart_deg - 180.0) > 1.0 {
        return None;
    }
    let half_sum = 0.5 * (a.mean_rate_dph + b.mean_rate_dph);
    half_sum.is_finite().then_some(half_sum)
}

/// The record a finished seek leaves (sequence 0: the ring numbers it), or `None` unless it
/// was a valid two-position seek with a temperature state: the half-sum of its two main
/// positions' compensated rates at `state` (the `SeekTempState` of its valid windows), at
/// its end time since power-on. `model_crc32`: the CRC-32 of the model that compensated it
/// (`None` without a model). The device and the host's simulated field seeks both form
/// their records here, so they are the same records.
pub fn record_of_seek(
    result: &crate::seeking::northfinder::SeekResult,
    validity: crate::seeking::quality::Validity,
    state: Option<TempState>,
    model_crc32: Option<u32>,
) -> Option<FieldRecord> {
    use crate::seeking::northfinder::SeekMode;
    use crate::seeking::quality::Validity;
    if validity != Validity::Valid || result.mode.forward() != SeekMode::TwoPosition {
        return None;
    }
    let residual_dph = two_position_residual_dph(result)?;
    let state = state?;
    let record = FieldRecord {
        sequence: 0,
        temp_c: state.temp_c,
        temp_rate_cps: state.temp_rate_cps,
        temp_accel_cps2: state.temp_accel_cps2,
        t_since_power_on_s: result.t_end_s as f32,
        residual_bias_dph: residual_dph as f32,
        model_crc32,
    };
    record.is_plausible().then_some(record)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::synthetic::SplitMix64;

    fn record(seq: u32) -> FieldRecord {
        FieldRecord {
            sequence: seq,
            temp_c: 31.25,
            temp_rate_cps: 0.004,
            temp_accel_cps2: -1.5e-6,
            t_since_power_on_s: 1234.5,
            residual_bias_dph: -0.0123,
            model_crc32: Some(0xDEAD_BEEF),
        }
    }

    #[test]
    fn records_roundtrip_through_the_flash_encoding() {
        for r in [
            record(1),
            FieldRecord {
                model_crc32: None,
                ..record(u32::MAX - 1)
            },
        ] {
            assert_eq!(FieldRecord::from_bytes(&r.to_bytes()), Ok(r));
        }
    }

    #[test]
    fn erased_is_empty_and_every_single_byte_change_is_corrupt() {
        assert_eq!(
            FieldRecord::from_bytes(&[0xFF; FIELD_RECORD_LEN]),
            Err(RecordDefect::Empty)
        );
        let good = record(7).to_bytes();
        let mut rng = SplitMix64::new(3);
        for i in 0..FIELD_RECORD_LEN {
            let mut b = good;
            b[i] ^= 1 + (rng.next_u64() % 255) as u8;
            assert_eq!(
                FieldRecord::from_bytes(&b),
                Err(RecordDefect::Corrupt),
                "byte {i}"
            );
        }
    }

    #[test]
    fn a_torn_write_is_never_a_record() {
        // NOR programming only clears bits: a write cut after k words leaves the rest 0xFF.
        let good = record(9).to_bytes();
        for words in 0..FIELD_RECORD_LEN / 4 {
            let mut b = [0xFFu8; FIELD_RECORD_LEN];
            b[..words * 4].copy_from_slice(&good[..words * 4]);
            assert!(FieldRecord::from_bytes(&b).is_err(), "{words} words");
        }
    }

    #[test]
    fn implausible_values_are_refused() {
        for bad in [
            FieldRecord {
                residual_bias_dph: f32::NAN,
                ..record(1)
            },
            FieldRecord {
                temp_c: 500.0,
                ..record(1)
            },
            FieldRecord {
                sequence: u32::MAX,
                ..record(1)
            },
        ] {
            assert!(!bad.is_plausible());
            assert_eq!(
                FieldRecord::from_bytes(&bad.to_bytes()),
                Err(RecordDefect::Corrupt)
            );
        }
    }

    /// A window with `temp`, `rate` and model inputs `inputs`.
    fn window(temp: f32, rate: f32, inputs: &[f32]) -> WindowResult {
        let mut w = WindowResult {
            t_start_s: 0.0,
            t_end_s: 10.0,
            mean_rate_dph: 0.0,
            temp_c: temp,
            temp_rate_cps: rate,
            inputs: [0.0; crate::model::format::MAX_INPUTS],
            n_inputs: inputs.len() as u8,
            drift_dph: 0.0,
            compensated_dph: 0.0,
            n_samples: 100,
            n_expected: 100,
            n_gaps: 0,
            model_applied: true,
            status: crate::compensation::compensator::WindowStatus::Valid,
        };
        w.inputs[..inputs.len()].copy_from_slice(inputs);
        w
    }

    fn model_with(kinds: &[FeatureKind]) -> RbfModel {
        let mut m = RbfModel::empty();
        for &k in kinds {
            m.inputs
                .push(crate::model::format::FeatureSpec::plain(k))
                .unwrap();
        }
        m
    }

    #[test]
    fn the_seek_state_is_the_window_mean_and_the_model_own_accel_input() {
        let mut s = SeekTempState::new();
        assert_eq!(s.state(), None);
        let m = model_with(&[
            FeatureKind::TempC,
            FeatureKind::TempRateCps,
            FeatureKind::TempAccelCps2,
        ]);
        assert_eq!(accel_input_index(&m), Some(2));
        let flat = model_with(&[
            FeatureKind::TempC,
            FeatureKind::TempAccelFlatStartCps2,
            FeatureKind::TempRateCps,
        ]);
        assert_eq!(accel_input_index(&flat), Some(1));
        // Early warm-up: the window estimates fall from +5e-4 to -2e-5 degC/s^2; the record
        // carries their mean (what a linear correction in that input averages to).
        let accels = [5e-4f32, 2e-4, 5e-5, -2e-5];
        let (mut sum_temp, mut sum_rate) = (0.0, 0.0);
        for (k, &a) in accels.iter().enumerate() {
            let temp = 20.0 + k as f32;
            let rate = 0.01 - 0.001 * k as f32;
            sum_temp += f64::from(temp);
            sum_rate += f64::from(rate);
            s.push_window(&window(temp, rate, &[temp, rate, a]), Some(&m));
        }
        s.push_window(&window(f32::NAN, 1.0, &[0.0, 0.0, 1.0]), Some(&m));
        let st = s.state().unwrap();
        assert_eq!(s.windows(), 4);
        assert!((f64::from(st.temp_c) - sum_temp / 4.0).abs() < 1e-5);
        assert!((f64::from(st.temp_rate_cps) - sum_rate / 4.0).abs() < 1e-8);
        let mean_accel = accels.iter().map(|&a| f64::from(a)).sum::<f64>() / 4.0;
        assert!(
            (f64::from(st.temp_accel_cps2) - mean_accel).abs() < 1e-9,
            "{st:?}"
        );
        s.reset();
        assert_eq!(s.state(), None);
        // A model without a d2T/dt2 input (or no model): the record carries 0.
        let plain = model_with(&[FeatureKind::TempC, FeatureKind::TempRateCps]);
        assert_eq!(accel_input_index(&plain), None);
        s.push_window(&window(20.0, 0.01, &[20.0, 0.01]), Some(&plain));
        s.push_window(&window(21.0, 0.01, &[]), None);
        assert_eq!(s.state().unwrap().temp_accel_cps2, 0.0);
    }
}
