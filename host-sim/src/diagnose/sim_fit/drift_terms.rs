//! Maps the named cause and its fitted coefficient(s) onto the project's simulator
//! (`fog_sim::sim::DriftTerm`), so the effect found in measured data can be re-simulated.
//!
//! The coefficients come from [`crate::diagnose::sim_fit::calibrate`], fitted on the *raw* transformed signal
//! (no normalisation), so they are already in the simulator's units: deg/h per unit of
//! the column (value, lag), per unit/s (rate), per unit/s^2 (accel), deg/h at power-on
//! (decay), deg/h per cos/sin (harmonic). Mapping of sources:
//! - a measured extra column -> `AuxSource::Series` of that run's column (one term per run;
//!   the coefficient is shared, the series is the run's own column as recorded, not the
//!   10 s bins). Each row is taken to stand for the sample interval that *ends* at its
//!   `t_s` (the convention of `fog_sim::sim::simulate_run`, whose rows are 10 s means
//!   stamped at the window end), so the series points sit half a sample period earlier;
//!   without this a rate term would be re-simulated 5 s late;
//! - `t_s:decay(tau)` -> `PowerOnDecay { tau }` with `Value`;
//! - `temp_c:*` -> the sensor temperature with the same transform;
//! - `heading_deg:harmonic` -> `HeadingCos` + `HeadingSin` (the input axis azimuth); any
//!   other `*_deg:harmonic` -> two series, cos and sin of the run's column;
//! - `earth_dph:*` -> the true input rate with the same transform (a scale-factor error).

use crate::diagnose::candidates::transforms::Transform;
use crate::diagnose::selection::cause::Cause;
use crate::io::runs::Run;
use crate::sim::{AuxSource, AuxTransform, DriftTerm};
use serde::Serialize;

/// Name of the column that is the input axis azimuth in fog-runs records.
pub const HEADING_COLUMN: &str = "heading_deg";

/// A simulator term as reported (JSON `simulation.term`); the series itself is per run.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct TermSummary {
    pub label: String,
    /// e.g. `series:supply_v`, `power_on_decay`, `sensor_temp_c`, `heading_cos`, `input_rate_dph`.
    pub source: String,
    /// `value`, `rate`, `accel` or `lag`.
    pub transform: String,
    pub tau_s: Option<f64>,
    /// deg/h per unit of the transformed raw signal.
    pub coeff_dph: f64,
}

/// The simulator transform for a diagnose transform (`decay` and `harmonic` act through
/// their source, so they are `Value`); `None` for a lag without its time constant.
fn sim_transform(t: Transform, tau_s: Option<f64>) -> Option<AuxTransform> {
    match t {
        Transform::Value | Transform::Decay | Transform::Harmonic => Some(AuxTransform::Value),
        Transform::Rate => Some(AuxTransform::Rate),
        Transform::Accel => Some(AuxTransform::Accel),
        Transform::Lag => tau_s.map(|tau_s| AuxTransform::Lag { tau_s }),
        Transform::Levels | Transform::Spline | Transform::Event | Transform::Hysteresis => None,
    }
}

/// Time of each row's interval centre (see the module header), s.
pub fn row_centres_s(run: &Run) -> Vec<f64> {
    let half = if run.len() > 1 {
        0.5 * run.sample_period_s()
    } else {
        0.0
    };
    run.t_s().iter().map(|t| t - half).collect()
}

fn series_of(run: &Run, values: Vec<f64>) -> AuxSource {
    AuxSource::Series {
        t_s: row_centres_s(run),
        values,
    }
}

/// The simulator terms for one run: `coef` are the fitted coefficients (two for a
/// harmonic). Returns an empty list when there is no cause or the coefficients do not
/// match it.
pub fn terms_for_run(run: &Run, cause: &Cause, coef: &[f64]) -> Vec<DriftTerm> {
    let Some(transform) = sim_transform(cause.transform, cause.tau_s) else {
        return Vec::new();
    };
    if !cause.is_plain() {
        return Vec::new();
    }
    let want = if cause.transform == Transform::Harmonic {
        2
    } else {
        1
    };
    if coef.len() != want || coef.iter().any(|c| !c.is_finite()) {
        return Vec::new();
    }
    let label = cause.label();
    let term = |label: String, source: AuxSource, coeff_dph: f64| DriftTerm {
        label,
        source,
        transform,
        coeff_dph,
        column: None,
    };
    let extra = run
        .column(&cause.column)
        .filter(|v| v.iter().all(|x| x.is_finite()))
        .map(<[f64]>::to_vec);
    match (cause.column.as_str(), cause.transform, extra) {
        ("t_s", Transform::Decay, _) => match cause.tau_s {
            Some(tau_s) => vec![term(label, AuxSource::PowerOnDecay { tau_s }, coef[0])],
            None => Vec::new(),
        },
        ("temp_c", _, _) => vec![term(label, AuxSource::SensorTempC, coef[0])],
        (HEADING_COLUMN, Transform::Harmonic, _) => vec![
            term(format!("{label}:cos"), AuxSource::HeadingCos, coef[0]),
            term(format!("{label}:sin"), AuxSource::HeadingSin, coef[1]),
        ],
        ("earth_dph", _, _) => vec![term(label, AuxSource::InputRateDph, coef[0])],
        (_, Transform::Harmonic, Some(x)) => {
            let cos = x.iter().map(|d| d.to_radians().cos()).collect();
            let sin = x.iter().map(|d| d.to_radians().sin()).collect();
            vec![
                term(format!("{label}:cos"), series_of(run, cos), coef[0]),
                term(format!("{label}:sin"), series_of(run, sin), coef[1]),
            ]
        }
        (_, Transform::Decay, _) => Vec::new(),
        (_, _, Some(x)) => vec![term(label, series_of(run, x), coef[0])],
        (_, _, None) => Vec::new(),
    }
}

/// The terms of every run, in the order given (empty lists when there is no cause).
pub fn terms_per_run(runs: &[Run], cause: Option<&Cause>, coef: &[f64]) -> Vec<Vec<DriftTerm>> {
    runs.iter()
        .map(|r| cause.map_or_else(Vec::new, |c| terms_for_run(r, c, coef)))
        .collect()
}

/// How a term is reported (the series values are left out: they are the run's column).
pub fn summarize(t: &DriftTerm, series_column: &str) -> TermSummary {
    let source = match &t.source {
        AuxSource::CoilTempC => "coil_temp_c".to_owned(),
        AuxSource::HousingTempC => "housing_temp_c".to_owned(),
        AuxSource::SensorTempC => "sensor_temp_c".to_owned(),
        AuxSource::PowerOnDecay { .. } => "power_on_decay".to_owned(),
        AuxSource::HeadingCos => "heading_cos".to_owned(),
        AuxSource::HeadingSin => "heading_sin".to_owned(),
        AuxSource::InputRateDph => "input_rate_dph".to_owned(),
        AuxSource::Series { .. } => format!("series:{series_column}"),
    };
    let (transform, tau_s) = match t.transform {
        AuxTransform::Value => ("value", None),
        AuxTransform::Rate => ("rate", None),
        AuxTransform::Accel => ("accel", None),
        AuxTransform::Lag { tau_s } => ("lag", Some(tau_s)),
    };
    let tau_s = match t.source {
        AuxSource::PowerOnDecay { tau_s } => Some(tau_s),
        _ => tau_s,
    };
    TermSummary {
        label: t.label.clone(),
        source,
        transform: transform.to_owned(),
        tau_s,
        coeff_dph: t.coeff_dph,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run() -> Run {
        let t: Vec<f64> = (1..=30).map(|k| k as f64 * 10.0).collect();
        let col = |f: fn(f64) -> f64| t.iter().map(|&x| f(x)).collect::<Vec<f64>>();
        Run::new(
            "r.csv",
            vec![],
            vec![
                ("t_s".into(), t.clone()),
                ("rate_dph".into(), col(|x| x * 1e-4)),
                ("temp_c".into(), col(|x| 20.0 + x / 100.0)),
                ("supply_v".into(), col(|x| 28.0 + x / 300.0)),
                (HEADING_COLUMN.into(), col(|x| x * 0.5)),
                ("mag_deg".into(), col(|x| x * 2.0)),
            ],
        )
        .unwrap()
    }

    fn cause(column: &str, transform: Transform, tau_s: Option<f64>) -> Cause {
        Cause::plain(column, transform, tau_s)
    }

    #[test]
    fn each_cause_maps_to_the_right_source_and_transform() {
        let r = run();
        let one = |cs: Cause, k: f64| {
            let t = terms_for_run(&r, &cs, &[k]);
            assert_eq!(t.len(), 1, "{cs:?}");
            t.into_iter().next().unwrap()
        };
        let t = one(cause("supply_v", Transform::Rate, None), 0.5);
        assert_eq!(t.transform, AuxTransform::Rate);
        assert_eq!(t.coeff_dph, 0.5);
        match &t.source {
            AuxSource::Series { t_s, values } => {
                assert_eq!(t_s[0], 5.0, "row 10 s stands for 0..10 s: centre 5 s");
                assert_eq!(values.as_slice(), r.column("supply_v").unwrap());
            }
            s => panic!("expected a series, got {s:?}"),
        }
        assert_eq!(summarize(&t, "supply_v").source, "series:supply_v");
        let t = one(cause("t_s", Transform::Decay, Some(240.0)), 0.02);
        assert_eq!(t.source, AuxSource::PowerOnDecay { tau_s: 240.0 });
        assert_eq!(t.transform, AuxTransform::Value);
        assert_eq!(summarize(&t, "t_s").tau_s, Some(240.0));
        let t = one(cause("temp_c", Transform::Lag, Some(480.0)), 0.01);
        assert_eq!(t.source, AuxSource::SensorTempC);
        assert_eq!(t.transform, AuxTransform::Lag { tau_s: 480.0 });
        assert_eq!(summarize(&t, "temp_c").tau_s, Some(480.0));
        let t = one(cause("temp_c", Transform::Accel, None), 3.0);
        assert_eq!(t.transform, AuxTransform::Accel);
        let t = one(cause("earth_dph", Transform::Value, None), 1e-4);
        assert_eq!(t.source, AuxSource::InputRateDph);
    }

    #[test]
    fn harmonics_give_two_terms_and_the_heading_uses_the_azimuth() {
        let r = run();
        let h = terms_for_run(
            &r,
            &cause(HEADING_COLUMN, Transform::Harmonic, None),
            &[0.01, -0.02],
        );
        assert_eq!(h.len(), 2);
        assert_eq!(h[0].source, AuxSource::HeadingCos);
        assert_eq!(h[1].source, AuxSource::HeadingSin);
        assert_eq!(h[1].coeff_dph, -0.02);
        let m = terms_for_run(
            &r,
            &cause("mag_deg", Transform::Harmonic, None),
            &[0.01, 0.02],
        );
        let first = r.column("mag_deg").unwrap()[0].to_radians();
        match (&m[0].source, &m[1].source) {
            (AuxSource::Series { values: c, .. }, AuxSource::Series { values: s, .. }) => {
                assert!((c[0] - first.cos()).abs() < 1e-12);
                assert!((s[0] - first.sin()).abs() < 1e-12);
            }
            s => panic!("expected two series, got {s:?}"),
        }
    }

    #[test]
    fn mismatched_or_missing_coefficients_give_no_term() {
        let r = run();
        let v = cause("supply_v", Transform::Value, None);
        assert!(terms_for_run(&r, &v, &[]).is_empty());
        assert!(terms_for_run(&r, &v, &[f64::NAN]).is_empty());
        assert!(terms_for_run(&r, &v, &[1.0, 2.0]).is_empty());
        assert!(terms_for_run(&r, &cause("nope", Transform::Value, None), &[1.0]).is_empty());
        assert!(terms_per_run(&[r], None, &[1.0])[0].is_empty());
    }
}
