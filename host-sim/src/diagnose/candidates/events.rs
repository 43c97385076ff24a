//! Event clocks (issue 38 item 1): the time since a column last changed by more than its
//! noise (a step, a switch) or since the time stamps last jumped (a gap), as a clock that
//! responses are built on. A drift that answers every change of a column with a transient
//! whatever the change's sign (a regulator settling after each load step, a relay, a
//! logger or power drop-out) is neither a value, a derivative nor a lag of that column;
//! on the clock it is one ordinary candidate, `exp(-(t - t_event) / tau)` after each event
//! (0 before a run's first event), on the library's memory time scales.
//!
//! Steps: a column's first differences minus what the local trend gives over the same
//! interval (the median of the five rates centred on the row, times the interval: a ramp
//! or a warm-up curve is no event, nor is the warm-up's progress across a gap of the stamps). The noise is the
//! column's own scatter about a local straight line (7 rows), 1.4826 x its median absolute
//! value over the campaign (MAD), times sqrt 2 for a difference; a change is an event
//! when it exceeds `EVENT_SIGMAS` of those, and consecutive flagged rows are one event (a
//! step inside a 10 s window is split over two rows). A change across a gap of the stamps is
//! no step: a wandering column moves while nothing is logged, and the gap has its own clock
//! (measured: a decoy random walk's clock was the gaps' clock under another name). The scatter, not the MAD of the
//! differences, because a quantised thermometer's differences are mostly 0 and their MAD
//! would make every one-quantum tick an event (measured: 22 "events" of 0.056-0.063 degC
//! on the simulator's 66-run campaign, none with the scatter). A column whose events fall
//! on more than `MAX_EVENT_SHARE` of its rows has no clock either: its "events" are its
//! noise. Gaps: a spacing longer than `GAP_SPACINGS` median
//! spacings plus `EVENT_SIGMAS` robust sigmas of the spacing; the clock restarts where the
//! stamps resume.

use crate::diagnose::input::{Campaign, Series};

/// A change must exceed this many robust noise sigmas (of a difference) to be an event.
pub const EVENT_SIGMAS: f64 = 8.0;
/// Half-width of the local line the noise is the scatter about, rows.
const SCATTER_HALF: usize = 3;
/// Most rows that may hold an event for a column to have a clock (beyond it the
/// "events" are the column's noise or quantisation).
pub const MAX_EVENT_SHARE: f64 = 0.05;
/// A gap: a spacing longer than this many median spacings (plus the noise margin).
pub const GAP_SPACINGS: f64 = 1.5;
/// Half-width of the local median the differences are compared with, rows.
const LOCAL_HALF: usize = 2;

/// What starts a column's clock.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EventRule {
    /// A change of the column of more than `threshold` (its units) beyond the local trend.
    Steps { threshold: f64 },
    /// A spacing of the time stamps longer than `threshold_s`.
    Gaps { threshold_s: f64 },
}

impl EventRule {
    /// What the events are, for labels: `steps` or `gaps`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Steps { .. } => "steps",
            Self::Gaps { .. } => "gaps",
        }
    }

    /// Times at which events happen in one run (`t`, the column `x`; `x` is unused for gaps).
    pub fn times(self, t: &[f64], x: &[f64]) -> Vec<f64> {
        match self {
            Self::Steps { threshold } => {
                let e = detrended_differences(t, x);
                let longest = GAP_SPACINGS * median_spacing(t);
                let mut out = Vec::new();
                let mut previous = false;
                for (i, v) in e.iter().enumerate() {
                    let flagged = v.abs() > threshold && t[i + 1] - t[i] <= longest;
                    if flagged && !previous {
                        // row i + 1 differs from row i: the change fell between them
                        out.push(0.5 * (t[i] + t[i + 1]));
                    }
                    previous = flagged;
                }
                out
            }
            Self::Gaps { threshold_s } => {
                let spacing = median_spacing(t);
                t.windows(2)
                    .filter(|w| w[1] - w[0] > threshold_s)
                    .map(|w| w[1] - 0.5 * spacing)
                    .collect()
            }
        }
    }
}

/// `exp(-(t - t_e) / tau_s)` after the latest event `t_e <= t`, 0 before the first.
pub fn clock_decay(t: &[f64], events: &[f64], tau_s: f64) -> Vec<f64> {
    let mut next = 0;
    let mut last: Option<f64> = None;
    t.iter()
        .map(|&ti| {
            while next < events.len() && events[next] <= ti {
                last = Some(events[next]);
                next += 1;
            }
            last.map_or(0.0, |te| (-(ti - te) / tau_s).exp())
        })
        .collect()
}

/// First differences minus the median of the `2 LOCAL_HALF + 1` rates around each (fewer
/// at the ends) times the difference's interval; one shorter than `x`.
fn detrended_differences(t: &[f64], x: &[f64]) -> Vec<f64> {
    let n = x.len().min(t.len());
    let dt: Vec<f64> = (1..n).map(|i| t[i] - t[i - 1]).collect();
    let d: Vec<f64> = (1..n).map(|i| x[i] - x[i - 1]).collect();
    let rate: Vec<f64> = d
        .iter()
        .zip(&dt)
        .map(|(v, h)| if *h > 0.0 { v / h } else { 0.0 })
        .collect();
    let mut buf = Vec::with_capacity(2 * LOCAL_HALF + 1);
    (0..d.len())
        .map(|i| {
            buf.clear();
            let lo = i.saturating_sub(LOCAL_HALF);
            let hi = (i + LOCAL_HALF + 1).min(d.len());
            buf.extend_from_slice(&rate[lo..hi]);
            d[i] - median_in_place(&mut buf) * dt[i]
        })
        .collect()
}

fn median_in_place(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    }
}

fn median_spacing(t: &[f64]) -> f64 {
    let mut d: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    median_in_place(&mut d)
}

/// 1.4826 x the median absolute value (a Gaussian sigma for Gaussian noise).
fn robust_sigma(mut v: Vec<f64>) -> f64 {
    v.iter_mut().for_each(|x| *x = x.abs());
    1.4826 * median_in_place(&mut v)
}

/// Residuals of `x` about the straight line through the `2 SCATTER_HALF + 1` rows
/// around each (fewer at the ends), in time `t`.
fn local_line_residuals(t: &[f64], x: &[f64]) -> Vec<f64> {
    let n = x.len().min(t.len());
    (0..n)
        .map(|i| {
            let (lo, hi) = (
                i.saturating_sub(SCATTER_HALF),
                (i + SCATTER_HALF + 1).min(n),
            );
            let m = (hi - lo) as f64;
            let mt = t[lo..hi].iter().sum::<f64>() / m;
            let mx = x[lo..hi].iter().sum::<f64>() / m;
            let (mut stt, mut stx) = (0.0, 0.0);
            for (ti, xi) in t[lo..hi].iter().zip(&x[lo..hi]) {
                stt += (ti - mt) * (ti - mt);
                stx += (ti - mt) * (xi - mx);
            }
            let slope = if stt > 0.0 { stx / stt } else { 0.0 };
            x[i] - (mx + slope * (t[i] - mt))
        })
        .collect()
}

/// The column's robust noise sigma (`x` gives it per run): its scatter about a local
/// line, 1.4826 x the median absolute value over the campaign (NaN without rows).
pub fn noise_sigma(c: &Campaign, x: impl Fn(&Series) -> &[f64]) -> f64 {
    let pooled: Vec<f64> = c
        .runs
        .iter()
        .flat_map(|s| local_line_residuals(&s.t_s, x(s)))
        .collect();
    if pooled.is_empty() {
        return f64::NAN;
    }
    robust_sigma(pooled)
}

/// The step rule of a column (`x` gives it per run), or why it has no clock.
pub fn step_rule(c: &Campaign, x: impl Fn(&Series) -> &[f64]) -> Result<EventRule, String> {
    if c.runs.iter().map(|s| x(s).len()).sum::<usize>() < 2 {
        return Err("too few rows".into());
    }
    let threshold = EVENT_SIGMAS * std::f64::consts::SQRT_2 * noise_sigma(c, &x);
    if !threshold.is_finite() {
        return Err("noise not finite".into());
    }
    let rule = EventRule::Steps { threshold };
    share_check(c, rule, |s| x(s))
}

/// The gap rule of the time stamps, or why they have no clock.
pub fn gap_rule(c: &Campaign) -> Result<EventRule, String> {
    let diffs: Vec<f64> = c
        .runs
        .iter()
        .flat_map(|s| s.t_s.windows(2).map(|w| w[1] - w[0]).collect::<Vec<_>>())
        .collect();
    let median = median_in_place(&mut diffs.clone());
    let jitter = robust_sigma(diffs.iter().map(|d| d - median).collect());
    let threshold_s = GAP_SPACINGS * median + EVENT_SIGMAS * jitter;
    if !(threshold_s.is_finite() && median > 0.0) {
        return Err("time stamps without a spacing".into());
    }
    share_check(c, EventRule::Gaps { threshold_s }, |s| &s.t_s)
}

/// `rule` when its events are neither absent nor on more than `MAX_EVENT_SHARE` of the rows.
fn share_check(
    c: &Campaign,
    rule: EventRule,
    x: impl Fn(&Series) -> &[f64],
) -> Result<EventRule, String> {
    let events: usize = c.runs.iter().map(|s| rule.times(&s.t_s, x(s)).len()).sum();
    let rows = c.points().max(1);
    let share = events as f64 / rows as f64;
    if events == 0 {
        Err(format!("no {} above its noise", rule.name()))
    } else if share > MAX_EVENT_SHARE {
        Err(format!(
            "{} above noise on {:.0} % of rows (more than {:.0} %): they are its noise, no clock",
            rule.name(),
            100.0 * share,
            100.0 * MAX_EVENT_SHARE
        ))
    } else {
        Ok(rule)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_step_starts_the_clock_a_ramp_does_not() {
        let t: Vec<f64> = (0..100).map(|i| 10.0 * f64::from(i)).collect();
        // a ramp with a step of 5 between rows 39 and 40
        let x: Vec<f64> = (0..100)
            .map(|i| 0.3 * f64::from(i) + if i >= 40 { 5.0 } else { 0.0 })
            .collect();
        let rule = EventRule::Steps { threshold: 1.0 };
        assert_eq!(rule.times(&t, &x), vec![395.0]);
        let c = clock_decay(&t, &rule.times(&t, &x), 100.0);
        assert_eq!(c[39], 0.0);
        assert!((c[40] - (-0.05f64).exp()).abs() < 1e-12);
        assert!((c[50] - (-1.05f64).exp()).abs() < 1e-12);
    }

    #[test]
    fn a_step_split_over_two_rows_is_one_event_and_gaps_restart_where_stamps_resume() {
        let t: Vec<f64> = (0..60).map(|i| 10.0 * f64::from(i)).collect();
        let mut x = vec![0.0; 60];
        x[20] = 0.4;
        x[21..].iter_mut().for_each(|v| *v = 1.0);
        let rule = EventRule::Steps { threshold: 0.2 };
        assert_eq!(rule.times(&t, &x), vec![195.0]);
        let mut tg: Vec<f64> = (0..30).map(|i| 10.0 * f64::from(i)).collect();
        tg.extend((0..30).map(|i| 400.0 + 10.0 * f64::from(i)));
        let gaps = EventRule::Gaps { threshold_s: 20.0 };
        assert_eq!(gaps.times(&tg, &tg), vec![395.0]);
    }

    /// Two runs of 10 s rows: a warm-up with noise, a switch, a ticking quantised ramp.
    fn campaign(gap: bool) -> Campaign {
        let mut noise = 0.3f64;
        let mut next = move || {
            noise = (noise * 997.0 + 0.123).fract();
            noise - 0.5
        };
        let runs = (0..2)
            .map(|r| {
                let n = 240;
                let t_s: Vec<f64> = (0..n)
                    .map(|i| 10.0 * f64::from(i) + if gap && i >= 100 { 200.0 } else { 0.0 })
                    .collect();
                let temp_c: Vec<f64> = t_s
                    .iter()
                    .map(|t| 20.0 + 8.0 * (1.0 - (-t / 600.0).exp()) + 0.01 * next())
                    .collect();
                let switch: Vec<f64> = (0..n)
                    .map(|i| f64::from(u8::from((i / 60 + r) % 2 == 1)))
                    .collect();
                let ramp: Vec<f64> = (0..n)
                    .map(|i| (f64::from(i) * 0.03 / 0.0625).round() * 0.0625)
                    .collect();
                Series {
                    name: format!("run{r}"),
                    ambient_c: None,
                    latitude_deg: None,
                    drift_dph: vec![0.0; n as usize],
                    t_s,
                    temp_c,
                    extras: vec![switch, ramp],
                }
            })
            .collect();
        Campaign {
            runs,
            extra_names: vec!["switch".into(), "ramp_c".into()],
            exclusions: vec![],
            derivative_widths: vec![],
        }
    }

    #[test]
    fn switches_and_gaps_have_clocks_a_warm_up_and_a_ticking_ramp_do_not() {
        let c = campaign(true);
        let switch = step_rule(&c, |s| &s.extras[0]).expect("a switch has events");
        let times = switch.times(&c.runs[0].t_s, &c.runs[0].extras[0]);
        assert_eq!(times.len(), 3, "{times:?}");
        assert!(
            step_rule(&c, |s| &s.temp_c).is_err(),
            "a warm-up is no event"
        );
        assert!(
            step_rule(&c, |s| &s.extras[1]).is_err(),
            "one-quantum ticks are noise"
        );
        let gapped: Vec<f64> = c.runs[1].t_s.iter().map(|t| 0.01 * t).collect();
        let across = EventRule::Steps { threshold: 0.5 };
        assert!(
            across.times(&c.runs[1].t_s, &gapped).is_empty(),
            "a change across a gap is no step"
        );
        let gaps = gap_rule(&c).expect("a gap is an event");
        assert_eq!(gaps.times(&c.runs[1].t_s, &c.runs[1].t_s), vec![1195.0]);
        assert!(gap_rule(&campaign(false)).is_err());
    }
}
