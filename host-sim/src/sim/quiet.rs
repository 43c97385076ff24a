//! The random parts of a simulated gyro, each of which can be switched off while every
//! random draw is still made: a campaign with a part silenced is the same campaign, draw
//! for draw, without that part. This is how one campaign's odd figure is traced to its
//! cause (docs/record/diagnose.md, the d2T/dt2 ratio of seed 9), and how the analysis
//! is checked to recover the simulator's physics exactly when nothing is random.

use super::params::GyroParams;

/// One random part of the simulated gyro.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RandomPart {
    /// All four gyro noise terms below.
    Gyro,
    /// Angle random walk (white rate noise).
    Arw,
    /// Bias instability (the three Gauss-Markov processes).
    BiasInstability,
    /// Rate random walk.
    Rrw,
    /// Output angle quantisation.
    Quantisation,
    /// Thermometer noise and its LSB.
    Sensor,
    /// Turn-on to turn-on bias.
    TurnOn,
    /// Run-to-run dissipation.
    Power,
    /// Start temperature off the ambient (imperfect soak).
    Soak,
}

impl RandomPart {
    /// Every part (switching them all off leaves a deterministic gyro).
    pub const ALL: [RandomPart; 5] = [
        RandomPart::Gyro,
        RandomPart::Sensor,
        RandomPart::TurnOn,
        RandomPart::Power,
        RandomPart::Soak,
    ];

    /// The part named `name` (`gyro`, `arw`, `bias-instability`, `rrw`, `quantisation`,
    /// `sensor`, `turn-on`, `power`, `soak`).
    pub fn parse(name: &str) -> Option<Self> {
        Some(match name {
            "gyro" => Self::Gyro,
            "arw" => Self::Arw,
            "bias-instability" => Self::BiasInstability,
            "rrw" => Self::Rrw,
            "quantisation" => Self::Quantisation,
            "sensor" => Self::Sensor,
            "turn-on" => Self::TurnOn,
            "power" => Self::Power,
            "soak" => Self::Soak,
            _ => return None,
        })
    }
}

impl GyroParams {
    /// These parameters with `part` switched off (its sigma set to zero).
    pub fn without(mut self, part: RandomPart) -> Self {
        let n = &mut self.noise;
        match part {
            RandomPart::Gyro => {
                n.arw_dpsh = 0.0;
                n.bias_instability_dph = 0.0;
                n.rrw_dph_per_sqrt_h = 0.0;
                n.quantization_arcsec = 0.0;
            }
            RandomPart::Arw => n.arw_dpsh = 0.0,
            RandomPart::BiasInstability => n.bias_instability_dph = 0.0,
            RandomPart::Rrw => n.rrw_dph_per_sqrt_h = 0.0,
            RandomPart::Quantisation => n.quantization_arcsec = 0.0,
            RandomPart::Sensor => {
                self.sensor.noise_c = 0.0;
                self.sensor.resolution_c = 0.0;
            }
            RandomPart::TurnOn => self.drift.turn_on_bias_sigma_dph = 0.0,
            RandomPart::Power => self.variation.power_sigma_frac = 0.0,
            RandomPart::Soak => self.variation.start_temp_sigma_c = 0.0,
        }
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::{simulate_run, RunSpec};

    fn spec() -> RunSpec {
        let mut s = RunSpec::paper(20.0, 5);
        s.minutes = 2.0;
        s.raw_rate_hz = 10.0;
        s
    }

    #[test]
    fn a_silenced_part_leaves_every_other_draw_as_it_was() {
        let p = GyroParams::paper_default();
        let full = simulate_run(&p, &spec()).unwrap();
        let no_sensor = simulate_run(&p.clone().without(RandomPart::Sensor), &spec()).unwrap();
        // the gyro's own rate noise is untouched: the rate column is the same to the bit
        // (the sensor reading does not feed the drift), the temperature column is not
        assert_eq!(full.column("rate_dph"), no_sensor.column("rate_dph"));
        assert_ne!(full.column("temp_c"), no_sensor.column("temp_c"));
        let quiet = RandomPart::ALL.iter().fold(p, |p, &r| p.without(r));
        let a = simulate_run(&quiet, &spec()).unwrap();
        let b = simulate_run(&quiet, &RunSpec { seed: 6, ..spec() }).unwrap();
        assert_eq!(
            a.column("rate_dph"),
            b.column("rate_dph"),
            "nothing random is left"
        );
    }

    #[test]
    fn every_part_has_a_name() {
        for name in ["gyro", "arw", "bias-instability", "rrw", "quantisation"] {
            assert!(RandomPart::parse(name).is_some(), "{name}");
        }
        assert_eq!(RandomPart::parse("turn-on"), Some(RandomPart::TurnOn));
        assert_eq!(RandomPart::parse("noise"), None);
    }
}
