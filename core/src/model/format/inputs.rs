//! What one model input is (`FeatureKind`, `FeatureSpec`), so the device can compute it
//! from its own sensors: the kinds, their aux channel and time-constant rules.

use serde::{Deserialize, Serialize};

/// What one model input is, so the device can compute it from its own sensors.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FeatureKind {
    /// Gyro temperature, degC.
    TempC,
    /// dT/dt, degC/s (least-squares slope, see `features`).
    TempRateCps,
    /// d2T/dt2, degC/s^2.
    TempAccelCps2,
    /// Temperature through a first-order lag of `tau_s`, degC.
    TempLagC,
    /// exp(-t / tau_s), t = time since power-on.
    PowerOnDecay,
    /// Auxiliary channel n (extra sensor column), its value.
    AuxValue(u8),
    /// Auxiliary channel n, its rate per second.
    AuxRate(u8),
    /// cos of an angle channel n (deg) -- heading harmonics.
    AuxCos(u8),
    /// sin of an angle channel n (deg).
    AuxSin(u8),
    /// d2T/dt2, degC/s^2, with the temperature series taken as flat before its first
    /// reading (a unit soaked before power-on whose thermometer lags the heat; see
    /// `TempRateEstimator::new_flat_start`). Identical to `TempAccelCps2` once the first
    /// reading has left the span. Appended last: existing model files keep their meaning.
    TempAccelFlatStartCps2,
    /// Temperature rise since power-on, degC: the row's temperature minus the first row's
    /// (the soaked unit's start temperature, i.e. about its ambient). With T and dT/dt it
    /// tells a cold start at one ambient from a settled row of a colder one, which the
    /// first minutes' d2T/dt2 can only tell through its noise. Appended last: existing
    /// model files keep their meaning.
    TempRiseC,
    /// (t / tau_s) exp(-t / tau_s), t = time since power-on: how `PowerOnDecay` changes when
    /// its time constant stretches (tau d/dtau of exp(-t / tau)), so a model linear in it
    /// carries a warm-up whose time constant differs by a few per cent from tau_s, e.g.
    /// with the ambient through a temperature-dependent conductance, which no fixed
    /// clock can (docs/record/fleet.md). Appended last: existing model files keep their
    /// meaning.
    PowerOnDecayStretch,
    /// dT/dt, degC/s, read in the clock of a warm-up by diffusion, g(t) = 1 - exp(-sqrt(t /
    /// tau_s)) (a thick coil heated from one face: T - T_a = R g(t), whose rate is unbounded
    /// at power-on, 1/sqrt(t)): the 60 s least-squares slope of the temperature against g,
    /// times g's mean rate over the last window (`TempRateEstimator::diffusion_clock_rate`).
    /// Exact for such a warm-up at every row from the second, where a slope against t
    /// reads up to 1.7 times the rate in the first minutes. `tau_s` is the type's, chosen
    /// from its runs' temperatures (host `train::warmup_clock`). Appended last: existing
    /// model files keep their meaning (a reader built before it refuses such a model at
    /// decode).
    TempRateDiffusionCps,
}

/// One model input: its kind and, for lags and decays, a time constant (s; 0 otherwise).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FeatureSpec {
    pub kind: FeatureKind,
    pub tau_s: f32,
}

impl FeatureSpec {
    /// An input without a time constant (rate and accel then use the estimator's default span).
    pub const fn plain(kind: FeatureKind) -> Self {
        Self { kind, tau_s: 0.0 }
    }
}

/// The paper's inputs: gyro temperature and its rate.
pub const PAPER_INPUTS: [FeatureSpec; 2] = [
    FeatureSpec::plain(FeatureKind::TempC),
    FeatureSpec::plain(FeatureKind::TempRateCps),
];

impl FeatureKind {
    /// The auxiliary channel this feature reads, if any.
    pub const fn aux_channel(self) -> Option<u8> {
        match self {
            FeatureKind::AuxValue(n)
            | FeatureKind::AuxRate(n)
            | FeatureKind::AuxCos(n)
            | FeatureKind::AuxSin(n) => Some(n),
            _ => None,
        }
    }

    /// True for kinds whose `tau_s` must be > 0 (lags and decays).
    pub const fn needs_time_constant(self) -> bool {
        matches!(
            self,
            FeatureKind::TempLagC
                | FeatureKind::PowerOnDecay
                | FeatureKind::PowerOnDecayStretch
                | FeatureKind::TempRateDiffusionCps
        )
    }

    /// The value an input that is a function of the time since power-on alone tends to as
    /// that time grows (exp(-t/tau) and (t/tau) exp(-t/tau) both to 0), `None` for inputs
    /// that read the gyro. A unit on for longer than any training run is further on the
    /// same curve, not in a state nobody saw: the trainer's declared range reaches this
    /// value (the gyro's own inputs still guard its state).
    pub const fn settled_value(self) -> Option<f32> {
        match self {
            FeatureKind::PowerOnDecay | FeatureKind::PowerOnDecayStretch => Some(0.0),
            _ => None,
        }
    }

    /// True for kinds that take the power-on to be a cold start from a soak: the clock
    /// since power-on, the rise since the first reading, and the lag and flat-start d2T/dt2
    /// that start from the first reading as if it were the unit's settled state. A model
    /// with one of them is valid only for such power-ons (`model::cold_start`).
    pub const fn assumes_cold_start(self) -> bool {
        matches!(
            self,
            FeatureKind::PowerOnDecay
                | FeatureKind::PowerOnDecayStretch
                | FeatureKind::TempRiseC
                | FeatureKind::TempLagC
                | FeatureKind::TempAccelFlatStartCps2
                | FeatureKind::TempRateDiffusionCps
        )
    }
}
