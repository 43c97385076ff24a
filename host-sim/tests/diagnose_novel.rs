//! Effects `diagnose` was not written around (issue 18): for every family of
//! `common/novel.rs` (its effect, a twin of another physical law, the null twin) and every
//! seed, `fog_sim::diagnose` (through its public entry point and the JSON of its report, so
//! that a restructured engine still runs here) and two generic peers on the same library
//! and naming test (`common/peer_library.rs`) are run side by side: the lasso peer of
//! `common/peer.rs` and the best-subset peer of `common/peer_subset.rs` (issue 38 item 5).
//! One table row per case: diagnose, then the lasso peer, then the best-subset peer. The
//! assertions hold what each achieves on the CI seeds (see docs/record/diagnose.md,
//! "Effects the library was not written around" and the 2026-12-02 best-subset section); the
//! rest is printed. Full table: `DIAG_SEEDS=11,22,33,44,55,66 cargo test -p fog-sim --test
//! integration diagnose_novel:: -- --nocapture --test-threads=2`.

use crate::common::novel;
use crate::common::peer;
use crate::common::peer_library;
use crate::common::peer_subset;
use crate::common::seeds;

use novel::{campaign, Family, Shape, Variant, VARIANTS};
use serde_json::Value;

/// Campaign shape of every case: 12 runs x 40 min, each planted cause at 1 sigma.
pub(crate) const SHAPE: Shape = Shape {
    runs: 12,
    minutes: 40.0,
    sigmas: 1.0,
};

/// The CI seed: one, since `diagnose` itself takes ~1-3 s a case and there are 18 cases.
pub(crate) const CI_SEED: u64 = seeds::SEEDS[0];

/// `DIAG_SEEDS` when set, else the CI seed.
pub(crate) fn case_seeds() -> Vec<u64> {
    if std::env::var("DIAG_SEEDS").is_ok() {
        seeds::seeds()
    } else {
        vec![CI_SEED]
    }
}

/// What `diagnose` names: every named cause's label (the report's `named_causes` when it
/// has them, else `named_cause` plus the between-run `named`), the extended model's
/// held-out gain and the p of the first named cause.
struct Engine {
    named: Vec<String>,
    gain_pct: f64,
    p_value: Option<f64>,
}

fn label_of(v: &Value) -> Option<String> {
    if let Some(s) = v.as_str() {
        return Some(s.to_owned());
    }
    if let Some(l) = v.get("label").and_then(Value::as_str) {
        return Some(l.to_owned());
    }
    let col = v.get("column")?.as_str()?;
    let tr = v.get("transform").and_then(Value::as_str).unwrap_or("?");
    Some(match v.get("tau_s").and_then(Value::as_f64) {
        Some(tau) => format!("{col}:{tr}(tau_s={tau})"),
        None => format!("{col}:{tr}"),
    })
}

/// p of a named label: its candidate or between-run row.
fn p_of(report: &Value, label: &str) -> Option<f64> {
    let col = label.split(':').next().unwrap_or("");
    let tr = label
        .split(':')
        .nth(1)
        .unwrap_or("")
        .split('(')
        .next()
        .unwrap_or("");
    let within = report.get("candidates")?.as_array()?.iter().find(|c| {
        c.get("column").and_then(Value::as_str) == Some(col)
            && c.get("transform").and_then(Value::as_str) == Some(tr)
    });
    let between = || {
        report
            .pointer("/between_run/rows")?
            .as_array()?
            .iter()
            .find(|r| r.get("label").and_then(Value::as_str) == Some(label))
            .cloned()
    };
    within.cloned().or_else(between)?.get("p_value")?.as_f64()
}

fn engine(runs: &[fog_sim::io::runs::Run]) -> Engine {
    let d = fog_sim::diagnose::diagnose(runs).expect("diagnose runs on the generated campaign");
    let v = serde_json::to_value(&d.report).expect("report serialises");
    let named: Vec<String> = match v.get("named_causes").and_then(Value::as_array) {
        Some(list) => list.iter().filter_map(label_of).collect(),
        None => v
            .get("named_cause")
            .and_then(label_of)
            .into_iter()
            .chain(v.pointer("/between_run/named").and_then(label_of))
            .collect(),
    };
    let first_p = v.pointer("/named_causes/0/p_value").and_then(Value::as_f64);
    Engine {
        gain_pct: v
            .pointer("/extended/gain_pct")
            .and_then(Value::as_f64)
            .unwrap_or(0.0),
        p_value: first_p.or_else(|| named.first().and_then(|l| p_of(&v, l))),
        named,
    }
}

/// Columns (or metadata keys) a label speaks of: `supply_v*temp_c:rate` -> supply_v,
/// temp_c; `# mount==B` -> mount; `heading_deg:run_harmonic` -> heading_deg.
fn columns_of(label: &str) -> Vec<String> {
    label
        .split('*')
        .map(|p| {
            let p = p.trim_start_matches("# ");
            p.split([':', '=', '(', '>']).next().unwrap_or(p).to_owned()
        })
        .collect()
}

/// right: every planted column named, nothing else (temp_c, the base's own column, aside);
/// partial: some planted column named; wrong: only other columns; miss / none: nothing.
fn verdict(truth: &[&str], named: &[String]) -> &'static str {
    let cols: Vec<String> = named.iter().flat_map(|l| columns_of(l)).collect();
    let hits = truth
        .iter()
        .filter(|c| cols.iter().any(|n| n == *c))
        .count();
    let extra = cols
        .iter()
        .any(|c| c != "temp_c" && !truth.contains(&c.as_str()));
    match (named.is_empty(), truth.is_empty()) {
        (true, true) => "none",
        (true, false) => "miss",
        (false, true) => "FALSE",
        _ if hits == truth.len() && !extra => "right",
        _ if hits > 0 => "partial",
        _ => "wrong",
    }
}

/// One case's table row: the verdicts of `diagnose` and the two peers, and what `diagnose`
/// named.
pub(crate) struct Row {
    pub(crate) variant: Variant,
    pub(crate) seed: u64,
    pub(crate) engine: &'static str,
    /// The lasso peer's verdict.
    pub(crate) peer: &'static str,
    /// The best-subset peer's verdict.
    pub(crate) subset: &'static str,
    pub(crate) named: Vec<String>,
    pub(crate) line: String,
}

fn run_family(family: Family) -> Vec<Row> {
    let cases: Vec<(Variant, u64)> = VARIANTS
        .iter()
        .flat_map(|v| case_seeds().into_iter().map(move |s| (*v, s)))
        .collect();
    cases
        .into_iter()
        .map(|(variant, seed)| run_case(family, variant, seed))
        .collect()
}

/// A table cell of names: comma separated, or "-".
fn or_dash(names: &[String]) -> String {
    if names.is_empty() {
        "-".to_owned()
    } else {
        names.join(", ")
    }
}

/// A peer's verdict and its table cells: named terms with p and the verdict, then the CV
/// gain % and selected-of-library.
fn peer_cells(truth: &[&str], p: &peer_library::PeerReport) -> (&'static str, String) {
    let labels: Vec<String> = p.named.iter().map(|n| n.label.clone()).collect();
    let v = verdict(truth, &labels);
    let named: Vec<String> = p
        .named
        .iter()
        .map(|n| format!("{} p{:.3}", n.label, n.p_value))
        .collect();
    let cells = format!(
        "{} {v} | {:+.1} ({} of {})",
        or_dash(&named),
        p.cv_gain_pct,
        p.selected,
        p.library_size,
    );
    (v, cells)
}

/// One case: the campaign of `family` / `variant` / `seed`, diagnosed and given to both peers.
pub(crate) fn run_case(family: Family, variant: Variant, seed: u64) -> Row {
    let (runs, truth) = campaign(family, variant, seed, SHAPE);
    let e = engine(&runs);
    let (pv, lasso) = peer_cells(&truth.columns, &peer::peer(&runs));
    let (sv, subset) = peer_cells(&truth.columns, &peer_subset::peer(&runs));
    let ev = verdict(&truth.columns, &e.named);
    let line = format!(
        "| {family:?} | {variant:?} | {seed} | {} | {} {ev} | {:+.1} | {} | {lasso} | {subset} |",
        truth.law,
        or_dash(&e.named),
        e.gain_pct,
        e.p_value.map_or("-".to_owned(), |p| format!("{p:.4}")),
    );
    println!("{line}");
    Row {
        variant,
        seed,
        engine: ev,
        peer: pv,
        subset: sv,
        named: e.named,
        line,
    }
}

/// Asserts `holds` on the CI seed's row of `variant` (other seeds are printed only; the
/// 6-seed table in docs/record/diagnose.md says how often each claim holds there).
pub(crate) fn assert_ci(rows: &[Row], variant: Variant, what: &str, holds: impl Fn(&Row) -> bool) {
    let bad: Vec<&str> = rows
        .iter()
        .filter(|r| r.seed == CI_SEED && r.variant == variant && !holds(r))
        .map(|r| r.line.as_str())
        .collect();
    assert!(bad.is_empty(), "{what}: {bad:#?}");
}

/// None of the three names anything on the null twin.
fn nulls_name_nothing(rows: &[Row]) {
    assert_ci(rows, Variant::Null, "null twin: nothing named", |r| {
        r.engine == "none" && r.peer == "none" && r.subset == "none"
    });
}

#[test]
fn product_of_two_columns() {
    let rows = run_family(Family::Product);
    nulls_name_nothing(&rows);
    assert_ci(&rows, Variant::Effect, "peer names supply_v x dT/dt", |r| {
        r.peer == "right"
    });
    assert_ci(
        &rows,
        Variant::Twin,
        "best-subset peer names supply_v x T",
        |r| r.subset == "right",
    );
}

#[test]
fn categorical_column() {
    let rows = run_family(Family::Categorical);
    nulls_name_nothing(&rows);
    assert_ci(&rows, Variant::Effect, "peer names the mode levels", |r| {
        r.peer == "right"
    });
}

#[test]
fn smooth_nonlinear_function_of_a_column() {
    let rows = run_family(Family::Smooth);
    nulls_name_nothing(&rows);
    assert_ci(&rows, Variant::Effect, "both name cabinet_c", |r| {
        r.engine == "right" && r.peer == "right"
    });
}

#[test]
fn rate_independent_memory() {
    let rows = run_family(Family::Memory);
    nulls_name_nothing(&rows);
    assert_ci(&rows, Variant::Twin, "both name a temp_c lag", |r| {
        r.engine == "right" && r.peer == "right"
    });
    // issue 38 item 6: the backlash is named as what it is, the stop operator of T (6 of 6
    // seeds, held-out gain +18-25 %), not as a lag of T (+3-11 %)
    assert_ci(
        &rows,
        Variant::Effect,
        "diagnose names T's hysteresis",
        |r| r.engine == "right" && r.named.iter().any(|n| n.starts_with("temp_c:hysteresis")),
    );
}

#[test]
fn between_run_effect_of_metadata() {
    let rows = run_family(Family::Metadata);
    nulls_name_nothing(&rows);
    assert_ci(&rows, Variant::Effect, "peer names # mount", |r| {
        r.peer == "right"
    });
}

#[test]
fn two_causes_at_once() {
    let rows = run_family(Family::Stacked);
    nulls_name_nothing(&rows);
}

#[test]
fn product_of_two_columns_neither_the_temperature() {
    let rows = run_family(Family::Pairwise);
    nulls_name_nothing(&rows);
    // issue 38 item 2: only a product of the two columns names both (6 of 6 seeds; the
    // twin 5 of 6, not seed 11; the peers 1 of 6 and 0 of 6)
    assert_ci(
        &rows,
        Variant::Effect,
        "diagnose names supply_v x cabinet_c",
        |r| r.engine == "right" && r.named.iter().any(|n| n == "cabinet_c:value*supply_v"),
    );
}

#[test]
fn narrow_peak_of_a_column() {
    let rows = run_family(Family::Peak);
    nulls_name_nothing(&rows);
    // issue 38 item 1: a peak a quarter of a degree wide (and the band twin) is named with
    // a spline of more knots than the 6 the library stopped at before (5 of 6 seeds each,
    // not seed 33; the held-out gain +7-19 % against +6-10 % with 6 knots)
    for variant in [Variant::Effect, Variant::Twin] {
        assert_ci(
            &rows,
            variant,
            "diagnose names cabinet_c with a dense spline",
            |r| {
                r.engine == "right"
                    && r.named.iter().any(|n| {
                        n.strip_prefix("cabinet_c:spline(knots=")
                            .and_then(|k| k.trim_end_matches(')').parse::<usize>().ok())
                            .is_some_and(|k| k > 6)
                    })
            },
        );
    }
}

/// Writes one family's campaigns (effect, twin, null; `SHAPE`) as fog-runs files into
/// `$NOVEL_OUT/{effect,twin,null}` (a scratch directory without it), for timing and reading
/// `fogsim diagnose` on them (docs/record/diagnose.md, 2026-12-03, issue 38 items 1 and 2):
/// `NOVEL_OUT=/tmp/p38 NOVEL_FAMILY=Pairwise NOVEL_SEED=11 cargo test -p fog-sim --test
/// integration -- --ignored write_novel_campaign` (the family by its name in `novel::FAMILIES`,
/// the pairwise one and the CI seed by default). Each file is read back whole: what is
/// timed is what was planted.
#[test]
#[ignore = "slow suite: writes a family's campaigns for timing the command line"]
fn write_novel_campaign() {
    let out = match std::env::var("NOVEL_OUT") {
        Ok(dir) => std::path::PathBuf::from(dir),
        Err(_) => crate::app_support::scratch_dir("novel-campaign"),
    };
    let family = std::env::var("NOVEL_FAMILY").map_or(Family::Pairwise, |name| {
        *novel::FAMILIES
            .iter()
            .find(|f| format!("{f:?}") == name)
            .unwrap_or_else(|| panic!("NOVEL_FAMILY {name}: not a family of novel::FAMILIES"))
    });
    let seed = std::env::var("NOVEL_SEED").map_or(CI_SEED, |s| {
        s.parse()
            .unwrap_or_else(|_| panic!("NOVEL_SEED {s}: not a seed"))
    });
    let stem = format!("{family:?}").to_lowercase();
    for variant in VARIANTS {
        let dir = out.join(format!("{variant:?}").to_lowercase());
        std::fs::create_dir_all(&dir).expect("output directory");
        let (runs, _) = campaign(family, variant, seed, SHAPE);
        assert_eq!(runs.len(), SHAPE.runs, "{variant:?}");
        for (i, run) in runs.iter().enumerate() {
            let path = dir.join(format!("{stem}_{i:02}.csv"));
            fog_sim::io::runs::write_run(&path, run).expect("run written");
            let back = fog_sim::io::runs::read_run(&path).expect("run read back");
            assert_eq!(back.columns, run.columns, "{}", path.display());
            assert_eq!(back.data[0].len(), run.data[0].len(), "{}", path.display());
        }
    }
}
