//! docs/workflow.md, run as written (issue 16.4): every fenced `sh` block of the page, in
//! order, each line one command, by the page runner of `docs_support` (`fogsim` the binary
//! under test, `cargo fw-run -- ARGS` its runner script on the firmware the QEMU tests
//! build, `&` a background job, the ports 4444-4447 free loopback ports, the registry in a
//! scratch `XDG_DATA_HOME`).
//!
//! Checked: every command succeeds, the path's steps all among them (import, train,
//! compensate, heading-cal, upload, rig, monitor, field pull, train --field, registry); the
//! seek's azimuth is within 3 of its reported sigma of the rig's truth and its tilt
//! (measured over the inclinometer link, no `tilt-mdeg=`) within 0.01 deg of the rig's
//! base; the seek's field record pulled and counted by `train --field` (all read from
//! the commands' own output lines); the model carries the heading calibration; the
//! registry shows the upload and the result. Prints the error, sigma and wall time.
//!
//! Skips loudly without QEMU / the target unless FOG_REQUIRE_QEMU=1.

use crate::docs_support::{Page, Walk};

/// The value of `key=` in a `key=value` line.
fn field(line: &str, key: &str) -> f64 {
    line.split_whitespace()
        .find_map(|w| w.strip_prefix(&format!("{key}=")))
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no {key}= in {line:?}"))
}

/// The seek's field record: pulled, then counted by `train --field` as measured under the
/// heading-calibrated variant of the retrained model (the registry knows it); one power-on
/// has no test power, the model is left unchanged.
fn check_field_step(walk: &Walk) {
    let pull = walk.output_of("fogsim field pull");
    assert!(
        pull.contains("pulled=1 ") && pull.contains("registry_added=1"),
        "{pull}"
    );
    let refined = walk.output_of("fogsim train runs --type type.json --out model-field.fogm");
    assert!(
        refined
            .contains("field refinement: 1 field seeks used (1 of them under heading-calibrated")
            && refined.contains("no test power"),
        "{refined}"
    );
    assert_eq!(
        std::fs::read(walk.dir.join("model-field.fogm")).unwrap(),
        std::fs::read(walk.dir.join("model.fogm")).unwrap(),
        "no test power: the model unchanged"
    );
}

#[test]
fn the_workflow_page_runs_as_written_and_finds_north() {
    let page = Page::load("docs/workflow.md");
    page.assert_steps(&[
        "fogsim import",
        "fogsim campaign --out fleet --units",
        "fogsim train fleet --type-out",
        "fogsim train runs --type",
        "fogsim compensate",
        "fogsim heading-cal --from-runs",
        "cargo fw-run",
        "fogsim rig",
        "fogsim upload",
        "fogsim monitor",
        "fogsim field pull",
        "fogsim train runs --type type.json --out model-field.fogm",
        "fogsim registry show",
    ]);
    assert!(
        !page.commands.iter().any(|c| c.contains("tilt-mdeg=")),
        "the walk's tilt comes over the inclinometer link"
    );
    let Some(walk) = page.run() else {
        return;
    };

    let rig = walk.job_log("fogsim rig");
    let truth_line = rig
        .lines()
        .find(|l| l.starts_with("rig truth"))
        .unwrap_or_else(|| panic!("rig output: {rig}"));
    let truth = field(truth_line, "azimuth_deg");
    let result = walk.line_of("fogsim monitor", "result ");
    let (azimuth, sigma) = (field(result, "azimuth_deg"), field(result, "sigma_deg"));
    let err = (azimuth - truth + 540.0).rem_euclid(360.0) - 180.0;
    eprintln!(
        "workflow: azimuth {azimuth:.4} deg, truth {truth:.4}, error {err:+.4} deg, reported sigma {sigma:.4} deg ({:.2} sigma); {} commands, wall {:.1} s",
        err.abs() / sigma,
        page.commands.len(),
        walk.wall_s
    );
    assert!(result.contains("verdict=valid"), "{result}");
    assert!(sigma > 0.0 && err.abs() <= 3.0 * sigma, "{result}");
    for axis in ["pitch_deg", "roll_deg"] {
        let (measured, base) = (field(result, axis), field(truth_line, axis));
        eprintln!("workflow: {axis} {measured} over the inclinometer link, rig base {base}");
        assert!(
            (measured - base).abs() <= 0.01,
            "{axis}: device {measured} over the inclinometer link, rig base {base}"
        );
    }
    assert!(
        walk.output_of("fogsim heading-cal")
            .contains("heading calibration a ="),
        "{}",
        walk.output_of("fogsim heading-cal")
    );
    check_field_step(&walk);
    let show = walk.output_of("fogsim registry show");
    assert!(
        show.contains("committed") && show.contains("seek results: 1"),
        "{show}"
    );
    let csv = walk.read("results.csv");
    assert_eq!(csv.lines().count(), 2, "{csv}");
    walk.finish();
}
