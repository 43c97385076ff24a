//! The model-slot flash region, and the field-record ring's, each as an `embedded_storage`
//! NOR flash. Under QEMU a region (linker symbols `_models_start`/`_models_end`,
//! `_field_start`/`_field_end`, see memory.x) is plain memory,
//! so this driver enforces NOR semantics itself: erase sets 4 KiB sectors to 0xFF,
//! a write can only clear bits. A real board replaces this file with its flash
//! controller driver (same traits, same geometry or its own). Under QEMU `AppFlash`
//! mirrors each region into its own host file, so both persist across QEMU restarts.

use core::ptr::{addr_of, read_volatile, write_volatile};

use embedded_storage::nor_flash::{
    check_erase, check_read, check_write, ErrorType, NorFlash, NorFlashError, NorFlashErrorKind,
    ReadNorFlash,
};

extern "C" {
    static _models_start: u8;
    static _models_end: u8;
    static _field_start: u8;
    static _field_end: u8;
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FlashError(pub NorFlashErrorKind);

impl NorFlashError for FlashError {
    fn kind(&self) -> NorFlashErrorKind {
        self.0
    }
}

pub struct ModelFlash {
    base: usize,
    len: usize,
}

impl ModelFlash {
    /// # Safety
    /// Only one `ModelFlash` may exist: it owns the region.
    pub unsafe fn take() -> Self {
        let base = addr_of!(_models_start) as usize;
        let end = addr_of!(_models_end) as usize;
        Self {
            base,
            len: end - base,
        }
    }

    /// The field-record ring's region (`fog_firmware::field_log`).
    ///
    /// # Safety
    /// Only one may exist: it owns the region.
    pub unsafe fn take_field() -> Self {
        let base = addr_of!(_field_start) as usize;
        let end = addr_of!(_field_end) as usize;
        Self {
            base,
            len: end - base,
        }
    }

    fn byte(&self, off: usize) -> u8 {
        // SAFETY: off < len (checked by the callers), region owned by self.
        unsafe { read_volatile((self.base + off) as *const u8) }
    }

    fn set(&mut self, off: usize, v: u8) {
        // SAFETY: as above.
        unsafe { write_volatile((self.base + off) as *mut u8, v) }
    }
}

impl ErrorType for ModelFlash {
    type Error = FlashError;
}

impl ReadNorFlash for ModelFlash {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), FlashError> {
        check_read(self, offset, bytes.len()).map_err(FlashError)?;
        for (i, b) in bytes.iter_mut().enumerate() {
            *b = self.byte(offset as usize + i);
        }
        Ok(())
    }

    fn capacity(&self) -> usize {
        self.len
    }
}

impl NorFlash for ModelFlash {
    const WRITE_SIZE: usize = 4;
    const ERASE_SIZE: usize = 4096;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), FlashError> {
        check_erase(self, from, to).map_err(FlashError)?;
        for off in from as usize..to as usize {
            self.set(off, 0xFF);
        }
        Ok(())
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), FlashError> {
        check_write(self, offset, bytes.len()).map_err(FlashError)?;
        for (i, &b) in bytes.iter().enumerate() {
            let off = offset as usize + i;
            let old = self.byte(off);
            self.set(off, old & b);
        }
        Ok(())
    }
}

/// The model flash `fog-app` uses. Under QEMU (semihosting builds) it is mirrored into
/// the host file named by `flash-file=PATH`, so models survive a QEMU restart
/// (`flash_file.rs`); otherwise the region alone.
#[cfg(feature = "log-semihosting")]
pub type AppFlash =
    fog_firmware::store::mirrored::MirroredFlash<ModelFlash, crate::flash_file::HostImage>;
#[cfg(not(feature = "log-semihosting"))]
pub type AppFlash = ModelFlash;

/// Takes the model region (and, under QEMU, attaches its image file).
///
/// # Safety
/// As [`ModelFlash::take`]: called once.
pub unsafe fn take_app_flash() -> AppFlash {
    // SAFETY: forwarded to the caller.
    let flash = unsafe { ModelFlash::take() };
    #[cfg(feature = "log-semihosting")]
    {
        let mut flash = flash;
        let image = crate::flash_file::open_image(&mut flash, crate::flash_file::MODELS_ARG);
        fog_firmware::store::mirrored::MirroredFlash::new(flash, image)
    }
    #[cfg(not(feature = "log-semihosting"))]
    flash
}

/// Takes the field-record region (and, under QEMU, attaches the `field-file=` image).
///
/// # Safety
/// As [`ModelFlash::take_field`]: called once.
pub unsafe fn take_field_flash() -> AppFlash {
    // SAFETY: forwarded to the caller.
    let flash = unsafe { ModelFlash::take_field() };
    #[cfg(feature = "log-semihosting")]
    {
        let mut flash = flash;
        let image = crate::flash_file::open_image(&mut flash, crate::flash_file::FIELD_ARG);
        fog_firmware::store::mirrored::MirroredFlash::new(flash, image)
    }
    #[cfg(not(feature = "log-semihosting"))]
    flash
}
