//! Seek quality around the north finder: refuses a seek that cannot succeed (built-in test
//! failed, tilt out of range), detects base motion during a dwell and restarts the seek with
//! the reason, reports progress (0..1) and a predicted 1-sigma from the noise observed so far,
//! and checks the host's latitude against the observed horizontal Earth rate at the end.
//!
//! Exists so that what a user of a fielded north finder sees ("ready", "restarted due to
//! excessive movement", "latitude check failed") is decided by pure, host-tested code that
//! the firmware only has to feed with windows, tilt and the BIT word.
//!
//! Motion: within one dwell the 10 s means of a still gyro scatter by the white noise
//! sigma_w = N / sqrt(10 s) (N the ARW) plus slow drift; a window more than `motion_k`
//! times max(observed scatter, sigma_w) away from the running dwell mean, or a tilt more than
//! `max_tilt_change_deg` away from the tilt at the start of the seek, is motion.
//! A tilt change d of the base moves the vertical leak by Omega_V d, i.e. the azimuth by
//! about tan(latitude) d: 0.05 deg of tilt change is 0.04 deg of azimuth at 40 deg N.

use crate::compensation::compensator::WindowResult;
use crate::consts::{EARTH_RATE_DPH, WINDOW_S};
use crate::hal::Turntable;
use crate::seeking::bit::{BitItem, BitWord};
use crate::seeking::northfinder::{
    NorthFinder, SeekConfig, SeekError, SeekMode, SeekResult, SeekStatus,
};
use crate::seeking::tilt::Tilt;
use serde::{Deserialize, Serialize};

/// Limits of the supervisor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QualityConfig {
    /// Largest |pitch| or |roll| of the base a seek accepts, deg (the inclinometer's and
    /// the tilt maths' range; commercial north finders quote +-30 deg).
    pub max_tilt_deg: f32,
    /// Largest tilt change from the start of the seek before it restarts, deg.
    pub max_tilt_change_deg: f32,
    /// Gyro angle random walk, deg/sqrt(h): sets the floor of the motion threshold.
    pub arw_dpsh: f32,
    /// Motion threshold in sigmas of the window scatter.
    pub motion_k: f32,
    /// Restarts before the seek gives up.
    pub max_restarts: u8,
    /// Latitude check: allowed |observed - expected| horizontal rate, as a fraction of
    /// Omega_H (scale factor and residual drift), on top of `latitude_k` 1-sigmas.
    pub latitude_rel_tolerance: f32,
    pub latitude_k: f32,
}

impl Default for QualityConfig {
    /// ARW 0.0011 deg/sqrt(h) (the simulator's paper gyro), 6-sigma motion threshold,
    /// 0.05 deg tilt change, 30 deg tilt range, 3 restarts, latitude within 3 % + 3 sigma.
    fn default() -> Self {
        Self {
            max_tilt_deg: 30.0,
            max_tilt_change_deg: 0.05,
            arw_dpsh: 0.0011,
            motion_k: 6.0,
            max_restarts: 3,
            latitude_rel_tolerance: 0.03,
            latitude_k: 3.0,
        }
    }
}

/// Why a seek was restarted.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum MotionReason {
    /// A window mean jumped by `sigmas` (rounded) times the scatter at `position`.
    RateJump { position: u8, sigmas: u16 },
    /// The tilt moved by `change_mdeg` millidegrees from the start of the seek.
    TiltChange { change_mdeg: u32 },
    /// Not motion: the gyro link stalled; `gap_ms` of sample time between the samples
    /// around the stall (lost frames included), so the dwell has a hole (link version 2).
    GyroStall { gap_ms: u32 },
}

/// Why a seek was refused or stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum QualityError {
    /// A built-in test item failed.
    Blocked(BitItem),
    /// Base tilt |pitch| or |roll| `tilt_cdeg` (centidegrees) beyond `max_cdeg`, or no
    /// finite tilt.
    TiltOutOfRange { tilt_cdeg: u32, max_cdeg: u32 },
    /// Still moving after `max_restarts` restarts; the last reason.
    TooMuchMotion(MotionReason),
    /// The north finder's own error, as a code (`SeekError` is not serialisable).
    Finder(FinderFault),
    /// `start` while a seek runs.
    Busy,
}

/// `SeekError` on the wire.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FinderFault {
    BadConfig,
    Turntable,
    TableTimeout { position: u8 },
    TooManyInvalidWindows { position: u8 },
    InconsistentRates,
}

impl From<SeekError> for QualityError {
    fn from(e: SeekError) -> Self {
        QualityError::Finder(match e {
            SeekError::BadConfig => FinderFault::BadConfig,
            SeekError::Busy => return QualityError::Busy,
            SeekError::Turntable => FinderFault::Turntable,
            SeekError::TableTimeout { position } => FinderFault::TableTimeout { position },
            SeekError::TooManyInvalidWindows { position } => {
                FinderFault::TooManyInvalidWindows { position }
            }
            SeekError::InconsistentRates => FinderFault::InconsistentRates,
        })
    }
}

impl core::fmt::Display for QualityError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::Blocked(item) => write!(f, "seek blocked: built-in test failed: {}", item.name()),
            Self::TiltOutOfRange {
                tilt_cdeg,
                max_cdeg,
            } => write!(
                f,
                "seek refused: tilt {:.2} deg beyond the {:.2} deg range",
                tilt_cdeg as f32 / 100.0,
                max_cdeg as f32 / 100.0
            ),
            Self::TooMuchMotion(r) => write!(f, "seek stopped: base keeps moving ({r:?})"),
            Self::Finder(e) => write!(f, "seek failed: {e:?}"),
            Self::Busy => write!(f, "a seek is already running"),
        }
    }
}

impl core::error::Error for QualityError {}

/// Whether a finished seek can be trusted.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Validity {
    Valid,
    /// The observed horizontal Earth rate does not fit the latitude given by the host;
    /// `observed_latitude_deg` is acos(observed / Omega).
    LatitudeMismatch {
        observed_latitude_deg: f32,
    },
}

/// What the supervisor is doing, for the status message.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SeekState {
    /// A built-in test item fails: no seek possible.
    NotReady(BitItem),
    /// Idle, BIT passed: a seek can start.
    Ready,
    Seeking,
}

/// What one window did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SupervisorEvent {
    /// Nothing new (idle, or the seek goes on).
    Running,
    /// Motion: the seek started again from its first position.
    Restarted(MotionReason),
    Done(SeekResult, Validity),
}

#[derive(Clone, Copy, Debug, Default)]
struct Running {
    n: u16,
    mean: f64,
    m2: f64,
}

/// The north finder with its quality checks.
#[derive(Clone, Debug)]
pub struct SeekSupervisor {
    finder: NorthFinder,
    cfg: QualityConfig,
    seeking: bool,
    start_tilt: Tilt,
    position: u8,
    dwell: Running,
    /// Pooled within-dwell variance of the window means, (sum of squares, degrees of freedom).
    pooled: (f64, u32),
    restarts: u8,
    last_restart: Option<MotionReason>,
}

impl SeekSupervisor {
    pub fn new(finder: NorthFinder, cfg: QualityConfig) -> Self {
        Self {
            finder,
            cfg,
            seeking: false,
            start_tilt: Tilt::LEVEL,
            position: 0,
            dwell: Running::default(),
            pooled: (0.0, 0),
            restarts: 0,
            last_restart: None,
        }
    }

    pub fn finder(&self) -> &NorthFinder {
        &self.finder
    }

    pub fn finder_mut(&mut self) -> &mut NorthFinder {
        &mut self.finder
    }

    /// True while a seek runs (including its restarts).
    pub fn is_seeking(&self) -> bool {
        self.seeking
    }

    /// Polls the turntable of the running seek; an error ends the seek.
    pub fn poll<T: Turntable>(&mut self, table: &mut T, t_now_s: f64) -> Result<(), QualityError> {
        if !self.seeking {
            return Ok(());
        }
        self.finder.poll(table, t_now_s).map(|_| ()).map_err(|e| {
            self.abort();
            e.into()
        })
    }

    /// New seek settings (mode, latitude, dwells) for the next seek; the heading
    /// calibration is kept. Refused while seeking (`Busy`) or if `cfg` is out of range.
    pub fn reconfigure(&mut self, cfg: SeekConfig) -> Result<(), SeekError> {
        if self.seeking {
            return Err(SeekError::Busy);
        }
        let mut finder = NorthFinder::new(cfg)?;
        finder.set_heading_correction(self.finder.heading_correction().copied());
        self.finder = finder;
        Ok(())
    }

    /// Restarts of the current (or last) seek and the last reason.
    pub fn restarts(&self) -> (u8, Option<MotionReason>) {
        (self.restarts, self.last_restart)
    }

    /// State for the status message under the current BIT word.
    pub fn state(&self, bit: BitWord) -> SeekState {
        if self.seeking {
            SeekState::Seeking
        } else if let Err(item) = bit.seek_permission() {
            SeekState::NotReady(item)
        } else {
            SeekState::Ready
        }
    }

    /// Refuses a tilt outside the range (or not finite).
    pub fn check_tilt(&self, tilt: Tilt) -> Result<(), QualityError> {
        if tilt.within(self.cfg.max_tilt_deg) {
            return Ok(());
        }
        let t = tilt.max_abs_deg();
        Err(QualityError::TiltOutOfRange {
            tilt_cdeg: if t.is_finite() {
                (t * 100.0).min(u32::MAX as f32) as u32
            } else {
                u32::MAX
            },
            max_cdeg: (self.cfg.max_tilt_deg * 100.0) as u32,
        })
    }

    /// Starts a seek if the BIT word passes and the base tilt is in range.
    pub fn start<T: Turntable>(
        &mut self,
        table: &mut T,
        t_now_s: f64,
        tilt: Tilt,
        bit: BitWord,
    ) -> Result<(), QualityError> {
        if self.seeking {
            return Err(QualityError::Busy);
        }
        bit.seek_permission().map_err(QualityError::Blocked)?;
        self.check_tilt(tilt)?;
        self.restarts = 0;
        self.last_restart = None;
        self.pooled = (0.0, 0);
        self.begin(table, t_now_s, tilt)
    }

    fn begin<T: Turntable>(
        &mut self,
        table: &mut T,
        t_now_s: f64,
        tilt: Tilt,
    ) -> Result<(), QualityError> {
        self.finder.abort();
        self.finder.start(table, t_now_s)?;
        self.seeking = true;
        self.start_tilt = tilt;
        self.position = 0;
        self.dwell = Running::default();
        Ok(())
    }

    /// Abandons the seek.
    /// The gyro link stalled during the seek and samples come again `lost_s` of sample
    /// time after the last one: the dwell has a hole, so the seek starts again from its first
    /// position (`Restarted(GyroStall)`), counted against `max_restarts` like motion.
    /// Nothing happens when no seek runs.
    pub fn on_gyro_stall<T: Turntable>(
        &mut self,
        table: &mut T,
        t_now_s: f64,
        tilt: Tilt,
        lost_s: f64,
    ) -> Result<SupervisorEvent, QualityError> {
        if !self.seeking {
            return Ok(SupervisorEvent::Running);
        }
        let gap_ms = libm::round(lost_s.max(0.0) * 1000.0).min(u32::MAX as f64) as u32;
        self.restart(table, t_now_s, tilt, MotionReason::GyroStall { gap_ms })
    }

    pub fn abort(&mut self) {
        self.finder.abort();
        self.seeking = false;
    }

    /// Fraction of the seek's windows collected, 0..1 (0 when idle).
    pub fn progress(&self) -> f32 {
        if !self.seeking {
            return 0.0;
        }
        let n = self.finder.n_steps();
        let total: u32 = (0..n).map(|k| self.finder.windows_needed(k) as u32).sum();
        let (pos, windows) = match self.finder.status() {
            SeekStatus::Dwelling { position, windows } => (position as usize, windows as u32),
            SeekStatus::Moving { position } => (position as usize, 0),
            _ => (0, 0),
        };
        let done: u32 = (0..pos)
            .map(|k| self.finder.windows_needed(k) as u32)
            .sum::<u32>()
            + windows;
        (done as f32 / total.max(1) as f32).min(1.0)
    }

    /// 10 s window white-noise sigma from the ARW, deg/h.
    fn window_floor_dph(&self) -> f64 {
        self.cfg.arw_dpsh as f64 * 60.0 / libm::sqrtf(WINDOW_S) as f64
    }

    /// Predicted 1-sigma of the azimuth at the end of this seek, deg, from the window scatter
    /// observed so far (pooled over dwells; the ARW floor before two windows). Two positions:
    /// the value at |sin psi| = 1, where the acos branch is best conditioned.
    pub fn predicted_sigma_deg(&self) -> f32 {
        let (ss, dof) = self.pooled;
        let cur_dof = self.dwell.n.saturating_sub(1) as u32;
        let var_w = if dof + cur_dof > 0 {
            (ss + self.dwell.m2) / (dof + cur_dof) as f64
        } else {
            let f = self.window_floor_dph();
            f * f
        };
        let n_main = self.finder.main_windows_per_position().max(1) as f64;
        // c = (m0 - m180) / 2 has var_w / (2 n); azimuth sigma = sigma_c / Omega_H.
        let sigma_c = libm::sqrtf((var_w / (2.0 * n_main)) as f32) as f64;
        let rad = sigma_c / self.finder.omega_h_dph();
        (rad.to_degrees()) as f32
    }

    /// Feeds one window with its mean base tilt.
    pub fn on_window<T: Turntable>(
        &mut self,
        w: &WindowResult,
        tilt: Tilt,
        table: &mut T,
    ) -> Result<SupervisorEvent, QualityError> {
        if !self.seeking {
            return Ok(SupervisorEvent::Running);
        }
        if let Some(reason) = self.motion(w, tilt) {
            return self.restart(table, w.t_end_s, tilt, reason);
        }
        let status = match self.finder.on_window_tilted(w, tilt, table) {
            Ok(s) => s,
            Err(e) => {
                self.seeking = false;
                return Err(e.into());
            }
        };
        match status {
            SeekStatus::Done(r) => {
                self.seeking = false;
                self.close_dwell();
                Ok(SupervisorEvent::Done(r, self.latitude_validity(&r)))
            }
            SeekStatus::Dwelling { position, windows } => {
                if position != self.position {
                    self.close_dwell();
                    self.position = position;
                }
                if windows > self.dwell.n && w.status.is_valid() {
                    self.add_to_dwell(w.compensated_dph as f64);
                }
                Ok(SupervisorEvent::Running)
            }
            SeekStatus::Moving { position } => {
                if position != self.position {
                    self.close_dwell();
                    self.position = position;
                }
                Ok(SupervisorEvent::Running)
            }
            SeekStatus::Idle => {
                self.seeking = false;
                Ok(SupervisorEvent::Running)
            }
        }
    }

    fn add_to_dwell(&mut self, v: f64) {
        let d = &mut self.dwell;
        d.n += 1;
        let delta = v - d.mean;
        d.mean += delta / d.n as f64;
        d.m2 += delta * (v - d.mean);
    }

    fn close_dwell(&mut self) {
        if self.dwell.n >= 2 {
            self.pooled.0 += self.dwell.m2;
            self.pooled.1 += (self.dwell.n - 1) as u32;
        }
        self.dwell = Running::default();
    }

    /// Motion in this window, if any: tilt change first, then a rate jump within a dwell.
    fn motion(&self, w: &WindowResult, tilt: Tilt) -> Option<MotionReason> {
        let dp = libm::fabsf(tilt.pitch_deg - self.start_tilt.pitch_deg);
        let dr = libm::fabsf(tilt.roll_deg - self.start_tilt.roll_deg);
        let change = dp.max(dr);
        if change.is_nan() || change > self.cfg.max_tilt_change_deg {
            return Some(MotionReason::TiltChange {
                change_mdeg: if change.is_finite() {
                    (change * 1000.0).min(u32::MAX as f32) as u32
                } else {
                    u32::MAX
                },
            });
        }
        let dwelling = matches!(self.finder.status(), SeekStatus::Dwelling { .. });
        if !dwelling || self.dwell.n < 2 || !w.status.is_valid() {
            return None;
        }
        let sd = libm::sqrtf((self.dwell.m2 / (self.dwell.n - 1) as f64) as f32) as f64;
        let scale = sd.max(self.window_floor_dph());
        let dev = libm::fabs(w.compensated_dph as f64 - self.dwell.mean) / scale;
        if dev > self.cfg.motion_k as f64 {
            return Some(MotionReason::RateJump {
                position: self.position,
                sigmas: dev.min(u16::MAX as f64) as u16,
            });
        }
        None
    }

    fn restart<T: Turntable>(
        &mut self,
        table: &mut T,
        t_now_s: f64,
        tilt: Tilt,
        reason: MotionReason,
    ) -> Result<SupervisorEvent, QualityError> {
        self.last_restart = Some(reason);
        if self.restarts >= self.cfg.max_restarts {
            self.abort();
            return Err(QualityError::TooMuchMotion(reason));
        }
        self.restarts += 1;
        if let Err(e) = self.check_tilt(tilt) {
            self.abort();
            return Err(e);
        }
        self.begin(table, t_now_s, tilt)?;
        Ok(SupervisorEvent::Restarted(reason))
    }

    /// Compares the observed horizontal Earth rate with Omega cos(latitude).
    pub fn latitude_validity(&self, r: &SeekResult) -> Validity {
        let expected = self.finder.omega_h_dph();
        let allowed = self.cfg.latitude_rel_tolerance as f64 * expected
            + self.cfg.latitude_k as f64 * r.horizontal_rate_sigma_dph;
        if libm::fabs(r.horizontal_rate_dph - expected) <= allowed {
            return Validity::Valid;
        }
        let ratio = (r.horizontal_rate_dph / EARTH_RATE_DPH).clamp(0.0, 1.0);
        Validity::LatitudeMismatch {
            observed_latitude_deg: libm::acosf(ratio as f32).to_degrees(),
        }
    }

    /// Seek mode of the wrapped finder.
    pub fn mode(&self) -> SeekMode {
        self.finder.config().mode
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compensation::compensator::WindowStatus;
    use crate::hal::TableState;
    use crate::model::synthetic::SplitMix64;
    use crate::seeking::bit::BitItem;
    use crate::seeking::tilt::earth_rate_on_axis_dph;

    /// Table that settles 5 s after every command.
    struct Table {
        now_s: f64,
        at_s: f64,
        target: f32,
    }
    impl Turntable for Table {
        type Error = ();
        fn command_heading(&mut self, h: f32) -> Result<(), ()> {
            self.target = h;
            self.at_s = self.now_s;
            Ok(())
        }
        fn poll(&mut self) -> Result<TableState, ()> {
            Ok(if self.now_s - self.at_s >= 5.0 {
                TableState::Settled {
                    heading_deg: self.target,
                }
            } else {
                TableState::Moving
            })
        }
    }

    fn window(t_end_s: f64, rate: f64) -> WindowResult {
        WindowResult {
            t_start_s: t_end_s - 10.0,
            t_end_s,
            mean_rate_dph: rate as f32,
            temp_c: 25.0,
            temp_rate_cps: 0.0,
            inputs: [0.0; crate::model::format::MAX_INPUTS],
            n_inputs: 0,
            drift_dph: 0.0,
            compensated_dph: rate as f32,
            n_samples: 1000,
            n_expected: 1000,
            n_gaps: 0,
            model_applied: false,
            status: WindowStatus::Valid,
        }
    }

    struct Outcome {
        events: std::vec::Vec<SupervisorEvent>,
        result: Result<(SeekResult, Validity), QualityError>,
        progress: std::vec::Vec<f32>,
        predicted: f32,
    }

    /// Runs a four-position seek (`run_mode`).
    fn run(site_lat: f64, noise_dph: f64, disturb: impl Fn(f64) -> (f64, f32)) -> Outcome {
        run_mode(SeekMode::FourPosition, site_lat, noise_dph, disturb)
    }

    /// Runs a seek of `mode` with 60 s dwells; `site_lat` is the true latitude, the finder
    /// is told 39.9 deg. `disturb(t)` adds a rate (deg/h) and a tilt change (deg) at time t.
    fn run_mode(
        mode: SeekMode,
        site_lat: f64,
        noise_dph: f64,
        disturb: impl Fn(f64) -> (f64, f32),
    ) -> Outcome {
        let cfg = SeekConfig {
            mode,
            dwell_s: 60.0,
            ..SeekConfig::default()
        };
        let mut sup = SeekSupervisor::new(NorthFinder::new(cfg).unwrap(), QualityConfig::default());
        let mut table = Table {
            now_s: 0.0,
            at_s: 0.0,
            target: 0.0,
        };
        let base = Tilt {
            pitch_deg: 4.0,
            roll_deg: -2.0,
        };
        sup.start(&mut table, 0.0, base, BitWord::PASS).unwrap();
        let mut rng = SplitMix64::new(3);
        let mut out = Outcome {
            events: std::vec::Vec::new(),
            result: Err(QualityError::Busy),
            progress: std::vec::Vec::new(),
            predicted: f32::NAN,
        };
        for k in 1..200 {
            let t = k as f64 * 10.0;
            table.now_s = t;
            let (extra, dtilt) = disturb(t);
            let tilt = Tilt {
                pitch_deg: base.pitch_deg + dtilt,
                ..base
            };
            let g = (-2.0 * rng.unit().max(1e-300).ln()).sqrt()
                * (2.0 * core::f64::consts::PI * rng.unit()).cos();
            let rate = earth_rate_on_axis_dph(site_lat, 108.4, tilt, table.target as f64)
                + 0.2
                + extra
                + noise_dph * g;
            out.predicted = sup.predicted_sigma_deg();
            match sup.on_window(&window(t, rate), tilt, &mut table) {
                Ok(SupervisorEvent::Done(r, v)) => {
                    out.result = Ok((r, v));
                    return out;
                }
                Ok(e) => out.events.push(e),
                Err(e) => {
                    out.result = Err(e);
                    return out;
                }
            }
            out.progress.push(sup.progress());
        }
        panic!("no end");
    }

    #[test]
    fn still_seek_is_valid_with_monotone_progress_and_a_fair_prediction() {
        let o = run(39.9, 0.02, |_| (0.0, 0.0));
        let (r, v) = o.result.unwrap();
        assert_eq!(v, Validity::Valid);
        assert!(o.events.iter().all(|e| *e == SupervisorEvent::Running));
        assert!(o.progress.windows(2).all(|p| p[1] >= p[0]));
        assert!(*o.progress.last().unwrap() > 0.9);
        // The prediction before the last window is within a factor 2 of the finder's own.
        let ratio = o.predicted as f64 / r.sigma_deg;
        assert!((0.5..2.0).contains(&ratio), "{ratio}");
    }

    #[test]
    fn a_bump_and_a_tilt_change_restart_with_their_reason() {
        let o = run(39.9, 0.02, |t| {
            (if (45.0..55.0).contains(&t) { 5.0 } else { 0.0 }, 0.0)
        });
        assert!(matches!(
            o.events.iter().find(|e| **e != SupervisorEvent::Running),
            Some(SupervisorEvent::Restarted(MotionReason::RateJump { .. }))
        ));
        assert_eq!(o.result.unwrap().1, Validity::Valid);
        let o = run(39.9, 0.02, |t| (0.0, if t > 150.0 { 0.2 } else { 0.0 }));
        assert!(o.events.iter().any(|e| matches!(
            e,
            SupervisorEvent::Restarted(MotionReason::TiltChange {
                change_mdeg: 199..=200
            })
        )));
        // A base that keeps settling (tilt creeping 0.01 deg per window): gives up after
        // max_restarts, naming the reason.
        let o = run(39.9, 0.02, |t| (0.0, (t * 0.001) as f32));
        assert!(matches!(
            o.result,
            Err(QualityError::TooMuchMotion(MotionReason::TiltChange { .. }))
        ));
    }

    /// The symmetric sequences under the same checks: a still seek is valid with monotone
    /// progress and a fair prediction (its main windows are both visits'), a rate jump in
    /// the last visit restarts the seek naming that step, a wrong latitude is flagged.
    #[test]
    fn symmetric_sequences_pass_the_same_checks() {
        // The window that ends at `bump_s` is the third of the last step (5 s table moves).
        for (mode, bump_s, last_step) in [
            (SeekMode::TwoPositionSymmetric, 280.0, 4),
            (SeekMode::FourPositionSymmetric, 520.0, 6),
        ] {
            let o = run_mode(mode, 39.9, 0.02, |_| (0.0, 0.0));
            let (r, v) = o.result.unwrap();
            assert_eq!(v, Validity::Valid, "{mode:?}");
            assert!(o.events.iter().all(|e| *e == SupervisorEvent::Running));
            assert!(o.progress.windows(2).all(|p| p[1] >= p[0]), "{mode:?}");
            assert!(*o.progress.last().unwrap() > 0.9, "{mode:?}");
            let ratio = o.predicted as f64 / r.sigma_deg;
            assert!((0.5..2.0).contains(&ratio), "{mode:?} {ratio}");
            let o = run_mode(mode, 39.9, 0.02, |t| {
                (
                    if (bump_s - 5.0..bump_s + 5.0).contains(&t) {
                        5.0
                    } else {
                        0.0
                    },
                    0.0,
                )
            });
            assert!(
                matches!(
                    o.events.iter().find(|e| **e != SupervisorEvent::Running),
                    Some(SupervisorEvent::Restarted(MotionReason::RateJump { position, .. }))
                        if *position == last_step
                ),
                "{mode:?} {:?}",
                o.events.iter().find(|e| **e != SupervisorEvent::Running)
            );
            let o = run_mode(mode, 65.0, 0.005, |_| (0.0, 0.0));
            assert!(
                matches!(o.result, Ok((_, Validity::LatitudeMismatch { .. }))),
                "{mode:?}"
            );
        }
    }

    #[test]
    fn wrong_latitude_is_flagged_with_the_observed_one() {
        let o = run(65.0, 0.005, |_| (0.0, 0.0));
        match o.result.unwrap().1 {
            Validity::LatitudeMismatch {
                observed_latitude_deg,
            } => assert!(
                (observed_latitude_deg - 65.0).abs() < 1.0,
                "{observed_latitude_deg}"
            ),
            v => panic!("{v:?}"),
        }
    }

    #[test]
    fn refusals_name_their_reason() {
        let mut sup = SeekSupervisor::new(
            NorthFinder::new(SeekConfig::default()).unwrap(),
            QualityConfig::default(),
        );
        let mut table = Table {
            now_s: 0.0,
            at_s: 0.0,
            target: 0.0,
        };
        let mut bit = BitWord::PASS;
        bit.set(BitItem::Inclinometer, true);
        assert_eq!(sup.state(bit), SeekState::NotReady(BitItem::Inclinometer));
        assert_eq!(
            sup.start(&mut table, 0.0, Tilt::LEVEL, bit),
            Err(QualityError::Blocked(BitItem::Inclinometer))
        );
        let steep = Tilt {
            pitch_deg: 31.0,
            roll_deg: 0.0,
        };
        assert_eq!(
            sup.start(&mut table, 0.0, steep, BitWord::PASS),
            Err(QualityError::TiltOutOfRange {
                tilt_cdeg: 3100,
                max_cdeg: 3000
            })
        );
        assert_eq!(sup.state(BitWord::PASS), SeekState::Ready);
        sup.start(&mut table, 0.0, Tilt::LEVEL, BitWord::PASS)
            .unwrap();
        assert_eq!(sup.state(BitWord::PASS), SeekState::Seeking);
    }
}
