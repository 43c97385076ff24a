//! The fault record that survives a reset, and the reset-loop rule built on it.
//!
//! Every fatal path (panic, HardFault, fatal boot error, watchdog) records why it reset
//! the chip; the next boot reports it. A fault that recurs at every boot would reset
//! the device for ever, so the record also counts **faults in a row**: resets by a fault
//! with neither a clean run (`CLEAN_RUN_S` of main loop without a fault) nor a good
//! model upload in between. After `SAFE_MODE_AFTER` of them the device boots into safe
//! mode: the host link and the upload server only, with the count and the last cause in
//! every status, until a good upload clears the count.
//!
//! Where it lives: in RAM that cortex-m-rt never initialises (`.uninit`), six words with
//! a magic word and a CRC-32 over the others, so power-on garbage (or a record of an
//! older layout, which had another magic) reads as "power-on" and never as a fault. The
//! flash store is not used: a record written at every fault would wear the model
//! sectors and could itself be cut by the reset. The target side (`resets.rs` under
//! `src/bin/target/`) only moves [`RawRecord`]s in and out of that RAM.

use fog_core::link::messages::FaultState;
use fog_core::link::upload::{ResetCause, ResetRecord};
use fog_core::model::crc::crc32;

/// Faults in a row that put the device in safe mode. One fault may be a glitch and a
/// second its after-effect (a watchdog reset while recovering); a third with no clean
/// run between is a loop.
pub const SAFE_MODE_AFTER: u32 = 3;

/// Main-loop time without a fault after which the run counts as clean and the count
/// of faults in a row is cleared, s: one 10 s compensation window, longer than every
/// boot path (all fatal boot errors, the store scan, the first gyro samples) and than
/// the 0.5 s watchdog deadline.
pub const CLEAN_RUN_S: f64 = 10.0;

/// Marks a record of this layout (an older layout had another magic and is ignored).
const MAGIC: u32 = 0xF0C5_FA17;

/// The record as stored: plain words, any bit pattern possible after power-on.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RawRecord {
    pub magic: u32,
    pub cause: u32,
    pub detail: u32,
    pub boots: u32,
    pub faults_in_a_row: u32,
    pub crc: u32,
}

/// What the record says: the reset it describes and the faults in a row so far.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FaultRecord {
    pub reset: ResetRecord,
    pub faults_in_a_row: u32,
}

impl RawRecord {
    fn crc_of(&self) -> u32 {
        let mut bytes = [0u8; 20];
        let words = [
            self.magic,
            self.cause,
            self.detail,
            self.boots,
            self.faults_in_a_row,
        ];
        for (chunk, w) in bytes.chunks_exact_mut(4).zip(words) {
            chunk.copy_from_slice(&w.to_le_bytes());
        }
        crc32(&bytes)
    }

    /// `record` with its magic and CRC.
    pub fn sealed(record: FaultRecord) -> Self {
        let mut raw = Self {
            magic: MAGIC,
            cause: cause_code(record.reset.cause),
            detail: record.reset.detail,
            boots: record.reset.boots,
            faults_in_a_row: record.faults_in_a_row,
            crc: 0,
        };
        raw.crc = raw.crc_of();
        raw
    }

    /// The record, if the words are one (magic, CRC and a known cause).
    pub fn open(&self) -> Option<FaultRecord> {
        if self.magic != MAGIC || self.crc != self.crc_of() {
            return None;
        }
        Some(FaultRecord {
            reset: ResetRecord {
                cause: cause_of(self.cause)?,
                detail: self.detail,
                boots: self.boots,
            },
            faults_in_a_row: self.faults_in_a_row,
        })
    }
}

fn cause_code(cause: ResetCause) -> u32 {
    match cause {
        ResetCause::PowerOn => 0,
        ResetCause::Watchdog => 1,
        ResetCause::Panic => 2,
        ResetCause::FatalBoot => 3,
        ResetCause::Exception => 4,
    }
}

fn cause_of(code: u32) -> Option<ResetCause> {
    Some(match code {
        0 => ResetCause::PowerOn,
        1 => ResetCause::Watchdog,
        2 => ResetCause::Panic,
        3 => ResetCause::FatalBoot,
        4 => ResetCause::Exception,
        _ => return None,
    })
}

impl FaultRecord {
    /// A first boot after power-on, no fault.
    pub const POWER_ON: Self = Self {
        reset: ResetRecord::POWER_ON,
        faults_in_a_row: 0,
    };

    /// This boot's record from what the previous run left (`None`: no valid record,
    /// i.e. power-on). Every cause but power-on is a fault and adds one to the count.
    pub fn at_boot(previous: Option<FaultRecord>) -> Self {
        let Some(p) = previous else {
            return Self::POWER_ON;
        };
        let fault = p.reset.cause != ResetCause::PowerOn;
        Self {
            reset: ResetRecord {
                boots: p.reset.boots.saturating_add(1),
                ..p.reset
            },
            faults_in_a_row: if fault {
                p.faults_in_a_row.saturating_add(1)
            } else {
                0
            },
        }
    }

    /// What to store while this boot runs: "watchdog", since a reset that records
    /// nothing else can only be the hardware watchdog's.
    pub fn armed(&self) -> Self {
        Self {
            reset: ResetRecord {
                cause: ResetCause::Watchdog,
                detail: 0,
                boots: self.reset.boots,
            },
            faults_in_a_row: self.faults_in_a_row,
        }
    }

    /// The record of a fatal `cause` in this run (boots and count kept; the next boot
    /// adds this fault to the count).
    pub fn fatal(&self, cause: ResetCause, detail: u32) -> Self {
        Self {
            reset: ResetRecord {
                cause,
                detail,
                boots: self.reset.boots,
            },
            faults_in_a_row: self.faults_in_a_row,
        }
    }

    /// After a clean run or a good upload: no faults in a row any more.
    pub fn cleared(&self) -> Self {
        Self {
            faults_in_a_row: 0,
            ..*self
        }
    }

    /// True if this boot must come up in safe mode.
    pub fn safe_mode(&self) -> bool {
        self.faults_in_a_row >= SAFE_MODE_AFTER
    }

    /// The link status' view: count, safe mode, and the last reset's cause and detail.
    pub fn state(&self, safe_mode: bool) -> FaultState {
        FaultState {
            faults_in_a_row: self.faults_in_a_row.min(u32::from(u8::MAX)) as u8,
            safe_mode,
            last_cause: self.reset.cause,
            last_detail: self.reset.detail,
        }
    }
}

/// Fatal boot errors (`ResetRecord::detail` of a `FatalBoot` reset).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u32)]
pub enum BootFault {
    /// The core peripherals were already taken (a software bug).
    CorePeripherals = 1,
    /// The model store's flash geometry does not hold two slots.
    StoreGeometry = 2,
    /// The application configuration was refused even without a model.
    Configuration = 3,
    /// A static singleton was initialised twice.
    Singleton = 4,
}

impl BootFault {
    pub const ALL: [Self; 4] = [
        Self::CorePeripherals,
        Self::StoreGeometry,
        Self::Configuration,
        Self::Singleton,
    ];

    /// The name in firmware arguments (`inject=boot-fault=NAME`) and docs.
    pub fn name(self) -> &'static str {
        match self {
            Self::CorePeripherals => "core-peripherals",
            Self::StoreGeometry => "store-geometry",
            Self::Configuration => "configuration",
            Self::Singleton => "singleton",
        }
    }

    pub fn code(self) -> u32 {
        self as u32
    }
}

/// Decides when a run has been clean long enough to clear the faults in a row: once,
/// at the first main-loop pass at or after `CLEAN_RUN_S`, and only if there is
/// something to clear.
#[derive(Clone, Copy, Debug)]
pub struct CleanRun {
    pending: bool,
}

impl CleanRun {
    pub fn new(boot: &FaultRecord) -> Self {
        Self {
            pending: boot.faults_in_a_row > 0,
        }
    }

    /// `true` exactly once, when the record is to be cleared (`now_s`: s since boot).
    pub fn due(&mut self, now_s: f64) -> bool {
        let due = self.pending && now_s >= CLEAN_RUN_S;
        if due {
            self.pending = false;
        }
        due
    }
}
