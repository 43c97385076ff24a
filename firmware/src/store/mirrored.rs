//! A NOR flash whose every change is written through to a backing image, so the model
//! store survives a restart of an emulator that has no persistent flash.
//!
//! QEMU's `mps2-an386` has no flash controller and no pflash: the model region is RAM,
//! lost when QEMU exits. The QEMU build therefore mirrors the region into a host file
//! (semihosting, `src/bin/target/flash_file.rs`): at boot the file is loaded into the
//! region ([`load_image`]), and afterwards each erase or write goes to the region first
//! and then, as the bytes the region now holds, to the same offset of the file. The
//! file is thus an exact image of the flash after every completed operation; a kill
//! between the two steps leaves the file one operation behind, which the A/B store
//! already treats like a power cut (the slot being written is incomplete).
//!
//! Once the backing has failed, every further erase and write fails too (like a flash
//! after a power cut): the region and the file may differ by that one operation, and
//! the store, seeing `Flash` errors, keeps the slot it had.

use embedded_storage::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash,
};

/// Where a flash image is kept (a host file under QEMU; a `Vec` in the host tests).
pub trait Backing {
    /// Writes `bytes` at `offset` of the image; all of them or an error.
    fn write_at(&mut self, offset: u32, bytes: &[u8]) -> Result<(), BackingFailed>;
}

/// The backing image could not be written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BackingFailed;

/// Failure of a [`MirroredFlash`] operation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MirrorError<E> {
    /// The flash itself refused (bounds, alignment, ...).
    Flash(E),
    /// The backing image could not be written (now, or earlier: the mirror is broken).
    Backing,
}

impl<E: NorFlashError> NorFlashError for MirrorError<E> {
    fn kind(&self) -> NorFlashErrorKind {
        match self {
            Self::Flash(e) => e.kind(),
            Self::Backing => NorFlashErrorKind::Other,
        }
    }
}

/// `flash` with every change written through to `backing` (`None`: no backing, the
/// flash alone, e.g. QEMU started without a flash file).
pub struct MirroredFlash<F, B> {
    flash: F,
    backing: Option<B>,
    broken: bool,
}

/// Bytes copied per backing write (erase fill and read-back chunks).
const CHUNK: usize = 256;

impl<F: NorFlash, B: Backing> MirroredFlash<F, B> {
    /// Mirrors `flash` into `backing`, which must already hold the same bytes (see
    /// [`load_image`]).
    pub fn new(flash: F, backing: Option<B>) -> Self {
        Self {
            flash,
            backing,
            broken: false,
        }
    }

    /// `true` while changes reach the backing (a backing exists and never failed).
    pub fn persistent(&self) -> bool {
        self.backing.is_some() && !self.broken
    }

    /// The flash and the backing back (tests reboot from the backing's image).
    pub fn into_parts(self) -> (F, Option<B>) {
        (self.flash, self.backing)
    }

    /// Copies `flash[offset..offset + len]` (as it now reads) into the backing.
    fn write_through(&mut self, offset: u32, len: usize) -> Result<(), MirrorError<F::Error>> {
        let Some(backing) = self.backing.as_mut() else {
            return Ok(());
        };
        if self.broken {
            return Err(MirrorError::Backing);
        }
        let mut piece = [0u8; CHUNK];
        let mut at = offset;
        let end = offset as usize + len;
        while (at as usize) < end {
            let n = (end - at as usize).min(CHUNK);
            self.flash
                .read(at, &mut piece[..n])
                .map_err(MirrorError::Flash)?;
            if backing.write_at(at, &piece[..n]).is_err() {
                self.broken = true;
                return Err(MirrorError::Backing);
            }
            at += n as u32;
        }
        Ok(())
    }

    fn usable(&self) -> Result<(), MirrorError<F::Error>> {
        if self.broken {
            Err(MirrorError::Backing)
        } else {
            Ok(())
        }
    }
}

impl<F: NorFlash, B> ErrorType for MirroredFlash<F, B> {
    type Error = MirrorError<F::Error>;
}

impl<F: NorFlash, B: Backing> ReadNorFlash for MirroredFlash<F, B> {
    const READ_SIZE: usize = F::READ_SIZE;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        self.flash.read(offset, bytes).map_err(MirrorError::Flash)
    }

    fn capacity(&self) -> usize {
        self.flash.capacity()
    }
}

impl<F: NorFlash, B: Backing> NorFlash for MirroredFlash<F, B> {
    const WRITE_SIZE: usize = F::WRITE_SIZE;
    const ERASE_SIZE: usize = F::ERASE_SIZE;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        self.usable()?;
        self.flash.erase(from, to).map_err(MirrorError::Flash)?;
        self.write_through(from, to.saturating_sub(from) as usize)
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        self.usable()?;
        self.flash
            .write(offset, bytes)
            .map_err(MirrorError::Flash)?;
        self.write_through(offset, bytes.len())
    }
}

/// Why a backing image was not loaded (the flash is then left erased and the image
/// untouched: a bad image is refused whole, never overwritten).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ImageError {
    /// The image is not exactly the flash's size (bytes found; the read stops at
    /// capacity + 1).
    Size { found: usize, expected: usize },
    /// Reading the image failed.
    Read,
    /// Erasing or programming the flash failed.
    Flash,
}

impl core::fmt::Display for ImageError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Size { found, expected } => write!(
                f,
                "image is {found} bytes{}, the flash {expected}: not a flash image",
                if found > expected { " or more" } else { "" }
            ),
            Self::Read => f.write_str("image read failed"),
            Self::Flash => f.write_str("flash erase/program failed while loading the image"),
        }
    }
}

/// Erases `flash` and programs it with the image `read` delivers (a reader filling a
/// buffer and returning the bytes read, 0 at the end). The image must be exactly
/// `flash.capacity()` bytes; otherwise the flash is left erased and an error returned.
pub fn load_image<F: NorFlash>(
    flash: &mut F,
    mut read: impl FnMut(&mut [u8]) -> Result<usize, BackingFailed>,
) -> Result<(), ImageError> {
    let capacity = flash.capacity();
    flash
        .erase(0, capacity as u32)
        .map_err(|_| ImageError::Flash)?;
    let mut piece = [0u8; CHUNK];
    let mut at = 0usize;
    loop {
        // Fill a whole piece (readers may return short counts) so writes stay aligned.
        let mut filled = 0;
        while filled < CHUNK {
            match read(&mut piece[filled..]).map_err(|_| ImageError::Read)? {
                0 => break,
                n => filled += n,
            }
        }
        if filled == 0 {
            break;
        }
        if at + filled > capacity || !filled.is_multiple_of(F::WRITE_SIZE) {
            let found = at + filled;
            let _ = flash.erase(0, capacity as u32);
            return Err(ImageError::Size {
                found,
                expected: capacity,
            });
        }
        // An erased word reads 0xFF; programming it with 0xFF is skipped (NOR: a word is
        // programmed once per erase).
        for (i, word) in piece[..filled].chunks_exact(F::WRITE_SIZE).enumerate() {
            if word.iter().any(|&b| b != 0xFF) {
                let offset = (at + i * F::WRITE_SIZE) as u32;
                flash.write(offset, word).map_err(|_| ImageError::Flash)?;
            }
        }
        at += filled;
        if filled < CHUNK {
            break;
        }
    }
    if at != capacity {
        let _ = flash.erase(0, capacity as u32);
        return Err(ImageError::Size {
            found: at,
            expected: capacity,
        });
    }
    Ok(())
}
