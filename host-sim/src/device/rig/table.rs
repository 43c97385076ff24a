//! The turntable controller's side of the ASCII line protocol
//! (`fog_core::sensor_link::table_line`, the one the firmware's driver speaks) on a
//! `SimTurntable`:
//! `MOV 180.000` -> `ACK` (move started) or `NAK` (not a heading), `POS?` ->
//! `POS 179.998 M` while moving (the true angle), `POS 180.000 S` once settled (the
//! encoder reads the commanded heading; the indexing error is what it cannot see).
//! Lines are bounded: a line longer than `MAX_LINE` is dropped up to its terminator.

use std::io::ErrorKind;

use fog_core::hal::{TableState, Turntable};
use fog_core::sensor_link::table_line::{
    deg_to_mdeg, CommandError, TableCommand, TableMotion, TableReply, TABLE_LINE_MAX,
};

use crate::device::upload::read_polled;
use crate::sim::SimTurntable;

/// Longest command line kept, bytes (`MOV 359.999` is 11).
const MAX_LINE: usize = TABLE_LINE_MAX;

/// The table controller.
pub struct TableServer {
    table: SimTurntable,
    line: Vec<u8>,
    overflow: bool,
    moves: u64,
}

impl TableServer {
    pub fn new(table: SimTurntable) -> Self {
        Self {
            table,
            line: Vec::with_capacity(MAX_LINE),
            overflow: false,
            moves: 0,
        }
    }

    pub fn table_mut(&mut self) -> &mut SimTurntable {
        &mut self.table
    }

    /// Moves commanded so far.
    pub fn moves(&self) -> u64 {
        self.moves
    }

    /// Reads what the link has (its read timeout bounds the wait) and answers every
    /// complete line; returns the number of commands answered. Err: the link closed.
    pub fn serve(&mut self, link: &mut dyn super::Link) -> std::io::Result<u64> {
        let mut buf = [0u8; 64];
        let n = match read_polled(link, &mut buf)? {
            Some(0) => return Err(ErrorKind::UnexpectedEof.into()),
            Some(n) => n,
            None => 0,
        };
        let mut answered = 0;
        for &b in &buf[..n] {
            if b == b'\r' || b == b'\n' {
                let line = std::mem::take(&mut self.line);
                if !std::mem::take(&mut self.overflow) && !line.is_empty() {
                    if let Some(reply) = self.answer(&line) {
                        link.write_all(format!("{reply}\r").as_bytes())?;
                        answered += 1;
                    }
                }
            } else if self.line.len() < MAX_LINE {
                self.line.push(b);
            } else {
                self.overflow = true;
            }
        }
        link.flush()?;
        Ok(answered)
    }

    /// The reply to one command line (`None`: not a command, ignored).
    pub fn answer(&mut self, line: &[u8]) -> Option<String> {
        let reply = match TableCommand::parse(line) {
            Err(CommandError::NotACommand) => return None,
            Err(CommandError::NotAHeading) => TableReply::Nak,
            Ok(TableCommand::Move { heading_mdeg }) => {
                let ok = self
                    .table
                    .command_heading(heading_mdeg as f32 / 1000.0)
                    .is_ok();
                self.moves += u64::from(ok);
                if ok {
                    TableReply::Ack
                } else {
                    TableReply::Nak
                }
            }
            Ok(TableCommand::QueryPosition) => match self.table.poll() {
                Ok(TableState::Settled { heading_deg }) => TableReply::Position {
                    angle_mdeg: deg_to_mdeg(f64::from(heading_deg)),
                    motion: TableMotion::Settled,
                },
                Ok(TableState::Moving) => TableReply::Position {
                    angle_mdeg: deg_to_mdeg(self.table.true_angle_deg()),
                    motion: TableMotion::Moving,
                },
                Err(_) => TableReply::Position {
                    angle_mdeg: 0,
                    motion: TableMotion::Fault(1),
                },
            },
        };
        Some(String::from_utf8_lossy(&reply.encode()).into_owned())
    }
}
