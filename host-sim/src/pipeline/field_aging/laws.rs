//! How the simulated gyro ages between the chamber campaign and the field: the laws the
//! aging measurement plants, each with the amounts it moves the bias law by.
//!
//! Why these: a FOG's bias law drifts over months to years as the coil's potting and
//! fibre coating relax and absorb moisture and the source and electronics age. What moves
//! is (a) the turn-on bias and the bias temperature coefficient (electronics, source
//! wavelength, coil stress at a given temperature) and (b) the Shupe coefficient, the bias
//! per degC/s of coil temperature rate (the coating's stiffness sets how a radial gradient
//! turns into a non-reciprocal phase). The amounts are stated, not measured on an aged
//! unit: a turn-on bias step of half the paper's 0.021 deg/h spec, the temperature
//! coefficient up by half, the Shupe coefficient up by a tenth. The null law leaves the
//! gyro as the chamber saw it: refinement must then not make seeks worse.

use serde::Serialize;

use crate::sim::GyroParams;

/// Turn-on bias step of the `TempcoTurnOn` law, deg/h (half the paper's 0.021 deg/h spec).
pub const TURN_ON_AGING_DPH: f64 = 0.010;
/// Bias temperature coefficient step of the `TempcoTurnOn` law, deg/h per degC
/// (+50 % of the default gyro's 0.002).
pub const TEMPCO_AGING_DPH_PER_C: f64 = 0.001;
/// Relative Shupe coefficient step of the `Shupe` law (+10 %: 14 -> 15.4 deg/h per degC/s
/// for the default gyro).
pub const SHUPE_AGING_FRAC: f64 = 0.10;

/// One aging law.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum AgingLaw {
    /// Turn-on bias and bias temperature coefficient move.
    TempcoTurnOn,
    /// The twin: the Shupe (dT/dt) coefficient moves.
    Shupe,
    /// The null twin: no aging.
    None,
}

impl AgingLaw {
    /// Every law, in the order the measurement reports them.
    pub const ALL: [AgingLaw; 3] = [AgingLaw::TempcoTurnOn, AgingLaw::Shupe, AgingLaw::None];

    /// Short name (the `--laws` values and the table's first column).
    pub fn name(self) -> &'static str {
        match self {
            AgingLaw::TempcoTurnOn => "tempco+turn-on",
            AgingLaw::Shupe => "shupe",
            AgingLaw::None => "none",
        }
    }

    /// The law of a name, or `None`.
    pub fn parse(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|l| l.name() == name)
    }

    /// The amounts, with units, for `params` (what the gyro had, what it has after aging).
    pub fn amounts(self, params: &GyroParams) -> String {
        let d = &params.drift;
        match self {
            AgingLaw::TempcoTurnOn => format!(
                "turn-on bias {:+.3} deg/h ({:.3} -> {:.3}), tempco {:+.4} deg/h/degC ({:.4} -> {:.4})",
                TURN_ON_AGING_DPH,
                d.bias_dph,
                d.bias_dph + TURN_ON_AGING_DPH,
                TEMPCO_AGING_DPH_PER_C,
                d.bias_dph_per_c,
                d.bias_dph_per_c + TEMPCO_AGING_DPH_PER_C
            ),
            AgingLaw::Shupe => format!(
                "Shupe {:+.0} % ({:.2} -> {:.2} deg/h per degC/s)",
                100.0 * SHUPE_AGING_FRAC,
                d.shupe_dph_per_cps,
                d.shupe_dph_per_cps * (1.0 + SHUPE_AGING_FRAC)
            ),
            AgingLaw::None => "no aging".to_string(),
        }
    }

    /// The gyro after aging.
    pub fn age(self, params: &GyroParams) -> GyroParams {
        let mut aged = params.clone();
        match self {
            AgingLaw::TempcoTurnOn => {
                aged.drift.bias_dph += TURN_ON_AGING_DPH;
                aged.drift.bias_dph_per_c += TEMPCO_AGING_DPH_PER_C;
            }
            AgingLaw::Shupe => aged.drift.shupe_dph_per_cps *= 1.0 + SHUPE_AGING_FRAC,
            AgingLaw::None => {}
        }
        aged
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn laws_move_only_their_terms_and_names_round_trip() {
        let p = GyroParams::paper_default();
        assert_eq!(AgingLaw::None.age(&p), p);
        let t = AgingLaw::TempcoTurnOn.age(&p);
        assert!((t.drift.bias_dph - p.drift.bias_dph - TURN_ON_AGING_DPH).abs() < 1e-12);
        assert_eq!(t.drift.shupe_dph_per_cps, p.drift.shupe_dph_per_cps);
        let s = AgingLaw::Shupe.age(&p);
        assert_eq!(s.drift.bias_dph, p.drift.bias_dph);
        assert!((s.drift.shupe_dph_per_cps / p.drift.shupe_dph_per_cps - 1.1).abs() < 1e-12);
        for l in AgingLaw::ALL {
            assert_eq!(AgingLaw::parse(l.name()), Some(l));
        }
        assert_eq!(AgingLaw::parse("old"), None);
    }
}
