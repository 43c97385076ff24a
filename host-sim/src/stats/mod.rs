//! Drift metrics in the paper's and IEEE Std 952's terms: plain and pooled standard
//! deviation, largest deviation from the run's settled mean, time until a 5-min moving
//! window of 10 s means stays within the spec, window means; the Allan-family
//! deviations and IEEE Std 952 noise terms are in `allan`.

pub mod allan;

pub mod special;
pub mod student_t;

/// The gyro's bias spec, deg/h (1 sigma of 10 s means; gyro 008 in the paper).
pub const SPEC_DPH: f64 = 0.021;
/// The paper's "stable" point: the settled (nominal) mean is taken after this, s.
pub const SETTLED_AFTER_S: f64 = 25.0 * 60.0;
/// Moving window of the time-to-spec metric, s.
pub const SPEC_WINDOW_S: f64 = 5.0 * 60.0;

/// Mean (NaN for an empty slice).
pub fn mean(x: &[f64]) -> f64 {
    x.iter().sum::<f64>() / x.len() as f64
}

/// Mean, 0 for an empty slice (where "nothing" should add nothing, as in sums of means).
pub fn mean_or_zero(x: &[f64]) -> f64 {
    x.iter().sum::<f64>() / x.len().max(1) as f64
}

/// Sample standard deviation (n - 1); 0 for fewer than two values.
pub fn std_dev(x: &[f64]) -> f64 {
    if x.len() < 2 {
        return 0.0;
    }
    let m = mean(x);
    (x.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (x.len() - 1) as f64).sqrt()
}

/// Root mean square (0 for an empty slice).
pub fn rms(x: &[f64]) -> f64 {
    (x.iter().map(|v| v * v).sum::<f64>() / x.len().max(1) as f64).sqrt()
}

/// Residual sum of squares of `y` about its least-squares line in `x` (`with_slope`) or
/// about its mean; the line is taken flat when `x` does not spread. NaN for no points.
pub fn line_residual_ss(x: &[f64], y: &[f64], with_slope: bool) -> f64 {
    let n = x.len().min(y.len()) as f64;
    let x_mean = x.iter().sum::<f64>() / n;
    let y_mean = y.iter().sum::<f64>() / n;
    let pairs = || x.iter().zip(y);
    let sxx: f64 = x.iter().map(|a| (a - x_mean).powi(2)).sum();
    let sxy: f64 = pairs().map(|(a, b)| (a - x_mean) * (b - y_mean)).sum();
    let slope = if with_slope && sxx > 0.0 {
        sxy / sxx
    } else {
        0.0
    };
    pairs()
        .map(|(a, b)| (b - y_mean - slope * (a - x_mean)).powi(2))
        .sum()
}

/// The pooled within-run standard deviation: the one "drift std" of several runs.
///
/// Definition: each run's values are taken about that run's own mean (so constant
/// run-to-run offsets do not count), the squared deviations are pooled over all runs and
/// divided by the degrees of freedom left, sum over runs of (n_i - 1):
/// sqrt( sum_i sum_j (y_ij - mean_i)^2 / sum_i (n_i - 1) ). With one run this is
/// `std_dev`. Empty runs are skipped; 0 when there are no degrees of freedom.
pub fn pooled_std(groups: &[&[f64]]) -> f64 {
    let (mut ss, mut n, mut k) = (0.0, 0usize, 0usize);
    for g in groups.iter().filter(|g| !g.is_empty()) {
        let m = mean(g);
        ss += g.iter().map(|v| (v - m) * (v - m)).sum::<f64>();
        n += g.len();
        k += 1;
    }
    if n > k {
        (ss / (n - k) as f64).sqrt()
    } else {
        0.0
    }
}

/// `pooled_std` of runs stacked in one slice, run `i` being `values[rows[i]]`.
pub fn pooled_std_of_rows(rows: &[std::ops::Range<usize>], values: &[f64]) -> f64 {
    let groups: Vec<&[f64]> = rows.iter().map(|r| &values[r.clone()]).collect();
    pooled_std(&groups)
}

/// Means over consecutive windows of `window_s` (window i holds the samples with
/// `i*window_s < t <= (i+1)*window_s`); returns (window end times, means), skipping
/// empty windows and an incomplete last window (one covering < 90 % of its span).
pub fn window_means(t_s: &[f64], y: &[f64], window_s: f64) -> (Vec<f64>, Vec<f64>) {
    let mut times = Vec::new();
    let mut means = Vec::new();
    let last_t = t_s.last().copied().unwrap_or(0.0);
    let mut i = 0;
    while i < t_s.len() {
        let w = (t_s[i] / window_s).ceil().max(1.0);
        let end = w * window_s;
        let (mut sum, mut n) = (0.0, 0usize);
        while i < t_s.len() && t_s[i] <= end + 1e-9 {
            sum += y[i];
            n += 1;
            i += 1;
        }
        let complete = last_t >= end - 0.1 * window_s;
        if n > 0 && complete {
            times.push(end);
            means.push(sum / n as f64);
        }
    }
    (times, means)
}

/// The run's nominal (settled) value: mean of the points after `SETTLED_AFTER_S`;
/// a run too short for that uses its last half.
pub fn settled_mean(t_s: &[f64], y: &[f64]) -> f64 {
    let after: Vec<f64> = t_s
        .iter()
        .zip(y)
        .filter(|(t, _)| **t >= SETTLED_AFTER_S)
        .map(|(_, v)| *v)
        .collect();
    if after.len() >= 2 {
        mean(&after)
    } else {
        mean(&y[y.len() / 2..])
    }
}

/// Largest |y - settled mean|, deg/h.
pub fn max_deviation(t_s: &[f64], y: &[f64]) -> f64 {
    let m = settled_mean(t_s, y);
    y.iter().map(|v| (v - m).abs()).fold(0.0, f64::max)
}

/// Time until the 10 s means stay within the spec, s since power-on: the start of the
/// first 5-min window from which on every window's rms deviation from the settled mean
/// is <= `spec_dph`. This is the paper's "10 s std about the nominal rate": the spread
/// of the 10 s means around the stable value (not around the window's own mean, which
/// would hide a slow trend). `Some(0.0)` = within spec from power-on; `None` = the last
/// window is still out of spec (or the run is shorter than one window).
pub fn time_to_spec_s(t_s: &[f64], y: &[f64], spec_dph: f64) -> Option<f64> {
    if t_s.len() < 2 {
        return None;
    }
    let nominal = settled_mean(t_s, y);
    let period = (t_s[1] - t_s[0]).max(0.0);
    let last_t = t_s[t_s.len() - 1];
    let start_of = |i: usize| if i == 0 { 0.0 } else { t_s[i] - period };
    // Walk the complete windows from the last one backwards; the answer is the start of
    // the window after the latest failing one.
    let mut last_ok_start = None;
    for i in (0..t_s.len()).rev() {
        let end = start_of(i) + SPEC_WINDOW_S;
        if last_t < end - 1e-9 {
            continue; // incomplete window at the end of the record
        }
        let dev: Vec<f64> = (i..t_s.len())
            .take_while(|&j| t_s[j] <= end + 1e-9)
            .map(|j| y[j] - nominal)
            .collect();
        let rms = (dev.iter().map(|d| d * d).sum::<f64>() / dev.len() as f64).sqrt();
        if rms > spec_dph {
            return last_ok_start;
        }
        last_ok_start = Some(start_of(i));
    }
    last_ok_start
}

/// Plain moving standard deviation of `window_s` windows (each about its own mean),
/// one value per window start; for plots.
pub fn moving_std(t_s: &[f64], y: &[f64], window_s: f64) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for i in 0..t_s.len() {
        let end = t_s[i] + window_s;
        if t_s[t_s.len() - 1] < end - 1e-9 {
            break;
        }
        let n = (i..t_s.len()).take_while(|&j| t_s[j] < end - 1e-9).count();
        out.push((t_s[i], std_dev(&y[i..i + n])));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_leaves_no_residual_about_itself_but_does_about_its_mean() {
        let x = [0.0, 1.0, 2.0, 3.0];
        let y = [1.0, 3.0, 5.0, 7.0];
        assert!(line_residual_ss(&x, &y, true) < 1e-24);
        // about the mean 4: 9 + 1 + 1 + 9
        assert!((line_residual_ss(&x, &y, false) - 20.0).abs() < 1e-12);
        // twin: a parabola keeps its curvature about its line
        let p = [0.0, 1.0, 4.0, 9.0];
        assert!((line_residual_ss(&x, &p, true) - 4.0).abs() < 1e-12);
        // null: x that does not spread takes the line flat
        assert_eq!(line_residual_ss(&[2.0; 4], &y, true), 20.0);
    }

    #[test]
    fn pooled_std_ignores_group_offsets() {
        let a = [1.0, 2.0, 3.0];
        let b = [101.0, 102.0, 103.0];
        assert!((pooled_std(&[&a, &b]) - 1.0).abs() < 1e-12);
        assert!((std_dev(&a) - 1.0).abs() < 1e-12);
        // Divisor sum(n_i - 1): 4 squared deviations of 1 over 2 + 1 degrees of freedom.
        let stacked = [0.0, 2.0, 10.0, 11.0, 12.0];
        let got = pooled_std_of_rows(&[0..2, 2..5], &stacked);
        assert!((got - (4.0f64 / 3.0).sqrt()).abs() < 1e-12, "{got}");
    }

    #[test]
    fn window_means_group_by_time() {
        let t: Vec<f64> = (1..=25).map(|i| i as f64).collect();
        let y: Vec<f64> = t.clone();
        let (wt, wm) = window_means(&t, &y, 10.0);
        assert_eq!(wt, vec![10.0, 20.0]);
        assert_eq!(wm, vec![5.5, 15.5]);
    }

    #[test]
    fn time_to_spec_finds_the_end_of_the_excursion() {
        // 10 s means: 0.1 deg/h for the first 10 min, then exactly nominal.
        let t: Vec<f64> = (1..=270).map(|i| i as f64 * 10.0).collect();
        let y: Vec<f64> = t
            .iter()
            .map(|&t| if t <= 600.0 { 0.1 } else { 0.0 })
            .collect();
        let tts = time_to_spec_s(&t, &y, 0.021).unwrap();
        // A window holding k excursion points has rms 0.1 sqrt(k/30) <= 0.021 for k <= 1.
        assert!((tts - 590.0).abs() < 1e-9, "{tts}");
        let flat = vec![0.0; 270];
        assert_eq!(time_to_spec_s(&t, &flat, 0.021), Some(0.0));
        let late: Vec<f64> = t
            .iter()
            .map(|&t| if t > 2600.0 { 1.0 } else { 0.0 })
            .collect();
        assert_eq!(time_to_spec_s(&t, &late, 0.021), None);
        assert!((max_deviation(&t, &y) - 0.1).abs() < 1e-12);
    }
}
