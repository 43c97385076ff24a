//! An independent gyro for the field-aging measurement: nothing shared with the project's
//! simulator (`fog_sim::sim`) but the traits the seek loop drives (fog-core's `Gyro`,
//! `TemperatureSensor`, `Turntable`, and `SeekInstrument`). Its own physics:
//!
//! - thermal: the coil warms by self-heating as a critically damped second-order response,
//!   T(t) = T_amb + R (1 - (1 + t/tau) e^(-t/tau)) (R and tau drawn per power-on): zero
//!   slope at power-on, no exponential modes (the simulator has a two-node network whose
//!   dT/dt is largest at power-on);
//! - bias law: a saturating temperature "knee", A tanh((T - T_k) / w) (the source
//!   wavelength and the coil stress settle between two regimes; the simulator's is a
//!   quadratic in T), a radial-gradient term k g with g a first-order lag (tau_g) of dT/dt
//!   (the simulator's Shupe term is instantaneous in dT/dt), an electronics settling
//!   c exp(-t / tau_e) since power-on (the model has no input for it), a turn-on bias
//!   drawn per power-on, a first-order Gauss-Markov bias and white noise (ARW);
//! - thermometer on the coil, 1 Hz, noise 0.02 degC, quantised to 0.0625 degC;
//! - its own turntable: 30 deg/s moves, settled 1 s after arriving, 0.002 deg indexing error.
//!
//! Aging laws (amounts stated, not measured on an aged unit): `knee` (a temperature law:
//! the knee's amplitude +40 % and its temperature -5 degC, as the potting relaxes),
//! `gradient-lag` (the twin, a rate law: the gradient coefficient +15 % and its lag
//! 120 -> 160 s, as the coating stiffens), `none` (the null twin).

use std::cell::RefCell;
use std::convert::Infallible;
use std::rc::Rc;

use anyhow::{anyhow, Result};
use fog_core::hal::{Gyro, GyroSample, TableState, TempSample, TemperatureSensor, Turntable};
use fog_core::seeking::tilt::Tilt;
use fog_sim::io::runs::Run;
use fog_sim::pipeline::campaign_steps::train_with;
use fog_sim::pipeline::field_aging::{AgingPlan, AgingSubject, Chamber};
use fog_sim::pipeline::north_seek::{run_seeks_on, Arm, ArmOutcome, MonteCarloConfig};
use fog_sim::sim::SeekInstrument;
use fog_sim::train::seek_score::{Criterion, DEFAULT_CRITERION_NAME};
use fog_sim::train::{choose_inputs_default, InputSet, TrainConfig};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

/// Earth rate, deg/h (sidereal).
const EARTH_DPH: f64 = 15.041_067;
/// Datasheet angle random walk, deg/sqrt(h).
pub const ARW_DPSH: f64 = 0.0007;
/// Thermometer period, s.
const TEMP_PERIOD_S: f64 = 1.0;

/// The bias law of one gyro (delivered or aged).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BiasLaw {
    pub bias_dph: f64,
    pub knee_dph: f64,
    pub knee_c: f64,
    pub knee_width_c: f64,
    /// Gradient coefficient, deg/h per degC/s, and the gradient's lag behind dT/dt, s.
    pub gradient_dph_per_cps: f64,
    pub gradient_lag_s: f64,
    pub settling_dph: f64,
    pub settling_tau_s: f64,
    pub turn_on_sigma_dph: f64,
    pub markov_sigma_dph: f64,
    pub markov_tau_s: f64,
}

impl BiasLaw {
    /// The gyro as delivered.
    pub const DELIVERED: BiasLaw = BiasLaw {
        bias_dph: 0.02,
        knee_dph: 0.03,
        knee_c: 28.0,
        knee_width_c: 10.0,
        gradient_dph_per_cps: 10.0,
        gradient_lag_s: 120.0,
        settling_dph: 0.02,
        settling_tau_s: 300.0,
        turn_on_sigma_dph: 0.003,
        markov_sigma_dph: 0.002,
        markov_tau_s: 300.0,
    };
}

/// The laws this gyro ages by.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IndependentLaw {
    Knee,
    GradientLag,
    None,
}

impl IndependentLaw {
    pub const ALL: [IndependentLaw; 3] = [Self::Knee, Self::GradientLag, Self::None];

    pub fn name(self) -> &'static str {
        match self {
            Self::Knee => "knee",
            Self::GradientLag => "gradient-lag",
            Self::None => "none",
        }
    }

    pub fn age(self, d: &BiasLaw) -> BiasLaw {
        match self {
            Self::Knee => BiasLaw {
                knee_dph: d.knee_dph * 1.4,
                knee_c: d.knee_c - 5.0,
                ..*d
            },
            Self::GradientLag => BiasLaw {
                gradient_dph_per_cps: d.gradient_dph_per_cps * 1.15,
                gradient_lag_s: 160.0,
                ..*d
            },
            Self::None => *d,
        }
    }

    pub fn amounts(self, d: &BiasLaw) -> String {
        let a = self.age(d);
        match self {
            Self::Knee => format!(
                "knee amplitude +40 % ({:.3} -> {:.3} deg/h), knee temperature {:.0} -> {:.0} degC",
                d.knee_dph, a.knee_dph, d.knee_c, a.knee_c
            ),
            Self::GradientLag => format!(
                "gradient coefficient +15 % ({:.1} -> {:.1} deg/h per degC/s), lag {:.0} -> {:.0} s",
                d.gradient_dph_per_cps, a.gradient_dph_per_cps, d.gradient_lag_s, a.gradient_lag_s
            ),
            Self::None => "no aging".into(),
        }
    }
}

/// Where the gyro is, per power-on.
#[derive(Clone, Copy, Debug)]
pub struct Site {
    pub ambient_c: f64,
    pub latitude_deg: f64,
    /// Azimuth of the input axis at table angle 0, deg; `None`: input axis vertical.
    pub azimuth_deg: Option<f64>,
    pub rate_hz: f64,
}

/// The turntable's state shared with the gyro on it.
#[derive(Debug, Default)]
struct TableShared {
    now_s: f64,
    from_deg: f64,
    to_deg: f64,
    move_start_s: f64,
    move_s: f64,
}

impl TableShared {
    fn angle_deg(&self, t_s: f64) -> f64 {
        let f = if self.move_s > 0.0 {
            ((t_s - self.move_start_s) / self.move_s).clamp(0.0, 1.0)
        } else {
            1.0
        };
        self.from_deg + (self.to_deg - self.from_deg) * f
    }
}

/// The turntable (30 deg/s, settled 1 s after arriving, 0.002 deg indexing error).
pub struct IndependentTable {
    shared: Rc<RefCell<TableShared>>,
    rng: ChaCha8Rng,
}

impl Turntable for IndependentTable {
    type Error = Infallible;
    fn command_heading(&mut self, heading_deg: f32) -> Result<(), Infallible> {
        let err: f64 = 0.002 * self.rng.sample::<f64, _>(StandardNormal);
        let mut s = self.shared.borrow_mut();
        let now = s.now_s;
        let from = s.angle_deg(now);
        let delta = (f64::from(heading_deg) + err - from + 180.0).rem_euclid(360.0) - 180.0;
        s.from_deg = from;
        s.to_deg = from + delta;
        s.move_start_s = now;
        s.move_s = delta.abs() / 30.0;
        Ok(())
    }
    fn poll(&mut self) -> Result<TableState, Infallible> {
        let s = self.shared.borrow();
        if s.now_s >= s.move_start_s + s.move_s + 1.0 {
            Ok(TableState::Settled {
                heading_deg: s.to_deg.rem_euclid(360.0) as f32,
            })
        } else {
            Ok(TableState::Moving)
        }
    }
}

/// One power-on of the gyro.
pub struct IndependentGyro {
    law: BiasLaw,
    site: Site,
    dt_s: f64,
    step: u64,
    rise_c: f64,
    tau_s: f64,
    turn_on_dph: f64,
    gradient_cps: f64,
    markov_dph: f64,
    white_sigma_dph: f64,
    table: Rc<RefCell<TableShared>>,
    rng: ChaCha8Rng,
    rng_temp: ChaCha8Rng,
}

impl IndependentGyro {
    /// The gyro powered on at t = 0, soaked at the ambient, and its table at 0.
    pub fn power_on(law: BiasLaw, site: Site, seed: u64) -> (Self, IndependentTable) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x1D3E_9F00);
        let mut n = || -> f64 { rng.sample(StandardNormal) };
        let rise_c = 16.0 + 0.5 * n();
        let tau_s = 400.0 * (1.0 + 0.05 * n());
        let turn_on_dph = law.turn_on_sigma_dph * n();
        let markov_dph = law.markov_sigma_dph * n();
        let table = Rc::new(RefCell::new(TableShared::default()));
        let dt_s = 1.0 / site.rate_hz;
        let gyro = Self {
            law,
            site,
            dt_s,
            step: 0,
            rise_c,
            tau_s,
            turn_on_dph,
            gradient_cps: 0.0,
            markov_dph,
            white_sigma_dph: ARW_DPSH * 60.0 / dt_s.sqrt(),
            table: Rc::clone(&table),
            rng,
            rng_temp: ChaCha8Rng::seed_from_u64(seed ^ 0x7E3F_0001),
        };
        let table = IndependentTable {
            shared: table,
            rng: ChaCha8Rng::seed_from_u64(seed ^ 0x7AB1_E000),
        };
        (gyro, table)
    }

    fn now_s(&self) -> f64 {
        self.step as f64 * self.dt_s
    }

    fn coil_c(&self, t_s: f64) -> f64 {
        let x = t_s / self.tau_s;
        self.site.ambient_c + self.rise_c * (1.0 - (1.0 + x) * (-x).exp())
    }

    fn coil_rate_cps(&self, t_s: f64) -> f64 {
        let x = t_s / self.tau_s;
        self.rise_c * x / self.tau_s * (-x).exp()
    }

    /// Next raw sample (rate at the interval's middle), deg/h.
    fn next_rate(&mut self) -> (f64, f64) {
        self.step += 1;
        let t = self.now_s();
        let mid = t - 0.5 * self.dt_s;
        self.table.borrow_mut().now_s = t;
        let l = &self.law;
        let rate = self.coil_rate_cps(mid);
        self.gradient_cps += self.dt_s / l.gradient_lag_s * (rate - self.gradient_cps);
        let phi = (-self.dt_s / l.markov_tau_s).exp();
        let w: f64 = self.rng.sample(StandardNormal);
        self.markov_dph = phi * self.markov_dph + l.markov_sigma_dph * (1.0 - phi * phi).sqrt() * w;
        let temp_c = self.coil_c(mid);
        let bias = l.bias_dph
            + self.turn_on_dph
            + l.knee_dph * ((temp_c - l.knee_c) / l.knee_width_c).tanh()
            + l.gradient_dph_per_cps * self.gradient_cps
            + l.settling_dph * (-mid / l.settling_tau_s).exp()
            + self.markov_dph;
        let lat = self.site.latitude_deg.to_radians();
        let earth = match self.site.azimuth_deg {
            None => EARTH_DPH * lat.sin(),
            Some(az) => {
                let angle = self.table.borrow().angle_deg(mid);
                EARTH_DPH * lat.cos() * (az + angle).to_radians().cos()
            }
        };
        let white: f64 = self.rng.sample(StandardNormal);
        (t, earth + bias + self.white_sigma_dph * white)
    }

    fn read_thermometer_c(&mut self) -> f64 {
        let noise: f64 = self.rng_temp.sample(StandardNormal);
        ((self.coil_c(self.now_s()) + 0.02 * noise) / 0.0625).round() * 0.0625
    }

    /// Earth rate along the input axis with the table at 0, deg/h.
    fn earth_at_rest_dph(&self) -> f64 {
        let lat = self.site.latitude_deg.to_radians();
        match self.site.azimuth_deg {
            None => EARTH_DPH * lat.sin(),
            Some(az) => EARTH_DPH * lat.cos() * az.to_radians().cos(),
        }
    }
}

impl Gyro for IndependentGyro {
    type Error = Infallible;
    fn read(&mut self) -> Result<Option<GyroSample>, Infallible> {
        let (t_s, rate) = self.next_rate();
        Ok(Some(GyroSample {
            t_s,
            rate_dph: rate as f32,
        }))
    }
}

impl TemperatureSensor for IndependentGyro {
    type Error = Infallible;
    fn read_temp(&mut self) -> Result<TempSample, Infallible> {
        Ok(TempSample {
            t_s: self.now_s(),
            temp_c: self.read_thermometer_c() as f32,
        })
    }
}

impl SeekInstrument for IndependentGyro {
    fn sample_period_s(&self) -> f64 {
        self.dt_s
    }
    fn temp_period_s(&self) -> f64 {
        TEMP_PERIOD_S
    }
    fn arw_dpsh(&self) -> f64 {
        ARW_DPSH
    }
    fn read_inclinometer(&mut self) -> Tilt {
        Tilt::LEVEL
    }
}

/// A chamber run: input axis vertical, `minutes` at 100 Hz, 10 s rows (mean rate, mean
/// thermometer reading), as `fogsim campaign` writes them.
pub fn chamber_run(
    law: BiasLaw,
    ambient_c: f64,
    latitude_deg: f64,
    minutes: f64,
    seed: u64,
) -> Run {
    let site = Site {
        ambient_c,
        latitude_deg,
        azimuth_deg: None,
        rate_hz: 100.0,
    };
    let (mut g, _table) = IndependentGyro::power_on(law, site, seed);
    let earth = g.earth_at_rest_dph();
    let rows = (minutes * 6.0) as usize;
    let mut cols: Vec<Vec<f64>> = (0..5).map(|_| Vec::with_capacity(rows)).collect();
    for r in 0..rows {
        let (mut rate, mut temp) = (0.0, 0.0);
        for _ in 0..10 {
            for _ in 0..100 {
                rate += g.next_rate().1;
            }
            temp += g.read_thermometer_c();
        }
        for (c, v) in cols.iter_mut().zip([
            10.0 * (r + 1) as f64,
            rate / 1000.0,
            temp / 10.0,
            earth,
            0.0,
        ]) {
            c.push(v);
        }
    }
    Run {
        path: format!("indep_field_{seed}.csv").into(),
        meta: vec![
            ("ambient_c".into(), format!("{ambient_c}")),
            ("latitude_deg".into(), format!("{latitude_deg}")),
            ("input_axis".into(), "vertical".into()),
        ],
        columns: ["t_s", "rate_dph", "temp_c", "earth_dph", "heading_deg"]
            .map(String::from)
            .to_vec(),
        data: cols,
    }
}

/// The independent gyro as the aging measurement's subject.
pub struct IndependentAging {
    pub laws: Vec<IndependentLaw>,
    /// Chamber runs per ambient, 45 min each.
    pub runs_per_ambient: usize,
}

impl AgingSubject for IndependentAging {
    fn laws(&self) -> Vec<(String, String)> {
        self.laws
            .iter()
            .map(|l| (l.name().to_string(), l.amounts(&BiasLaw::DELIVERED)))
            .collect()
    }

    /// `train`'s defaults (inputs chosen by validation, the seek criterion) on the runs of
    /// the delivered gyro at every ambient.
    fn chamber(&self, plan: &AgingPlan) -> Result<Chamber> {
        let mut runs = Vec::new();
        for (a, &amb) in plan.ambients_c.iter().enumerate() {
            for k in 0..self.runs_per_ambient {
                let seed =
                    fog_sim::seed::derive_seed(plan.seed, 0x43_48_41_4D, (a * 1000 + k) as u64);
                runs.push(chamber_run(
                    BiasLaw::DELIVERED,
                    amb,
                    plan.latitude_deg,
                    45.0,
                    seed,
                ));
            }
        }
        let dwell_s = MonteCarloConfig::paper(plan.seed).dwell_s as f64;
        let criterion = Criterion::parse(DEFAULT_CRITERION_NAME, dwell_s, plan.latitude_deg)
            .map_err(|e| anyhow!("criterion: {e}"))?;
        let cfg = TrainConfig {
            criterion,
            ..TrainConfig::default()
        };
        let (selection, _) = choose_inputs_default(&runs, &InputSet::ALL, &cfg)
            .map_err(|e| anyhow!("choosing inputs: {e}"))?;
        let refs: Vec<&Run> = runs.iter().collect();
        let trained = train_with(&refs, &selection.chosen.specs(), "indep", criterion)?;
        Ok(Chamber {
            centres: trained.report.n_centers,
            runs: runs.len(),
            model: trained.model,
        })
    }

    fn power_on(
        &self,
        law: usize,
        cfg: &MonteCarloConfig,
        arm: Arm<'_>,
        seed: u64,
    ) -> Result<ArmOutcome> {
        let site = Site {
            ambient_c: cfg.ambient_c,
            latitude_deg: cfg.latitude_deg,
            azimuth_deg: Some(cfg.true_azimuth_deg),
            rate_hz: cfg.raw_rate_hz,
        };
        let (mut gyro, mut table) =
            IndependentGyro::power_on(self.laws[law].age(&BiasLaw::DELIVERED), site, seed);
        run_seeks_on(&mut gyro, &mut table, cfg, arm)
    }
}
