//! fog-runs v1 reader/writer: round trip, accessors, and every rejection case
//! (each must name the file, the line and, where one applies, the column).

use fog_sim::io::runs::{parse_run, read_run, read_runs, write_run, Run, RunErrorKind};
use std::path::{Path, PathBuf};

const GOOD: &str = "# fog-runs v1
# gyro: 008
# latitude_deg: 39.9
# ambient_c: 20.0
t_s,rate_dph,temp_c,earth_dph,heading_deg,supply_v
10.0,0.1234,20.51,9.7012,0.0,24.01
20.0,0.1187,20.63,9.7012,0.0,24.02
";

fn scratch_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("fog_sim_runs_{tag}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn reject(text: &str) -> fog_sim::io::runs::RunError {
    parse_run(Path::new("bad.csv"), text).expect_err("must be rejected")
}

#[test]
fn parses_the_format_example() {
    let run = parse_run(Path::new("x.csv"), GOOD).unwrap();
    assert_eq!(run.len(), 2);
    assert_eq!(run.t_s(), &[10.0, 20.0]);
    assert_eq!(run.rate_dph(), &[0.1234, 0.1187]);
    assert_eq!(run.temp_c(), &[20.51, 20.63]);
    assert_eq!(run.earth_dph(), vec![9.7012, 9.7012]);
    assert!((run.drift_dph()[0] - (0.1234 - 9.7012)).abs() < 1e-12);
    assert_eq!(run.latitude_deg(), Some(39.9));
    assert_eq!(run.ambient_c(), Some(20.0));
    assert_eq!(run.meta_value("gyro"), Some("008"));
    let extra: Vec<&str> = run.extra_columns().map(|(n, _)| n).collect();
    assert_eq!(extra, ["earth_dph", "heading_deg", "supply_v"]);
    assert_eq!(run.column("supply_v"), Some(&[24.01, 24.02][..]));
    assert!((run.sample_period_s() - 10.0).abs() < 1e-12);
}

#[test]
fn earth_rate_from_metadata_else_zero() {
    let with_meta = "# fog-runs v1\n# earth_dph: 5.5\nt_s,rate_dph,temp_c\n1,6,20\n2,6.5,20\n";
    let run = parse_run(Path::new("m.csv"), with_meta).unwrap();
    assert_eq!(run.earth_dph(), vec![5.5, 5.5]);
    assert_eq!(run.drift_dph(), vec![0.5, 1.0]);
    let none = "# fog-runs v1\ntemp_c,t_s,rate_dph\n20,1,6\n";
    let run = parse_run(Path::new("n.csv"), none).unwrap();
    assert_eq!(run.earth_dph(), vec![0.0]);
    assert_eq!(run.latitude_deg(), None);
    assert_eq!(run.rate_dph(), &[6.0]);
}

#[test]
fn write_then_read_is_identical_and_atomic() {
    let dir = scratch_dir("rt");
    let mut run = parse_run(Path::new("x.csv"), GOOD).unwrap();
    run.data[1][0] = 0.1 + 0.2; // needs all 17 digits to round-trip
    let path = dir.join("r.csv");
    write_run(&path, &run).unwrap();
    let back = read_run(&path).unwrap();
    assert_eq!(back.data, run.data);
    assert_eq!(back.meta, run.meta);
    assert_eq!(back.columns, run.columns);
    // No temporary file is left behind.
    let names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 1, "{names:?}");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn write_rejects_an_invalid_run_and_leaves_nothing() {
    let dir = scratch_dir("wbad");
    let run = Run {
        path: PathBuf::new(),
        meta: vec![],
        columns: vec!["t_s".into(), "rate_dph".into(), "temp_c".into()],
        data: vec![vec![1.0, 1.0], vec![0.0, 0.0], vec![20.0, 20.0]],
    };
    let path = dir.join("r.csv");
    let e = write_run(&path, &run).unwrap_err();
    assert!(
        matches!(e.kind, RunErrorKind::TimeNotIncreasing { .. }),
        "{e}"
    );
    assert!(e.to_string().contains("r.csv"), "{e}");
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn reads_directories_in_name_order() {
    let dir = scratch_dir("dir");
    let base = parse_run(Path::new("x.csv"), GOOD).unwrap();
    for (name, tag) in [("b.csv", "B"), ("a.csv", "A"), ("c.csv", "C")] {
        let mut r = base.clone();
        r.set_meta("tag", tag);
        write_run(dir.join(name), &r).unwrap();
    }
    std::fs::write(dir.join("notes.txt"), "not a run").unwrap();
    let runs = read_runs(&[&dir]).unwrap();
    let tags: Vec<_> = runs.iter().map(|r| r.meta_value("tag").unwrap()).collect();
    assert_eq!(tags, ["A", "B", "C"]);
    // One bad file rejects the whole call.
    std::fs::write(
        dir.join("d.csv"),
        "# fog-runs v1\nt_s,rate_dph,temp_c\n1,x,2\n",
    )
    .unwrap();
    let e = read_runs(&[&dir]).unwrap_err();
    assert!(e.path.ends_with("d.csv") && e.line == Some(3), "{e}");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn rejects_missing_file_and_empty_directory() {
    let dir = scratch_dir("empty");
    let e = read_runs(&[&dir]).unwrap_err();
    assert_eq!(e.kind, RunErrorKind::EmptyDirectory);
    let e = read_run(dir.join("nope.csv")).unwrap_err();
    assert!(
        matches!(e.kind, RunErrorKind::Io(_)) && e.to_string().contains("nope.csv"),
        "{e}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn rejects_wrong_or_missing_format_line() {
    let e = reject("t_s,rate_dph,temp_c\n1,2,3\n");
    assert_eq!((e.kind, e.line), (RunErrorKind::NotFogRuns, Some(1)));
    let e = reject("");
    assert_eq!(e.kind, RunErrorKind::NotFogRuns);
    let e = reject("# fog-runs v2\nt_s,rate_dph,temp_c\n1,2,3\n");
    assert!(matches!(e.kind, RunErrorKind::UnsupportedVersion(_)), "{e}");
}

#[test]
fn rejects_bad_metadata() {
    let e = reject("# fog-runs v1\n# just a comment\nt_s,rate_dph,temp_c\n1,2,3\n");
    assert_eq!((e.kind, e.line), (RunErrorKind::BadMetadata, Some(2)));
    let e = reject("# fog-runs v1\n# a: 1\n# a: 2\nt_s,rate_dph,temp_c\n1,2,3\n");
    assert_eq!(e.line, Some(3));
    assert!(matches!(e.kind, RunErrorKind::DuplicateMetadata(_)));
    let e = reject("# fog-runs v1\n# earth_dph: lots\nt_s,rate_dph,temp_c\n1,2,3\n");
    assert!(
        matches!(e.kind, RunErrorKind::BadMetadataValue(_)) && e.line == Some(2),
        "{e}"
    );
}

#[test]
fn rejects_header_problems() {
    let e = reject("# fog-runs v1\n# a: 1\n");
    assert_eq!(e.kind, RunErrorKind::MissingHeader);
    let e = reject("# fog-runs v1\nt_s,rate_dph\n1,2\n");
    assert_eq!(
        (e.kind, e.line, e.column.as_deref()),
        (RunErrorKind::MissingColumn, Some(2), Some("temp_c"))
    );
    let e = reject("# fog-runs v1\nt_s,rate_dph,temp_c,t_s\n1,2,3,1\n");
    assert_eq!(
        (e.kind, e.column.as_deref()),
        (RunErrorKind::DuplicateColumn, Some("t_s"))
    );
    let e = reject("# fog-runs v1\nt_s,,rate_dph,temp_c\n1,2,3,4\n");
    assert_eq!(e.kind, RunErrorKind::EmptyColumnName);
}

#[test]
fn rejects_bad_cells_with_line_and_column() {
    let e = reject("# fog-runs v1\nt_s,rate_dph,temp_c\n1,2,3\n2,abc,3\n");
    assert_eq!((e.line, e.column.as_deref()), (Some(4), Some("rate_dph")));
    assert!(matches!(e.kind, RunErrorKind::NotNumeric(_)));
    let msg = e.to_string();
    assert!(
        msg.contains("bad.csv:4") && msg.contains("rate_dph") && msg.contains("abc"),
        "{msg}"
    );
    let e = reject("# fog-runs v1\nt_s,rate_dph,temp_c\n1,2,NaN\n");
    assert_eq!(
        (e.kind, e.line, e.column.as_deref()),
        (RunErrorKind::NotFinite, Some(3), Some("temp_c"))
    );
    let e = reject("# fog-runs v1\nt_s,rate_dph,temp_c\n1,inf,3\n");
    assert_eq!(e.kind, RunErrorKind::NotFinite);
    let e = reject("# fog-runs v1\nt_s,rate_dph,temp_c\n1,2,\n");
    assert!(matches!(e.kind, RunErrorKind::NotNumeric(_)) && e.column.as_deref() == Some("temp_c"));
}

#[test]
fn rejects_ragged_rows_and_comments_in_data() {
    let e = reject("# fog-runs v1\nt_s,rate_dph,temp_c\n1,2,3\n2,3\n");
    assert_eq!(
        (e.kind, e.line),
        (
            RunErrorKind::RaggedRow {
                expected: 3,
                found: 2
            },
            Some(4)
        )
    );
    let e = reject("# fog-runs v1\nt_s,rate_dph,temp_c\n1,2,3,4\n");
    assert!(matches!(e.kind, RunErrorKind::RaggedRow { found: 4, .. }));
    let e = reject("# fog-runs v1\nt_s,rate_dph,temp_c\n1,2,3\n# late: 1\n");
    assert_eq!(
        (e.kind, e.line),
        (RunErrorKind::CommentAfterHeader, Some(4))
    );
}

#[test]
fn rejects_non_increasing_time_and_empty_data() {
    let e = reject("# fog-runs v1\nt_s,rate_dph,temp_c\n1,2,3\n\n2,2,3\n2,2,3\n");
    assert_eq!((e.line, e.column.as_deref()), (Some(6), Some("t_s")));
    assert!(matches!(e.kind, RunErrorKind::TimeNotIncreasing { .. }));
    let e = reject("# fog-runs v1\nt_s,rate_dph,temp_c\n5,2,3\n4,2,3\n");
    assert_eq!(e.line, Some(4));
    let e = reject("# fog-runs v1\nt_s,rate_dph,temp_c\n");
    assert_eq!((e.kind, e.line), (RunErrorKind::NoRows, Some(2)));
}

#[test]
fn accepts_crlf_and_blank_lines() {
    let text = GOOD.replace('\n', "\r\n") + "\r\n";
    let run = parse_run(Path::new("w.csv"), &text).unwrap();
    assert_eq!(run.len(), 2);
    assert_eq!(run.column("supply_v").unwrap()[1], 24.02);
}

#[test]
fn in_memory_construction_is_validated() {
    let cols = |t: Vec<f64>| {
        vec![
            ("t_s".to_string(), t),
            ("rate_dph".into(), vec![0.0, 0.0]),
            ("temp_c".into(), vec![1.0, 2.0]),
        ]
    };
    assert!(Run::new("m.csv", vec![], cols(vec![0.0, 10.0])).is_ok());
    let e = Run::new("m.csv", vec![], cols(vec![0.0])).unwrap_err();
    assert_eq!(e.kind, RunErrorKind::ShapeMismatch);
    let e = Run::new(
        "m.csv",
        vec![("k".into(), "a\nb".into())],
        cols(vec![0.0, 1.0]),
    )
    .unwrap_err();
    assert_eq!(e.kind, RunErrorKind::BadMetadata);
}
