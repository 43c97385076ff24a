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
// Split along its sections is deferred (issue 12, second part); allowed until then.
#[allow(clippy::too_many_lines)]
pub fn simulate_run(params: &GyroParams, spec: &RunSpec) -> Result<Run, SimError> {
    let mut gyro = SimGyro::new(params, spec)?;
    let per_window = spec.raw_rate_hz * MEAN_WINDOW_S;
    if (per_window - per_window.round()).abs() > 1e-9 {
        return Err(SimError::BadParameter {
            name: "run.raw_rate_hz",
            value: spec.raw_rate_hz,
            why: "must give a whole number of samples per 10 s window",
        });
    }
    let per_window = per_window.round() as usize;
    let windows = (spec.minutes * 60.0 / MEAN_WINDOW_S).floor() as usize;
    if windows == 0 {
        return Err(SimError::BadParameter {
            name: "run.minutes",
            value: spec.minutes,
            why: "must cover at least one 10 s window",
        });
    }
    let sensor_every = ((params.sensor.sample_period_s * spec.raw_rate_hz).round() as usize).max(1);
    let aux: Vec<(String, usize)> = params
        .extra_terms
        .iter()
        .enumerate()
        .filter_map(|(i, t)| t.column.clone().map(|c| (c, i)))
        .collect();

    let mut t_s = Vec::with_capacity(windows);
    let mut rate = Vec::with_capacity(windows);
    let mut temp = Vec::with_capacity(windows);
    let mut earth = Vec::with_capacity(windows);
    let mut heading = Vec::with_capacity(windows);
    let mut aux_cols = vec![Vec::with_capacity(windows); aux.len()];
    for _ in 0..windows {
        let (mut r, mut e, mut h) = (0.0, 0.0, 0.0);
        let (mut temp_sum, mut temp_n) = (0.0, 0usize);
        let mut aux_sum = vec![0.0; aux.len()];
        for k in 1..=per_window {
            let s = gyro.next_sample();
            r += s.rate_dph;
            e += s.earth_dph;
            h += s.azimuth_deg;
            if k % sensor_every == 0 {
                temp_sum += gyro.read_sensor_c();
                temp_n += 1;
            }
            if !aux.is_empty() {
                let x = gyro.term_inputs();
                for (sum, (_, i)) in aux_sum.iter_mut().zip(&aux) {
                    *sum += source_value(&params.extra_terms[*i].source, &x);
                }
            }
        }
        if temp_n == 0 {
            temp_sum = gyro.read_sensor_c();
            temp_n = 1;
        }
        let n = per_window as f64;
        t_s.push(gyro.now_s());
        rate.push(r / n);
        temp.push(temp_sum / temp_n as f64);
        earth.push(e / n);
        heading.push((h / n).rem_euclid(360.0));
        for (col, sum) in aux_cols.iter_mut().zip(aux_sum) {
            col.push(sum / n);
        }
    }

    let mut columns = vec![
        ("t_s".to_string(), t_s),
        ("rate_dph".to_string(), rate),
        ("temp_c".to_string(), temp),
        ("earth_dph".to_string(), earth),
        ("heading_deg".to_string(), heading),
    ];
    columns.extend(aux.into_iter().map(|(c, _)| c).zip(aux_cols));
    let start = match spec.start {
        StartState::Soaked => "soaked".to_string(),
        StartState::Warm => "warm".to_string(),
        StartState::Restart { above_ambient_c } => format!("restart +{above_ambient_c} degC"),
    };
    let meta = vec![
        ("gyro".to_string(), "fog-sim paper_default".to_string()),
        ("latitude_deg".to_string(), spec.latitude_deg.to_string()),
        ("ambient_c".to_string(), spec.ambient_c.to_string()),
        (
            "input_axis".to_string(),
            if spec.input_axis_vertical {
                "vertical"
            } else {
                "horizontal"
            }
            .to_string(),
        ),
        ("raw_rate_hz".to_string(), spec.raw_rate_hz.to_string()),
        ("start".to_string(), start),
        ("seed".to_string(), spec.seed.to_string()),
        (
            "simulator".to_string(),
            format!("fog-sim {}", env!("CARGO_PKG_VERSION")),
        ),
    ];
    Run::new("", meta, columns).map_err(|_| SimError::BadParameter {
        name: "run",
        value: f64::NAN,
        why: "simulation produced a non-finite value (check the parameters)",
    })
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
