//! The turntable controller's side of `fog_firmware::drivers::turntable`'s ASCII protocol
//! (one line per command, CR terminated, LF tolerated) on a `SimTurntable`:
//! `MOV 180.000` -> `ACK` (move started) or `NAK` (not a heading), `POS?` ->
//! `POS 179.998 M` while moving (the true angle), `POS 180.000 S` once settled (the
//! encoder reads the commanded heading; the indexing error is what it cannot see).
//! Lines are bounded: a line longer than `MAX_LINE` is dropped up to its terminator.

use std::io::ErrorKind;

use fog_core::hal::{TableState, Turntable};

use crate::sim::SimTurntable;
use crate::upload::read_polled;

/// Longest command line kept, bytes (`MOV 359.999` is 11).
const MAX_LINE: usize = 32;

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
        let text = std::str::from_utf8(line).ok()?.trim();
        if let Some(h) = text.strip_prefix("MOV ") {
            let ok = h
                .trim()
                .parse::<f32>()
                .ok()
                .filter(|h| (0.0..360.0).contains(h))
                .is_some_and(|h| self.table.command_heading(h).is_ok());
            if ok {
                self.moves += 1;
            }
            return Some(if ok { "ACK" } else { "NAK" }.to_string());
        }
        if text == "POS?" {
            return Some(match self.table.poll() {
                Ok(TableState::Settled { heading_deg }) => format!("POS {heading_deg:.3} S"),
                Ok(TableState::Moving) => format!("POS {:.3} M", self.table.true_angle_deg()),
                Err(_) => "POS 0.000 F1".to_string(),
            });
        }
        None
    }
}
