//! An independent fleet generator (nothing shared with the project's simulator,
//! `sim::fleet` or the other generators here): N units of one gyro type, each with a few
//! cold starts at given ambients, as 10 s means (or 1 Hz rows: [`cold_start_rows`]), each
//! run tagged with its `unit_id`.
//!
//! - Its own thermal law: the coil warms as a stretched exponential,
//!   T = T_a + R (1 - exp(-sqrt(t / tau))) (a thick spool heated from one face:
//!   diffusion, steep at first and slow to finish; no exponential modes), the rise R
//!   larger in the cold, R = R_0 (1 + c (20 - T_a)). The thermometer reads the coil every
//!   second with 0.02 degC noise and a 0.0625 degC resolution.
//! - Its own drift law: b_0 + b_1 (T - 20) + k dT/dt (true T), a turn-on offset per run
//!   and white noise of [`NOISE_10S_DPH`] in 10 s means.
//! - Its own unit-to-unit law: uniform, not normal, and not in the logarithm: each unit's
//!   k, tau, R_0 and b_1 are the type's times (1 + w u), u uniform in [-1, 1] (relative
//!   standard deviation w / sqrt 3), its b_0 the type's plus a uniform offset.
//!
//! [`FleetLaw`] picks the fleet: every unit of the type (`Type`); its twin whose last
//! unit has a Shupe term of the opposite sign (a coil wound the other way round, which no
//! spread about the type's value carries: `OddUnit`); and its null twin, every unit the
//! type itself, units differing only in their runs' noise and turn-on offsets
//! (`Identical`). The twins make the same draws in the same order as `Type`.

use fog_sim::io::runs::Run;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// White noise of the 10 s means, deg/h.
pub const NOISE_10S_DPH: f64 = 0.01;
/// Turn-on offset between runs (1 sigma), deg/h.
pub const TURN_ON_DPH: f64 = 0.005;
/// The type's Shupe coefficient, deg/h per degC/s.
pub const TYPE_SHUPE_DPH_PER_CPS: f64 = 9.0;
/// Half-width of the uniform unit-to-unit law, relative: the relative standard deviation
/// of k over units is this / sqrt 3 (0.0866).
pub const UNIT_HALF_WIDTH: f64 = 0.15;

/// Which fleet.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FleetLaw {
    /// Every unit drawn from the type by the uniform law.
    Type,
    /// The same fleet; the last unit's Shupe term has the opposite sign.
    OddUnit,
    /// The null twin: every unit is the type (the same draws are made and not used).
    Identical,
    /// Single-effect twins (the same draws; only these parameters of each unit kept):
    /// the Shupe coefficient alone, or the thermal ones alone (time constant and rise).
    OnlyShupe,
    OnlyThermal,
}

/// One unit's physics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnitTruth {
    pub shupe_dph_per_cps: f64,
    pub tau_s: f64,
    pub rise_c: f64,
    pub bias_dph: f64,
    pub bias_dph_per_c: f64,
}

impl UnitTruth {
    const TYPE: UnitTruth = UnitTruth {
        shupe_dph_per_cps: TYPE_SHUPE_DPH_PER_CPS,
        tau_s: 400.0,
        rise_c: 7.0,
        bias_dph: 0.03,
        bias_dph_per_c: 0.003,
    };

    fn draw(rng: &mut ChaCha8Rng) -> Self {
        let mut scale = || 1.0 + UNIT_HALF_WIDTH * rng.random_range(-1.0..1.0);
        let t = Self::TYPE;
        let (k, tau, rise, b1) = (scale(), scale(), scale(), scale());
        Self {
            shupe_dph_per_cps: t.shupe_dph_per_cps * k,
            tau_s: t.tau_s * tau,
            rise_c: t.rise_c * rise,
            bias_dph: t.bias_dph + rng.random_range(-0.02..0.02),
            bias_dph_per_c: t.bias_dph_per_c * b1,
        }
    }
}

/// A generated fleet: its runs (unit by unit, then ambient, then run) and each unit's truth.
pub struct Fleet {
    pub runs: Vec<Run>,
    pub units: Vec<UnitTruth>,
}

/// `units` units, each with `runs_per_ambient` cold starts of `minutes` at every one of
/// `ambients_c`.
pub fn fleet(
    law: FleetLaw,
    units: usize,
    ambients_c: &[f64],
    runs_per_ambient: usize,
    minutes: usize,
    seed: u64,
) -> Fleet {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0xF1EE_7000);
    let mut truths = Vec::new();
    let mut runs = Vec::new();
    for u in 0..units {
        let drawn = UnitTruth::draw(&mut rng);
        let mut truth = match law {
            FleetLaw::Identical => UnitTruth::TYPE,
            FleetLaw::Type | FleetLaw::OddUnit => drawn,
            FleetLaw::OnlyShupe => UnitTruth {
                shupe_dph_per_cps: drawn.shupe_dph_per_cps,
                ..UnitTruth::TYPE
            },
            FleetLaw::OnlyThermal => UnitTruth {
                tau_s: drawn.tau_s,
                rise_c: drawn.rise_c,
                ..UnitTruth::TYPE
            },
        };
        if law == FleetLaw::OddUnit && u + 1 == units {
            truth.shupe_dph_per_cps = -truth.shupe_dph_per_cps;
        }
        for &amb in ambients_c {
            for r in 0..runs_per_ambient {
                let mut run = cold_start(&truth, amb, minutes, &mut rng);
                run.path = format!("fleet{seed}_u{:03}_a{amb}_r{r}.csv", u + 1).into();
                run.meta.push(("unit_id".into(), format!("U{}", u + 1)));
                runs.push(run);
            }
        }
        truths.push(truth);
    }
    Fleet {
        runs,
        units: truths,
    }
}

/// More cold starts of one unit (`truth`, `unit_id`) than its fleet gave it: numbers `ks`,
/// the k-th at `ambients_c[k % len]` (spread evenly), named `{prefix}a{amb}_r{k}.csv`.
pub fn extra_cold_starts(
    truth: &UnitTruth,
    unit_id: &str,
    ambients_c: &[f64],
    ks: std::ops::Range<usize>,
    minutes: usize,
    prefix: &str,
    rng: &mut ChaCha8Rng,
) -> Vec<Run> {
    ks.map(|k| {
        let amb = ambients_c[k % ambients_c.len()];
        let mut run = cold_start(truth, amb, minutes, rng);
        run.path = format!("{prefix}a{amb}_r{k}.csv").into();
        run.meta.push(("unit_id".into(), unit_id.into()));
        run
    })
    .collect()
}

/// One cold start of unit `truth` at ambient `amb`: 1 s physics, 10 s means (`rng` is
/// the caller's stream: more cold starts of a unit than its fleet gave it).
pub fn cold_start(truth: &UnitTruth, amb: f64, minutes: usize, rng: &mut ChaCha8Rng) -> Run {
    cold_start_rows(truth, amb, minutes, rng, 10)
}

/// As [`cold_start`], with a row every `every_s` seconds (1: the logger's 1 Hz rows; 10:
/// the device's 10 s means), each the mean of its seconds; the same draws either way.
pub fn cold_start_rows(
    truth: &UnitTruth,
    amb: f64,
    minutes: usize,
    rng: &mut ChaCha8Rng,
    every_s: usize,
) -> Run {
    let g = Normal::new(0.0, 1.0).unwrap();
    let rise = truth.rise_c * (1.0 + 0.01 * (20.0 - amb));
    let offset = TURN_ON_DPH * g.sample(rng);
    let white_1s = NOISE_10S_DPH * 10f64.sqrt();
    let mut cols: Vec<Vec<f64>> = vec![Vec::new(); 3];
    let (mut rate_sum, mut temp_sum) = (0.0, 0.0);
    for k in 1..=minutes * 60 {
        let t = k as f64;
        let s = (t / truth.tau_s).sqrt();
        let temp = amb + rise * (1.0 - (-s).exp());
        let dtemp = rise * (-s).exp() / (2.0 * (t * truth.tau_s).sqrt());
        let drift = truth.bias_dph
            + truth.bias_dph_per_c * (temp - 20.0)
            + truth.shupe_dph_per_cps * dtemp
            + offset;
        rate_sum += drift + white_1s * g.sample(rng);
        temp_sum += ((temp + 0.02 * g.sample(rng)) / 0.0625).round() * 0.0625;
        if k % every_s == 0 {
            let n = every_s as f64;
            for (c, v) in cols.iter_mut().zip([t, rate_sum / n, temp_sum / n]) {
                c.push(v);
            }
            (rate_sum, temp_sum) = (0.0, 0.0);
        }
    }
    Run {
        path: Default::default(),
        meta: vec![("ambient_c".into(), format!("{amb}"))],
        columns: ["t_s", "rate_dph", "temp_c"].map(String::from).to_vec(),
        data: cols,
    }
}
