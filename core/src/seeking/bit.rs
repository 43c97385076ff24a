//! Built-in test (BIT): one word of named pass/fail items and the rule that any failed item
//! blocks seeking and names itself.
//!
//! Exists so that the firmware, the status message and `fogsim monitor` agree on what each
//! bit means, and so that the rule is a pure, host-tested function. A bit SET means the item
//! FAILED, so 0 is "all good" and a new item added later reads as passing on old hosts.
//!
//! It lives in `seeking` because the rule is the seek's: the seek supervisor (`quality`)
//! refuses to start or continue on a failed item; the link (`link::messages`) only carries
//! the word in the status, so it imports it from here, never the other way round.

use serde::{Deserialize, Serialize};

/// One BIT item (its discriminant is its bit number).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum BitItem {
    /// No gyro frame for longer than `BitLimits::gyro_silence_s`.
    GyroLink = 0,
    /// Gyro frame-error rate above `BitLimits::max_frame_error_rate`.
    GyroFrameErrors = 1,
    /// Temperature outside the sensor's plausible range.
    TemperatureRange = 2,
    /// |dT/dt| above what the gyro's thermal mass allows.
    TemperatureRate = 3,
    /// No inclinometer reading (or its status word reports an error).
    Inclinometer = 4,
    /// The turntable does not answer.
    Turntable = 5,
    /// No valid drift model in flash.
    Model = 6,
    /// Flash read-back or store check failed.
    Flash = 7,
}

impl BitItem {
    pub const ALL: [BitItem; 8] = [
        BitItem::GyroLink,
        BitItem::GyroFrameErrors,
        BitItem::TemperatureRange,
        BitItem::TemperatureRate,
        BitItem::Inclinometer,
        BitItem::Turntable,
        BitItem::Model,
        BitItem::Flash,
    ];

    /// Short name for displays and logs.
    pub fn name(self) -> &'static str {
        match self {
            BitItem::GyroLink => "gyro link silent",
            BitItem::GyroFrameErrors => "gyro frame-error rate too high",
            BitItem::TemperatureRange => "temperature implausible",
            BitItem::TemperatureRate => "temperature changing implausibly fast",
            BitItem::Inclinometer => "inclinometer not answering",
            BitItem::Turntable => "turntable not answering",
            BitItem::Model => "no valid drift model",
            BitItem::Flash => "flash check failed",
        }
    }

    fn mask(self) -> u16 {
        1 << (self as u16)
    }
}

/// The BIT word: bit `BitItem as u16` set = that item failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BitWord(pub u16);

impl BitWord {
    pub const PASS: BitWord = BitWord(0);

    pub fn failed(self, item: BitItem) -> bool {
        self.0 & item.mask() != 0
    }

    pub fn set(&mut self, item: BitItem, failed: bool) {
        if failed {
            self.0 |= item.mask();
        } else {
            self.0 &= !item.mask();
        }
    }

    /// Failed items in bit order.
    pub fn failures(self) -> impl Iterator<Item = BitItem> {
        BitItem::ALL.into_iter().filter(move |i| self.failed(*i))
    }

    /// The rule: any failed item blocks seeking, and the first failed item in bit order is
    /// the reason. Bits this build does not know (from a newer device) are ignored.
    pub fn seek_permission(self) -> Result<(), BitItem> {
        match self.failures().next() {
            Some(item) => Err(item),
            None => Ok(()),
        }
    }
}

/// What the firmware measured for the BIT.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BitInputs {
    /// Seconds since the last good gyro frame.
    pub gyro_silence_s: f32,
    /// Gyro frames received and rejected over the last BIT period.
    pub gyro_frames_ok: u32,
    pub gyro_frames_bad: u32,
    /// Latest temperature and its rate (NaN if none).
    pub temp_c: f32,
    pub temp_rate_cps: f32,
    /// Seconds since the last good inclinometer reading.
    pub inclinometer_silence_s: f32,
    pub turntable_answering: bool,
    pub model_valid: bool,
    pub flash_ok: bool,
}

/// Thresholds of the BIT.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BitLimits {
    pub gyro_silence_s: f32,
    pub max_frame_error_rate: f32,
    pub temp_min_c: f32,
    pub temp_max_c: f32,
    pub max_temp_rate_cps: f32,
    pub inclinometer_silence_s: f32,
}

impl Default for BitLimits {
    /// Gyro silent > 1 s; > 1 % bad frames; -55..+125 degC (the TMP117's range);
    /// |dT/dt| > 0.5 degC/s (a coil with minutes of thermal time constant cannot do that:
    /// the simulated and measured warm-ups peak far below 0.05 degC/s); inclinometer
    /// silent > 2 s.
    fn default() -> Self {
        Self {
            gyro_silence_s: 1.0,
            max_frame_error_rate: 0.01,
            temp_min_c: -55.0,
            temp_max_c: 125.0,
            max_temp_rate_cps: 0.5,
            inclinometer_silence_s: 2.0,
        }
    }
}

/// `x <= limit`, false for NaN (so a missing measurement fails).
fn at_most(x: f32, limit: f32) -> bool {
    matches!(
        x.partial_cmp(&limit),
        Some(core::cmp::Ordering::Less | core::cmp::Ordering::Equal)
    )
}

/// Evaluates every item; a NaN measurement fails its item.
pub fn evaluate(x: &BitInputs, lim: &BitLimits) -> BitWord {
    let mut w = BitWord::PASS;
    w.set(
        BitItem::GyroLink,
        !at_most(x.gyro_silence_s, lim.gyro_silence_s),
    );
    let total = x.gyro_frames_ok.saturating_add(x.gyro_frames_bad);
    let rate = if total == 0 {
        0.0
    } else {
        x.gyro_frames_bad as f32 / total as f32
    };
    w.set(BitItem::GyroFrameErrors, rate > lim.max_frame_error_rate);
    w.set(
        BitItem::TemperatureRange,
        !(x.temp_c >= lim.temp_min_c && x.temp_c <= lim.temp_max_c),
    );
    w.set(
        BitItem::TemperatureRate,
        !at_most(libm::fabsf(x.temp_rate_cps), lim.max_temp_rate_cps),
    );
    w.set(
        BitItem::Inclinometer,
        !at_most(x.inclinometer_silence_s, lim.inclinometer_silence_s),
    );
    w.set(BitItem::Turntable, !x.turntable_answering);
    w.set(BitItem::Model, !x.model_valid);
    w.set(BitItem::Flash, !x.flash_ok);
    w
}

#[cfg(test)]
mod tests {
    use super::*;

    fn healthy() -> BitInputs {
        BitInputs {
            gyro_silence_s: 0.01,
            gyro_frames_ok: 10_000,
            gyro_frames_bad: 3,
            temp_c: 24.0,
            temp_rate_cps: 0.004,
            inclinometer_silence_s: 0.1,
            turntable_answering: true,
            model_valid: true,
            flash_ok: true,
        }
    }

    #[test]
    fn healthy_device_may_seek() {
        let w = evaluate(&healthy(), &BitLimits::default());
        assert_eq!(w, BitWord::PASS);
        assert_eq!(w.seek_permission(), Ok(()));
    }

    #[test]
    fn each_fault_blocks_with_its_own_name() {
        let lim = BitLimits::default();
        type Breaker = fn(&mut BitInputs);
        let cases: [(Breaker, BitItem); 8] = [
            (|x| x.gyro_silence_s = 5.0, BitItem::GyroLink),
            (|x| x.gyro_frames_bad = 500, BitItem::GyroFrameErrors),
            (|x| x.temp_c = f32::NAN, BitItem::TemperatureRange),
            (|x| x.temp_rate_cps = -3.0, BitItem::TemperatureRate),
            (
                |x| x.inclinometer_silence_s = f32::INFINITY,
                BitItem::Inclinometer,
            ),
            (|x| x.turntable_answering = false, BitItem::Turntable),
            (|x| x.model_valid = false, BitItem::Model),
            (|x| x.flash_ok = false, BitItem::Flash),
        ];
        for (break_it, item) in cases {
            let mut x = healthy();
            break_it(&mut x);
            let w = evaluate(&x, &lim);
            assert_eq!(w.seek_permission(), Err(item), "{item:?}");
            assert_eq!(w.failures().count(), 1, "{item:?}");
        }
    }

    #[test]
    fn first_failure_in_bit_order_is_the_reason_and_unknown_bits_are_ignored() {
        let mut w = BitWord::PASS;
        w.set(BitItem::Flash, true);
        w.set(BitItem::Inclinometer, true);
        assert_eq!(w.seek_permission(), Err(BitItem::Inclinometer));
        w.set(BitItem::Inclinometer, false);
        assert_eq!(w.seek_permission(), Err(BitItem::Flash));
        assert_eq!(BitWord(0x8000).seek_permission(), Ok(()));
    }
}
