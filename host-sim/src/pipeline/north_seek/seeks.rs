//! One power-on's seeks, as the device runs them: a simulated gyro on the turntable,
//! fog-core's `Compensator` feeding its `NorthFinder` under the `SeekSupervisor`, back to
//! back until `seeks_per_start` are done; each seek's outcome, refusals, tilt, BIT word
//! and field record.

use anyhow::{anyhow, bail, Result};
use fog_core::compensation::compensator::{Compensator, CompensatorConfig};
use fog_core::hal::{Gyro, GyroSample, TempSample, TemperatureSensor, Turntable};
use fog_core::model::format::RbfModel;
use fog_core::model::heading::HeadingHarmonic;
use fog_core::seeking::bit::{evaluate, BitInputs, BitLimits, BitWord};
use fog_core::seeking::field_record::{record_of_seek, FieldRecord, SeekTempState};
use fog_core::seeking::northfinder::{NorthFinder, SeekStatus, MAX_STEPS};
use fog_core::seeking::quality::{
    QualityConfig, QualityError, SeekSupervisor, SupervisorEvent, Validity,
};
use fog_core::seeking::tilt::Tilt;

use super::config::{MonteCarloConfig, INIT_S};
use crate::sim::{rig, BaseMotion, GyroParams, RunSpec, SeekInstrument};
/// One finished seek.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SeekOutcome {
    /// Which seek after power-on (0-based): the column of the per-seek tables.
    pub index: usize,
    /// Restarts the supervisor made for base motion during this seek.
    pub restarts: u8,
    /// False when the latitude check flagged the result (`Validity::LatitudeMismatch`).
    pub latitude_valid: bool,
    pub azimuth_deg: f64,
    /// The north finder's own 1-sigma estimate, deg.
    pub sigma_deg: f64,
    pub t_start_s: f64,
    pub duration_s: f64,
    /// Measuring time actually used per main position, s (windows x 10 s, both visits of
    /// a symmetric sequence).
    pub main_dwell_s: f64,
    /// The field record the device would keep for this seek (`record_of_seek`: residual
    /// bias = half-sum of the two positions at the seek's temperature state; sequence 0,
    /// model CRC-32 of the arm's model), `None` where the device keeps none.
    pub field_record: Option<FieldRecord>,
    /// When each position's accepted windows lie (`PositionSpans`).
    pub position_spans_s: PositionSpans,
}

/// Where each step's accepted 10 s windows lie, s since power-on: the first window's
/// start and the last one's end, by step of the sequence (`SeekMode::steps`; a forward
/// sequence's steps are its positions; None for a step not dwelt at).
/// What the trainer's seek refit reads the device's seek timing from (`seek_schedule`).
pub type PositionSpans = [Option<(f64, f64)>; MAX_STEPS];

/// No position dwelt at yet.
pub const NO_SPANS: PositionSpans = [None; MAX_STEPS];

/// The running seek's `PositionSpans`: a window counts for the position the finder was
/// dwelling at when it arrived if, after it, that position has one window more, the
/// table moves on, or the seek is done (an invalid or too early window changes none).
struct SpanTracker {
    spans: PositionSpans,
}

impl SpanTracker {
    fn reset(&mut self) {
        self.spans = NO_SPANS;
    }

    /// Feeds `w` to the running seek and tracks which position it counted for (a motion
    /// restart forgets the spans).
    fn feed<T: Turntable>(
        &mut self,
        sup: &mut SeekSupervisor,
        w: &fog_core::compensation::compensator::WindowResult,
        tilt: Tilt,
        table: &mut T,
    ) -> Result<SupervisorEvent, QualityError> {
        let before = sup.finder().status();
        let event = sup.on_window(w, tilt, table);
        if matches!(event, Ok(SupervisorEvent::Restarted(_))) {
            self.reset();
        } else {
            self.on_window(w, before, &event, sup.finder().status());
        }
        event
    }

    fn on_window(
        &mut self,
        w: &fog_core::compensation::compensator::WindowResult,
        before: SeekStatus,
        event: &Result<SupervisorEvent, QualityError>,
        after: SeekStatus,
    ) {
        let SeekStatus::Dwelling { position, windows } = before else {
            return;
        };
        let counted = matches!(event, Ok(SupervisorEvent::Done(..)))
            || match after {
                SeekStatus::Dwelling {
                    position: p,
                    windows: n,
                } => p != position || n > windows,
                SeekStatus::Moving { .. } => true,
                _ => false,
            };
        if let (true, Some(span)) = (counted, self.spans.get_mut(position as usize)) {
            let start_s = span.map_or(w.t_start_s, |(start_s, _)| start_s);
            *span = Some((start_s, w.t_end_s));
        }
    }
}

/// A seek attempt that ended without a result (refused at its start or stopped by the
/// supervisor or the finder): the seek it was for, when, and why.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Refusal {
    pub index: usize,
    pub t_s: f64,
    pub reason: QualityError,
}

/// Attempts one seek gets before the Monte Carlo records it as failed and goes on with
/// the next (the device would report the failure and wait for the user).
pub const MAX_ATTEMPTS_PER_SEEK: usize = 4;

/// What one arm of one cold start did: the seeks that finished, every refused attempt,
/// and the seeks given up after `MAX_ATTEMPTS_PER_SEEK` attempts.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct ArmOutcome {
    pub seeks: Vec<SeekOutcome>,
    pub refusals: Vec<Refusal>,
    pub failed_seeks: usize,
    /// The compensator found this power-on not to be a cold start of its model's
    /// (`WindowStatus::NotColdStart`).
    pub warm_restart_detected: bool,
}

/// The arms of one cold start (`tilt_uncompensated` and `heading_uncalibrated` are empty
/// when the Monte Carlo has no tilt / no heading bias).
#[derive(Clone, Debug, PartialEq)]
pub struct StartOutcome {
    pub seed: u64,
    pub uncompensated: ArmOutcome,
    pub compensated: ArmOutcome,
    pub tilt_uncompensated: ArmOutcome,
    pub heading_uncalibrated: ArmOutcome,
}

/// What one arm applies.
#[derive(Clone, Copy, Debug)]
pub struct Arm<'a> {
    /// Drift model (None: uncompensated drift).
    pub model: Option<&'a RbfModel>,
    /// Give the finder the measured tilt (false: it assumes a level base).
    pub feed_tilt: bool,
    /// Heading calibration applied by the finder.
    pub heading: Option<HeadingHarmonic>,
}

/// Inclinometer readings (1 Hz) averaged over one 10 s window, as the firmware does.
#[derive(Default)]
struct TiltMean {
    sum_deg: [f64; 2],
    n: u32,
}

impl TiltMean {
    fn add(&mut self, t: Tilt) {
        self.sum_deg[0] += t.pitch_deg as f64;
        self.sum_deg[1] += t.roll_deg as f64;
        self.n += 1;
    }

    /// The window's mean (level when `feed` is false: a finder that ignores tilt), reset.
    fn take(&mut self, feed: bool) -> Tilt {
        let n = self.n.max(1) as f64;
        let mean = Tilt {
            pitch_deg: (self.sum_deg[0] / n) as f32,
            roll_deg: (self.sum_deg[1] / n) as f32,
        };
        *self = Self::default();
        if feed {
            mean
        } else {
            Tilt::LEVEL
        }
    }

    /// The mean so far without resetting (level before any reading or when not fed).
    fn peek(&self, feed: bool) -> Tilt {
        if !feed || self.n == 0 {
            return Tilt::LEVEL;
        }
        let n = self.n as f64;
        Tilt {
            pitch_deg: (self.sum_deg[0] / n) as f32,
            roll_deg: (self.sum_deg[1] / n) as f32,
        }
    }
}

/// The built-in test as the device evaluates it from what the simulator provides: the
/// latest temperature reading and the last window's dT/dt (0 before it is known, as the
/// compensator reports). Links, inclinometer, table and flash are not simulated as
/// failing, so they pass; the model item passes in every arm (the uncompensated arm is
/// the reference without a model, not a device refusing to seek).
fn simulated_bit(temp_c: f32, temp_rate_cps: f32) -> BitWord {
    evaluate(
        &BitInputs {
            gyro_silence_s: 0.0,
            gyro_frames_ok: 1,
            gyro_frames_bad: 0,
            temp_c,
            temp_rate_cps,
            inclinometer_silence_s: 0.0,
            turntable_answering: true,
            model_valid: true,
            flash_ok: true,
        },
        &BitLimits::default(),
    )
}

/// Bookkeeping of the seeks of one arm: which seek is due, its attempts, and the record.
struct SeekLedger {
    wanted: usize,
    index: usize,
    attempts: usize,
    out: ArmOutcome,
}

impl SeekLedger {
    fn done(&self) -> bool {
        self.index >= self.wanted
    }

    /// Records a refused attempt; after `MAX_ATTEMPTS_PER_SEEK` the seek is given up.
    fn refuse(&mut self, t_s: f64, reason: QualityError) {
        self.out.refusals.push(Refusal {
            index: self.index,
            t_s,
            reason,
        });
        self.attempts += 1;
        if self.attempts >= MAX_ATTEMPTS_PER_SEEK {
            self.out.failed_seeks += 1;
            self.next();
        }
    }

    /// Records what the supervisor made of one window (`restarts` of the running seek).
    fn record(
        &mut self,
        event: Result<SupervisorEvent, QualityError>,
        t_s: f64,
        restarts: u8,
        field_record: Option<FieldRecord>,
        position_spans_s: PositionSpans,
    ) {
        match event {
            Ok(SupervisorEvent::Done(r, validity)) => {
                let n_main = r.positions[0].n_windows as f64;
                self.out.seeks.push(SeekOutcome {
                    index: self.index,
                    restarts,
                    latitude_valid: validity == Validity::Valid,
                    azimuth_deg: r.azimuth_deg,
                    sigma_deg: r.sigma_deg,
                    t_start_s: r.t_start_s,
                    duration_s: r.duration_s,
                    main_dwell_s: n_main * fog_core::consts::WINDOW_S as f64,
                    field_record,
                    position_spans_s,
                });
                self.next();
            }
            Ok(_) => {}
            Err(e) => self.refuse(t_s, e),
        }
    }

    fn next(&mut self) {
        self.index += 1;
        self.attempts = 0;
    }
}

/// What the device records per seek (`fog_firmware::app`): the temperature state of the
/// seek's valid windows, reset at each start and motion restart, and the model's CRC-32.
struct FieldRecorder {
    seek_temp: SeekTempState,
    model_crc32: Option<u32>,
}

impl FieldRecorder {
    fn new(model: Option<&RbfModel>) -> Result<Self> {
        Ok(Self {
            seek_temp: SeekTempState::new(),
            model_crc32: model.map(crate::io::model::model_crc32).transpose()?,
        })
    }

    /// A window of a running seek (before the supervisor sees it, as on the device), with
    /// the model that compensated it (its own d2T/dt2 input goes into the record).
    fn on_window(
        &mut self,
        w: &fog_core::compensation::compensator::WindowResult,
        model: Option<&RbfModel>,
    ) {
        if w.status.is_valid() {
            self.seek_temp.push_window(w, model);
        }
    }

    /// The record of a finished seek; a restart forgets the state.
    fn on_event(&mut self, event: &Result<SupervisorEvent, QualityError>) -> Option<FieldRecord> {
        match event {
            Ok(SupervisorEvent::Done(r, validity)) => {
                record_of_seek(r, *validity, self.seek_temp.state(), self.model_crc32)
            }
            Ok(SupervisorEvent::Restarted(_)) => {
                self.seek_temp.reset();
                None
            }
            _ => None,
        }
    }
}

/// Direction of the base tilt of a start, deg (pitch = tilt cos, roll = tilt sin).
fn tilt_direction_deg(seed: u64) -> f64 {
    (seed % 3600) as f64 / 10.0
}

/// Runs `cfg.seeks_per_start` seeks after one cold start with the given seed, with the
/// arm's model, tilt input and heading calibration, through fog-core's `SeekSupervisor`
/// (built-in test, tilt range, motion restarts, latitude check) as the device runs them.
/// A seek that is refused or fails is recorded and started again at the next window
/// (`MAX_ATTEMPTS_PER_SEEK` attempts); the Monte Carlo never aborts on a refusal.
/// `params` is already `cfg.gyro_params`.
pub fn run_seeks(
    params: &GyroParams,
    cfg: &MonteCarloConfig,
    arm: Arm<'_>,
    seed: u64,
) -> Result<ArmOutcome> {
    let spec = RunSpec {
        ambient_c: cfg.ambient_c,
        minutes: cfg.seeks_per_start as f64 * 10.0,
        latitude_deg: cfg.latitude_deg,
        heading_deg: cfg.true_azimuth_deg,
        input_axis_vertical: false,
        raw_rate_hz: cfg.raw_rate_hz,
        seed,
        start: cfg.start_state(),
    };
    let (mut gyro, mut table) =
        rig(params, &spec, cfg.turntable.clone()).map_err(|e| anyhow!("simulator: {e}"))?;
    if cfg.tilt_deg > 0.0 {
        gyro.set_base(BaseMotion::tilted(cfg.tilt_deg, tilt_direction_deg(seed)))
            .map_err(|e| anyhow!("simulator: {e}"))?;
    }
    run_seeks_on(&mut gyro, &mut table, cfg, arm)
}

/// When `run_seeks_on` gives up, s since power-on. A generous bound: every attempt of every
/// seek restarted as often as the supervisor allows, each taking twice its nominal time
/// (the longer of 3 dwells + 60 s and the sequence's windows with two per step for turns).
fn time_limit_s(cfg: &MonteCarloConfig, finder: &NorthFinder, max_restarts: u8) -> f64 {
    let worst_attempts = (MAX_ATTEMPTS_PER_SEEK * (1 + max_restarts as usize)) as f64;
    let window_s = fog_core::consts::WINDOW_S as f64;
    let nominal_s = (0..finder.n_steps())
        .map(|k| (finder.windows_needed(k) as f64 + 2.0) * window_s)
        .sum::<f64>();
    INIT_S
        + cfg.seeks_per_start as f64
            * worst_attempts
            * 2.0
            * (3.0 * cfg.dwell_s as f64 + 60.0).max(nominal_s)
}

/// `run_seeks` on any gyro and turntable behind fog-core's traits (the gyro powered on at
/// t = 0, the table at its zero): the seeks of one power-on, as the device runs them.
pub fn run_seeks_on<G, T>(
    gyro: &mut G,
    table: &mut T,
    cfg: &MonteCarloConfig,
    arm: Arm<'_>,
) -> Result<ArmOutcome>
where
    G: Gyro + TemperatureSensor + SeekInstrument,
    T: Turntable,
{
    let model = arm.model;
    let dt_s = gyro.sample_period_s();
    let temp_period_s = gyro.temp_period_s();
    let comp_cfg = CompensatorConfig {
        gyro_rate_hz: cfg.raw_rate_hz as f32,
        temp_rate_hz: (1.0 / temp_period_s) as f32,
        ..CompensatorConfig::default()
    };
    let mut comp = Compensator::new(comp_cfg, model.cloned()).map_err(|e| anyhow!("{e}"))?;
    let mut recorder = FieldRecorder::new(model)?;
    let mut finder = NorthFinder::new(cfg.seek_config()).map_err(|e| anyhow!("{e}"))?;
    finder.set_heading_correction(arm.heading);
    // The motion threshold's floor from the simulated gyro's own ARW (its datasheet value).
    let quality = QualityConfig {
        arw_dpsh: gyro.arw_dpsh() as f32,
        ..QualityConfig::default()
    };
    let mut sup = SeekSupervisor::new(finder, quality);
    let mut inclinometer = TiltMean::default();
    let temp_every = ((temp_period_s / dt_s).round() as u64).max(1);
    let poll_every = ((1.0 / dt_s).round() as u64).max(1);
    let t_limit_s = time_limit_s(cfg, sup.finder(), quality.max_restarts);
    let mut ledger = SeekLedger {
        wanted: cfg.seeks_per_start,
        index: 0,
        attempts: 0,
        out: ArmOutcome::default(),
    };
    let mut step: u64 = 0;
    let mut sensor_c = f32::NAN;
    let mut temp_rate_cps = 0.0f32;
    let mut window_tilt: Option<Tilt> = None;
    let mut spans = SpanTracker { spans: NO_SPANS };
    while !ledger.done() {
        let s = match gyro.read() {
            Ok(Some(s)) => s,
            Ok(None) => continue,
            Err(e) => bail!("gyro: {e:?}"),
        };
        step += 1;
        if s.t_s > t_limit_s {
            bail!(
                "seek {} did not finish within {t_limit_s:.0} s of power-on",
                ledger.index + 1
            );
        }
        if step.is_multiple_of(temp_every) {
            sensor_c = gyro
                .read_temp()
                .map_err(|e| anyhow!("temperature sensor: {e:?}"))?
                .temp_c;
            comp.push_temp(TempSample {
                t_s: s.t_s,
                temp_c: sensor_c,
            });
        }
        if step.is_multiple_of(poll_every) {
            inclinometer.add(gyro.read_inclinometer());
            if sup.is_seeking() {
                if let Err(e) = sup.poll(table, s.t_s) {
                    ledger.refuse(s.t_s, e);
                }
            }
        }
        // The first seek starts after the fast initialisation, every later one (and every
        // new attempt) as soon as the previous one ended.
        if !sup.is_seeking() && !ledger.done() && s.t_s >= INIT_S {
            let tilt = window_tilt.unwrap_or_else(|| inclinometer.peek(arm.feed_tilt));
            let bit = simulated_bit(sensor_c, temp_rate_cps);
            recorder.seek_temp.reset();
            spans.reset();
            if let Err(e) = sup.start(table, s.t_s, tilt, bit) {
                ledger.refuse(s.t_s, e);
            }
        }
        // A raw sample is the mean over (t - dt, t]: time-stamp it at the interval's middle.
        let sample = GyroSample {
            t_s: s.t_s - 0.5 * dt_s,
            rate_dph: s.rate_dph,
        };
        let Some(w) = comp.push_gyro(sample) else {
            continue;
        };
        let tilt = inclinometer.take(arm.feed_tilt);
        window_tilt = Some(tilt);
        temp_rate_cps = w.temp_rate_cps;
        if sup.is_seeking() {
            recorder.on_window(&w, comp.model());
            let event = spans.feed(&mut sup, &w, tilt, table);
            let field_record = recorder.on_event(&event);
            ledger.record(
                event,
                w.t_end_s,
                sup.restarts().0,
                field_record,
                spans.spans,
            );
        }
    }
    ledger.out.warm_restart_detected = comp.warm_restart();
    Ok(ledger.out)
}
