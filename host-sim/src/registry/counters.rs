//! Security counters: issued once each, strictly increasing per gyro, never 0.
//!
//! The device refuses a model whose counter is not above its floor (the highest counter it
//! holds); the registry makes sure the PC never signs two models with one counter, which
//! would let an old signed model be replayed in place of a newer one with the same counter.
//! A counter is issued (and so spent) before the upload starts: a failed upload does not
//! give it back.

use rusqlite::{params, OptionalExtension, TransactionBehavior};

use super::Registry;
use crate::io::utc::now_utc;

/// Why a requested counter is refused (the issue is then not recorded).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CounterRefusal {
    /// 0 is never issued: a device with nothing installed has floor 0, and a counter-0
    /// model could otherwise be installed again and again.
    Zero,
    /// Not above the last counter this registry issued for the gyro (reuse or rollback).
    NotAboveIssued { requested: u32, last_issued: u32 },
    /// Not above the counter of the model the device runs.
    NotAboveDevice { requested: u32, device: u32 },
    /// The counter space of this gyro is used up.
    Exhausted,
}

impl std::fmt::Display for CounterRefusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Self::Zero => write!(f, "security counter 0 is never issued (counters start at 1)"),
            Self::NotAboveIssued { requested, last_issued } => write!(
                f,
                "security counter {requested} is not above {last_issued}, the last one issued for this gyro: counters are never reused"
            ),
            Self::NotAboveDevice { requested, device } => write!(
                f,
                "security counter {requested} is not above the device's {device}: it would refuse it as a rollback"
            ),
            Self::Exhausted => write!(f, "security counters of this gyro are used up (4294967295 issued)"),
        }
    }
}

impl std::error::Error for CounterRefusal {}

impl Registry {
    /// Issues the counter for the next upload of the model with CRC `model_crc32` to
    /// `gyro_id`: `requested` if it is above both the last issued and the device's floor
    /// (`device_counter`), else refused; without a request, one above both. One
    /// `BEGIN IMMEDIATE` transaction: concurrent issuers are serialised, and the primary
    /// key (gyro, counter) makes a second issue of one counter impossible in any case.
    pub fn issue_counter(
        &mut self,
        gyro_id: &str,
        requested: Option<u32>,
        device_counter: u32,
        model_crc32: u32,
    ) -> anyhow::Result<u32> {
        if requested == Some(0) {
            return Err(CounterRefusal::Zero.into());
        }
        let tx = self
            .conn
            .transaction_with_behavior(TransactionBehavior::Immediate)?;
        let last_issued = last_counter_in(&tx, gyro_id)?.unwrap_or(0);
        let counter = match requested {
            Some(c) if c <= last_issued => {
                return Err(CounterRefusal::NotAboveIssued {
                    requested: c,
                    last_issued,
                }
                .into())
            }
            Some(c) if c <= device_counter => {
                return Err(CounterRefusal::NotAboveDevice {
                    requested: c,
                    device: device_counter,
                }
                .into())
            }
            Some(c) => c,
            None => last_issued
                .max(device_counter)
                .checked_add(1)
                .ok_or(CounterRefusal::Exhausted)?,
        };
        tx.execute(
            "INSERT INTO counters (gyro_id, counter, issued_utc, model_crc32) VALUES (?1, ?2, ?3, ?4)",
            params![gyro_id, counter, now_utc(), model_crc32],
        )?;
        tx.commit()?;
        Ok(counter)
    }

    /// The highest counter issued for `gyro_id`, if any.
    pub fn last_counter(&self, gyro_id: &str) -> anyhow::Result<Option<u32>> {
        Ok(last_counter_in(&self.conn, gyro_id)?)
    }
}

fn last_counter_in(conn: &rusqlite::Connection, gyro_id: &str) -> rusqlite::Result<Option<u32>> {
    conn.query_row(
        "SELECT max(counter) FROM counters WHERE gyro_id = ?1",
        [gyro_id],
        |r| r.get::<_, Option<u32>>(0),
    )
    .optional()
    .map(Option::flatten)
}

#[cfg(test)]
mod tests {
    use super::super::test_registry;
    use super::*;

    fn refusal(e: anyhow::Error) -> CounterRefusal {
        *e.downcast_ref::<CounterRefusal>()
            .expect("a counter refusal")
    }

    #[test]
    fn counters_increase_are_never_reused_and_never_zero() {
        let (dir, mut reg) = test_registry("counters");
        assert_eq!(reg.last_counter("G1").unwrap(), None);
        assert_eq!(
            refusal(reg.issue_counter("G1", Some(0), 0, 1).unwrap_err()),
            CounterRefusal::Zero
        );
        assert_eq!(reg.issue_counter("G1", None, 0, 1).unwrap(), 1);
        // The device already runs counter 5 (installed by another PC): the next is 6.
        assert_eq!(reg.issue_counter("G1", None, 5, 1).unwrap(), 6);
        assert_eq!(
            refusal(reg.issue_counter("G1", Some(6), 0, 1).unwrap_err()),
            CounterRefusal::NotAboveIssued {
                requested: 6,
                last_issued: 6
            }
        );
        assert_eq!(
            refusal(reg.issue_counter("G1", Some(3), 0, 1).unwrap_err()),
            CounterRefusal::NotAboveIssued {
                requested: 3,
                last_issued: 6
            }
        );
        assert_eq!(
            refusal(reg.issue_counter("G1", Some(8), 9, 1).unwrap_err()),
            CounterRefusal::NotAboveDevice {
                requested: 8,
                device: 9
            }
        );
        assert_eq!(reg.issue_counter("G1", Some(10), 9, 1).unwrap(), 10);
        // Other gyros have their own sequence.
        assert_eq!(reg.issue_counter("G2", None, 0, 1).unwrap(), 1);
        assert_eq!(reg.last_counter("G1").unwrap(), Some(10));
        assert_eq!(
            refusal(reg.issue_counter("G3", None, u32::MAX, 1).unwrap_err()),
            CounterRefusal::Exhausted
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
