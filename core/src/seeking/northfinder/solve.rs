//! The end of a seek: the dwells' means and scatter -> azimuth, bias, horizontal rate and
//! their 1-sigmas, for the forward and symmetric two- and four-position modes.

use super::machine::NorthFinder;
use super::types::{PositionMean, SeekError, SeekResult, MAX_POSITIONS};
use crate::numeric::wrap_360_deg as wrap_360;
use crate::seeking::sequence::SeekMode;
use crate::seeking::tilt::{axis_coefficients, AxisCoefficients};

impl NorthFinder {
    /// Horizontal rate the solution scales by, deg/h, and the azimuth offset it adds, rad
    /// (Omega_H and 0 without a heading calibration; see the module header).
    fn effective_horizontal(&self) -> (f64, f64) {
        match &self.heading {
            None => (self.omega_h_dph, 0.0),
            Some(h) => {
                let a = self.omega_h_dph + h.cos_dph as f64;
                let b = h.sin_dph as f64;
                (
                    libm::sqrtf((a * a + b * b) as f32) as f64,
                    libm::atan2f(b as f32, a as f32) as f64,
                )
            }
        }
    }

    fn position_mean(&self, k: usize) -> PositionMean {
        let a = &self.acc[k];
        let n = a.n.max(1) as f64;
        let mean = a.sum / n;
        let sigma = if a.n >= 2 {
            let var = ((a.sum_sq - n * mean * mean) / (n - 1.0)).max(0.0);
            // A 1-sigma estimate: f32 `sqrtf` (7 significant digits) is plenty.
            libm::sqrtf((var / n) as f32) as f64
        } else {
            0.0
        };
        PositionMean {
            heading_deg: self.heading_of(k),
            mean_rate_dph: mean,
            sigma_dph: sigma,
            n_windows: a.n,
        }
    }

    pub(super) fn solve(&self, t_end_s: f64) -> Result<SeekResult, SeekError> {
        let np = self.n_positions();
        let mut positions = [PositionMean::default(); MAX_POSITIONS];
        for (k, p) in positions.iter_mut().enumerate().take(np) {
            *p = self.position_mean(k);
        }
        let tilt = self.mean_tilt();
        let lat = self.cfg.latitude_deg;
        let (oh, offset_rad) = self.effective_horizontal();
        let coeff = |k: usize| axis_coefficients(tilt, self.heading_of(k) as f64, lat);
        let m: [f64; MAX_POSITIONS] = core::array::from_fn(|k| positions[k].mean_rate_dph);
        let v: [f64; MAX_POSITIONS] =
            core::array::from_fn(|k| positions[k].sigma_dph * positions[k].sigma_dph);
        // Two equations, linear in (X, Y) = Omega_H (cos A, sin A) (see `tilt`):
        // c = P0 X + Q0 Y + V0 from the two opposite main dwells, q = P90 X + Q90 Y + V90
        // from the quadrature dwell(s); the bias cancels in both.
        let (k_c, k_q, c, q, var_c, var_q, bias) = match self.cfg.mode.forward() {
            SeekMode::TwoPosition
            | SeekMode::TwoPositionSymmetric
            | SeekMode::TwoPositionThueMorse => {
                let bias = 0.5 * (m[0] + m[1]);
                let var_c = (v[0] + v[1]) / 4.0;
                (
                    coeff(0),
                    coeff(2),
                    0.5 * (m[0] - m[1]),
                    m[2] - bias,
                    var_c,
                    v[2] + var_c,
                    bias,
                )
            }
            SeekMode::FourPosition | SeekMode::FourPositionSymmetric => (
                coeff(0),
                coeff(1),
                0.5 * (m[0] - m[2]),
                0.5 * (m[1] - m[3]),
                (v[0] + v[2]) / 4.0,
                (v[1] + v[3]) / 4.0,
                0.25 * (m[0] + m[1] + m[2] + m[3]),
            ),
        };
        let direct =
            solve_pair(k_c, k_q, c, q, var_c, var_q).ok_or(SeekError::InconsistentRates)?;
        let (az_rad, sigma_rad) = match self.cfg.mode.forward() {
            SeekMode::FourPosition | SeekMode::FourPositionSymmetric => {
                (direct.azimuth_rad, direct.sigma_rad)
            }
            SeekMode::TwoPosition
            | SeekMode::TwoPositionSymmetric
            | SeekMode::TwoPositionThueMorse => {
                // c - V0 = Omega_H R0 cos(A - d0): acos of the two long dwells, the sign (and,
                // near A - d0 = 0/180 deg, where acos is ill-conditioned, the whole angle) from
                // the quadrature dwell.
                let r0 = libm::sqrtf((k_c.p * k_c.p + k_c.q * k_c.q) as f32) as f64;
                let cos_arg = (c - k_c.v_dph) / (oh * r0);
                if libm::fabs(cos_arg) > 1.1 {
                    return Err(SeekError::InconsistentRates);
                }
                // Angles in f32 (acosf/atan2f, ~1e-7 rad = 6e-6 deg): far inside the 1e-4 deg
                // noiseless tests and any gyro's noise, and the firmware then needs no f64
                // trigonometry. Sums and rates stay f64.
                let c_in = cos_arg.clamp(-1.0, 1.0);
                let half = libm::acosf(c_in as f32) as f64;
                let d0 = libm::atan2f(k_c.q as f32, k_c.p as f32) as f64;
                // sin(acos c) = sqrt((1 - c)(1 + c)): exact identity, no sine needed.
                let sin0 = libm::sqrtf(((1.0 - c_in) * (1.0 + c_in)) as f32) as f64;
                if sin0 >= self.direct_sine_below() {
                    // The side of d0 the quadrature solution lies on: sign of sin(A_direct - d0).
                    let side = direct.y_dph * k_c.p - direct.x_dph * k_c.q;
                    let a = if side >= 0.0 { d0 + half } else { d0 - half };
                    (a, libm::sqrtf(var_c as f32) as f64 / (oh * r0 * sin0))
                } else {
                    (direct.azimuth_rad, direct.sigma_rad)
                }
            }
        };
        let azimuth = wrap_360((az_rad + offset_rad).to_degrees());
        Ok(SeekResult {
            azimuth_deg: azimuth,
            sigma_deg: sigma_rad.to_degrees(),
            duration_s: t_end_s - self.t_start_s,
            t_start_s: self.t_start_s,
            t_end_s,
            bias_dph: bias,
            mode: self.cfg.mode,
            positions,
            n_positions: np as u8,
            tilt,
            horizontal_rate_dph: direct.magnitude_dph,
            horizontal_rate_sigma_dph: direct.magnitude_sigma_dph,
        })
    }
}

/// (X, Y) = Omega_H (cos A, sin A) from the two equations c, q, with 1-sigmas.
#[derive(Clone, Copy, Debug)]
struct PairSolution {
    x_dph: f64,
    y_dph: f64,
    azimuth_rad: f64,
    sigma_rad: f64,
    magnitude_dph: f64,
    magnitude_sigma_dph: f64,
}

/// Solves `c = P_c X + Q_c Y + V_c`, `q = P_q X + Q_q Y + V_q`; `None` when singular or when
/// the rates are all zero (no direction).
fn solve_pair(
    k_c: AxisCoefficients,
    k_q: AxisCoefficients,
    c: f64,
    q: f64,
    var_c: f64,
    var_q: f64,
) -> Option<PairSolution> {
    let det = k_c.p * k_q.q - k_c.q * k_q.p;
    if !det.is_finite() || libm::fabs(det) < 1e-6 {
        return None;
    }
    // Inverse of [[P_c, Q_c], [P_q, Q_q]].
    let inv = [[k_q.q / det, -k_c.q / det], [-k_q.p / det, k_c.p / det]];
    let (rc, rq) = (c - k_c.v_dph, q - k_q.v_dph);
    let x = inv[0][0] * rc + inv[0][1] * rq;
    let y = inv[1][0] * rc + inv[1][1] * rq;
    let r2 = x * x + y * y;
    if r2.is_nan() || r2 <= 0.0 {
        return None;
    }
    let r = libm::sqrtf(r2 as f32) as f64;
    // d atan2(y, x) = (x dy - y dx) / r^2 and d r = (x dx + y dy) / r, through the inverse.
    let da = |j: usize| (x * inv[1][j] - y * inv[0][j]) / r2;
    let dr = |j: usize| (x * inv[0][j] + y * inv[1][j]) / r;
    let var_a = da(0) * da(0) * var_c + da(1) * da(1) * var_q;
    let var_r = dr(0) * dr(0) * var_c + dr(1) * dr(1) * var_q;
    Some(PairSolution {
        x_dph: x,
        y_dph: y,
        azimuth_rad: libm::atan2f(y as f32, x as f32) as f64,
        sigma_rad: libm::sqrtf(var_a as f32) as f64,
        magnitude_dph: r,
        magnitude_sigma_dph: libm::sqrtf(var_r as f32) as f64,
    })
}
