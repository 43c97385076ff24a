//! A small `fogsim reproduce` (two temperatures, four runs each, two cold starts, a
//! qualification campaign of six runs per temperature): the report holds every section
//! for the three models, per-ambient held-out figures, the paper-vs-us table and the plots.

use crate::app_support;

use app_support::{fogsim, scratch_dir, stderr};
use serde_json::Value;

#[test]
fn small_reproduce_writes_report_and_plots() {
    let dir = scratch_dir("reproduce");
    let args = [
        "reproduce",
        "--ambient",
        "0,20",
        "--runs",
        "4",
        "--starts",
        "2",
        "--qualification-runs",
        "6",
        "--json",
        "r.json",
        "--plots",
        "plots",
    ];
    let out = fogsim(&dir, &args);
    assert!(out.status.success(), "{}", stderr(&out));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("paper vs this project"), "{stdout}");
    let json: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("r.json")).unwrap()).unwrap();
    let models = json["models"].as_array().unwrap();
    assert_eq!(
        models.len(),
        3,
        "paper inputs, the global model and the qualification model"
    );
    for m in models {
        let amb = m["per_ambient"].as_array().unwrap();
        assert_eq!(amb.len(), 2);
        for a in amb {
            assert_eq!(a["heldout_runs"].as_u64(), Some(1));
            assert!(
                a["after"]["std_dph"].as_f64().unwrap() < a["before"]["std_dph"].as_f64().unwrap()
            );
        }
        assert_eq!(m["validation"]["runs"].as_array().unwrap().len(), 2);
        assert!(m["training"]["n_centers"].as_u64().unwrap() >= 1);
        assert_eq!(m["north_seek"]["starts"].as_u64(), Some(2));
        assert!(m["targets"]["azimuth_std_over_floor"].as_f64().is_some());
    }
    assert!(json["paper_vs_us"].as_array().unwrap().len() >= 10);
    // The deployable models beside the plots: the ones the report describes (the paper's
    // inputs, then the global model's, chosen by `train`'s defaults and reported).
    assert_eq!(models[0]["model_file"], "model_t_rate.bin");
    assert!(models[0]["input_selection"].is_null());
    let chosen = models[1]["input_selection"]["chosen"].as_str().unwrap();
    assert_eq!(
        models[1]["model_file"].as_str().unwrap(),
        format!("model_{}.bin", chosen.replace(',', "_"))
    );
    for m in models {
        let file = m["model_file"].as_str().unwrap();
        let inputs = m["training"]["inputs"].as_array().unwrap().len();
        let bytes = std::fs::read(dir.join("plots").join(file)).unwrap();
        let model = fog_core::model::format::RbfModel::decode(&bytes).unwrap();
        assert_eq!(model.n_inputs(), inputs, "{file}");
        assert_eq!(
            model.n_centers() as u64,
            m["training"]["n_centers"].as_u64().unwrap(),
            "{file}"
        );
    }
    // The qualification model: `north-seek`'s recipe (the chosen inputs, then the warm-up
    // clock when the runs have one) on its own campaign.
    assert_eq!(models[2]["model_file"], "model_qualification.bin");
    let chosen = models[2]["input_selection"]["chosen"].as_str().unwrap();
    let label = models[2]["label"].as_str().unwrap();
    assert!(label.contains(chosen), "{label}");
    let inputs = models[2]["training"]["inputs"].as_array().unwrap().len();
    assert!(inputs >= chosen.split(',').count(), "{inputs} inputs");
    assert_eq!(
        models[2]["north_seek_other_ambients"]
            .as_array()
            .unwrap()
            .len(),
        2,
        "-40 and +60 degC"
    );
    check_plots(&dir.join("plots"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Every model's plots in its folder, the campaign's at the top, and the top's startup and
/// azimuth plots the recommended model's (the last one, the qualification model here), not
/// the paper inputs'.
fn check_plots(plots: &std::path::Path) {
    for f in [
        "model_paper/startup_after.svg",
        "model_paper/azimuth_scatter.svg",
        "model_extended/startup_after.svg",
        "model_extended/azimuth_scatter.svg",
        "model_qualification/startup_after.svg",
        "model_qualification/azimuth_scatter.svg",
    ] {
        assert!(plots.join(f).exists(), "{f}");
    }
    for f in [
        "startup_before.svg",
        "startup_after.svg",
        "temperature.svg",
        "allan.svg",
        "azimuth_scatter.svg",
    ] {
        let svg = std::fs::read_to_string(plots.join(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
        assert!(svg.contains("</svg>"), "{f}");
    }
    // The pictures at the top are the recommended model's (the last one, the
    // qualification model here), not the paper inputs'.
    let read = |f: &str| std::fs::read(plots.join(f)).unwrap();
    for f in ["startup_after.svg", "azimuth_scatter.svg"] {
        assert!(read(f) == read(&format!("model_qualification/{f}")), "{f}");
        assert!(read(f) != read(&format!("model_paper/{f}")), "{f}");
    }
}
