//! Where one long log's runs start: the default split gap from the first rows' spacing,
//! the step that starts a run or is refused, and the splitter that feeds the writer.

use super::super::mapping::TimeUnit;
use super::super::ImportError;
use super::rows::Row;
use super::spec::RunSummary;
use super::writer::RunWriter;
use crate::io::run_format::excerpt;
use crate::io::StagedFiles;

/// Rows whose spacings set a file's sample spacing (the default split gap).
pub const LEAD_ROWS: usize = 65;
/// Smallest default split gap, s: a gyro off for less than a minute has not cooled
/// (thermal time constants of FOG coils are minutes), so it is not a new cold start.
pub const MIN_DEFAULT_GAP_S: f64 = 60.0;
/// Default split gap in median sample spacings.
pub const GAP_SPACINGS: f64 = 10.0;

/// The split gap of a file from its first rows' spacing (see the module doc).
fn gap_from_lead(lead: &[Row]) -> f64 {
    let mut steps: Vec<f64> = lead
        .windows(2)
        .map(|w| w[1].time_s - w[0].time_s)
        .filter(|d| *d > 0.0)
        .collect();
    steps.sort_by(f64::total_cmp);
    let median = steps.get(steps.len() / 2).copied().unwrap_or(0.0);
    (GAP_SPACINGS * median).max(MIN_DEFAULT_GAP_S)
}

/// Whether `row` starts a new run after `prev`, or is refused.
fn starts_run(
    file: &str,
    prev: &Row,
    row: &Row,
    gap_s: f64,
    unit: TimeUnit,
) -> Result<bool, ImportError> {
    let step = row.time_s - prev.time_s;
    if step > gap_s {
        return Ok(true);
    }
    if step > 0.0 {
        return Ok(false);
    }
    if unit != TimeUnit::Iso && -step > gap_s {
        return Ok(true);
    }
    Err(ImportError::at(
        file,
        Some(row.line),
        format!(
            "time `{}` is not after `{}` on line {}: timestamps must increase{}",
            excerpt(&row.time_text),
            excerpt(&prev.time_text),
            prev.line,
            if unit == TimeUnit::Iso {
                ""
            } else {
                " (a clock restart steps back by more than the split gap)"
            }
        ),
    ))
}

/// Decides where runs start and feeds rows to the writer; the first [`LEAD_ROWS`] rows
/// wait until the sample spacing (and so the default split gap) is known.
pub(super) struct Splitter<'a> {
    pub(super) file: &'a str,
    pub(super) unit: TimeUnit,
    pub(super) gap_s: Option<f64>,
    pub(super) lead: Vec<Row>,
    pub(super) prev: Option<Row>,
    pub(super) writer: RunWriter<'a>,
}

impl Splitter<'_> {
    pub(super) fn push(&mut self, row: Row, staged: &mut StagedFiles) -> Result<(), ImportError> {
        match self.gap_s {
            Some(g) if self.lead.is_empty() => self.emit(row, g, staged),
            _ => {
                self.lead.push(row);
                if self.lead.len() == LEAD_ROWS {
                    self.flush_lead(staged)?;
                }
                Ok(())
            }
        }
    }

    fn flush_lead(&mut self, staged: &mut StagedFiles) -> Result<(), ImportError> {
        let g = *self.gap_s.get_or_insert_with(|| gap_from_lead(&self.lead));
        for row in std::mem::take(&mut self.lead) {
            self.emit(row, g, staged)?;
        }
        Ok(())
    }

    fn emit(&mut self, row: Row, gap_s: f64, staged: &mut StagedFiles) -> Result<(), ImportError> {
        let new_run = match &self.prev {
            None => true,
            Some(p) => starts_run(self.file, p, &row, gap_s, self.unit)?,
        };
        if new_run {
            self.writer.start(staged, &row)?;
        }
        self.writer.push(&row)?;
        self.prev = Some(row);
        Ok(())
    }

    /// Ends the file: the runs written and the split gap used.
    pub(super) fn finish(
        mut self,
        staged: &mut StagedFiles,
    ) -> Result<(Vec<RunSummary>, f64), ImportError> {
        self.flush_lead(staged)?;
        if self.prev.is_none() {
            return Err(ImportError::at(self.file, None, "no data rows"));
        }
        self.writer.finish()?;
        Ok((self.writer.runs, self.gap_s.unwrap_or(0.0)))
    }
}
