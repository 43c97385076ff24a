//! `fogsim import` of logger CSVs, as a user runs it: each layout a real logger writes is
//! generated from known values (a warm-up drift law in deg/h and degC), imported through
//! the command line, read back as fog-runs and compared with the values it was made from.
//! Also: splitting one long log into power-on runs, and bad input refused whole.

use crate::app_support;

use app_support::{fogsim, scratch_dir, stderr};
use fog_sim::io::runs::{read_run, read_runs};
use std::path::Path;

const DPS: f64 = 3600.0;
const RPS: f64 = 180.0 / std::f64::consts::PI * 3600.0;

/// The truth a log is made from: rows at `period_s` from power-on.
struct Truth {
    t_s: Vec<f64>,
    rate_dph: Vec<f64>,
    temp_c: Vec<f64>,
}

/// A cold start: coil temperature rising towards ambient + 12 degC, drift decaying with a
/// slow wander, plus a constant Earth-rate projection.
fn truth(period_s: f64, minutes: f64, ambient_c: f64) -> Truth {
    let n = (minutes * 60.0 / period_s) as usize;
    let t_s: Vec<f64> = (0..n).map(|k| k as f64 * period_s).collect();
    Truth {
        rate_dph: t_s
            .iter()
            .map(|t| 9.7 + 0.12 * (-t / 900.0).exp() + 0.01 * (t / 97.0).sin())
            .collect(),
        temp_c: t_s
            .iter()
            .map(|t| ambient_c + 12.0 * (1.0 - (-t / 600.0).exp()))
            .collect(),
        t_s,
    }
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

/// Imports with `args` (after the log and `--out`) and returns stdout; panics with stderr.
fn import(dir: &Path, log: &str, out: &str, args: &[&str]) -> String {
    let mut all = vec!["import", log, "--out", out];
    all.extend_from_slice(args);
    let o = fogsim(dir, &all);
    assert!(o.status.success(), "fogsim {all:?}: {}", stderr(&o));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// The one run written to `out` equals the truth within `tol_*`.
fn assert_round_trip(out: &Path, truth: &Truth, tol_rate_dph: f64, tol_temp_c: f64) {
    let runs = read_runs(&[out]).unwrap();
    assert_eq!(runs.len(), 1, "one run");
    let r = &runs[0];
    assert_eq!(r.len(), truth.t_s.len());
    for i in 0..r.len() {
        assert!(
            (r.t_s()[i] - truth.t_s[i]).abs() < 1e-6,
            "t_s row {i}: {} vs {}",
            r.t_s()[i],
            truth.t_s[i]
        );
        assert!(
            (r.rate_dph()[i] - truth.rate_dph[i]).abs() <= tol_rate_dph,
            "rate row {i}: {} vs {}",
            r.rate_dph()[i],
            truth.rate_dph[i]
        );
        assert!(
            (r.temp_c()[i] - truth.temp_c[i]).abs() <= tol_temp_c,
            "temp row {i}: {} vs {}",
            r.temp_c()[i],
            truth.temp_c[i]
        );
    }
}

/// ISO 8601 of `t` s after 2026-03-05 23:59:00 (crossing midnight), with a decimal comma.
fn iso(t: f64) -> String {
    let whole = t.floor() as i64;
    let ms = ((t - t.floor()) * 1000.0).round() as i64;
    let s = 23 * 3600 + 59 * 60 + whole;
    let (day, s) = (5 + s / 86_400, s % 86_400);
    format!(
        "2026-03-{day:02}T{:02}:{:02}:{:02},{ms:03}",
        s / 3600,
        s / 60 % 60,
        s % 60
    )
}

#[test]
fn semicolon_decimal_comma_and_iso_timestamps() {
    let dir = scratch_dir("imp-semicolon");
    let tr = truth(10.0, 45.0, 20.0);
    let mut s = String::from("Zeit;Drehrate [°/h];Temperatur [°C];Versorgung [V]\r\n");
    for i in 0..tr.t_s.len() {
        s += &format!(
            "{};{:.9};{:.6};24,01\r\n",
            iso(tr.t_s[i]),
            tr.rate_dph[i],
            tr.temp_c[i]
        )
        .replace('.', ",");
    }
    let log = write(&dir, "fog_log.csv", &s);
    let out = import(
        &dir,
        &log,
        "runs",
        &[
            "--time",
            "Zeit:iso",
            "--rate",
            "Drehrate [°/h]:dph",
            "--temp",
            "Temperatur [°C]:c",
            "--keep",
            "Versorgung [V]",
            "--gyro-id",
            "FOG-7",
            "--latitude-deg",
            "39.9",
        ],
    );
    assert!(out.contains("semicolon-delimited, decimal comma"), "{out}");
    assert_round_trip(&dir.join("runs"), &tr, 1e-9, 1e-6);
    let r = read_run(dir.join("runs/fog_log_run01.csv")).unwrap();
    assert_eq!(r.column("versorgung_v").unwrap()[0], 24.01);
    assert_eq!(r.meta_value("gyro"), Some("FOG-7"));
    assert_eq!(r.latitude_deg(), Some(39.9));
}

#[test]
fn degrees_per_second_at_one_hertz() {
    let dir = scratch_dir("imp-dps");
    let tr = truth(1.0, 20.0, -10.0);
    let mut s = String::from("time_s,gyro_z_dps,temp_degC\n");
    for i in 0..tr.t_s.len() {
        s += &format!(
            "{},{:e},{}\n",
            1000.0 + tr.t_s[i],
            tr.rate_dph[i] / DPS,
            tr.temp_c[i]
        );
    }
    let log = write(&dir, "dps.csv", &s);
    let out = import(
        &dir,
        &log,
        "runs",
        &[
            "--time",
            "time_s:s",
            "--rate",
            "gyro_z_dps:dps",
            "--temp",
            "temp_degC:c",
        ],
    );
    assert!(out.contains("comma-delimited, decimal point"), "{out}");
    assert!(out.contains("(1200 rows"), "{out}");
    assert_round_trip(&dir.join("runs"), &tr, 1e-9, 1e-9);
}

#[test]
fn radians_per_second_tab_separated_milliseconds() {
    let dir = scratch_dir("imp-rps");
    let tr = truth(10.0, 45.0, 40.0);
    let mut s = String::from("ms\twz [rad/s]\tT\n");
    for i in 0..tr.t_s.len() {
        s += &format!(
            "{}\t{:e}\t{}\n",
            (tr.t_s[i] * 1000.0) as u64,
            tr.rate_dph[i] / RPS,
            tr.temp_c[i]
        );
    }
    let log = write(&dir, "rps.tsv", &s);
    let out = import(
        &dir,
        &log,
        "runs",
        &[
            "--time",
            "ms:ms",
            "--rate",
            "wz [rad/s]:rps",
            "--temp",
            "T:c",
        ],
    );
    assert!(out.contains("tab-delimited"), "{out}");
    assert_round_trip(&dir.join("runs"), &tr, 1e-9, 1e-9);
}

#[test]
fn fahrenheit_and_microseconds() {
    let dir = scratch_dir("imp-degf");
    let tr = truth(10.0, 45.0, 0.0);
    let mut s = String::from("t_us,rate,coil_F\n");
    for i in 0..tr.t_s.len() {
        s += &format!(
            "{},{},{}\n",
            (tr.t_s[i] * 1e6) as u64,
            tr.rate_dph[i],
            tr.temp_c[i] * 9.0 / 5.0 + 32.0
        );
    }
    let log = write(&dir, "degf.csv", &s);
    import(
        &dir,
        &log,
        "runs",
        &[
            "--time", "t_us:us", "--rate", "rate:dph", "--temp", "coil_F:f",
        ],
    );
    assert_round_trip(&dir.join("runs"), &tr, 1e-12, 1e-9);
}

#[test]
fn counts_with_a_scale_and_kelvin() {
    let dir = scratch_dir("imp-counts");
    let mut tr = truth(10.0, 45.0, 20.0);
    // The logger writes integer counts of 1e-6 deg/s: the truth is what counts can say.
    let counts: Vec<i64> = tr
        .rate_dph
        .iter()
        .map(|r| (r / DPS * 1e6).round() as i64)
        .collect();
    tr.rate_dph = counts.iter().map(|&c| c as f64 * 1e-6 * DPS).collect();
    let mut s = String::from("sec;cnt;kelvin\n");
    for (i, count) in counts.iter().enumerate() {
        s += &format!("{};{count};{}\n", tr.t_s[i], tr.temp_c[i] + 273.15);
    }
    let log = write(&dir, "counts.csv", &s);
    let out = import(
        &dir,
        &log,
        "runs",
        &[
            "--time",
            "sec",
            "--rate",
            "cnt:dps*1e-6",
            "--temp",
            "kelvin:k",
        ],
    );
    assert!(out.contains("semicolon-delimited, decimal point"), "{out}");
    assert_round_trip(&dir.join("runs"), &tr, 1e-9, 1e-9);
}

#[test]
fn header_less_file_with_named_columns() {
    let dir = scratch_dir("imp-noheader");
    let tr = truth(10.0, 45.0, 60.0);
    let mut s = String::new();
    for i in 0..tr.t_s.len() {
        s += &format!(
            "{},{},{},{}\n",
            tr.t_s[i], 5.0, tr.rate_dph[i], tr.temp_c[i]
        );
    }
    let log = write(&dir, "raw.txt", &s);
    let out = import(
        &dir,
        &log,
        "runs",
        &[
            "--columns",
            "t,volts,w,temp",
            "--time",
            "t",
            "--rate",
            "w:dph",
            "--temp",
            "temp:c",
            "--heading-deg",
            "90",
        ],
    );
    assert!(out.contains("no header (--columns)"), "{out}");
    assert_round_trip(&dir.join("runs"), &tr, 1e-12, 1e-12);
    let r = read_run(dir.join("runs/raw_run01.csv")).unwrap();
    assert!(r.column("heading_deg").unwrap().iter().all(|&h| h == 90.0));
    // The same file without --columns: its first line is taken as the header and the
    // mapping names columns it does not have.
    let o = fogsim(
        &dir,
        &[
            "import", &log, "--out", "runs2", "--time", "t", "--rate", "w:dph", "--temp", "temp:c",
        ],
    );
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("raw.txt:1: --time: no column `t`"),
        "{}",
        stderr(&o)
    );
}

/// One long log: two power-ons with the gyro off for 20 min in between (wall clock), and
/// a clock that restarts at power-on (time since power-on): both split into runs whose
/// t_s starts at 0.
#[test]
fn a_long_log_splits_at_power_on_gaps_and_clock_restarts() {
    let dir = scratch_dir("imp-split");
    let a = truth(10.0, 30.0, 20.0);
    let mut s = String::from("t;rate;temp\n");
    let mut restart = String::from("t;rate;temp\n");
    for (offset, tr) in [(0.0, &a), (1800.0 + 1200.0, &a)] {
        for i in 0..tr.t_s.len() {
            s += &format!(
                "{};{};{}\n",
                offset + tr.t_s[i],
                tr.rate_dph[i],
                tr.temp_c[i]
            );
            restart += &format!("{};{};{}\n", 5.0 + tr.t_s[i], tr.rate_dph[i], tr.temp_c[i]);
        }
    }
    let gap = write(&dir, "gap.csv", &s);
    let rs = write(&dir, "restart.csv", &restart);
    let out = import(
        &dir,
        &gap,
        "runs",
        &["--time", "t", "--rate", "rate:dph", "--temp", "temp:c"],
    );
    assert!(out.contains("split gap 100 s (10 sample spacings"), "{out}");
    let out2 = import(
        &dir,
        &rs,
        "runs",
        &[
            "--time",
            "t",
            "--rate",
            "rate:dph",
            "--temp",
            "temp:c",
            "--split-gap-s",
            "120",
        ],
    );
    assert!(out2.contains("2 run(s)"), "{out2}");
    let runs = read_runs(&[dir.join("runs")]).unwrap();
    assert_eq!(runs.len(), 4);
    for r in &runs {
        assert_eq!(r.len(), a.t_s.len());
        assert_eq!(r.t_s()[0], 0.0);
        assert_eq!(r.t_s(), &a.t_s[..]);
        assert_eq!(r.rate_dph(), &a.rate_dph[..]);
    }
}

/// Bad input: one line naming file, line and column, and nothing written (not even the
/// runs of an earlier, good log of the same command).
#[test]
fn bad_logs_are_refused_whole_with_the_line() {
    let dir = scratch_dir("imp-bad");
    let good = write(&dir, "good.csv", "t,r,T\n0,1,20\n10,1,20\n");
    let cases: [(&str, &str, &str); 7] = [
        ("back.csv", "t,r,T\n0,1,20\n10,1,20\n9.5,1,20\n", "back.csv:4: time `9.5` is not after `10` on line 3"),
        ("cell.csv", "t,r,T\n0,1,20\n10,x1,20\n", "cell.csv:3: column 2 (`2`): `x1` is not a number"),
        ("inf.csv", "t,r,T\n0,1,20\n10,1,1e400\n", "inf.csv:3: column 3 (`1e400`) as temp_c: value is NaN or infinite"),
        ("cold.csv", "t,r,T\n0,1,20\n10,1,-300\n", "cold.csv:3: column 3 (`-300`) as temp_c: value -3e2 is outside the physical range [-2.7315e2, 1e3]"),
        ("hot.csv", "t,r,T\n0,1,20\n10,1,1e300\n", "hot.csv:3: column 3 (`1e300`) as temp_c: value 1e300 is outside"),
        ("ragged.csv", "t,r,T\n0,1,20\n10,1\n", "ragged.csv:3: 2 cells, the header has 3"),
        ("utf16.csv", "\u{feff}", ""),
    ];
    for (name, text, want) in cases {
        let bad = if name == "utf16.csv" {
            let p = dir.join(name);
            std::fs::write(&p, b"\xFF\xFEt\x00,\x00").unwrap();
            p.display().to_string()
        } else {
            write(&dir, name, text)
        };
        let o = fogsim(
            &dir,
            &[
                "import", &good, &bad, "--out", "runs", "--time", "t", "--rate", "r:dph", "--temp",
                "T:c",
            ],
        );
        let err = stderr(&o);
        assert!(!o.status.success(), "{name} accepted");
        assert_eq!(err.lines().count(), 1, "{name}: one line: {err}");
        assert!(err.contains(want), "{name}: {err}");
        assert!(err.len() < 400, "{name}: short: {err}");
        if name == "utf16.csv" {
            assert!(err.contains("UTF-16LE byte-order mark (BOM)"), "{err}");
        }
        let left: Vec<_> = std::fs::read_dir(dir.join("runs")).unwrap().collect();
        assert!(left.is_empty(), "{name}: nothing written, found {left:?}");
    }
    // An equal timestamp is not an increase either; a UTF-8 BOM is skipped and said.
    let bom = write(&dir, "bom.csv", "\u{feff}t,r,T\n0,1,20\n10,1,20\n");
    let out = import(
        &dir,
        &bom,
        "runs",
        &["--time", "t", "--rate", "r:dph", "--temp", "T:c"],
    );
    assert!(out.contains("UTF-8 byte-order mark (BOM) skipped"), "{out}");
    // The rate unit is never guessed.
    let o = fogsim(
        &dir,
        &[
            "import", &good, "--out", "runs3", "--time", "t", "--rate", "r", "--temp", "T:c",
        ],
    );
    assert!(stderr(&o).contains("give the unit"), "{}", stderr(&o));
}
