//! A run's `# key: value` metadata as run-constant columns, whatever the value's type
//! (issue 38 item 3). A key enters when it is present in every run and varies between
//! them, read in the first way that fits every run's value:
//!
//! - numbers, as they are (`# supply_nominal_v: 28`);
//! - times (ISO 8601 dates or date-times, all with a zone or all without:
//!   `io::utc::parse_iso8601`), as days since the earliest run: a drift that ages
//!   with the calendar is linear in it, and the gaps between runs say how far apart they
//!   are (their order alone does not; the order is a run-level candidate of its own,
//!   `between_runs::run_features`);
//! - version strings (`1.2.10`, `v2.0.1`), as their rank in version order (numeric:
//!   a change that grows release by release), and also as levels when they are few
//!   (a change that one release brought and the next did not; with two versions the
//!   rank and the levels are the same feature, so only the levels);
//! - other words, as categories when 2..=`MAX_LEVELS` of them cover fewer runs than
//!   there are (a value unique to each run is a name, not a level).
//!
//! A key that fits none of these (a time stamp with one value unparseable, zones mixed
//! with wall clocks, many free-text values) is read as the next type down, or left out.
//! `ambient_c` and `latitude_deg` are left out: `between_runs` and the azimuth already
//! use them.

use crate::io::runs::Run;
use crate::io::utc::parse_iso8601;

/// Columns and metadata fields with at most this many distinct values also get level
/// indicators (categories).
pub const MAX_LEVELS: usize = 5;

/// How a metadata key's values were read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MetaKind {
    Number,
    /// Days since the earliest run.
    Time,
    /// Rank in version order.
    Version,
    /// Category codes (only levels make sense).
    Category,
}

impl MetaKind {
    /// The run-level operator's name in labels (`# start_time:days`).
    pub fn run_operator(self) -> &'static str {
        match self {
            Self::Number => "run_value",
            Self::Time => "days",
            Self::Version => "order",
            Self::Category => "levels",
        }
    }
}

/// A metadata key as a run-constant column.
#[derive(Clone, Debug, PartialEq)]
pub struct MetaColumn {
    pub key: String,
    /// Per run: the number, days since the earliest run, the version's rank, or the
    /// index of the value among the sorted distinct values.
    pub run_values: Vec<f64>,
    pub kind: MetaKind,
}

/// Every metadata key present in all runs that varies between them, read as the module
/// header says (a version key may give two columns: its rank and its levels).
pub fn metadata(runs: &[Run]) -> Vec<MetaColumn> {
    let Some(first) = runs.first() else {
        return vec![];
    };
    let mut out = Vec::new();
    for (key, _) in &first.meta {
        if key == "ambient_c" || key == "latitude_deg" {
            continue;
        }
        let Some(words) = runs
            .iter()
            .map(|r| r.meta_value(key).map(str::trim))
            .collect::<Option<Vec<&str>>>()
        else {
            continue;
        };
        let column = |kind, run_values| MetaColumn {
            key: key.clone(),
            run_values,
            kind,
        };
        let read: Vec<MetaColumn> = if let Some(v) = numbers(&words) {
            vec![column(MetaKind::Number, v)]
        } else if let Some(v) = days(&words) {
            vec![column(MetaKind::Time, v)]
        } else if let Some(v) = version_ranks(&words) {
            let levels = categories(&words);
            let mut both = Vec::new();
            if distinct(&v) > 2 || levels.is_none() {
                both.push(column(MetaKind::Version, v));
            }
            both.extend(levels.map(|l| column(MetaKind::Category, l)));
            both
        } else {
            categories(&words)
                .map(|l| column(MetaKind::Category, l))
                .into_iter()
                .collect()
        };
        out.extend(read.into_iter().filter(|c| distinct(&c.run_values) > 1));
    }
    out
}

fn distinct(v: &[f64]) -> usize {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    s.dedup();
    s.len()
}

fn numbers(words: &[&str]) -> Option<Vec<f64>> {
    words
        .iter()
        .map(|w| w.parse::<f64>().ok().filter(|x| x.is_finite()))
        .collect()
}

/// Days since the earliest value, when every value is an ISO 8601 instant and either
/// all carry a zone or none does.
fn days(words: &[&str]) -> Option<Vec<f64>> {
    let parsed: Vec<(f64, bool)> = words
        .iter()
        .map(|w| parse_iso8601(w))
        .collect::<Option<_>>()?;
    let zoned = parsed.first()?.1;
    if parsed.iter().any(|p| p.1 != zoned) {
        return None;
    }
    let first = parsed.iter().map(|p| p.0).fold(f64::INFINITY, f64::min);
    Some(parsed.iter().map(|p| (p.0 - first) / 86_400.0).collect())
}

/// `1.2.10` or `v1.2.10` (two or more dot-separated numbers) as its parts.
fn version(w: &str) -> Option<Vec<u64>> {
    let w = w.strip_prefix(['v', 'V']).unwrap_or(w);
    let parts: Vec<u64> = w
        .split('.')
        .map(|p| {
            (!p.is_empty() && p.bytes().all(|b| b.is_ascii_digit()))
                .then(|| p.parse().ok())
                .flatten()
        })
        .collect::<Option<_>>()?;
    (parts.len() >= 2).then_some(parts)
}

/// Each value's rank among the distinct versions (0 = oldest), when all are versions.
fn version_ranks(words: &[&str]) -> Option<Vec<f64>> {
    let v: Vec<Vec<u64>> = words.iter().map(|w| version(w)).collect::<Option<_>>()?;
    let mut order = v.clone();
    order.sort();
    order.dedup();
    Some(
        v.iter()
            .map(|x| order.iter().position(|o| o == x).unwrap_or(0) as f64)
            .collect(),
    )
}

/// Category codes (index among the sorted distinct values) when 2..=`MAX_LEVELS`
/// values cover fewer runs than there are.
fn categories(words: &[&str]) -> Option<Vec<f64>> {
    let mut d: Vec<&str> = words.to_vec();
    d.sort_unstable();
    d.dedup();
    (d.len() <= MAX_LEVELS && d.len() < words.len()).then(|| {
        words
            .iter()
            .map(|w| d.iter().position(|x| x == w).unwrap_or(0) as f64)
            .collect()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn runs(key: &str, values: &[&str]) -> Vec<Run> {
        values
            .iter()
            .enumerate()
            .map(|(i, v)| {
                let meta = vec![(key.to_owned(), (*v).to_owned())];
                let cols = vec![
                    ("t_s".to_owned(), vec![10.0, 20.0]),
                    ("rate_dph".to_owned(), vec![0.0, 0.0]),
                    ("temp_c".to_owned(), vec![20.0, 20.1]),
                ];
                Run::new(format!("r{i}.csv"), meta, cols).expect("valid run")
            })
            .collect()
    }

    fn kinds(key: &str, values: &[&str]) -> Vec<(MetaKind, Vec<f64>)> {
        metadata(&runs(key, values))
            .into_iter()
            .map(|c| (c.kind, c.run_values))
            .collect()
    }

    #[test]
    fn times_become_days_since_the_earliest_run() {
        let t = kinds(
            "start_time",
            &[
                "2025-03-24T08:00:00Z",
                "2025-03-23T08:00:00Z",
                "2025-03-23T20:00:00+00:00",
                "2025-03-23",
            ],
        );
        // the bare date has no zone: mixed, so not a time; four distinct words, as many as runs: dropped
        assert!(t.is_empty(), "{t:?}");
        let t = kinds(
            "start_time",
            &[
                "2025-03-24T08:00:00Z",
                "2025-03-23T08:00:00Z",
                "2025-03-23T20:00:00+00:00",
            ],
        );
        assert_eq!(t, vec![(MetaKind::Time, vec![1.0, 0.0, 0.5])]);
        let d = kinds("date", &["2025-03-23", "2025-04-02", "2025-03-23"]);
        assert_eq!(d, vec![(MetaKind::Time, vec![0.0, 10.0, 0.0])]);
    }

    #[test]
    fn an_unparseable_time_degrades_to_a_category_or_nothing() {
        let c = kinds("start_time", &["2025-03-23", "soon", "2025-03-23", "soon"]);
        assert_eq!(c, vec![(MetaKind::Category, vec![0.0, 1.0, 0.0, 1.0])]);
        assert!(kinds(
            "start_time",
            &[
                "2025-03-23T08:00Z",
                "2025-02-30T08:00Z",
                "2025-03-25T08:00Z"
            ]
        )
        .is_empty());
    }

    #[test]
    fn versions_are_ranked_in_version_order_and_also_levels_when_few() {
        let v = kinds("fw", &["1.2.10", "1.2.9", "1.10.0", "1.2.9"]);
        assert_eq!(
            v,
            vec![
                (MetaKind::Version, vec![1.0, 0.0, 2.0, 0.0]),
                (MetaKind::Category, vec![1.0, 2.0, 0.0, 2.0]), // codes in text order
            ]
        );
        // two versions: the rank is the levels' one indicator, so levels only
        let two = kinds("fw", &["v1.2.0", "v1.3.0", "v1.3.0"]);
        assert_eq!(two, vec![(MetaKind::Category, vec![0.0, 1.0, 1.0])]);
        // one version per run: no levels, the rank only
        let each = kinds("fw", &["1.0.1", "1.0.3", "1.0.2"]);
        assert_eq!(each, vec![(MetaKind::Version, vec![0.0, 2.0, 1.0])]);
    }

    #[test]
    fn numbers_stay_numbers_and_constant_keys_are_dropped() {
        assert_eq!(
            kinds("v", &["28", "24.5", "28"]),
            vec![(MetaKind::Number, vec![28.0, 24.5, 28.0])]
        );
        assert!(kinds("gyro", &["008", "008"]).is_empty());
        assert!(kinds("id", &["a", "b", "c"]).is_empty());
    }
}
