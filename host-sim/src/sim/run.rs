//! Whole records: `simulate_run` turns one simulated power-on into a fog-runs v1 `Run`
//! of 10 s means, and `rig` mounts a gyro on a turntable for north-seek simulations.

use super::error::SimError;
use super::gyro::{stream_rng, SimGyro, STREAM_TABLE};
use super::params::GyroParams;
use super::spec::{RunSpec, StartState};
use super::terms::source_value;
use super::turntable::{SimTurntable, TurntableParams};
use crate::io::runs::Run;
use fog_core::consts::WINDOW_S;

/// Length of one output row, s (the paper's 10 s means).
pub const MEAN_WINDOW_S: f64 = WINDOW_S as f64;

/// Simulates one power-on and returns its 10 s means as a fog-runs v1 record with
/// columns `t_s, rate_dph, temp_c, earth_dph, heading_deg` (+ one column per extra
/// term that names one). `temp_c` is the mean of the sensor readings in the window.
pub fn simulate_run(params: &GyroParams, spec: &RunSpec) -> Result<Run, SimError> {
    let mut gyro = SimGyro::new(params, spec)?;
    let layout = WindowLayout::new(params, spec)?;
    let aux = AuxColumns::of(params);
    let mut columns = Columns::with_capacity(layout.windows, aux.names.len());
    for _ in 0..layout.windows {
        columns.push(mean_window(&mut gyro, params, &aux, &layout));
    }
    Run::new("", run_meta(spec), columns.named(aux.names)).map_err(|_| SimError::BadParameter {
        name: "run",
        value: f64::NAN,
        why: "simulation produced a non-finite value (check the parameters)",
    })
}

/// How a run is cut into windows: raw samples per 10 s window, whole windows in the
/// run, and raw samples per temperature-sensor reading.
struct WindowLayout {
    per_window: usize,
    windows: usize,
    sensor_every: usize,
}

impl WindowLayout {
    fn new(params: &GyroParams, spec: &RunSpec) -> Result<Self, SimError> {
        let per_window = spec.raw_rate_hz * MEAN_WINDOW_S;
        if (per_window - per_window.round()).abs() > 1e-9 {
            return Err(SimError::BadParameter {
                name: "run.raw_rate_hz",
                value: spec.raw_rate_hz,
                why: "must give a whole number of samples per 10 s window",
            });
        }
        let windows = (spec.minutes * 60.0 / MEAN_WINDOW_S).floor() as usize;
        if windows == 0 {
            return Err(SimError::BadParameter {
                name: "run.minutes",
                value: spec.minutes,
                why: "must cover at least one 10 s window",
            });
        }
        let sensor_every =
            ((params.sensor.sample_period_s * spec.raw_rate_hz).round() as usize).max(1);
        Ok(Self {
            per_window: per_window.round() as usize,
            windows,
            sensor_every,
        })
    }
}

/// The extra terms that write a column: their column names and term indices.
struct AuxColumns {
    names: Vec<String>,
    terms: Vec<usize>,
}

impl AuxColumns {
    fn of(params: &GyroParams) -> Self {
        let (names, terms) = params
            .extra_terms
            .iter()
            .enumerate()
            .filter_map(|(i, t)| t.column.clone().map(|c| (c, i)))
            .unzip();
        Self { names, terms }
    }
}

/// The means of one 10 s window.
struct WindowMeans {
    t_s: f64,
    rate_dph: f64,
    temp_c: f64,
    earth_dph: f64,
    heading_deg: f64,
    aux: Vec<f64>,
}

/// Reads one window of raw samples (and the sensor every `sensor_every` samples) from
/// `gyro` and averages them.
fn mean_window(
    gyro: &mut SimGyro,
    params: &GyroParams,
    aux: &AuxColumns,
    layout: &WindowLayout,
) -> WindowMeans {
    let (mut r, mut e, mut h) = (0.0, 0.0, 0.0);
    let (mut temp_sum, mut temp_n) = (0.0, 0usize);
    let mut aux_sum = vec![0.0; aux.terms.len()];
    for k in 1..=layout.per_window {
        let s = gyro.next_sample();
        r += s.rate_dph;
        e += s.earth_dph;
        h += s.azimuth_deg;
        if k % layout.sensor_every == 0 {
            temp_sum += gyro.read_sensor_c();
            temp_n += 1;
        }
        if !aux.terms.is_empty() {
            let x = gyro.term_inputs();
            for (sum, &i) in aux_sum.iter_mut().zip(&aux.terms) {
                *sum += source_value(&params.extra_terms[i].source, &x);
            }
        }
    }
    if temp_n == 0 {
        temp_sum = gyro.read_sensor_c();
        temp_n = 1;
    }
    let n = layout.per_window as f64;
    WindowMeans {
        t_s: gyro.now_s(),
        rate_dph: r / n,
        temp_c: temp_sum / temp_n as f64,
        earth_dph: e / n,
        heading_deg: (h / n).rem_euclid(360.0),
        aux: aux_sum.into_iter().map(|sum| sum / n).collect(),
    }
}

/// The record's columns, filled window by window.
struct Columns {
    t_s: Vec<f64>,
    rate_dph: Vec<f64>,
    temp_c: Vec<f64>,
    earth_dph: Vec<f64>,
    heading_deg: Vec<f64>,
    aux: Vec<Vec<f64>>,
}

impl Columns {
    fn with_capacity(windows: usize, n_aux: usize) -> Self {
        Self {
            t_s: Vec::with_capacity(windows),
            rate_dph: Vec::with_capacity(windows),
            temp_c: Vec::with_capacity(windows),
            earth_dph: Vec::with_capacity(windows),
            heading_deg: Vec::with_capacity(windows),
            aux: vec![Vec::with_capacity(windows); n_aux],
        }
    }

    fn push(&mut self, w: WindowMeans) {
        self.t_s.push(w.t_s);
        self.rate_dph.push(w.rate_dph);
        self.temp_c.push(w.temp_c);
        self.earth_dph.push(w.earth_dph);
        self.heading_deg.push(w.heading_deg);
        for (col, v) in self.aux.iter_mut().zip(w.aux) {
            col.push(v);
        }
    }

    /// The columns with their fog-runs names, the extra terms' after the standard five.
    fn named(self, aux_names: Vec<String>) -> Vec<(String, Vec<f64>)> {
        let mut columns = vec![
            ("t_s".to_string(), self.t_s),
            ("rate_dph".to_string(), self.rate_dph),
            ("temp_c".to_string(), self.temp_c),
            ("earth_dph".to_string(), self.earth_dph),
            ("heading_deg".to_string(), self.heading_deg),
        ];
        columns.extend(aux_names.into_iter().zip(self.aux));
        columns
    }
}

/// The record's metadata: simulator, site, protocol and seed.
fn run_meta(spec: &RunSpec) -> Vec<(String, String)> {
    let start = match spec.start {
        StartState::Soaked => "soaked".to_string(),
        StartState::Warm => "warm".to_string(),
        StartState::Restart { above_ambient_c } => format!("restart +{above_ambient_c} degC"),
    };
    let input_axis = if spec.input_axis_vertical {
        "vertical"
    } else {
        "horizontal"
    };
    vec![
        ("gyro".to_string(), "fog-sim paper_default".to_string()),
        ("latitude_deg".to_string(), spec.latitude_deg.to_string()),
        ("ambient_c".to_string(), spec.ambient_c.to_string()),
        ("input_axis".to_string(), input_axis.to_string()),
        ("raw_rate_hz".to_string(), spec.raw_rate_hz.to_string()),
        ("start".to_string(), start),
        ("seed".to_string(), spec.seed.to_string()),
        (
            "simulator".to_string(),
            format!("fog-sim {}", env!("CARGO_PKG_VERSION")),
        ),
    ]
}

/// A gyro mounted with its input axis on a turntable, sharing the table's clock.
/// `spec.heading_deg` is the azimuth of the table's zero; the table starts at 0 deg.
/// Time advances only as the gyro is read.
pub fn rig(
    params: &GyroParams,
    spec: &RunSpec,
    table: TurntableParams,
) -> Result<(SimGyro, SimTurntable), SimError> {
    table.validate()?;
    let mut gyro = SimGyro::new(params, spec)?;
    let table = SimTurntable::new(table, 0.0, stream_rng(spec.seed, STREAM_TABLE));
    gyro.attach_table(table.link());
    Ok((gyro, table))
}
