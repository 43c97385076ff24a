//! The five estimators on one segment's phase (the integrated rate, x_k = tau0 sum y):
//! overlapping Allan (ADEV), modified Allan (MDEV), overlapping Hadamard (HDEV), time
//! (TDEV = tau MDEV / sqrt 3) and total (TOTDEV, reflected ends) deviation, with the
//! definitions of NIST SP 1065 (as allantools' `oadev`, `mdev`, `ohdev`, `tdev`,
//! `totdev` compute them). Segments are summed separately and pooled by their sums.

use serde::Serialize;
use std::fmt;
use std::str::FromStr;

/// Which deviation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    Adev,
    Mdev,
    Hdev,
    Tdev,
    Totdev,
}

impl Kind {
    /// Every kind, in the order the command lists them.
    pub const ALL: [Kind; 5] = [Kind::Adev, Kind::Mdev, Kind::Hdev, Kind::Tdev, Kind::Totdev];

    /// Unit of the deviation for a rate in deg/h and tau in s (TDEV is an angle:
    /// deg/h times s is 1/3600 deg, i.e. arcsec).
    pub fn unit(self) -> &'static str {
        match self {
            Kind::Tdev => "arcsec",
            _ => "deg/h",
        }
    }

    /// Long name for tables and plots.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Adev => "overlapping Allan deviation",
            Kind::Mdev => "modified Allan deviation",
            Kind::Hdev => "overlapping Hadamard deviation",
            Kind::Tdev => "time (angle) deviation",
            Kind::Totdev => "total deviation",
        }
    }

    /// Order of the phase difference (2 Allan, 3 Hadamard): also the EDF's `d`.
    pub fn difference_order(self) -> usize {
        match self {
            Kind::Hdev => 3,
            _ => 2,
        }
    }

    /// Largest averaging factor with at least two terms on `phase_len` phase points.
    pub fn max_factor(self, phase_len: usize) -> usize {
        let n = phase_len;
        match self {
            Kind::Adev | Kind::Totdev => n.saturating_sub(2) / 2,
            Kind::Hdev => n.saturating_sub(2) / 3,
            Kind::Mdev | Kind::Tdev => n.saturating_sub(1) / 3,
        }
    }
}

impl FromStr for Kind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Kind::ALL
            .into_iter()
            .find(|k| k.to_string() == s)
            .ok_or_else(|| format!("'{s}' is not a deviation (adev, mdev, hdev, tdev, totdev)"))
    }
}

impl fmt::Display for Kind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Kind::Adev => "adev",
            Kind::Mdev => "mdev",
            Kind::Hdev => "hdev",
            Kind::Tdev => "tdev",
            Kind::Totdev => "totdev",
        })
    }
}

/// Phase of a rate segment: x_0 = 0, x_k = tau0 sum_{j<k} (y_j - mean y); deg/h times s.
pub fn phase(rate: &[f64], tau0_s: f64) -> Vec<f64> {
    let mean = rate.iter().sum::<f64>() / rate.len().max(1) as f64;
    let mut x = Vec::with_capacity(rate.len() + 1);
    let mut acc = 0.0;
    x.push(acc);
    for y in rate {
        acc += (y - mean) * tau0_s;
        x.push(acc);
    }
    x
}

/// Pooled sums of one estimator at one factor: squared differences and the divisor count.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sums {
    pub sum_sq: f64,
    pub count: u64,
}

impl Sums {
    /// Adds another segment's sums.
    pub fn add(&mut self, other: Sums) {
        self.sum_sq += other.sum_sq;
        self.count += other.count;
    }

    /// The deviation from the pooled sums at tau = m tau0 (NaN without terms).
    pub fn deviation(self, kind: Kind, m: usize, tau0_s: f64) -> f64 {
        let mf = m as f64;
        let tau = mf * tau0_s;
        let n = self.count as f64;
        let var = match kind {
            Kind::Adev | Kind::Totdev => self.sum_sq / (2.0 * n * tau * tau),
            Kind::Hdev => self.sum_sq / (6.0 * n * tau * tau),
            Kind::Mdev | Kind::Tdev => self.sum_sq / (2.0 * n * mf * mf * tau * tau),
        };
        let dev = var.sqrt();
        if kind == Kind::Tdev {
            tau * dev / 3f64.sqrt()
        } else {
            dev
        }
    }
}

/// The sums of `kind` at factor `m` over one segment's phase `x` (None if too short).
pub fn segment_sums(kind: Kind, x: &[f64], m: usize) -> Option<Sums> {
    if m == 0 || m > kind.max_factor(x.len()) {
        return None;
    }
    let n = x.len();
    let second = |i: usize| x[i + 2 * m] - 2.0 * x[i + m] + x[i];
    let sums = match kind {
        Kind::Adev => Sums {
            sum_sq: (0..n - 2 * m).map(|i| second(i).powi(2)).sum(),
            count: (n - 2 * m) as u64,
        },
        Kind::Hdev => Sums {
            sum_sq: (0..n - 3 * m)
                .map(|i| (x[i + 3 * m] - 3.0 * x[i + 2 * m] + 3.0 * x[i + m] - x[i]).powi(2))
                .sum(),
            count: (n - 3 * m) as u64,
        },
        Kind::Mdev | Kind::Tdev => {
            // Moving sums of m consecutive second differences.
            let mut window: f64 = (0..m).map(second).sum();
            let mut sum_sq = window * window;
            for j in 1..=n - 3 * m {
                window += second(j + m - 1) - second(j - 1);
                sum_sq += window * window;
            }
            Sums {
                sum_sq,
                count: (n - 3 * m + 1) as u64,
            }
        }
        Kind::Totdev => {
            // Reflected extension: x*(-k) = 2 x_0 - x_k, x*(n-1+k) = 2 x_{n-1} - x_{n-1-k}.
            let last = n - 1;
            let ext = |k: isize| -> f64 {
                if k < 0 {
                    2.0 * x[0] - x[k.unsigned_abs()]
                } else if k as usize > last {
                    2.0 * x[last] - x[2 * last - k as usize]
                } else {
                    x[k as usize]
                }
            };
            let mi = m as isize;
            let sum_sq = (1..last as isize)
                .map(|c| (ext(c - mi) - 2.0 * x[c as usize] + ext(c + mi)).powi(2))
                .sum();
            Sums {
                sum_sq,
                count: (n - 2) as u64,
            }
        }
    };
    Some(sums)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_constant_rate_has_zero_deviation_and_a_ramp_the_textbook_one() {
        let flat = phase(&[3.0; 64], 1.0);
        for kind in Kind::ALL {
            let s = segment_sums(kind, &flat, 4).unwrap();
            assert!(s.deviation(kind, 4, 1.0).abs() < 1e-12, "{kind}");
        }
        // Rate ramp y = R t: Allan variance R^2 tau^2 / 2 exactly; Hadamard removes it.
        let ramp: Vec<f64> = (0..200).map(|k| 0.5 * k as f64).collect();
        let x = phase(&ramp, 1.0);
        let adev = segment_sums(Kind::Adev, &x, 8)
            .unwrap()
            .deviation(Kind::Adev, 8, 1.0);
        assert!((adev - 0.5 * 8.0 / 2f64.sqrt()).abs() < 1e-9, "{adev}");
        let hdev = segment_sums(Kind::Hdev, &x, 8)
            .unwrap()
            .deviation(Kind::Hdev, 8, 1.0);
        assert!(hdev.abs() < 1e-9, "{hdev}");
        assert!(segment_sums(Kind::Adev, &x, 100).is_none());
        assert_eq!("totdev".parse::<Kind>(), Ok(Kind::Totdev));
    }
}
