//! A log's columns and rows: the header's names -> the positions of the mapped columns,
//! and each data line -> one row of time and values in fog-runs units.

use super::super::dialect::Dialect;
use super::super::mapping::{fog_runs_name, Heading};
use super::super::timestamp::{parse_iso, Instant};
use super::super::ImportError;
use super::spec::LoggerSpec;
use crate::io::run_format::check_value;
use crate::io::run_format::excerpt;

/// Column positions of one file.
pub(super) struct Columns {
    count: usize,
    time: usize,
    rate: usize,
    temp: usize,
    heading: Option<usize>,
    /// (position, fog-runs name).
    keep: Vec<(usize, String)>,
}

/// The fog-runs header of every run: t_s, rate_dph, temp_c, [heading_deg], kept columns.
pub(super) fn output_columns(cols: &Columns, heading: &Heading) -> Vec<String> {
    let mut names: Vec<String> = ["t_s", "rate_dph", "temp_c"].map(String::from).to_vec();
    if !matches!(heading, Heading::Unknown) {
        names.push("heading_deg".into());
    }
    names.extend(cols.keep.iter().map(|(_, n)| n.clone()));
    names
}

pub(super) fn resolve(
    file: &str,
    line: usize,
    header: &[String],
    spec: &LoggerSpec,
) -> Result<Columns, ImportError> {
    let find = |name: &str, flag: &str| {
        header.iter().position(|h| h == name).ok_or_else(|| {
            ImportError::at(
                file,
                Some(line),
                format!(
                    "{flag}: no column `{}` (columns: {})",
                    excerpt(name),
                    excerpt(&header.join(", "))
                ),
            )
        })
    };
    let heading = match &spec.heading {
        Heading::Column(c) => Some(find(c, "--heading-col")?),
        _ => None,
    };
    let mut keep = Vec::new();
    let mut taken: Vec<String> = ["t_s", "rate_dph", "temp_c", "heading_deg"]
        .map(String::from)
        .to_vec();
    for k in &spec.keep {
        let name = fog_runs_name(k);
        if taken.contains(&name) {
            return Err(ImportError::at(
                file,
                Some(line),
                format!(
                    "--keep {}: its fog-runs name `{name}` is already taken",
                    excerpt(k)
                ),
            ));
        }
        taken.push(name.clone());
        keep.push((find(k, "--keep")?, name));
    }
    Ok(Columns {
        count: header.len(),
        time: find(&spec.time.column, "--time")?,
        rate: find(&spec.rate.column, "--rate")?,
        temp: find(&spec.temp.column, "--temp")?,
        heading,
        keep,
    })
}

/// One parsed row: its time, s from the file's first row, and the output values.
pub(super) struct Row {
    pub(super) line: usize,
    pub(super) time_s: f64,
    pub(super) time_text: String,
    pub(super) values: Vec<f64>,
}

/// Reads one data row into fog-runs units.
pub(super) struct RowParser<'a> {
    pub(super) file: &'a str,
    pub(super) spec: &'a LoggerSpec,
    pub(super) cols: Columns,
    pub(super) out_names: Vec<String>,
    pub(super) dialect: Dialect,
    pub(super) origin: Option<Instant>,
}

impl RowParser<'_> {
    pub(super) fn parse(&mut self, line: usize, cells: &[String]) -> Result<Row, ImportError> {
        let fail = |what: String| ImportError::at(self.file, Some(line), what);
        if cells.len() != self.cols.count {
            return Err(fail(format!(
                "{} cells, the header has {}",
                cells.len(),
                self.cols.count
            )));
        }
        let cell_name = |i: usize| match &self.spec.columns {
            Some(c) => c[i].clone(),
            None => format!("{}", i + 1),
        };
        let number = |i: usize| {
            self.dialect.number(&cells[i]).ok_or_else(|| {
                fail(format!(
                    "column {} (`{}`): `{}` is not a number ({})",
                    i + 1,
                    excerpt(&cell_name(i)),
                    excerpt(&cells[i]),
                    self.dialect
                ))
            })
        };
        let t = self.cols.time;
        let time_s = match self.spec.time.unit.seconds_per_unit() {
            Some(per) => number(t)? * per,
            None => {
                let at =
                    parse_iso(&cells[t]).map_err(|e| fail(format!("column {}: {e}", t + 1)))?;
                at.since(*self.origin.get_or_insert(at))
            }
        };
        if !time_s.is_finite() {
            return Err(fail(format!(
                "column {}: time `{}` is not finite",
                t + 1,
                excerpt(&cells[t])
            )));
        }
        let mut values = vec![
            0.0,
            self.spec.rate.to_dph(number(self.cols.rate)?),
            self.spec.temp.to_c(number(self.cols.temp)?),
        ];
        let mut sources = vec![t, self.cols.rate, self.cols.temp];
        match (&self.spec.heading, self.cols.heading) {
            (_, Some(h)) => {
                values.push(number(h)?);
                sources.push(h);
            }
            (Heading::Fixed(deg), None) => {
                values.push(*deg);
                sources.push(usize::MAX);
            }
            _ => {}
        }
        for (k, _) in &self.cols.keep {
            values.push(number(*k)?);
            sources.push(*k);
        }
        for (i, (&v, name)) in values.iter().zip(&self.out_names).enumerate().skip(1) {
            if let Err(kind) = check_value(name, v) {
                let src = sources[i];
                let cell = cells
                    .get(src)
                    .map_or(String::new(), |c| format!(" (`{}`)", excerpt(c)));
                return Err(fail(format!(
                    "column {}{cell} as {name}: {}",
                    src.saturating_add(1),
                    kind
                )));
            }
        }
        Ok(Row {
            line,
            time_s,
            time_text: cells[t].clone(),
            values,
        })
    }
}
