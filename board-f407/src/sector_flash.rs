//! The model slots in the STM32F407's own flash: sectors 10 and 11 (0x080C_0000,
//! 128 KiB each, linker symbols `_models_start`/`_models_end`) as an `embedded_storage`
//! NOR flash for the A/B store: ERASE_SIZE = one 128 KiB sector (one slot per sector),
//! WRITE_SIZE = 4 (32-bit parallelism, VDD 2.7-3.6 V).
//!
//! Register level (RM0090 §3.9; FLASH at 0x4002_3C00: ACR 0x00, KEYR 0x04, SR 0x0C,
//! CR 0x10) rather than the HAL's `UnlockedFlash`, which erases with 8-bit parallelism
//! (a 128 KiB sector: 2 s typical, 4 s max; 32-bit: 1 s / 2 s, datasheet "Flash memory
//! programming") and keeps the controller unlocked while it lives. Here the controller
//! is unlocked per operation and locked again, errors are read from SR, and the data
//! cache is reset after each change so reads never see stale lines. The CPU stalls on
//! instruction fetch while the bank erases (one bank on the F407): the watchdog is fed
//! just before each sector erase, and its period (3 s) covers the 2 s worst case; the
//! gyro DMA keeps running, so an erase loses at most what overflows its ring.

use core::ptr::{addr_of, read_volatile, write_volatile};

use embedded_storage::nor_flash::{
    check_erase, check_read, check_write, ErrorType, NorFlash, NorFlashError, NorFlashErrorKind,
    ReadNorFlash,
};

extern "C" {
    static _models_start: u8;
    static _models_end: u8;
}

const FLASH: usize = 0x4002_3C00;
const ACR: usize = 0x00;
const KEYR: usize = 0x04;
const SR: usize = 0x0C;
const CR: usize = 0x10;
const KEY1: u32 = 0x4567_0123;
const KEY2: u32 = 0xCDEF_89AB;
const SR_BSY: u32 = 1 << 16;
/// OPERR, WRPERR, PGAERR, PGPERR, PGSERR (write 1 to clear), and EOP.
const SR_ERRORS: u32 = 0b1111_0010;
const SR_EOP: u32 = 1;
const CR_PG: u32 = 1 << 0;
const CR_SER: u32 = 1 << 1;
const CR_SNB_SHIFT: u32 = 3;
const CR_PSIZE_X32: u32 = 0b10 << 8;
const CR_STRT: u32 = 1 << 16;
const CR_LOCK: u32 = 1 << 31;
const ACR_DCEN: u32 = 1 << 10;
const ACR_DCRST: u32 = 1 << 12;
/// Sector of `_models_start`, and its address on a 1 MiB F407.
const FIRST_SECTOR: u32 = 10;
const FIRST_SECTOR_ADDR: usize = 0x080C_0000;
const SECTOR_LEN: usize = 128 * 1024;
/// IWDG key register: writing 0xAAAA reloads the counter.
const IWDG_KR: usize = 0x4000_3000;

/// What the flash controller reported.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum SectorFlashError {
    /// Misaligned or out of range (`NorFlashErrorKind` as a code: 0 alignment, 1 range).
    Bounds(u8),
    /// SR error bits after the operation (OPERR/WRPERR/PGAERR/PGPERR/PGSERR).
    Controller(u32),
}

impl NorFlashError for SectorFlashError {
    fn kind(&self) -> NorFlashErrorKind {
        match self {
            Self::Bounds(0) => NorFlashErrorKind::NotAligned,
            Self::Bounds(_) => NorFlashErrorKind::OutOfBounds,
            Self::Controller(_) => NorFlashErrorKind::Other,
        }
    }
}

fn bounds(kind: NorFlashErrorKind) -> SectorFlashError {
    SectorFlashError::Bounds(u8::from(kind != NorFlashErrorKind::NotAligned))
}

fn read_reg(off: usize) -> u32 {
    // SAFETY: a FLASH controller register.
    unsafe { read_volatile((FLASH + off) as *const u32) }
}

fn write_reg(off: usize, v: u32) {
    // SAFETY: as above; the controller is owned by the one `SectorFlash`.
    unsafe { write_volatile((FLASH + off) as *mut u32, v) }
}

/// Sectors 10 and 11.
pub struct SectorFlash {
    base: usize,
    len: usize,
}

impl SectorFlash {
    /// The model sectors, or `None` if the linker's `MODELS` region is not exactly
    /// sectors 10-11 (a changed memory.x must never make an erase hit the code).
    ///
    /// # Safety
    /// Only one `SectorFlash` may exist, and nothing else may use the flash controller.
    pub unsafe fn take() -> Option<Self> {
        let base = addr_of!(_models_start) as usize;
        let end = addr_of!(_models_end) as usize;
        (base == FIRST_SECTOR_ADDR && end == FIRST_SECTOR_ADDR + 2 * SECTOR_LEN).then_some(Self {
            base,
            len: end - base,
        })
    }

    /// Runs `op` with the controller unlocked, then waits, checks and locks it again.
    fn unlocked(&mut self, op: impl FnOnce()) -> Result<(), SectorFlashError> {
        while read_reg(SR) & SR_BSY != 0 {}
        write_reg(SR, SR_ERRORS | SR_EOP);
        if read_reg(CR) & CR_LOCK != 0 {
            write_reg(KEYR, KEY1);
            write_reg(KEYR, KEY2);
        }
        op();
        while read_reg(SR) & SR_BSY != 0 {}
        let errors = read_reg(SR) & SR_ERRORS;
        write_reg(CR, CR_LOCK);
        // Drop cached lines of the changed area (RM0090 §3.5.2: reset with DCEN off).
        let acr = read_reg(ACR);
        write_reg(ACR, acr & !ACR_DCEN);
        write_reg(ACR, (acr & !ACR_DCEN) | ACR_DCRST);
        write_reg(ACR, acr & !ACR_DCRST);
        if errors != 0 {
            write_reg(SR, errors);
            return Err(SectorFlashError::Controller(errors));
        }
        Ok(())
    }
}

impl ErrorType for SectorFlash {
    type Error = SectorFlashError;
}

impl ReadNorFlash for SectorFlash {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        check_read(self, offset, bytes.len()).map_err(bounds)?;
        for (i, b) in bytes.iter_mut().enumerate() {
            // SAFETY: inside the model sectors (checked above).
            *b = unsafe { read_volatile((self.base + offset as usize + i) as *const u8) };
        }
        Ok(())
    }

    fn capacity(&self) -> usize {
        self.len
    }
}

impl NorFlash for SectorFlash {
    const WRITE_SIZE: usize = 4;
    const ERASE_SIZE: usize = SECTOR_LEN;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        check_erase(self, from, to).map_err(bounds)?;
        for sector in (from as usize / SECTOR_LEN)..(to as usize / SECTOR_LEN) {
            let snb = FIRST_SECTOR + sector as u32;
            // SAFETY: IWDG reload key (the erase stalls the CPU for up to 2 s).
            unsafe { write_volatile(IWDG_KR as *mut u32, 0xAAAA) };
            self.unlocked(|| {
                let cr = CR_PSIZE_X32 | CR_SER | (snb << CR_SNB_SHIFT);
                write_reg(CR, cr);
                write_reg(CR, cr | CR_STRT);
            })?;
        }
        Ok(())
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        check_write(self, offset, bytes.len()).map_err(bounds)?;
        let base = self.base + offset as usize;
        self.unlocked(|| {
            write_reg(CR, CR_PSIZE_X32 | CR_PG);
            for (i, word) in bytes.chunks_exact(4).enumerate() {
                let value = u32::from_le_bytes([word[0], word[1], word[2], word[3]]);
                // SAFETY: an aligned word inside the model sectors (checked above).
                unsafe { write_volatile((base + 4 * i) as *mut u32, value) };
                while read_reg(SR) & SR_BSY != 0 {}
            }
        })
    }
}
