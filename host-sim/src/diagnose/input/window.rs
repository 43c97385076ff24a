//! The 10 s window the diagnosis works on, in its own file because both the averaging
//! (`input`) and the derivative width grid (`input::derivatives`) need its length.

/// Window length the model works on, s.
pub const WINDOW_S: f64 = 10.0;

/// Row ranges `[start, end)` forming the 10 s windows; one row per window when the
/// record is already at 10 s or slower.
pub fn window_bins(t: &[f64]) -> Vec<(usize, usize)> {
    let mut dt: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    dt.sort_by(f64::total_cmp);
    let median = dt.get(dt.len() / 2).copied().unwrap_or(WINDOW_S);
    if median >= 0.95 * WINDOW_S {
        return (0..t.len()).map(|i| (i, i + 1)).collect();
    }
    let mut bins = Vec::new();
    let mut start = 0;
    for i in 1..=t.len() {
        let same = i < t.len() && (t[i] / WINDOW_S).floor() == (t[start] / WINDOW_S).floor();
        if !same {
            bins.push((start, i));
            start = i;
        }
    }
    bins
}
