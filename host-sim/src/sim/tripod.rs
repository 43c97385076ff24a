//! The base the turntable stands on: a fixed tilt (pitch/roll), an optional disturbance
//! episode (the base rocking, e.g. someone leaning on the tripod), and the inclinometer that
//! measures it.
//!
//! Exists so that north-seek simulations can test the tilt maths and the motion detection.
//! The Earth rate on the tilted input axis is computed here by rotating the NED Earth-rate
//! vector with explicit 3x3 matrices (C = Rz(A) Ry(pitch) Rx(roll), see `fog_core::seeking::tilt`),
//! not with fog-core's closed form, so the two are independent; the rocking also adds its own
//! angular rate d(pitch)/dt about the base y axis, seen by the input axis as sin(h) dp/dt.

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

use super::checks::{finite, non_negative, positive};
use super::error::SimError;
use fog_core::consts::EARTH_RATE_DPH;
use fog_core::seeking::tilt::Tilt;

/// A rocking episode: pitch += amplitude sin(2 pi (t - start) / period) during it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Disturbance {
    pub start_s: f64,
    pub duration_s: f64,
    pub amplitude_deg: f64,
    pub period_s: f64,
}

/// Base attitude and inclinometer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BaseMotion {
    pub pitch_deg: f64,
    pub roll_deg: f64,
    pub disturbance: Option<Disturbance>,
    /// Inclinometer white noise per reading, deg (SCL3300 mode 4: about 0.001 deg rms
    /// at 10 Hz output after its internal filter; we use a conservative 0.003 deg).
    pub inclinometer_noise_deg: f64,
}

impl BaseMotion {
    /// A still base tilted by `tilt_deg` towards azimuth `direction_deg` of the base frame.
    pub fn tilted(tilt_deg: f64, direction_deg: f64) -> Self {
        Self {
            pitch_deg: tilt_deg * direction_deg.to_radians().cos(),
            roll_deg: tilt_deg * direction_deg.to_radians().sin(),
            disturbance: None,
            inclinometer_noise_deg: 0.003,
        }
    }

    pub fn validate(&self) -> Result<(), SimError> {
        finite("base.pitch_deg", self.pitch_deg)?;
        finite("base.roll_deg", self.roll_deg)?;
        if self.pitch_deg.abs() >= 90.0 || self.roll_deg.abs() >= 90.0 {
            return Err(SimError::BadParameter {
                name: "base.tilt",
                value: self.pitch_deg.abs().max(self.roll_deg.abs()),
                why: "pitch and roll must be within +-90 deg",
            });
        }
        non_negative("base.inclinometer_noise_deg", self.inclinometer_noise_deg)?;
        if let Some(d) = self.disturbance {
            finite("base.disturbance.start_s", d.start_s)?;
            non_negative("base.disturbance.duration_s", d.duration_s)?;
            finite("base.disturbance.amplitude_deg", d.amplitude_deg)?;
            positive("base.disturbance.period_s", d.period_s)?;
        }
        Ok(())
    }

    /// (pitch, roll, pitch rate deg/s) at time t.
    fn attitude(&self, t_s: f64) -> (f64, f64, f64) {
        let mut pitch = self.pitch_deg;
        let mut rate_dps = 0.0;
        if let Some(d) = self.disturbance {
            let u = t_s - d.start_s;
            if (0.0..d.duration_s).contains(&u) {
                let w = 2.0 * std::f64::consts::PI / d.period_s;
                pitch += d.amplitude_deg * (w * u).sin();
                rate_dps = d.amplitude_deg * w * (w * u).cos();
            }
        }
        (pitch, self.roll_deg, rate_dps)
    }

    /// True tilt at t.
    pub fn tilt(&self, t_s: f64) -> Tilt {
        let (p, r, _) = self.attitude(t_s);
        Tilt {
            pitch_deg: p as f32,
            roll_deg: r as f32,
        }
    }

    /// One inclinometer reading at t.
    pub fn read_inclinometer(&self, t_s: f64, rng: &mut ChaCha8Rng) -> Tilt {
        let (p, r, _) = self.attitude(t_s);
        let mut n =
            || -> f64 { self.inclinometer_noise_deg * rng.sample::<f64, _>(StandardNormal) };
        Tilt {
            pitch_deg: (p + n()) as f32,
            roll_deg: (r + n()) as f32,
        }
    }

    /// Angular rate along the input axis at table heading `heading_deg` with table zero at
    /// `azimuth_deg`: Earth rate through the rotation matrices plus the base's own rocking, deg/h.
    pub fn input_rate_dph(
        &self,
        latitude_deg: f64,
        azimuth_deg: f64,
        heading_deg: f64,
        t_s: f64,
    ) -> f64 {
        let (p, r, pitch_rate_dps) = self.attitude(t_s);
        let (l, a, p, r, h) = (
            latitude_deg.to_radians(),
            azimuth_deg.to_radians(),
            p.to_radians(),
            r.to_radians(),
            heading_deg.to_radians(),
        );
        let rz = [
            [a.cos(), -a.sin(), 0.0],
            [a.sin(), a.cos(), 0.0],
            [0.0, 0.0, 1.0],
        ];
        let ry = [
            [p.cos(), 0.0, p.sin()],
            [0.0, 1.0, 0.0],
            [-p.sin(), 0.0, p.cos()],
        ];
        let rx = [
            [1.0, 0.0, 0.0],
            [0.0, r.cos(), -r.sin()],
            [0.0, r.sin(), r.cos()],
        ];
        let c = matmul(&rz, &matmul(&ry, &rx));
        let axis_body = [h.cos(), h.sin(), 0.0];
        let axis_ned: [f64; 3] =
            std::array::from_fn(|i| (0..3).map(|j| c[i][j] * axis_body[j]).sum());
        let earth = [EARTH_RATE_DPH * l.cos(), 0.0, -EARTH_RATE_DPH * l.sin()];
        let earth_on_axis: f64 = (0..3).map(|i| axis_ned[i] * earth[i]).sum();
        earth_on_axis + h.sin() * pitch_rate_dps * 3600.0
    }
}

fn matmul(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use fog_core::seeking::tilt::earth_rate_on_axis_dph;

    #[test]
    fn matrices_agree_with_fog_cores_closed_form() {
        for (p, r) in [(0.0, 0.0), (5.0, 1.0), (-15.0, 15.0), (30.0, -30.0)] {
            let b = BaseMotion {
                pitch_deg: p,
                roll_deg: r,
                disturbance: None,
                inclinometer_noise_deg: 0.0,
            };
            for h in [0.0, 45.0, 90.0, 200.0] {
                for az in [0.0, 108.4, 250.0] {
                    let got = b.input_rate_dph(39.9, az, h, 0.0);
                    let want = earth_rate_on_axis_dph(39.9, az, b.tilt(0.0), h);
                    // f32 tilt in fog-core: ~1e-7 relative.
                    assert!((got - want).abs() < 1e-5, "p {p} r {r} h {h} az {az}");
                }
            }
        }
    }

    #[test]
    fn rocking_is_seen_only_during_the_episode() {
        let b = BaseMotion {
            disturbance: Some(Disturbance {
                start_s: 100.0,
                duration_s: 20.0,
                amplitude_deg: 0.5,
                period_s: 4.0,
            }),
            ..BaseMotion::tilted(5.0, 30.0)
        };
        assert_eq!(b.tilt(99.0), b.tilt(130.0));
        assert!((b.tilt(101.0).pitch_deg - b.tilt(99.0).pitch_deg).abs() > 0.3);
        assert!(
            (b.input_rate_dph(39.9, 0.0, 90.0, 100.0) - b.input_rate_dph(39.9, 0.0, 90.0, 99.0))
                .abs()
                > 1000.0
        );
    }
}
