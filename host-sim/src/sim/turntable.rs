//! Simulated single-axis indexing turntable (implements `fog_core::hal::Turntable`).
//!
//! It shares a clock with the `SimGyro` it carries (see `sim::rig`): time advances
//! only as gyro samples are read, exactly as on the device where samples keep arriving
//! while the firmware polls the table. A move turns at `rate_dps` along the shorter way,
//! lands with a random indexing error and reports `Settled` after `settle_s`; while it
//! turns, the gyro senses the table rate.

use super::checks::{non_negative, positive};
use super::error::SimError;
use fog_core::hal::{TableState, Turntable};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use std::cell::RefCell;
use std::fmt;
use std::rc::Rc;

/// Mechanical properties of the table.
#[derive(Clone, Debug, PartialEq)]
pub struct TurntableParams {
    /// Slew rate, deg/s.
    pub rate_dps: f64,
    /// Time after the end of a move before the table reports `Settled`, s.
    pub settle_s: f64,
    /// Indexing error of each stop, deg (1 sigma).
    pub indexing_sigma_deg: f64,
}

impl Default for TurntableParams {
    /// A precision indexing table: 20 deg/s, 2 s settling, 0.001 deg (3.6") indexing.
    fn default() -> Self {
        Self {
            rate_dps: 20.0,
            settle_s: 2.0,
            indexing_sigma_deg: 0.001,
        }
    }
}

impl TurntableParams {
    /// Checks every parameter.
    pub fn validate(&self) -> Result<(), SimError> {
        positive("turntable.rate_dps", self.rate_dps)?;
        non_negative("turntable.settle_s", self.settle_s)?;
        non_negative("turntable.indexing_sigma_deg", self.indexing_sigma_deg)
    }
}

/// One commanded move.
#[derive(Clone, Copy, Debug)]
struct Motion {
    t0_s: f64,
    start_deg: f64,
    delta_deg: f64,
    move_s: f64,
    settle_s: f64,
    commanded_deg: f32,
}

impl Motion {
    fn angle_deg(&self, t_s: f64) -> f64 {
        let f = if self.move_s > 0.0 {
            ((t_s - self.t0_s) / self.move_s).clamp(0.0, 1.0)
        } else {
            1.0
        };
        self.start_deg + self.delta_deg * f
    }

    fn settled_at_s(&self) -> f64 {
        self.t0_s + self.move_s + self.settle_s
    }
}

/// State shared between the table and the gyro on it.
#[derive(Debug)]
pub struct TableShared {
    now_s: f64,
    motion: Motion,
}

impl TableShared {
    fn new(initial_deg: f64) -> Self {
        let motion = Motion {
            t0_s: 0.0,
            start_deg: initial_deg,
            delta_deg: 0.0,
            move_s: 0.0,
            settle_s: 0.0,
            commanded_deg: initial_deg as f32,
        };
        Self { now_s: 0.0, motion }
    }

    /// Table angle (table frame, not wrapped), deg, at `t_s`.
    pub fn angle_deg(&self, t_s: f64) -> f64 {
        self.motion.angle_deg(t_s)
    }

    /// Advances the shared clock (called by the gyro).
    pub fn set_now(&mut self, t_s: f64) {
        self.now_s = t_s;
    }
}

/// Handle through which the gyro reads the table.
pub type TableLink = Rc<RefCell<TableShared>>;

/// Errors of the simulated table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TurntableError {
    /// A NaN or infinite heading was commanded.
    NonFiniteHeading,
}

impl fmt::Display for TurntableError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TurntableError::NonFiniteHeading => {
                write!(f, "turntable: commanded heading is not finite")
            }
        }
    }
}

impl std::error::Error for TurntableError {}

/// The simulated table.
#[derive(Debug)]
pub struct SimTurntable {
    params: TurntableParams,
    shared: TableLink,
    rng: ChaCha8Rng,
}

impl SimTurntable {
    /// A table at angle `initial_deg`, with its own random stream for indexing errors.
    pub(crate) fn new(params: TurntableParams, initial_deg: f64, rng: ChaCha8Rng) -> Self {
        Self {
            params,
            shared: Rc::new(RefCell::new(TableShared::new(initial_deg))),
            rng,
        }
    }

    /// The link the gyro needs to sense the table.
    pub(crate) fn link(&self) -> TableLink {
        Rc::clone(&self.shared)
    }

    /// True table angle now (including indexing error), deg, wrapped to 0..360.
    pub fn true_angle_deg(&self) -> f64 {
        let s = self.shared.borrow();
        s.angle_deg(s.now_s).rem_euclid(360.0)
    }

    /// Current simulation time, s since power-on.
    pub fn now_s(&self) -> f64 {
        self.shared.borrow().now_s
    }
}

impl Turntable for SimTurntable {
    type Error = TurntableError;

    fn command_heading(&mut self, heading_deg: f32) -> Result<(), Self::Error> {
        if !heading_deg.is_finite() {
            return Err(TurntableError::NonFiniteHeading);
        }
        let err: f64 = self.rng.sample::<f64, _>(StandardNormal) * self.params.indexing_sigma_deg;
        let mut s = self.shared.borrow_mut();
        let now = s.now_s;
        let start = s.angle_deg(now);
        let target = f64::from(heading_deg) + err;
        let delta = (target - start + 180.0).rem_euclid(360.0) - 180.0;
        s.motion = Motion {
            t0_s: now,
            start_deg: start,
            delta_deg: delta,
            move_s: delta.abs() / self.params.rate_dps,
            settle_s: self.params.settle_s,
            commanded_deg: heading_deg.rem_euclid(360.0),
        };
        Ok(())
    }

    fn poll(&mut self) -> Result<TableState, Self::Error> {
        let s = self.shared.borrow();
        if s.now_s >= s.motion.settled_at_s() {
            Ok(TableState::Settled {
                heading_deg: s.motion.commanded_deg,
            })
        } else {
            Ok(TableState::Moving)
        }
    }
}
