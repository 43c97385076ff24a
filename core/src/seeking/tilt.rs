//! Earth rate seen by a gyro whose input axis turns on a tilted turntable.
//!
//! Exists so that the north finder, the heading calibration and the tests share one derived
//! model of what a tilted gyro reads, written once in closed form.
//!
//! Frames: local level NED (x north, y east, z down); base frame (x = table heading 0,
//! y = table heading 90, z down through the table). The base is at azimuth A (yaw), then
//! pitched by `pitch` (about y, positive = table heading 0 raised) and rolled by `roll`
//! (about x, positive = table heading 90 lowered), aerospace 3-2-1 order: C = Rz(A) Ry(p) Rx(r).
//! The inclinometer sits on the base (it does not turn with the table) and measures p and r.
//! At table heading h the input axis is b = (cos h, sin h, 0) in the base frame, and Earth
//! rate is Omega (cos L, 0, -sin L) in NED. The gyro reads (C^T omega) . b:
//!
//! ```text
//! w_x = cos p Omega_H cos A + sin p Omega_V
//! w_y = -cos r Omega_H sin A + sin r (sin p Omega_H cos A - cos p Omega_V)
//! w(h) = w_x cos h + w_y sin h
//!      = Omega_H (cos A P(h) + sin A Q(h)) + V(h)
//! P(h) = cos p cos h + sin r sin p sin h,   Q(h) = -cos r sin h,
//! V(h) = Omega_V (sin p cos h - sin r cos p sin h)
//! ```
//!
//! with Omega_H = Omega cos L, Omega_V = Omega sin L. Level (p = r = 0) this is the familiar
//! Omega_H cos(A + h). At h = 0 it is the textbook Omega (cos L cos A cos p + sin L sin p):
//! the vertical Earth rate leaks in through sin p and the horizontal one shrinks by cos p;
//! roll enters only at headings off the pitch axis. The simulator (`fog-sim`, `sim::base`)
//! computes the same rate with explicit rotation matrices, and its tests compare the two.

use crate::consts::EARTH_RATE_DPH;
use crate::numeric::sin_cos_deg;

/// Base tilt measured by the inclinometer, deg.
#[derive(Clone, Copy, Debug, PartialEq, Default, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Tilt {
    /// Rotation about the base y axis, positive = table heading 0 raised, deg.
    pub pitch_deg: f32,
    /// Rotation about the base x axis, positive = table heading 90 lowered, deg.
    pub roll_deg: f32,
}

impl Tilt {
    pub const LEVEL: Tilt = Tilt {
        pitch_deg: 0.0,
        roll_deg: 0.0,
    };

    /// Both angles finite and within +-`max_deg`.
    pub fn within(&self, max_deg: f32) -> bool {
        self.pitch_deg.is_finite()
            && self.roll_deg.is_finite()
            && libm::fabsf(self.pitch_deg) <= max_deg
            && libm::fabsf(self.roll_deg) <= max_deg
    }

    /// Larger of |pitch| and |roll|, deg.
    pub fn max_abs_deg(&self) -> f32 {
        libm::fabsf(self.pitch_deg).max(libm::fabsf(self.roll_deg))
    }
}

/// The coefficients of `w(h) = Omega_H (cos A P + sin A Q) + V` at one heading.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisCoefficients {
    pub p: f64,
    pub q: f64,
    /// Vertical Earth-rate leak, deg/h.
    pub v_dph: f64,
}

/// P, Q and V of the module header for heading `heading_deg` under `tilt` at `latitude_deg`.
pub fn axis_coefficients(tilt: Tilt, heading_deg: f64, latitude_deg: f64) -> AxisCoefficients {
    let (sp, cp) = sin_cos_deg(tilt.pitch_deg as f64);
    let (sr, cr) = sin_cos_deg(tilt.roll_deg as f64);
    let (sh, ch) = sin_cos_deg(heading_deg);
    let omega_v = EARTH_RATE_DPH * sin_cos_deg(latitude_deg).0;
    AxisCoefficients {
        p: cp * ch + sr * sp * sh,
        q: -cr * sh,
        v_dph: omega_v * (sp * ch - sr * cp * sh),
    }
}

/// Earth rate along the input axis, deg/h (the forward model of the module header).
pub fn earth_rate_on_axis_dph(
    latitude_deg: f64,
    azimuth_deg: f64,
    tilt: Tilt,
    heading_deg: f64,
) -> f64 {
    let k = axis_coefficients(tilt, heading_deg, latitude_deg);
    let (sa, ca) = sin_cos_deg(azimuth_deg);
    let omega_h = EARTH_RATE_DPH * sin_cos_deg(latitude_deg).1;
    omega_h * (ca * k.p + sa * k.q) + k.v_dph
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pitched_axis_at_heading_zero_is_the_textbook_formula() {
        let (lat, az, p) = (39.9f64, 108.4f64, 7.0f64);
        let tilt = Tilt {
            pitch_deg: p as f32,
            roll_deg: 4.0,
        };
        let want = EARTH_RATE_DPH
            * (lat.to_radians().cos() * az.to_radians().cos() * p.to_radians().cos()
                + lat.to_radians().sin() * p.to_radians().sin());
        assert!((earth_rate_on_axis_dph(lat, az, tilt, 0.0) - want).abs() < 1e-9);
    }

    #[test]
    fn tilt_range_check() {
        let t = Tilt {
            pitch_deg: 29.9,
            roll_deg: -30.0,
        };
        assert!(t.within(30.0));
        assert!(!t.within(29.95));
        assert!(!Tilt {
            pitch_deg: f32::NAN,
            roll_deg: 0.0
        }
        .within(30.0));
    }
}
