//! Every docs page with a fenced `sh` block, run as written (issue 39 item 2), one test
//! per page, each in its own scratch directory, by the page runner of `docs_support` (its
//! module doc says how `fogsim`, `cargo fw-run`, `&`, the ports and `../shared/` are run).
//! docs/workflow.md is `workflow.rs`; the pages' other fenced blocks are synopses with
//! placeholders (`RUNS...`, `[--opt]`, `/dev/ttyUSB0`), name-checked by `docs_commands.rs`.
//!
//! Checked: every command succeeds, the page keeps its steps, and what they make is there
//! (the fleet's unit model, diagnose's JSON naming a base, the trainer's model and report,
//! the uploaded model in the device's status, the field records pulled and counted). A
//! page that stops working fails here, and a page given an `sh` block without a test here
//! fails `every_page_with_an_sh_block_is_run_here`.
//!
//! The fast suite runs the cheapest pages (diagnose 1.3 s, upload under QEMU 0.4 s); the
//! trainer, simulator and fleet pages (about 2 s each) and the field page (QEMU, two seeks,
//! about 37 s) are in the slow suite (docs/record/suite.md). The QEMU pages skip loudly
//! without QEMU unless FOG_REQUIRE_QEMU=1.

use crate::docs_support::{pages_with_sh, Page, Walk};

const DIAGNOSE: &str = "docs/explain/diagnose.md";
const SIMULATOR: &str = "docs/explain/simulator.md";
const TRAINER: &str = "docs/explain/trainer.md";
const FIELD: &str = "docs/guide/field.md";
const FLEET: &str = "docs/guide/fleet.md";
const UPLOAD: &str = "docs/guide/upload.md";

/// The pages this file runs, one test each.
const PAGES: [&str; 6] = [DIAGNOSE, SIMULATOR, TRAINER, FIELD, FLEET, UPLOAD];

#[test]
fn every_page_with_an_sh_block_is_run_here() {
    let mut expected: Vec<String> = PAGES.iter().map(|p| p.to_string()).collect();
    expected.push("docs/workflow.md".into()); // workflow.rs
    expected.sort();
    assert_eq!(pages_with_sh(), expected);
}

/// Runs `path` after checking it keeps `steps`; asserts each of `files` was made.
fn run_page(path: &str, steps: &[&str], files: &[&str]) -> Option<Walk> {
    let page = Page::load(path);
    page.assert_steps(steps);
    let walk = page.run()?;
    for f in files {
        let p = walk.dir.join(f);
        assert!(
            p.metadata().is_ok_and(|m| m.len() > 0),
            "{path}: its commands did not make {f}"
        );
    }
    Some(walk)
}

#[test]
#[ignore = "slow suite: docs pages run as written"]
fn the_fleet_guide_runs_as_written() {
    let Some(walk) = run_page(
        FLEET,
        &[
            "fogsim campaign --out fleet --units",
            "fogsim train",
            "fogsim train fleet/u011_* --type type.json",
        ],
        &["type.json", "type.fogm", "u11.fogm", "reg.sqlite"],
    ) else {
        return;
    };
    let unit = walk.output_of("fogsim train fleet/u011_*");
    assert!(unit.contains("unit U11"), "{unit}");
    walk.finish();
}

#[test]
fn the_diagnose_page_runs_as_written() {
    let Some(walk) = run_page(
        DIAGNOSE,
        &["fogsim campaign", "fogsim diagnose", "fogsim import"],
        &["camp.json", "pan/x.json"],
    ) else {
        return;
    };
    for json in ["camp.json", "pan/x.json"] {
        let v: serde_json::Value = serde_json::from_str(&walk.read(json)).unwrap();
        assert!(v["base"]["name"].is_string(), "{json} names no base: {v}");
        assert!(v.get("named_cause").is_some(), "{json}: no named_cause");
    }
    walk.finish();
}

#[test]
#[ignore = "slow suite: docs pages run as written"]
fn the_simulator_page_runs_as_written() {
    let steps = ["fogsim campaign", "fogsim train train"];
    if let Some(walk) = run_page(SIMULATOR, &steps, &["model.bin"]) {
        walk.finish();
    }
}

#[test]
#[ignore = "slow suite: docs pages run as written"]
fn the_trainer_page_runs_as_written() {
    let made = ["model.bin", "train.json"];
    if let Some(walk) = run_page(TRAINER, &["fogsim train train"], &made) {
        walk.finish();
    }
}

#[test]
#[ignore = "slow suite: docs pages run as written"]
fn the_field_guide_runs_as_written_under_qemu() {
    let Some(walk) = run_page(
        FIELD,
        &[
            "cargo fw-run",
            "fogsim rig",
            "fogsim upload",
            "for i in 1 2; do fogsim monitor",
            "fogsim field pull",
            "fogsim train sim-runs --out refined.fogm",
        ],
        &["model.fogm", "refined.fogm", "reg.sqlite"],
    ) else {
        return;
    };
    let pull = walk.output_of("fogsim field pull");
    assert!(
        pull.contains("pulled=2 ") && pull.contains("registry_added=2"),
        "{pull}"
    );
    let refined = walk.output_of("fogsim train sim-runs --out refined.fogm");
    assert!(refined.contains("no test power"), "{refined}");
    assert_eq!(
        std::fs::read(walk.dir.join("refined.fogm")).unwrap(),
        std::fs::read(walk.dir.join("model.fogm")).unwrap(),
        "two seeks of one power-on: no test power, the model unchanged"
    );
    walk.finish();
}

#[test]
fn the_upload_guide_runs_as_written_under_qemu() {
    let Some(walk) = run_page(
        UPLOAD,
        &[
            "fogsim train runs --out model.fogm --gyro-id QEMU-FOG-1",
            "cargo fw-run &",
            "fogsim upload --port tcp:127.0.0.1:4444 model.fogm",
            "fogsim upload --port tcp:127.0.0.1:4444 --status-only",
        ],
        &["model.fogm"],
    ) else {
        return;
    };
    let now = walk.line_of(
        "fogsim upload --port tcp:127.0.0.1:4444 model.fogm",
        "device model now:",
    );
    let now = now.trim_start_matches("device model now:").trim();
    let status = walk.output_of("fogsim upload --port tcp:127.0.0.1:4444 --status-only");
    assert!(
        status.contains(now) && status.contains("gyro QEMU-FOG-1"),
        "the status shows the model just uploaded ({now}):\n{status}"
    );
    walk.finish();
}
