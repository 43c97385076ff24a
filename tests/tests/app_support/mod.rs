//! Shared by the host tests of `fog_firmware::app`: a turntable that settles at once.
#![allow(dead_code)]

use fog_core::hal::{TableState, Turntable};

/// A table that settles at once wherever it is told to go; `.0` is its heading, deg.
pub struct InstantTable(pub f32);

impl Turntable for InstantTable {
    type Error = ();
    fn command_heading(&mut self, h: f32) -> Result<(), ()> {
        self.0 = h;
        Ok(())
    }
    fn poll(&mut self) -> Result<TableState, ()> {
        Ok(TableState::Settled {
            heading_deg: self.0,
        })
    }
}
