//! `fogsim allan` end to end on 1 Hz rows of the simulated gyro (two warm 8 h runs, each
//! its own segment): the ARW and bias instability come back near the simulator's, the
//! JSON and the plot are written; bad input gets one error line and no output.

use crate::app_support;

use app_support::{fogsim, scratch_dir, stderr};
use fog_sim::sim::{GyroParams, RunSpec, SimGyro, StartState};
use std::fmt::Write;
use std::path::Path;

/// Writes a warm 1 Hz run of `hours` as fog-runs v1 (t_s, rate_dph, temp_c, earth_dph).
fn write_1hz_run(path: &Path, seed: u64, hours: f64) {
    let spec = RunSpec {
        minutes: hours * 60.0,
        raw_rate_hz: 1.0,
        start: StartState::Warm,
        ..RunSpec::paper(20.0, seed)
    };
    let gyro = SimGyro::new(&GyroParams::paper_default(), &spec).unwrap();
    let mut text = String::from("# fog-runs v1\n# ambient_c: 20\nt_s,rate_dph,temp_c,earth_dph\n");
    for s in gyro.take((hours * 3600.0) as usize) {
        let _ = writeln!(
            text,
            "{},{},{:.4},{}",
            s.t_s, s.rate_dph, s.coil_c, s.earth_dph
        );
    }
    std::fs::write(path, text).unwrap();
}

#[test]
fn allan_of_1_hz_rows_gives_the_simulators_noise_terms() {
    let dir = scratch_dir("allan");
    std::fs::create_dir_all(dir.join("runs")).unwrap();
    write_1hz_run(&dir.join("runs/a.csv"), 1, 8.0);
    write_1hz_run(&dir.join("runs/b.csv"), 2, 8.0);
    let out = fogsim(
        &dir,
        &[
            "allan",
            "runs",
            "--json",
            "allan.json",
            "--plot",
            "allan.svg",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    println!("{text}");
    assert!(text.contains("2 segment(s)"), "{text}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("allan.json")).unwrap()).unwrap();
    let term = |t: &str| {
        json["analysis"]["noise"]["terms"]
            .as_array()
            .unwrap()
            .iter()
            .find(|x| x["term"] == t)
            .unwrap()
            .clone()
    };
    let noise = GyroParams::paper_default().noise;
    let n = term("N")["value"].as_f64().unwrap();
    assert!(
        (n / noise.arw_dpsh - 1.0).abs() < 0.05,
        "N {n} vs {}",
        noise.arw_dpsh
    );
    let b = term("B");
    assert!(b["detected"].as_bool().unwrap());
    let b = b["value"].as_f64().unwrap();
    assert!(
        (b / noise.bias_instability_dph - 1.0).abs() < 0.3,
        "B {b} vs {}",
        noise.bias_instability_dph
    );
    let svg = std::fs::read_to_string(dir.join("allan.svg")).unwrap();
    assert!(svg.contains("<svg") && svg.contains("</svg>"));
}

#[test]
fn bad_input_gets_one_line_and_no_output() {
    let dir = scratch_dir("allan-bad");
    let head = "# fog-runs v1\nt_s,rate_dph,temp_c\n";
    let rows = |dt: f64| -> String {
        (1..=100)
            .map(|i| format!("{},{},20\n", i as f64 * dt, (i % 7) as f64 * 0.01))
            .collect()
    };
    std::fs::write(dir.join("one_hz.csv"), format!("{head}{}", rows(1.0))).unwrap();
    std::fs::write(dir.join("ten_s.csv"), format!("{head}{}", rows(10.0))).unwrap();
    let cases: [(&[&str], &str); 4] = [
        (
            &["allan", "one_hz.csv", "ten_s.csv", "--json", "o.json"],
            "ten_s.csv: row spacing 10 s differs",
        ),
        (
            &[
                "allan",
                "one_hz.csv",
                "--column",
                "pressure",
                "--json",
                "o.json",
            ],
            "no column 'pressure'",
        ),
        (&["allan", "one_hz.csv", "--json", "one_hz.csv"], "--json"),
        (
            &["allan", "one_hz.csv", "--kind", "xdev", "--json", "o.json"],
            "xdev",
        ),
    ];
    for (args, needle) in cases {
        let out = fogsim(&dir, args);
        let err = stderr(&out);
        assert!(
            !out.status.success() && !err.contains("panicked"),
            "{args:?}: {err}"
        );
        let line = err
            .lines()
            .find(|l| l.contains("error"))
            .unwrap_or_default();
        assert!(line.contains(needle), "{args:?}: {err}");
        assert!(!dir.join("o.json").exists(), "{args:?} wrote output");
    }
    let kept = std::fs::read_to_string(dir.join("one_hz.csv")).unwrap();
    assert!(kept.starts_with(head), "the input is never overwritten");
}
