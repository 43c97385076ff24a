//! `fogsim field pull`'s link client: asks the device for its field records from
//! sequence 0 (or a given one), a bounded batch per request, until a reply carries none.
//!
//! Each request is preceded by `FIELD_REQUEST_PADDING` zero bytes (empty frames the device
//! ignores) that pay for the answer under the device's reply budget (it never sends more
//! bytes than it received). Status frames the device sends meanwhile are skipped. Memory
//! stays bounded: at most `max_records` records are kept, then the pull stops with an error.

use std::io::{Read, Write};
use std::time::{Duration, Instant};

use anyhow::{bail, Result};
use fog_core::link::messages::{
    decode, encode, Command, DeviceFrame, DeviceMessage, FieldRecordBatch, HostFrame,
    FIELD_REQUEST_PADDING, MAX_FIELD_RECORDS_PER_REPLY,
};
use fog_core::link::upload::{FrameReceiver, MAX_WIRE_FRAME_LEN};
use fog_core::seeking::field_record::FieldRecord;

use crate::device::upload::read_polled;

/// Most records one pull keeps (a 16 KiB ring holds ~450).
pub const MAX_PULLED_RECORDS: usize = 100_000;

/// Pulls every record with sequence >= `from` (oldest first), waiting at most `timeout`
/// for each reply.
pub fn pull_records<L: Read + Write>(
    link: &mut L,
    from: u32,
    timeout: Duration,
    max_records: usize,
) -> Result<Vec<FieldRecord>> {
    let mut out: Vec<FieldRecord> = Vec::new();
    let mut next = from;
    loop {
        let batch = request(link, next, timeout)?;
        if !batch.readable {
            bail!("the device could not read its field log (flash fault)");
        }
        let records = batch.records();
        let Some(last) = records.last() else {
            return Ok(out);
        };
        for r in records {
            if r.sequence < next || !r.is_plausible() {
                bail!(
                    "device sent record {} out of order or implausible (asked from {next})",
                    r.sequence
                );
            }
        }
        if out.len() + records.len() > max_records {
            bail!("more than {max_records} field records: stopped (raise the limit)");
        }
        out.extend_from_slice(records);
        if batch.newest_sequence.is_some_and(|n| last.sequence >= n) {
            return Ok(out);
        }
        next = match last.sequence.checked_add(1) {
            Some(n) => n,
            None => return Ok(out),
        };
    }
}

/// One `GetFieldRecords` and its answer.
fn request<L: Read + Write>(
    link: &mut L,
    from: u32,
    timeout: Duration,
) -> Result<FieldRecordBatch> {
    let mut wire = [0u8; MAX_WIRE_FRAME_LEN];
    let cmd = Command::GetFieldRecords {
        from_sequence: from,
        max_count: MAX_FIELD_RECORDS_PER_REPLY as u8,
    };
    let n = encode(&HostFrame::Link(cmd), &mut wire)
        .map_err(|e| anyhow::anyhow!("encoding the request: {e}"))?;
    link.write_all(&[0u8; FIELD_REQUEST_PADDING])?;
    link.write_all(&wire[..n])?;
    link.flush()?;
    let deadline = Instant::now() + timeout;
    let mut rx = FrameReceiver::new();
    let mut buf = [0u8; 256];
    while Instant::now() < deadline {
        let got = match read_polled(link, &mut buf)? {
            Some(0) => bail!("the device closed the link"),
            Some(k) => k,
            None => continue,
        };
        for &b in &buf[..got] {
            let Some(Ok(payload)) = rx.push(b) else {
                continue;
            };
            match decode::<DeviceFrame>(payload) {
                Ok(DeviceFrame::Link(DeviceMessage::FieldRecords(batch))) => return Ok(batch),
                Ok(DeviceFrame::Link(DeviceMessage::Refused(why))) => {
                    bail!("the device refused GetFieldRecords: {why:?}")
                }
                _ => {}
            }
        }
    }
    bail!("no field-record reply within {timeout:?} (asked from sequence {from})")
}
