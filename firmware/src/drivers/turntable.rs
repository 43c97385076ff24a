//! Indexing turntable controller on a serial line as a `fog_core::hal::Turntable`.
//!
//! The ASCII line protocol (`MOV 180.000` -> `ACK`/`NAK`, `POS?` -> `POS 179.998 M`/`S`/
//! `F<n>`) is defined once, in `fog_core::sensor_link::table_line`, which the host's rig
//! also speaks; this driver adds the timing.
//!
//! Everything is non-blocking: `command_heading` queues the command, `poll` pushes bytes
//! out, reads replies, queries the position every `query_interval_s` while moving and
//! enforces the timeouts. Faults are reported, never hidden: no ACK or no reply within
//! `reply_timeout_s` is `Timeout`, not settled within `move_timeout_s` is `MoveTimeout`,
//! settled further than `position_tolerance_deg` from the command is `PositionFault`,
//! a controller fault code is `Fault`. After an error the driver stays failed (each
//! `poll` repeats the error) until a new command is given.

use embedded_hal_nb::nb;
use embedded_hal_nb::serial::{Error as _, ErrorKind, Read, Write};
use fog_core::hal::{TableState, Turntable};
use fog_core::sensor_link::table_line::{TableCommand, TableLine, TableMotion, TableReply};

use crate::clock::Clock;

/// Timing and tolerance of a table controller.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TurntableConfig {
    /// Longest wait for an `ACK` or a `POS` reply, s.
    pub reply_timeout_s: f64,
    /// Longest time from command to settled, s.
    pub move_timeout_s: f64,
    /// Position query interval while moving, s.
    pub query_interval_s: f64,
    /// Largest accepted |settled - commanded|, deg.
    pub position_tolerance_deg: f32,
}

impl Default for TurntableConfig {
    fn default() -> Self {
        Self {
            reply_timeout_s: 0.5,
            move_timeout_s: 30.0,
            query_interval_s: 0.1,
            position_tolerance_deg: 0.01,
        }
    }
}

/// Why a move failed.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TurntableError {
    /// UART error while talking to the controller.
    Serial(SerialFault),
    /// No reply to a command or query within the reply timeout.
    Timeout,
    /// The controller refused the command (`NAK`).
    Rejected,
    /// The controller reports fault code n.
    Fault(u8),
    /// Settled, but not where commanded.
    PositionFault { commanded_deg: f32, actual_deg: f32 },
    /// Not settled within the move timeout.
    MoveTimeout,
    /// A reply that is not part of the protocol.
    Garbled,
    /// The heading is not a finite angle.
    BadHeading,
    /// `poll` before any command.
    NotCommanded,
}

/// Serial error kinds (a `Copy` mirror of `embedded_hal_nb::serial::ErrorKind`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SerialFault {
    Overrun,
    FrameFormat,
    Parity,
    Noise,
    Other,
}

impl From<ErrorKind> for SerialFault {
    fn from(kind: ErrorKind) -> Self {
        match kind {
            ErrorKind::Overrun => Self::Overrun,
            ErrorKind::FrameFormat => Self::FrameFormat,
            ErrorKind::Parity => Self::Parity,
            ErrorKind::Noise => Self::Noise,
            _ => Self::Other,
        }
    }
}

impl core::fmt::Display for TurntableError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Serial(k) => write!(f, "turntable: serial error {k:?}"),
            Self::Timeout => write!(f, "turntable: no reply within the reply timeout"),
            Self::Rejected => write!(f, "turntable: controller refused the move (NAK)"),
            Self::Fault(n) => write!(f, "turntable: controller fault code {n}"),
            Self::PositionFault {
                commanded_deg,
                actual_deg,
            } => write!(
                f,
                "turntable: settled at {actual_deg} deg, commanded {commanded_deg} deg"
            ),
            Self::MoveTimeout => write!(f, "turntable: not settled within the move timeout"),
            Self::Garbled => write!(f, "turntable: unparseable reply"),
            Self::BadHeading => write!(f, "turntable: commanded heading is not finite"),
            Self::NotCommanded => write!(f, "turntable: polled before any command"),
        }
    }
}

impl core::error::Error for TurntableError {}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Phase {
    Idle,
    AwaitAck {
        deadline_s: f64,
    },
    Moving {
        query_deadline_s: Option<f64>,
        next_query_s: f64,
    },
    Settled {
        heading_deg: f32,
    },
    Failed(TurntableError),
}

/// Serial turntable controller driver.
pub struct SerialTurntable<S, C> {
    uart: S,
    clock: C,
    config: TurntableConfig,
    phase: Phase,
    target_deg: f32,
    move_deadline_s: f64,
    tx: TableLine,
    tx_sent: usize,
    rx: TableLine,
}

impl<S: Read<u8> + Write<u8>, C: Clock> SerialTurntable<S, C> {
    pub fn new(uart: S, clock: C, config: TurntableConfig) -> Self {
        Self {
            uart,
            clock,
            config,
            phase: Phase::Idle,
            target_deg: 0.0,
            move_deadline_s: 0.0,
            tx: TableLine::new(),
            tx_sent: 0,
            rx: TableLine::new(),
        }
    }

    /// Give the UART back.
    pub fn release(self) -> S {
        self.uart
    }

    fn queue_line(&mut self, line: &[u8]) {
        self.tx.clear();
        self.tx_sent = 0;
        // A `TableLine` holds the longest command ("MOV 359.999\r" is 12 bytes).
        let _ = self.tx.extend_from_slice(line);
        let _ = self.tx.push(b'\r');
    }

    /// Push queued bytes until the UART would block.
    fn flush_tx(&mut self) -> Result<(), TurntableError> {
        while self.tx_sent < self.tx.len() {
            match self.uart.write(self.tx[self.tx_sent]) {
                Ok(()) => self.tx_sent += 1,
                Err(nb::Error::WouldBlock) => return Ok(()),
                Err(nb::Error::Other(e)) => return Err(TurntableError::Serial(e.kind().into())),
            }
        }
        Ok(())
    }

    /// Read bytes until a full line is available or the UART would block.
    fn read_line(&mut self) -> Result<Option<TableLine>, TurntableError> {
        loop {
            match self.uart.read() {
                Ok(b'\r' | b'\n') => {
                    if self.rx.is_empty() {
                        continue;
                    }
                    return Ok(Some(core::mem::take(&mut self.rx)));
                }
                Ok(b) => {
                    if self.rx.push(b).is_err() {
                        self.rx.clear();
                        return Err(TurntableError::Garbled);
                    }
                }
                Err(nb::Error::WouldBlock) => return Ok(None),
                Err(nb::Error::Other(e)) => return Err(TurntableError::Serial(e.kind().into())),
            }
        }
    }

    fn step(&mut self) -> Result<TableState, TurntableError> {
        let now = self.clock.now_s();
        self.flush_tx()?;
        while let Some(line) = self.read_line()? {
            self.handle_line(&line, now)?;
        }
        match self.phase {
            Phase::Idle => Err(TurntableError::NotCommanded),
            Phase::Failed(e) => Err(e),
            Phase::Settled { heading_deg } => Ok(TableState::Settled { heading_deg }),
            Phase::AwaitAck { deadline_s } if now > deadline_s => Err(TurntableError::Timeout),
            Phase::AwaitAck { .. } => Ok(TableState::Moving),
            Phase::Moving { .. } if now > self.move_deadline_s => Err(TurntableError::MoveTimeout),
            Phase::Moving {
                query_deadline_s: Some(d),
                ..
            } if now > d => Err(TurntableError::Timeout),
            Phase::Moving {
                query_deadline_s: None,
                next_query_s,
            } if now >= next_query_s => {
                self.queue_line(&TableCommand::QueryPosition.encode());
                self.flush_tx()?;
                self.phase = Phase::Moving {
                    query_deadline_s: Some(now + self.config.reply_timeout_s),
                    next_query_s,
                };
                Ok(TableState::Moving)
            }
            Phase::Moving { .. } => Ok(TableState::Moving),
        }
    }

    fn handle_line(&mut self, line: &[u8], now: f64) -> Result<(), TurntableError> {
        let reply = TableReply::parse(line).ok_or(TurntableError::Garbled)?;
        match (self.phase, reply) {
            (Phase::AwaitAck { .. }, TableReply::Ack) => {
                self.phase = Phase::Moving {
                    query_deadline_s: None,
                    next_query_s: now + self.config.query_interval_s,
                };
                Ok(())
            }
            (Phase::AwaitAck { .. }, TableReply::Nak) => Err(TurntableError::Rejected),
            (Phase::Moving { .. }, TableReply::Position { angle_mdeg, motion }) => {
                let pos_deg = angle_mdeg as f32 / 1000.0;
                match motion {
                    TableMotion::Fault(code) => Err(TurntableError::Fault(code)),
                    TableMotion::Moving => {
                        self.phase = Phase::Moving {
                            query_deadline_s: None,
                            next_query_s: now + self.config.query_interval_s,
                        };
                        Ok(())
                    }
                    TableMotion::Settled => {
                        if libm::fabsf(angle_diff_deg(pos_deg, self.target_deg))
                            > self.config.position_tolerance_deg
                        {
                            return Err(TurntableError::PositionFault {
                                commanded_deg: self.target_deg,
                                actual_deg: pos_deg,
                            });
                        }
                        self.phase = Phase::Settled {
                            heading_deg: pos_deg,
                        };
                        Ok(())
                    }
                }
            }
            // A late reply after settling or failing: nothing to learn from it.
            (_, TableReply::Position { .. }) => Ok(()),
            (_, TableReply::Fault(code)) => Err(TurntableError::Fault(code)),
            _ => Err(TurntableError::Garbled),
        }
    }
}

impl<S: Read<u8> + Write<u8>, C: Clock> Turntable for SerialTurntable<S, C> {
    type Error = TurntableError;

    fn command_heading(&mut self, heading_deg: f32) -> Result<(), TurntableError> {
        if !heading_deg.is_finite() {
            return Err(TurntableError::BadHeading);
        }
        let heading = wrap_360(heading_deg);
        let mdeg = ((heading * 1000.0 + 0.5) as u32) % 360_000;
        self.queue_line(&TableCommand::Move { heading_mdeg: mdeg }.encode());
        self.rx.clear();
        let now = self.clock.now_s();
        self.target_deg = mdeg as f32 / 1000.0;
        self.move_deadline_s = now + self.config.move_timeout_s;
        self.phase = Phase::AwaitAck {
            deadline_s: now + self.config.reply_timeout_s,
        };
        self.flush_tx()
            .inspect_err(|&e| self.phase = Phase::Failed(e))
    }

    fn poll(&mut self) -> Result<TableState, TurntableError> {
        let result = self.step();
        if let Err(e) = result {
            if self.phase != Phase::Idle {
                self.phase = Phase::Failed(e);
            }
        }
        result
    }
}

/// Signed shortest difference a - b on the circle, deg.
fn angle_diff_deg(a: f32, b: f32) -> f32 {
    let d = wrap_360(a - b);
    if d > 180.0 {
        d - 360.0
    } else {
        d
    }
}

/// x modulo 360 in [0, 360) (360 itself for tiny negative x, as f32 rounds it). Exact
/// in f64 (`fog_core::numeric::wrap_360_deg`, |x| < 3e21) instead of f32 `%`, whose
/// `fmodf` pulls 1.5 KB of 64-bit division into the firmware.
fn wrap_360(x: f32) -> f32 {
    fog_core::numeric::wrap_360_deg(x as f64) as f32
}
