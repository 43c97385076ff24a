//! One candidate explanatory feature: which column, under which transform, and how it
//! is computed per run. The generic library (`generic`) decides which candidates exist;
//! this module only says what each one is.
//!
//! Derivatives are local least-squares polynomial fits over a centred window (zero
//! delay, edges use the samples available) whose half-width was chosen per column by
//! leave-one-out validation (`derivatives`): a diagnosis looks at the whole record, so it
//! need not be causal. Lags are exact first-order low-passes started at the first value.
//! Splines are natural (restricted) cubic splines with knots at the column's campaign
//! quantiles; levels are indicators of all but the most common value; a product
//! multiplies the (centred) feature by one of the base's inputs (T - mean T, dT/dt), a
//! pairwise product by another extra column less its campaign mean (`pairs`).
//! An event clock decays after each change of its column larger than the column's noise
//! (or each gap of the time stamps; `events`).

use crate::diagnose::candidates::events::{clock_decay, EventRule};
use crate::diagnose::candidates::hysteresis;
use crate::diagnose::input::derivatives;
use crate::diagnose::input::{Campaign, Series};
use serde::Serialize;

/// How a column is turned into a feature.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Transform {
    Value,
    Rate,
    Accel,
    Harmonic,
    Levels,
    Decay,
    Lag,
    /// The column less its play (`hysteresis`): rate-independent memory.
    Hysteresis,
    Spline,
    /// A decay on the clock since the column's last event (`Candidate::event`).
    Event,
}

impl Transform {
    /// Report name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Value => "value",
            Self::Rate => "rate",
            Self::Accel => "accel",
            Self::Harmonic => "harmonic",
            Self::Levels => "levels",
            Self::Decay => "decay",
            Self::Lag => "lag",
            Self::Hysteresis => "hysteresis",
            Self::Spline => "spline",
            Self::Event => "event",
        }
    }

    /// Parsimony rank: fewer free choices first (lag and decay carry a fitted tau, a
    /// spline its knots).
    pub fn complexity(self) -> u8 {
        self as u8
    }
}

/// Which signal a candidate is computed from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    Time,
    Temp,
    Extra(usize),
    /// A run-level metadata value (`Candidate::run_values`), constant within each run.
    Meta,
}

/// One of the base's inputs a feature can be multiplied by.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BaseInput {
    /// T minus its campaign mean.
    Temp,
    /// dT/dt over the base's window.
    TempRate,
}

impl BaseInput {
    /// Report name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Temp => "temp_c",
            Self::TempRate => "temp_c:rate",
        }
    }
}

/// Another extra column a feature is multiplied by (a pairwise product, `pairs`).
#[derive(Clone, Debug, PartialEq)]
pub struct Partner {
    /// Its index among the extra columns (`Source::Extra`).
    pub index: usize,
    pub column: String,
    /// Its campaign mean, subtracted before the product.
    pub centre: f64,
}

impl Source {
    /// This signal in one run (`None` for metadata, which has no series).
    pub fn of(self, s: &Series) -> Option<&[f64]> {
        match self {
            Source::Time => Some(&s.t_s),
            Source::Temp => Some(&s.temp_c),
            Source::Extra(i) => Some(&s.extras[i]),
            Source::Meta => None,
        }
    }
}

/// One candidate feature (one or two model columns).
#[derive(Clone, Debug, PartialEq)]
pub struct Candidate {
    pub column: String,
    pub source: Source,
    pub transform: Transform,
    pub tau_s: Option<f64>,
    /// Half-width of a `rate` or `accel` window, s (validated per column).
    pub half_s: Option<f64>,
    /// Spline knots, or the levels indicated (all but the reference level).
    pub knots: Vec<f64>,
    /// Every level of a `Levels` column, sorted (the reference included).
    pub levels: Vec<f64>,
    /// The base input the feature is multiplied by, if any.
    pub times: Option<BaseInput>,
    /// The other extra column the feature is multiplied by, if any (never with `times`).
    pub partner: Option<Partner>,
    /// Centre subtracted from the feature before a product (its campaign mean), and
    /// the campaign mean of T for `BaseInput::Temp`.
    pub centres: (f64, f64),
    /// Half-width of the base's dT/dt window, s (products with `BaseInput::TempRate`).
    pub base_rate_half_s: f64,
    /// Per-run values of a `Source::Meta` column.
    pub run_values: Vec<f64>,
    /// What starts the clock of an `Event` candidate.
    pub event: Option<EventRule>,
    /// Half-width of a `Hysteresis` candidate's play, in the column's units.
    pub width: Option<f64>,
}

impl Candidate {
    /// The report name, e.g. `temp_c:lag(tau_s=240)` (see `fog_core::compensation::label::feature_label`).
    pub fn label(&self) -> String {
        let own = match self.transform {
            Transform::Spline => format!("{}:spline(knots={})", self.column, self.knots.len()),
            Transform::Hysteresis => format!(
                "{}:hysteresis(width={:.3})",
                self.column,
                self.width.unwrap_or(0.0)
            ),
            Transform::Event => format!(
                "{}:exp decay {:.0} s after {}",
                self.column,
                self.tau_s.unwrap_or(0.0),
                self.event.map_or("events", EventRule::name)
            ),
            _ => fog_core::compensation::label::feature_label(
                &self.column,
                self.transform.name(),
                self.tau_s,
            )
            .to_string(),
        };
        let own = if self.source == Source::Meta {
            format!("# {own}")
        } else {
            own
        };
        match (self.times, &self.partner) {
            (Some(b), _) => format!("{own}*{}", b.name()),
            (None, Some(p)) => format!("{own}*{}", p.column),
            (None, None) => own,
        }
    }

    /// Parsimony rank within a column (see `Transform::complexity`), except that for an
    /// angle (`*_deg`) the harmonic is the natural form: its raw value wraps at 360 deg
    /// and is only equivalent when few headings occur (e.g. two, 180 deg apart). Within a
    /// transform, fewer spline knots rank simpler (a smooth law is named with the fewest
    /// knots that are not significantly worse held out; a narrow feature keeps its many).
    pub fn complexity(&self) -> (u8, usize) {
        let own = match self.transform {
            Transform::Harmonic if self.column.ends_with("_deg") => 0,
            Transform::Value if self.column.ends_with("_deg") => Transform::Harmonic.complexity(),
            t => t.complexity(),
        };
        let knots = if self.transform == Transform::Spline {
            self.knots.len()
        } else {
            0
        };
        (own + if self.is_product() { 16 } else { 0 }, knots)
    }

    /// Whether the feature is multiplied by a base input or by another column.
    pub fn is_product(&self) -> bool {
        self.times.is_some() || self.partner.is_some()
    }

    /// The feature's columns for run `run` (`s`, its series).
    pub fn compute(&self, run: usize, s: &Series) -> Vec<Vec<f64>> {
        let own = self.own_columns(run, s);
        let partner: Vec<f64> = match (self.times, &self.partner) {
            (Some(BaseInput::Temp), _) => s.temp_c.iter().map(|t| t - self.centres.1).collect(),
            (Some(BaseInput::TempRate), _) => {
                derivatives::centred(&s.t_s, &s.temp_c, 1, self.base_rate_half_s)
            }
            (None, Some(p)) => s.extras[p.index].iter().map(|v| v - p.centre).collect(),
            (None, None) => return own,
        };
        let centre = if self.transform == Transform::Levels {
            0.0
        } else {
            self.centres.0
        };
        own.into_iter()
            .map(|c| {
                c.iter()
                    .zip(&partner)
                    .map(|(x, p)| (x - centre) * p)
                    .collect()
            })
            .collect()
    }

    fn own_columns(&self, run: usize, s: &Series) -> Vec<Vec<f64>> {
        let n = s.t_s.len();
        let meta = vec![self.run_values.get(run).copied().unwrap_or(0.0); n];
        let x = self.source.of(s).unwrap_or(&meta);
        let tau = self.tau_s.unwrap_or(0.0);
        let half_s = self
            .half_s
            .unwrap_or(2.0 * crate::diagnose::input::window::WINDOW_S);
        match self.transform {
            Transform::Value => vec![x.to_vec()],
            Transform::Rate => vec![derivatives::centred(&s.t_s, x, 1, half_s)],
            Transform::Accel => vec![derivatives::centred(&s.t_s, x, 2, half_s)],
            Transform::Lag => vec![first_order_lag(&s.t_s, x, tau)],
            Transform::Hysteresis => vec![hysteresis::stop(x, self.width.unwrap_or(0.0))],
            Transform::Decay => vec![s.t_s.iter().map(|t| (-t / tau).exp()).collect()],
            Transform::Harmonic => vec![
                x.iter().map(|d| d.to_radians().cos()).collect(),
                x.iter().map(|d| d.to_radians().sin()).collect(),
            ],
            Transform::Levels => self
                .knots
                .iter()
                .map(|l| {
                    x.iter()
                        .map(|v| level_weight(*v, *l, &self.levels))
                        .collect()
                })
                .collect(),
            Transform::Spline => std::iter::once(x.to_vec())
                .chain(natural_spline(x, &self.knots))
                .collect(),
            Transform::Event => {
                let events = self.event.map(|e| e.times(&s.t_s, x)).unwrap_or_default();
                vec![clock_decay(&s.t_s, &events, tau)]
            }
        }
    }
}

/// The candidate's columns for every run, stacked run after run.
pub fn stacked_columns(campaign: &Campaign, cand: &Candidate) -> Vec<Vec<f64>> {
    let per_run: Vec<Vec<Vec<f64>>> = campaign
        .runs
        .iter()
        .enumerate()
        .map(|(r, s)| cand.compute(r, s))
        .collect();
    let m = per_run.first().map_or(0, Vec::len);
    (0..m)
        .map(|j| per_run.iter().flat_map(|r| r[j].iter().copied()).collect())
        .collect()
}

/// Membership of `x` in `level` among the sorted `levels`: 1 on the level, falling
/// linearly to 0 at the neighbouring levels (a window mean of a switch between adjacent
/// levels is split in the right shares), 0 beyond.
pub fn level_weight(x: f64, level: f64, levels: &[f64]) -> f64 {
    let i = levels.iter().position(|l| *l == level).unwrap_or(0);
    let below = i.checked_sub(1).map(|j| levels[j]);
    let above = levels.get(i + 1).copied();
    if x == level {
        1.0
    } else if x < level {
        below.map_or(0.0, |b| ((x - b) / (level - b)).max(0.0))
    } else {
        above.map_or(0.0, |a| ((a - x) / (a - level)).max(0.0))
    }
}

/// Restricted (natural) cubic spline basis without its linear term: for knots
/// t_1 < ... < t_K, K - 2 columns, each cubic between knots and linear beyond the end
/// knots (Harrell's form, scaled by (t_K - t_1)^2 so the columns are in the column's units).
pub fn natural_spline(x: &[f64], knots: &[f64]) -> Vec<Vec<f64>> {
    let k = knots.len();
    if k < 3 {
        return vec![];
    }
    let (tk, tk1) = (knots[k - 1], knots[k - 2]);
    let scale = (tk - knots[0]).powi(2).max(1e-300);
    let cube = |v: f64| v.max(0.0).powi(3);
    (0..k - 2)
        .map(|j| {
            let tj = knots[j];
            x.iter()
                .map(|&v| {
                    (cube(v - tj) - cube(v - tk1) * (tk - tj) / (tk - tk1)
                        + cube(v - tk) * (tk1 - tj) / (tk - tk1))
                        / scale
                })
                .collect()
        })
        .collect()
}

/// First-order low-pass with time constant `tau_s`, exact for piecewise-constant input.
pub fn first_order_lag(t: &[f64], x: &[f64], tau_s: f64) -> Vec<f64> {
    let mut out = Vec::with_capacity(x.len());
    let mut y = x.first().copied().unwrap_or(0.0);
    for i in 0..x.len() {
        if i > 0 {
            let a = 1.0 - (-(t[i] - t[i - 1]) / tau_s).exp();
            y += a * (x[i] - y);
        }
        out.push(y);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lag_settles_to_a_step() {
        let t: Vec<f64> = (0..200).map(|i| 10.0 * i as f64).collect();
        let mut x = vec![0.0; 200];
        x[1..].iter_mut().for_each(|v| *v = 1.0);
        let y = first_order_lag(&t, &x, 100.0);
        // the step is held from t[0] to t[1]; ten 10 s steps later it has risen 1 - e^-1
        assert!((y[10] - (1.0 - (-1.0f64).exp())).abs() < 1e-12);
    }

    #[test]
    fn fewer_knots_rank_simpler_and_a_spline_after_the_value() {
        let spline = |knots: usize| Candidate {
            column: "c".into(),
            source: Source::Extra(0),
            transform: Transform::Spline,
            tau_s: None,
            half_s: None,
            knots: (0..knots).map(|k| k as f64).collect(),
            levels: vec![],
            times: None,
            partner: None,
            centres: (0.0, 0.0),
            base_rate_half_s: 1.0,
            run_values: vec![],
            event: None,
            width: None,
        };
        let value = Candidate {
            transform: Transform::Value,
            knots: vec![],
            ..spline(0)
        };
        assert!(spline(6).complexity() < spline(40).complexity());
        assert!(value.complexity() < spline(4).complexity());
    }

    #[test]
    fn the_natural_spline_is_linear_beyond_its_end_knots() {
        let knots = [0.0, 1.0, 2.0, 3.0];
        let x: Vec<f64> = (0..100).map(|i| -5.0 + 0.2 * f64::from(i)).collect();
        let cols = natural_spline(&x, &knots);
        assert_eq!(cols.len(), 2);
        for c in &cols {
            // second differences vanish below t_1 and above t_K, not in between
            let d2 = |i: usize| c[i + 1] - 2.0 * c[i] + c[i - 1];
            assert!(
                d2(5).abs() < 1e-12 && d2(90).abs() < 1e-9,
                "{} {}",
                d2(5),
                d2(90)
            );
            assert!(d2(30).abs() > 1e-6);
        }
    }
}
