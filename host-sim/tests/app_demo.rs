//! `fogsim demo` whole, as the README gives it (no flags, in a fresh directory), run twice:
//! the first run learns the fleet's type and the 96-run model and keeps them in
//! `out/demo/`; the second reads them back and must give the same report and recipe
//! figures byte for byte, so the cache can never change what the demo says. The plots at
//! the top of `out/demo/` must be the recommended model's (the one validation chose), with
//! the paper's inputs beside it in its own folder.

use crate::app_support;

use std::path::Path;

use app_support::{fogsim, scratch_dir, stderr};
use serde_json::Value;

/// Every file the demo promises (README, "The two commands"), besides the kept type and
/// 96-run model whose names carry the cache key.
const FILES: &[&str] = &[
    "report.json",
    "recipes.json",
    "model_t_rate.bin",
    "model_t_rate_accel.bin",
    "startup_before.svg",
    "startup_after.svg",
    "azimuth_scatter.svg",
    "temperature.svg",
    "allan.svg",
    "model_paper/startup_after.svg",
    "model_paper/azimuth_scatter.svg",
    "model_extended/startup_after.svg",
    "model_extended/azimuth_scatter.svg",
];

fn read(dir: &Path, name: &str) -> Vec<u8> {
    std::fs::read(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The demo's stdout without the lines that may differ between a first and a later run:
/// the elapsed time, and whether the type was learnt or read back.
fn steady_lines(stdout: &[u8]) -> Vec<String> {
    String::from_utf8_lossy(stdout)
        .lines()
        .filter(|l| !l.contains(" written to ") && !l.starts_with("production recipe:"))
        .map(str::to_owned)
        .collect()
}

#[test]
fn demo_runs_whole_and_its_cache_changes_nothing() {
    let dir = scratch_dir("demo");
    let first = fogsim(&dir, &["demo"]);
    assert!(first.status.success(), "{}", stderr(&first));
    let text = String::from_utf8_lossy(&first.stdout);
    for section in [
        "held-out drift of 10 s means",
        "north seek at 20 degC",
        "paper vs this project",
        "production recipe",
        "6 own runs + type of 10 units",
        "96 own runs at the seek's ambient",
    ] {
        assert!(text.contains(section), "no {section:?} in:\n{text}");
    }
    let out = dir.join("out/demo");
    for f in FILES {
        assert!(!read(&out, f).is_empty(), "{f} is empty");
    }
    let kept: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("fleet-type-") || n.starts_with("unit-96-runs-"))
        .collect();
    assert_eq!(kept.len(), 2, "the kept type and 96-run model: {kept:?}");
    // The pictures at the top are the recommended model's, not the paper inputs'.
    for plot in ["startup_after.svg", "azimuth_scatter.svg"] {
        assert_eq!(
            read(&out, plot),
            read(&out, &format!("model_extended/{plot}")),
            "{plot}"
        );
        assert_ne!(read(&out, plot), read(&out, &format!("model_paper/{plot}")));
    }
    let recipes: Value = serde_json::from_slice(&read(&out, "recipes.json")).unwrap();
    let rows = recipes["rows"].as_array().expect("recipes.json: rows");
    assert_eq!(rows.len(), 3, "{recipes}");
    let report = read(&out, "report.json");
    let recipe_bytes = read(&out, "recipes.json");

    let second = fogsim(&dir, &["demo"]);
    assert!(second.status.success(), "{}", stderr(&second));
    assert!(
        String::from_utf8_lossy(&second.stdout).contains("(kept type "),
        "the second run reads the kept type back"
    );
    assert_eq!(read(&out, "report.json"), report, "report.json changed");
    assert_eq!(
        read(&out, "recipes.json"),
        recipe_bytes,
        "recipes.json changed"
    );
    assert_eq!(steady_lines(&second.stdout), steady_lines(&first.stdout));
}
