//! Power-law noise type at each tau, by the lag-1 autocorrelation method (W. J. Riley,
//! C. A. Greenhall, "Power law noise identification using the lag 1 autocorrelation",
//! EFTF 2004; allantools' `autocorr_noise_id` on rate data): average the rate in blocks
//! of m, remove a linear trend, difference until the lag-1 correlation rho is below
//! 0.25 (or `d_max` differences), then alpha = -round(2 rho) - 2 d. The EDF needs it.

/// Fewest block means the method is applied to (Riley and Greenhall's minimum).
pub const MIN_POINTS: usize = 30;

fn lag1_autocorrelation(x: &[f64]) -> f64 {
    let mu = x.iter().sum::<f64>() / x.len() as f64;
    let num: f64 = x.windows(2).map(|w| (w[0] - mu) * (w[1] - mu)).sum();
    let den: f64 = x.iter().map(|v| (v - mu) * (v - mu)).sum();
    if den > 0.0 {
        num / den
    } else {
        0.0
    }
}

/// Removes the least-squares line.
fn detrend_linear(x: &mut [f64]) {
    let n = x.len() as f64;
    let tm = (n - 1.0) / 2.0;
    let xm = x.iter().sum::<f64>() / n;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (i, v) in x.iter().enumerate() {
        let dt = i as f64 - tm;
        sxy += dt * (v - xm);
        sxx += dt * dt;
    }
    let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    for (i, v) in x.iter_mut().enumerate() {
        *v -= xm + slope * (i as f64 - tm);
    }
}

/// Integer noise exponent alpha (S_y ~ f^alpha) of the rate `y` averaged over `m`
/// samples, differencing at most `d_max` times; None with fewer than `MIN_POINTS` means.
pub fn alpha_at(y: &[f64], m: usize, d_max: usize) -> Option<i32> {
    if m == 0 {
        return None;
    }
    let mut x: Vec<f64> = y
        .chunks_exact(m)
        .map(|c| c.iter().sum::<f64>() / m as f64)
        .collect();
    if x.len() < MIN_POINTS {
        return None;
    }
    detrend_linear(&mut x);
    let mut d = 0usize;
    loop {
        let r1 = lag1_autocorrelation(&x);
        let rho = r1 / (1.0 + r1);
        if rho < 0.25 || d >= d_max {
            return Some(-(2.0 * rho).round() as i32 - 2 * d as i32);
        }
        x = x.windows(2).map(|w| w[1] - w[0]).collect();
        d += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    #[test]
    fn white_walk_and_white_angle_are_told_apart() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let w: Vec<f64> = (0..4096).map(|_| StandardNormal.sample(&mut rng)).collect();
        let walk: Vec<f64> = w
            .iter()
            .scan(0.0, |s, v| {
                *s += v;
                Some(*s)
            })
            .collect();
        let angle: Vec<f64> = w.windows(2).map(|p| p[1] - p[0]).collect();
        assert_eq!(alpha_at(&w, 1, 2), Some(0));
        assert_eq!(alpha_at(&w, 16, 2), Some(0));
        assert_eq!(alpha_at(&walk, 4, 2), Some(-2));
        assert_eq!(alpha_at(&angle, 1, 2), Some(2));
        assert_eq!(alpha_at(&w, 200, 2), None, "20 block means are too few");
    }
}
