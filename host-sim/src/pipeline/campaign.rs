//! The paper's test campaign in simulation: at each chamber temperature, several cold
//! power-ons of 45 min, input axis vertical, one fog-runs CSV per power-on. Runs are
//! simulated in parallel (each from its own derived seed, so the bytes never depend
//! on the thread schedule) and written only when all succeeded.

use crate::io::runs::{write_run, Run, RunError};
use crate::sim::{simulate_run, GyroParams, RunSpec, SimError, StartState, DEFAULT_LATITUDE_DEG};
use std::fmt;
use std::path::{Path, PathBuf};

/// The paper's chamber temperatures, degC.
pub const PAPER_AMBIENTS_C: [f64; 11] = [
    -40.0, -30.0, -20.0, -10.0, 0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0,
];
/// Power-ons per temperature in the paper (3 train, 2 validate).
pub const PAPER_RUNS: usize = 5;
/// Record length in the paper, min.
pub const PAPER_MINUTES: f64 = 45.0;

/// Most record time a campaign may hold, s of 1 Hz rows over all its runs: every run is
/// simulated into memory before it is written or trained on. 3e6 s is 1,111 runs of 45
/// min (11 ambients x 96 runs + 5, `reproduce`'s largest qualification campaign with the
/// paper's); `reproduce --starts 2` peaked at 89 MB with 583 such runs.
pub const MAX_CAMPAIGN_RECORD_S: f64 = 3.0e6;

/// What to simulate.
#[derive(Clone, Debug, PartialEq)]
pub struct CampaignSpec {
    pub ambients_c: Vec<f64>,
    pub runs_per_ambient: usize,
    pub minutes: f64,
    pub seed: u64,
    pub latitude_deg: f64,
    pub raw_rate_hz: f64,
    /// Warm restarts among the power-ons (None: every power-on a cold start from a soak,
    /// the paper's protocol).
    pub warm_restarts: Option<WarmRestarts>,
}

/// Some power-ons of a campaign are restarts of a gyro still warm from its last run, as a
/// chamber protocol that powers the unit off for a few minutes between runs gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WarmRestarts {
    /// Every `every`-th power-on at an ambient (the last of each group) is a restart.
    pub every: usize,
    /// The restarts start 0..`max_above_c` degC above the ambient (uniform, drawn from
    /// the run's seed).
    pub max_above_c: f64,
}

impl CampaignSpec {
    /// The paper's protocol: -40..+60 degC every 10, 5 runs of 45 min each.
    pub fn paper(seed: u64) -> Self {
        Self {
            ambients_c: PAPER_AMBIENTS_C.to_vec(),
            runs_per_ambient: PAPER_RUNS,
            minutes: PAPER_MINUTES,
            seed,
            latitude_deg: DEFAULT_LATITUDE_DEG,
            raw_rate_hz: 100.0,
            warm_restarts: None,
        }
    }

    /// The run spec of power-on `run` (0-based) at ambient index `amb`.
    pub fn run_spec(&self, amb: usize, run: usize) -> RunSpec {
        let seed = crate::seed::derive_seed(self.seed, amb as u64, run as u64);
        let start = match self.warm_restarts {
            Some(w) if w.every > 0 && run % w.every == w.every - 1 => {
                // the top 53 bits of another derived seed: uniform in [0, 1)
                let draw = crate::seed::derive_seed(seed, u64::MAX, 0) >> 11;
                let u = draw as f64 / (1u64 << 53) as f64;
                StartState::Restart {
                    above_ambient_c: w.max_above_c * u,
                }
            }
            _ => StartState::Soaked,
        };
        RunSpec {
            minutes: self.minutes,
            latitude_deg: self.latitude_deg,
            raw_rate_hz: self.raw_rate_hz,
            start,
            ..RunSpec::paper(self.ambients_c[amb], seed)
        }
    }

    /// Refuses, in one line naming the flags to lower, a campaign whose 1 Hz records
    /// (`power_ons_per_run` of them per ambient and run: the headings of a heading
    /// campaign, else 1) exceed `MAX_CAMPAIGN_RECORD_S`. Called before anything is simulated.
    pub fn check_record_size(&self, power_ons_per_run: usize) -> Result<(), CampaignError> {
        self.check_record_size_with(&[(power_ons_per_run, "headings", "--headings-deg")])
    }

    /// `check_record_size` with every ambient and run repeated by each of `factors`:
    /// (count, what it counts, the flag that sets it), e.g. the headings and the units of
    /// a fleet.
    pub fn check_record_size_with(
        &self,
        factors: &[(usize, &str, &str)],
    ) -> Result<(), CampaignError> {
        let repeats: f64 = factors.iter().map(|f| f.0 as f64).product();
        let record_s = self.ambients_c.len() as f64
            * self.runs_per_ambient as f64
            * repeats
            * self.minutes
            * 60.0;
        if record_s > MAX_CAMPAIGN_RECORD_S {
            let shown = factors.iter().filter(|f| f.0 > 1);
            let times: String = shown
                .clone()
                .map(|f| format!(" x {} {}", f.0, f.1))
                .collect();
            let flags: String = shown.map(|f| format!(", {}", f.2)).collect();
            return Err(CampaignError::Spec(format!(
                "{} ambients x {} runs{times} x {} min = {record_s:.3e} s of 1 Hz records, more than the {MAX_CAMPAIGN_RECORD_S:.0} s a campaign holds in memory (lower --runs, --duration-min{flags}, or the number of ambients)",
                self.ambients_c.len(),
                self.runs_per_ambient,
                self.minutes,
            )));
        }
        Ok(())
    }

    /// File name of a run; sorts by ambient (in list order), then by run number.
    pub fn file_name(&self, amb: usize, run: usize) -> String {
        let a = self.ambients_c[amb];
        let sign = if a < 0.0 { 'm' } else { 'p' };
        format!(
            "amb{amb:02}_{sign}{:03}c_run{}.csv",
            a.abs().round() as i64,
            run + 1
        )
    }
}

/// One simulated power-on of a campaign (`run.path` is its file name).
#[derive(Clone, Debug)]
pub struct CampaignRun {
    pub ambient_c: f64,
    /// 1-based index of the run at its temperature (the paper trains on 1-3).
    pub index: usize,
    pub run: Run,
}

/// Why a campaign failed.
#[derive(Debug)]
pub enum CampaignError {
    Spec(String),
    Sim(SimError),
    Write(RunError),
}

impl fmt::Display for CampaignError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CampaignError::Spec(s) => write!(f, "{s}"),
            CampaignError::Sim(e) => write!(f, "{e}"),
            CampaignError::Write(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for CampaignError {}

/// Simulates every run (in parallel over the available cores), in file order, each
/// tagged with its ambient and 1-based index.
pub fn simulate_campaign(
    params: &GyroParams,
    spec: &CampaignSpec,
) -> Result<Vec<CampaignRun>, CampaignError> {
    if spec.ambients_c.is_empty() {
        return Err(CampaignError::Spec(
            "campaign: no ambient temperatures".into(),
        ));
    }
    if spec.runs_per_ambient == 0 {
        return Err(CampaignError::Spec(
            "campaign: runs per ambient must be >= 1".into(),
        ));
    }
    let jobs: Vec<(usize, usize)> = (0..spec.ambients_c.len())
        .flat_map(|a| (0..spec.runs_per_ambient).map(move |r| (a, r)))
        .collect();
    // Fail fast on a bad spec before spawning anything.
    spec.run_spec(0, 0).validate().map_err(CampaignError::Sim)?;
    spec.check_record_size(1)?;
    let results = crate::fanout::map_in_order(jobs.len(), crate::fanout::thread_count(None), |j| {
        let (a, r) = jobs[j];
        simulate_run(params, &spec.run_spec(a, r))
    });
    jobs.iter()
        .zip(results)
        .map(|(&(a, r), res)| {
            let run = res.map_err(CampaignError::Sim)?;
            Ok(CampaignRun::named(spec, a, r, run, spec.file_name(a, r)))
        })
        .collect()
}

impl CampaignRun {
    /// Power-on `run` (0-based) at ambient index `amb`, stored under file name `name`.
    pub fn named(spec: &CampaignSpec, amb: usize, run: usize, mut data: Run, name: String) -> Self {
        data.path = PathBuf::from(name);
        data.set_meta("run", run + 1);
        CampaignRun {
            ambient_c: spec.ambients_c[amb],
            index: run + 1,
            run: data,
        }
    }
}

/// Writes a simulated campaign into `dir` (created if missing). If any file fails, the
/// files written by this call are removed again: no partial campaign is left.
pub fn write_campaign(dir: &Path, runs: &[CampaignRun]) -> Result<Vec<PathBuf>, CampaignError> {
    let io = |e: std::io::Error| {
        CampaignError::Write(RunError::new(
            dir,
            None,
            None,
            crate::io::runs::RunErrorKind::Io(e.to_string()),
        ))
    };
    if dir.is_dir() {
        // Stale runs of another campaign would silently join this one when the directory
        // is read back (e.g. by `fogsim train DIR`): refuse before writing anything.
        let ours: Vec<String> = runs.iter().map(|c| c.run.name()).collect();
        for entry in std::fs::read_dir(dir).map_err(io)? {
            let name = entry
                .map_err(io)?
                .file_name()
                .to_string_lossy()
                .into_owned();
            if name.to_ascii_lowercase().ends_with(".csv") && !ours.contains(&name) {
                return Err(CampaignError::Spec(format!(
                    "output directory {}: holds {name}, which is not part of this campaign and would mix with it; use an empty directory",
                    dir.display()
                )));
            }
        }
    }
    let created_dir = !dir.exists();
    std::fs::create_dir_all(dir).map_err(io)?;
    let mut written = Vec::new();
    for c in runs {
        let path = dir.join(c.run.name());
        if let Err(e) = write_run(&path, &c.run) {
            for p in &written {
                let _ = std::fs::remove_file(p);
            }
            if created_dir {
                let _ = std::fs::remove_dir(dir);
            }
            return Err(CampaignError::Write(e));
        }
        written.push(path);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_nth_power_on_is_a_warm_restart_within_its_range_and_the_rest_are_soaked() {
        let spec = CampaignSpec {
            ambients_c: vec![-40.0, 20.0],
            runs_per_ambient: 30,
            warm_restarts: Some(WarmRestarts {
                every: 3,
                max_above_c: 6.0,
            }),
            ..CampaignSpec::paper(7)
        };
        let mut above = Vec::new();
        for amb in 0..2 {
            for run in 0..30 {
                match spec.run_spec(amb, run).start {
                    StartState::Restart { above_ambient_c } => {
                        assert_eq!(run % 3, 2, "run {run} restarted");
                        assert!((0.0..6.0).contains(&above_ambient_c));
                        above.push(above_ambient_c);
                    }
                    StartState::Soaked => assert_ne!(run % 3, 2, "run {run} soaked"),
                    StartState::Warm => panic!("run {run} warm"),
                }
            }
        }
        assert_eq!(above.len(), 20);
        // drawn, not one value: spread over the range
        let lo = above.iter().cloned().fold(f64::INFINITY, f64::min);
        let hi = above.iter().cloned().fold(0.0, f64::max);
        assert!(lo < 2.0 && hi > 4.0, "restarts {lo}..{hi} degC");
        // the same seed gives the same campaign; without restarts every run is soaked
        assert_eq!(spec.run_spec(1, 5), spec.run_spec(1, 5));
        let cold = CampaignSpec {
            warm_restarts: None,
            ..spec.clone()
        };
        assert!((0..30).all(|r| cold.run_spec(0, r).start == StartState::Soaked));
        assert_eq!(cold.run_spec(0, 2).seed, spec.run_spec(0, 2).seed);
    }
}
