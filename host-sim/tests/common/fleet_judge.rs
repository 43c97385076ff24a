//! A judge of fleets that knows neither generator: each unit's Shupe coefficient read
//! from its runs' data alone (10 s means of drift and temperature, `unit_id` metadata),
//! and the robust statistics that say whether the units spread as stated or one unit
//! stands outside the type.
//!
//! The estimate: within each run (its own mean removed, so turn-on offsets and the Earth
//! rate drop out), drift = k dT/dt, dT/dt the central difference of the 10 s temperature
//! means; least squares pooled over the unit's runs. No temperature coefficient: once a
//! warm-up's fast mode has died, dT/dt is a linear function of T within a run
//! ((T_end - T) / tau), so with a coefficient on T as well the two trade off freely
//! (measured on the project's fleet: estimates of 14 deg/h per degC/s scattered from -1 to
//! 4.6); without it the coefficient on T adds about -b_1 tau to k, the same in every unit. A lagged or quantised
//! thermometer biases k the same way in every unit, so the judge compares units, not
//! absolute values.

use fog_sim::io::runs::Run;

/// Each unit's Shupe estimate, deg/h per degC/s, in the order the units first appear.
pub fn shupe_by_unit(runs: &[Run]) -> Vec<(String, f64)> {
    let mut sums: Vec<(String, [f64; 2])> = Vec::new();
    for run in runs {
        let id = run
            .meta_value("unit_id")
            .expect("a fleet run has a unit_id");
        let s = match sums.iter_mut().find(|(u, _)| u == id) {
            Some((_, s)) => s,
            None => {
                sums.push((id.to_string(), [0.0; 2]));
                &mut sums.last_mut().unwrap().1
            }
        };
        add_run(s, run);
    }
    sums.into_iter()
        .map(|(u, [sxx, sxy])| (u, sxy / sxx))
        .collect()
}

/// Adds one run's centred cross products (T'.T', T'.drift) to `s`.
fn add_run(s: &mut [f64; 2], run: &Run) {
    let (t, temp, drift) = (run.t_s(), run.temp_c(), run.drift_dph());
    let rows: Vec<[f64; 2]> = (1..t.len() - 1)
        .map(|i| {
            [
                (temp[i + 1] - temp[i - 1]) / (t[i + 1] - t[i - 1]),
                drift[i],
            ]
        })
        .collect();
    let n = rows.len() as f64;
    let (mx, my) = (
        rows.iter().map(|r| r[0]).sum::<f64>() / n,
        rows.iter().map(|r| r[1]).sum::<f64>() / n,
    );
    for r in &rows {
        s[0] += (r[0] - mx) * (r[0] - mx);
        s[1] += (r[0] - mx) * (r[1] - my);
    }
}

/// Standard deviation (n - 1) of `v`.
pub fn std_dev(v: &[f64]) -> f64 {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}

/// The median of `v`.
fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    }
}

/// Each value's distance from the median in robust sigmas (1.4826 x the median absolute
/// deviation): one unit outside the type stands far out, the rest near 1.
pub fn robust_z(v: &[f64]) -> Vec<f64> {
    let m = median(v);
    let dev: Vec<f64> = v.iter().map(|x| (x - m).abs()).collect();
    let sigma = 1.4826 * median(&dev);
    dev.iter().map(|d| d / sigma).collect()
}

/// Pearson correlation of `a` and `b`.
pub fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let cov: f64 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let va: f64 = a.iter().map(|x| (x - ma).powi(2)).sum();
    let vb: f64 = b.iter().map(|y| (y - mb).powi(2)).sum();
    cov / (va * vb).sqrt()
}
