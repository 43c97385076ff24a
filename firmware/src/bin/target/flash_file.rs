//! The QEMU build's persistent model flash: the model region mirrored into a host file
//! through semihosting, so a model uploaded in one QEMU process is in flash when QEMU
//! is started again on the same file (mps2-an386 has no pflash to do this).
//!
//! The file is named by the semihosting argument `flash-file=PATH`. At boot:
//! - no argument: the region is RAM only (models are lost when QEMU exits);
//! - the file exists: it must be exactly the region's size, and is loaded into it;
//!   any other file is refused whole (region erased, file untouched, reason logged);
//! - the file does not exist: it is created, fully erased (0xFF).
//!
//! Afterwards every erase and write is written through (`fog_firmware::store::mirrored`).
//! The field-record ring's region is kept the same way in its own file (`field-file=PATH`).
//! Each outcome is logged, also as a plain `FOG-FLASH` line on the semihosting console.

use core::ffi::CStr;
use core::sync::atomic::{AtomicU32, Ordering};

use embedded_storage::nor_flash::{NorFlash, ReadNorFlash};
use fog_firmware::store::mirrored::{load_image, Backing, BackingFailed, ImageError};
use semihosting::fs::File;
use semihosting::io::{Read as _, Seek as _, SeekFrom, Write as _};

use crate::flash::ModelFlash;
use crate::semi::Args;

/// The semihosting argument naming the model flash's image file.
pub const MODELS_ARG: &str = "flash-file=";
/// The semihosting argument naming the field-record ring's image file.
pub const FIELD_ARG: &str = "field-file=";

/// The flash image file, opened for reading and writing.
pub struct HostImage(File);

/// `flash-cut-at=N` (0: none): the N-th write to the image since boot is not made;
/// the firmware says so on the console and waits to be killed, so a test cuts the power
/// at a known point of an upload (tests/tests/qemu_power_cut.rs).
static CUT_AT: AtomicU32 = AtomicU32::new(0);
/// `flash-tear-at=N` (0: none): the N-th write is made in its first half only (a write
/// torn by the power cut), then the firmware waits to be killed.
static TEAR_AT: AtomicU32 = AtomicU32::new(0);
static WRITES: AtomicU32 = AtomicU32::new(0);

/// Arms the power-cut point (`flash-cut-at=N`); call before the first write.
pub fn cut_at(n: u32) {
    CUT_AT.store(n, Ordering::Relaxed);
}

/// Arms the torn-write point (`flash-tear-at=N`); call before the first write.
pub fn tear_at(n: u32) {
    TEAR_AT.store(n, Ordering::Relaxed);
}

/// Writes made to the images since boot.
pub fn writes() -> u32 {
    WRITES.load(Ordering::Relaxed)
}

impl Backing for HostImage {
    fn write_at(&mut self, offset: u32, bytes: &[u8]) -> Result<(), BackingFailed> {
        let n = WRITES.fetch_add(1, Ordering::Relaxed) + 1;
        if n == CUT_AT.load(Ordering::Relaxed) {
            semihosting::eprintln!("FOG-FLASH-CUT write={} offset={}", n, offset);
            // Powerless from here: only the watchdog is kept quiet until the kill.
            loop {
                crate::watchdog::feed();
            }
        }
        let torn = n == TEAR_AT.load(Ordering::Relaxed);
        // Torn: the first half of the bytes, in whole 4-byte flash words.
        let bytes = if torn {
            bytes.get(..bytes.len() / 8 * 4).unwrap_or(&[])
        } else {
            bytes
        };
        self.0
            .seek(SeekFrom::Start(u64::from(offset)))
            .map_err(|_| BackingFailed)?;
        self.0.write_all(bytes).map_err(|_| BackingFailed)?;
        if torn {
            semihosting::eprintln!(
                "FOG-FLASH-TEAR write={} offset={} bytes={}",
                n,
                offset,
                bytes.len()
            );
            loop {
                crate::watchdog::feed();
            }
        }
        Ok(())
    }
}

/// Loads or creates the image named on the command line by `arg` (`MODELS_ARG`,
/// `FIELD_ARG`); `None`: no persistence.
pub fn open_image(flash: &mut ModelFlash, arg: &str) -> Option<HostImage> {
    let args = Args::get().ok()?;
    let path = (0..args.len()).find_map(|i| args.value_path(i, arg))?;
    let name = path.to_str().unwrap_or("<not UTF-8>");
    match attach(flash, path) {
        Ok((image, what)) => {
            defmt::info!("flash image: {} ({})", name, what);
            semihosting::eprintln!("FOG-FLASH file={} {}", name, what);
            Some(image)
        }
        Err(why) => {
            defmt::error!("flash image {} refused: not kept across restarts", name);
            semihosting::eprintln!("FOG-FLASH file={} refused: {}", name, why);
            None
        }
    }
}

/// Why the image file is not used.
enum AttachError {
    Image(ImageError),
    File(&'static str),
}

impl core::fmt::Display for AttachError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Image(e) => write!(f, "{e} (file left as it was)"),
            Self::File(e) => f.write_str(e),
        }
    }
}

fn attach(flash: &mut ModelFlash, path: &CStr) -> Result<(HostImage, &'static str), AttachError> {
    let capacity = flash.capacity();
    if let Ok(mut existing) = File::open(path) {
        load_image(flash, |buf| existing.read(buf).map_err(|_| BackingFailed))
            .map_err(AttachError::Image)?;
        drop(existing);
        let file = File::options()
            .read(true)
            .write(true)
            .open(path)
            .map_err(|_| AttachError::File("loaded, but cannot be opened for writing"))?;
        return Ok((HostImage(file), "loaded"));
    }
    let mut file = File::options()
        .read(true)
        .write(true)
        .create(true)
        .truncate(true)
        .open(path)
        .map_err(|_| AttachError::File("cannot be created"))?;
    let erased = [0xFFu8; 256];
    for _ in 0..capacity / erased.len() {
        file.write_all(&erased)
            .map_err(|_| AttachError::File("cannot be written"))?;
    }
    flash
        .erase(0, capacity as u32)
        .map_err(|_| AttachError::File("flash erase failed"))?;
    Ok((HostImage(file), "created, erased"))
}
