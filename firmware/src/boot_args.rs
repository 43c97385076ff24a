//! The firmware's program arguments (semihosting, QEMU only), parsed in one place so
//! that an argument the firmware does not know, or a value it cannot read, is refused
//! at boot with its name instead of being ignored (a typo such as `gyro-rat=200` used to
//! run silently at 2 kHz). docs/guide/firmware.md lists every argument in one table; this
//! parser is the source of that table. Hardware builds have no arguments.

use crate::fault_record::BootFault;

/// One line naming every argument, for the refusal message.
pub const KNOWN: &str = "flash-file=PATH field-file=PATH gyro-rate=HZ seek-dwell-s=S \
tilt-mdeg=PITCH:ROLL inject=panic|hang|panic-after-commit|hardfault|boot-fault=NAME \
flash-cut-at=N flash-tear-at=N";

/// A fault the QEMU scenarios inject (first boot only, except where noted).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Inject {
    None,
    /// A Rust panic at boot.
    Panic,
    /// The main loop stops feeding the watchdog.
    Hang,
    /// A panic right after the next committed upload.
    PanicAfterCommit,
    /// An undefined instruction at boot: a HardFault.
    HardFault,
    /// This fatal boot error, taken where the boot detects it.
    Boot(BootFault),
}

/// Everything the arguments set; `None`: the firmware's default.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BootArgs {
    pub inject: Inject,
    /// `gyro-rate=HZ`: the gyro's frame rate (QEMU cannot carry 2 kHz in real time).
    pub gyro_rate_hz: Option<u32>,
    /// `seek-dwell-s=S`: dwell per main seek position, s.
    pub seek_dwell_s: Option<u32>,
    /// `tilt-mdeg=PITCH:ROLL`: the simulated inclinometer's base tilt, millidegrees.
    pub tilt_mdeg: Option<(i32, i32)>,
    /// `flash-file=PATH` was given (opened by the flash driver itself).
    pub flash_file: bool,
    /// `flash-cut-at=N`: stop before the N-th write to the flash image (1 = first
    /// since boot) and wait there to be killed: a power cut at a known point.
    pub flash_cut_at: Option<u32>,
    /// `field-file=PATH` was given (the field-record ring's image, opened by the flash
    /// driver itself).
    pub field_file: bool,
    /// `flash-tear-at=N`: the N-th write to a flash image (counted over all images since
    /// boot) is made only in its first half, then the firmware waits to be killed: a
    /// power cut in the middle of a flash write.
    pub flash_tear_at: Option<u32>,
}

impl BootArgs {
    pub const DEFAULT: Self = Self {
        inject: Inject::None,
        gyro_rate_hz: None,
        seek_dwell_s: None,
        tilt_mdeg: None,
        flash_file: false,
        flash_cut_at: None,
        field_file: false,
        flash_tear_at: None,
    };
}

/// An argument refused: which one, and why.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ArgError<'a> {
    pub arg: &'a str,
    pub why: &'static str,
}

impl core::fmt::Display for ArgError<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        // Quoted by hand: `{:?}` would pull the char-escaping code (and its panic paths)
        // into the image; an argument is printable text anyway.
        write!(
            f,
            "argument \"{}\": {} (known: {})",
            self.arg, self.why, KNOWN
        )
    }
}

/// Parses the arguments after argv[0]; the first bad one is refused.
pub fn parse<'a>(args: impl IntoIterator<Item = &'a str>) -> Result<BootArgs, ArgError<'a>> {
    let mut out = BootArgs::DEFAULT;
    for arg in args {
        let err = |why| ArgError { arg, why };
        let (key, value) = arg.split_once('=').ok_or(err("unknown argument"))?;
        match key {
            "flash-file" if !value.is_empty() => out.flash_file = true,
            "flash-file" => return Err(err("needs a file name")),
            "field-file" if !value.is_empty() => out.field_file = true,
            "field-file" => return Err(err("needs a file name")),
            "flash-tear-at" => {
                out.flash_tear_at = Some(
                    number(value)
                        .filter(|&n| n > 0)
                        .ok_or(err("not a write number >= 1"))?,
                )
            }
            "gyro-rate" => {
                out.gyro_rate_hz = Some(number(value).ok_or(err("not a whole number of Hz"))?)
            }
            "seek-dwell-s" => {
                out.seek_dwell_s = Some(number(value).ok_or(err("not a whole number of s"))?)
            }
            "tilt-mdeg" => {
                out.tilt_mdeg = Some(tilt(value).ok_or(err("not PITCH:ROLL in whole mdeg"))?)
            }
            "flash-cut-at" => {
                out.flash_cut_at = Some(
                    number(value)
                        .filter(|&n| n > 0)
                        .ok_or(err("not a write number >= 1"))?,
                )
            }
            "inject" => out.inject = inject(value).ok_or(err("unknown fault to inject"))?,
            _ => return Err(err("unknown argument")),
        }
    }
    Ok(out)
}

fn number(v: &str) -> Option<u32> {
    v.parse().ok()
}

fn tilt(v: &str) -> Option<(i32, i32)> {
    let (p, r) = v.split_once(':')?;
    Some((p.parse().ok()?, r.parse().ok()?))
}

fn inject(v: &str) -> Option<Inject> {
    Some(match v {
        "panic" => Inject::Panic,
        "hang" => Inject::Hang,
        "panic-after-commit" => Inject::PanicAfterCommit,
        "hardfault" => Inject::HardFault,
        _ => {
            let name = v.strip_prefix("boot-fault=")?;
            Inject::Boot(BootFault::ALL.into_iter().find(|f| f.name() == name)?)
        }
    })
}
