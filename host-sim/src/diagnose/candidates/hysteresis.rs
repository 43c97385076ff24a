//! Rate-independent memory (issue 38 items 1 and 6): a drift that depends on where a column
//! has been, not on how fast it got there, such as the hysteresis of a coil's winding, a
//! mechanical play, or a magnetised part. No lag or derivative expresses it: a lag forgets
//! at a fixed time constant, while a play forgets only when the column moves on by more
//! than its width. The operator is the Prandtl-Ishlinskii stop operator, the column less
//! its play of half-width h: `x - p`, where the play `p` stays put until `x` leaves
//! `[p - h, p + h]` and is then dragged along (`p = clamp(p, x - h, x + h)`), so the
//! feature saturates at +/-h and turns over at every reversal of the column. Any
//! rate-independent hysteresis with the wiping-out property is a weighted sum of such
//! operators over widths, so the library offers one per width on a ladder: from
//! `MIN_WIDTH_NOISE` robust noise sigmas of the column (a narrower play only follows the
//! noise) doubling up to a quarter of the column's median within-run range (a wider one
//! never turns over). The play starts at each run's first value (the state of a part that
//! has rested at its start): a campaign cannot tell the initial state.

use crate::diagnose::candidates::events;
use crate::diagnose::input::{Campaign, Series};

/// The narrowest play, in robust noise sigmas of the column's scatter about a local line.
pub const MIN_WIDTH_NOISE: f64 = 4.0;
/// The widest play, as a share of the column's median within-run range.
pub const MAX_WIDTH_RANGE: f64 = 0.25;

/// The stop operator of `x` with half-width `h`: `x - play`, in `[-h, h]`.
pub fn stop(x: &[f64], h: f64) -> Vec<f64> {
    let mut p = x.first().copied().unwrap_or(0.0);
    x.iter()
        .map(|v| {
            p = p.clamp(v - h, v + h);
            v - p
        })
        .collect()
}

/// The half-widths the record supports for the column `x` gives per run, narrowest first;
/// `Err` with the reason when none does (a flat column, or noise spanning its range).
pub fn widths(c: &Campaign, x: impl Fn(&Series) -> &[f64]) -> Result<Vec<f64>, String> {
    let noise = events::noise_sigma(c, &x);
    let mut ranges: Vec<f64> = c
        .runs
        .iter()
        .map(|s| {
            let v = x(s);
            let (lo, hi) = v
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                    (lo.min(*x), hi.max(*x))
                });
            hi - lo
        })
        .filter(|r| r.is_finite())
        .collect();
    ranges.sort_by(f64::total_cmp);
    let Some(&range) = ranges.get(ranges.len() / 2) else {
        return Err("no rows".into());
    };
    let widest = MAX_WIDTH_RANGE * range;
    let mut h = MIN_WIDTH_NOISE * noise;
    if !(h.is_finite() && h > 0.0) || h > widest {
        return Err(format!(
            "its noise ({noise:.3e}) leaves no play narrower than a quarter of its range ({range:.3e})"
        ));
    }
    let mut out = Vec::new();
    while h <= widest {
        out.push(h);
        h *= 2.0;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One run of a column cycling over 10 units with a noise of about `noise` (sd).
    fn cycling(noise: f64) -> Campaign {
        let mut u = 0.37f64;
        let n = 600;
        let x: Vec<f64> = (0..n)
            .map(|i| {
                u = (u * 997.0 + 0.123).fract();
                5.0 + 5.0 * (f64::from(i) / 50.0).sin() + noise * 3.46 * (u - 0.5)
            })
            .collect();
        Campaign {
            runs: vec![Series {
                name: "run".into(),
                ambient_c: None,
                latitude_deg: None,
                t_s: (0..n).map(|i| 10.0 * f64::from(i)).collect(),
                drift_dph: vec![0.0; n as usize],
                temp_c: vec![20.0; n as usize],
                extras: vec![x],
            }],
            extra_names: vec!["x".into()],
            exclusions: vec![],
            derivative_widths: vec![],
        }
    }

    #[test]
    fn widths_run_from_the_noise_to_a_quarter_of_the_range_doubling() {
        let w = widths(&cycling(0.01), |s| &s.extras[0]).unwrap();
        assert!(w.len() >= 5, "{w:?}");
        assert!(w[0] > 0.02 && w[0] < 0.08, "{w:?}");
        assert!(
            *w.last().unwrap() <= 2.5 && *w.last().unwrap() > 1.2,
            "{w:?}"
        );
        assert!(w.windows(2).all(|p| (p[1] / p[0] - 2.0).abs() < 1e-12));
        // a column whose noise spans its range has no play to offer, and says why
        let why = widths(&cycling(4.0), |s| &s.extras[0]).unwrap_err();
        assert!(why.contains("no play narrower"), "{why}");
    }

    #[test]
    fn the_stop_operator_saturates_and_turns_over_at_reversals() {
        let x = [0.0, 1.0, 2.0, 3.0, 2.0, 1.0, 0.0, 0.5];
        let s = stop(&x, 1.0);
        // dragged up: saturates at +h; back down: falls to -h; a small reversal moves it
        // within the band without dragging the play
        assert_eq!(s, vec![0.0, 1.0, 1.0, 1.0, 0.0, -1.0, -1.0, -0.5]);
        // the same path at another speed gives the same values at the same positions
        let slow = [0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 2.0, 1.0, 0.0];
        let s2 = stop(&slow, 1.0);
        assert_eq!(s2[6], 1.0);
        assert_eq!(s2[9], -1.0);
    }
}
