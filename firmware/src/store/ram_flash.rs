//! A NOR flash held in RAM, with real NOR rules and optional power-cut injection.
//!
//! Two uses: the host tests cut power after any number of word writes / page erases to
//! prove the A/B store never exposes a torn model, and the QEMU build (mps2-an386 has
//! no flash controller) stores models in it. NOR rules enforced: erase sets a page to
//! 0xFF; a write may only program an erased word (no second write to the same word
//! before an erase) and can only clear bits; a cut write leaves that word half
//! programmed, a cut erase leaves that page half erased, and after a cut every
//! operation fails until `power_cycle` (the "reboot").

use embedded_storage::nor_flash::{
    check_erase, check_read, check_write, ErrorType, NorFlash, NorFlashError, NorFlashErrorKind,
    ReadNorFlash,
};

/// Failure of a [`RamNorFlash`] operation.
// No defmt::Format: embedded-storage's NorFlashErrorKind does not implement it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RamFlashError {
    /// Misaligned or out of range (the `embedded-storage` kind).
    Bounds(NorFlashErrorKind),
    /// A write to a word that was not erased since its last write.
    NotErased { offset: u32 },
    /// The injected power cut happened (or had happened) during this operation.
    PowerLost,
}

impl NorFlashError for RamFlashError {
    fn kind(&self) -> NorFlashErrorKind {
        match self {
            Self::Bounds(kind) => *kind,
            Self::NotErased { .. } | Self::PowerLost => NorFlashErrorKind::Other,
        }
    }
}

/// `N` bytes of NOR flash with `W`-byte words and `E`-byte erase pages.
#[derive(Clone)]
pub struct RamNorFlash<const N: usize, const W: usize, const E: usize> {
    mem: [u8; N],
    /// Word writes + page erases still allowed before the power cut (`None`: never cut).
    ops_before_cut: Option<u32>,
    powered: bool,
    ops_done: u32,
}

impl<const N: usize, const W: usize, const E: usize> Default for RamNorFlash<N, W, E> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize, const W: usize, const E: usize> RamNorFlash<N, W, E> {
    /// A fully erased device.
    pub const fn new() -> Self {
        Self {
            mem: [0xFF; N],
            ops_before_cut: None,
            powered: true,
            ops_done: 0,
        }
    }

    /// Cuts the power after `ops` more word writes / page erases: operation number `ops`
    /// (0-based from now) is torn and fails, and so does everything after it.
    pub fn cut_power_after(&mut self, ops: u32) {
        self.ops_before_cut = Some(ops);
    }

    /// Power back on (the reboot); no further cut is scheduled.
    pub fn power_cycle(&mut self) {
        self.ops_before_cut = None;
        self.powered = true;
    }

    /// Word writes + page erases performed so far (the cut points of a sequence).
    pub fn ops_done(&self) -> u32 {
        self.ops_done
    }

    /// Whether the injected cut has happened.
    pub fn power_lost(&self) -> bool {
        !self.powered
    }

    /// The raw contents (for inspection in tests).
    pub fn contents(&self) -> &[u8] {
        &self.mem
    }

    /// Spends one operation of the power budget; `false` if this operation is the torn one.
    fn spend_op(&mut self) -> Result<bool, RamFlashError> {
        if !self.powered {
            return Err(RamFlashError::PowerLost);
        }
        if let Some(left) = self.ops_before_cut.as_mut() {
            if *left == 0 {
                self.powered = false;
                return Ok(false);
            }
            *left -= 1;
        }
        self.ops_done += 1;
        Ok(true)
    }
}

impl<const N: usize, const W: usize, const E: usize> ErrorType for RamNorFlash<N, W, E> {
    type Error = RamFlashError;
}

impl<const N: usize, const W: usize, const E: usize> ReadNorFlash for RamNorFlash<N, W, E> {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        check_read(self, offset, bytes.len()).map_err(RamFlashError::Bounds)?;
        if !self.powered {
            return Err(RamFlashError::PowerLost);
        }
        let start = offset as usize;
        bytes.copy_from_slice(&self.mem[start..start + bytes.len()]);
        Ok(())
    }

    fn capacity(&self) -> usize {
        N
    }
}

impl<const N: usize, const W: usize, const E: usize> NorFlash for RamNorFlash<N, W, E> {
    const WRITE_SIZE: usize = W;
    const ERASE_SIZE: usize = E;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        check_erase(self, from, to).map_err(RamFlashError::Bounds)?;
        for page in (from as usize..to as usize).step_by(E) {
            let complete = self.spend_op()?;
            let page_mem = &mut self.mem[page..page + E];
            if complete {
                page_mem.fill(0xFF);
            } else {
                // Torn erase: the first half of the page made it to 0xFF, the rest did not.
                page_mem[..E / 2].fill(0xFF);
                return Err(RamFlashError::PowerLost);
            }
        }
        Ok(())
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        check_write(self, offset, bytes.len()).map_err(RamFlashError::Bounds)?;
        for (i, word) in bytes.chunks_exact(W).enumerate() {
            let at = offset as usize + i * W;
            if self.mem[at..at + W].iter().any(|&b| b != 0xFF) {
                return Err(RamFlashError::NotErased { offset: at as u32 });
            }
            let complete = self.spend_op()?;
            let target = &mut self.mem[at..at + W];
            if complete {
                target.iter_mut().zip(word).for_each(|(m, w)| *m &= w);
            } else {
                // Torn write: only the first half of the word's bytes got programmed.
                target[..W.div_ceil(2)]
                    .iter_mut()
                    .zip(word)
                    .for_each(|(m, w)| *m &= w);
                return Err(RamFlashError::PowerLost);
            }
        }
        Ok(())
    }
}
