//! Event clocks (issue 38 item 1): a drift that answers each change of a column with a
//! transient is found as "exp decay ... after steps / gaps" of that column. Generator:
//! `common/novel.rs`, family `Event` (12 runs x 40 min of 10 s rows, the novel
//! generator's restarts, decoys and switching columns, 3 logger gaps of 40-120 s per
//! run; the planted cause at 1 noise sigma after removing what the paper's base absorbs):
//! the effect (a decay after every step of `supply_v`, whatever the step's sign), its
//! different-law twin (a decay after every gap of the time stamps) and the null twin
//! (the same steps and gaps, no response). `diagnose` and the two generic peers (the lasso
//! and the best subset) are run side by side as in `diagnose_novel`; one case a test so each stays short. Other seeds:
//! `DIAG_SEEDS=11,22,33,44,55,66 cargo test -p fog-sim --test integration diagnose_events
//! -- --nocapture`.

use crate::common::novel::{Family, Variant};
use crate::diagnose_novel::{assert_ci, case_seeds, run_case, Row};

fn rows(variant: Variant) -> Vec<Row> {
    case_seeds()
        .into_iter()
        .map(|seed| run_case(Family::Event, variant, seed))
        .collect()
}

/// Whether every label `diagnose` named is the event clock of `column` (`events`).
fn only_the_clock(r: &Row, column: &str, events: &str) -> bool {
    r.engine == "right"
        && r.named
            .iter()
            .any(|l| l.starts_with(&format!("{column}:exp decay")) && l.ends_with(events))
}

#[test]
fn a_transient_after_each_step_is_named_as_the_columns_step_clock() {
    let rows = rows(Variant::Effect);
    assert_ci(&rows, Variant::Effect, "supply_v's step clock named", |r| {
        only_the_clock(r, "supply_v", "after steps")
    });
}

#[test]
fn a_transient_after_each_gap_is_named_as_the_gap_clock() {
    let rows = rows(Variant::Twin);
    assert_ci(
        &rows,
        Variant::Twin,
        "the time stamps' gap clock named",
        |r| only_the_clock(r, "t_s", "after gaps"),
    );
}

#[test]
fn steps_and_gaps_without_a_response_name_nothing() {
    let rows = rows(Variant::Null);
    assert_ci(&rows, Variant::Null, "null twin: nothing named", |r| {
        r.engine == "none"
    });
}

/// The report says per operator family how many candidates it gave and what the test's
/// power is for it (issue 38 item 4): on the null twin nothing is named, so the planted-shape
/// check runs, and the event-clock family is among the families it checks.
#[test]
fn the_null_twin_reports_candidates_and_power_per_operator_family() {
    let (runs, _) = crate::common::novel::campaign(
        Family::Event,
        Variant::Null,
        crate::diagnose_novel::CI_SEED,
        crate::diagnose_novel::SHAPE,
    );
    let d = fog_sim::diagnose::diagnose(&runs).expect("diagnose runs");
    let families = &d.report.campaign.operator_families;
    for f in families {
        println!(
            "{}: {} candidates, {} cut, {} skipped, planted {} named {}: {} {:?}",
            f.family,
            f.candidates,
            f.cut_by_cap,
            f.skipped,
            f.shapes_planted,
            f.shapes_named,
            f.power,
            f.why_cut
        );
    }
    let total: usize = families.iter().map(|f| f.candidates).sum();
    assert_eq!(
        total, d.report.campaign.library_size,
        "every candidate in one family"
    );
    let clock = families
        .iter()
        .find(|f| f.family == "event clock")
        .expect("the event-clock family is reported");
    assert!(
        clock.candidates > 0,
        "steps of supply_v and gaps give clocks"
    );
    assert_eq!(
        clock.shapes_planted, 1,
        "its shape is planted: {}",
        clock.power
    );
    assert!(
        clock.power.contains("planted shapes named") || clock.power.starts_with("no test power"),
        "{}",
        clock.power
    );
    let text = fog_sim::diagnose::report::text::render_text(&d.report);
    assert!(text.contains("within-run candidates per operator family: value"));
    assert!(text.contains("    event clock: "));
}
