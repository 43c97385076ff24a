//! `fogsim campaign --logger-csv`: the campaign's runs as one lab logger's log (semicolon,
//! decimal comma, ISO 8601 time, deg/s, degF, 4 h off between power-ons), the input
//! docs/workflow.md imports. Checked as a user runs it: `fogsim import` of that log with
//! its units gives back every run of the campaign, row for row, within the logged
//! digits; and a log path that cannot be a file is refused by its flag, nothing written.

use crate::app_support;

use app_support::{fogsim, scratch_dir, stderr};
use fog_sim::io::runs::read_runs;

#[test]
fn the_logged_campaign_imports_back_to_its_runs() {
    let dir = scratch_dir("campaign_logger_csv");
    let o = fogsim(
        &dir,
        &[
            "campaign",
            "--out",
            "sim",
            "--ambient",
            "10,30",
            "--runs",
            "2",
            "--minutes",
            "20",
            "--raw-rate-hz",
            "10",
            "--seed",
            "5",
            "--logger-csv",
            "log.csv",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(dir.join("log.csv")).unwrap();
    assert!(
        text.starts_with("timestamp;rate_dps;coil_temp_f\n"),
        "{text:.200}"
    );
    assert!(text
        .lines()
        .nth(1)
        .unwrap()
        .starts_with("2026-01-05T08:00:10,000Z;"));
    let o = fogsim(
        &dir,
        &[
            "import",
            "log.csv",
            "--out",
            "imported",
            "--time",
            "timestamp:iso",
            "--rate",
            "rate_dps:dps",
            "--temp",
            "coil_temp_f:f",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let said = String::from_utf8_lossy(&o.stdout);
    assert!(
        said.contains("semicolon-delimited, decimal comma"),
        "{said}"
    );
    let mut sim = read_runs(&[dir.join("sim")]).unwrap();
    sim.sort_by(|a, b| a.path.cmp(&b.path));
    let imported = read_runs(&[dir.join("imported")]).unwrap();
    assert_eq!(imported.len(), sim.len(), "{said}");
    // The log holds the runs in campaign order; the import names them in log order.
    for (s, i) in sim.iter().zip(&imported) {
        let col = |r: &fog_sim::io::Run, n: &str| r.column(n).unwrap().to_vec();
        let (st, it) = (col(s, "t_s"), col(i, "t_s"));
        assert_eq!(st.len(), it.len(), "{}", i.path.display());
        for k in 0..st.len() {
            // Power-on is the first logged row (the first 10 s mean).
            assert!((it[k] - (st[k] - st[0])).abs() < 1e-9);
            let (sr, ir) = (col(s, "rate_dph")[k], col(i, "rate_dph")[k]);
            assert!((sr - ir).abs() <= 0.5e-10 * 3600.0 + 1e-9, "{sr} {ir}");
            let (sc, ic) = (col(s, "temp_c")[k], col(i, "temp_c")[k]);
            assert!((sc - ic).abs() <= 0.5e-5 * 5.0 / 9.0 + 1e-9, "{sc} {ic}");
        }
    }
    // A directory as the log: refused by its flag before anything is simulated.
    let o = fogsim(
        &dir,
        &[
            "campaign",
            "--out",
            "sim2",
            "--runs",
            "1",
            "--minutes",
            "1",
            "--logger-csv",
            ".",
        ],
    );
    assert!(!o.status.success());
    assert!(stderr(&o).contains("--logger-csv"), "{}", stderr(&o));
    assert!(!dir.join("sim2").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
