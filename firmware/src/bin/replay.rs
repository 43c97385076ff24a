//! QEMU scenario 1 (replay): reads a recorded cold start through semihosting files,
//! runs the application logic exactly as the firmware does (`fog_firmware::replay::run`:
//! gyro driver -> compensator -> north finder), and writes every 10 s window and seek
//! to an output file for `tests/tests/qemu_replay.rs` to compare with the host.
//!
//! Arguments: `MODEL GYRO_STREAM TABLE_LOG OUT RATE_HZ SEEKS [f32|fixed]`.
//! It also paints the stack and appends to OUT the high-water mark of the sample loop
//! (steady state) and of the boot: the model decode and the application construction,
//! each measured on its own, and their maximum (the boot peak).
#![no_std]
#![no_main]

#[path = "target/panic.rs"]
mod panic;
#[path = "target/semi.rs"]
mod semi;
#[path = "target/stack.rs"]
mod stack;

use core::ffi::CStr;
use core::fmt::Write as _;

use cortex_m_rt::entry;
use fog_core::compensation::compensator::Compensator;
use fog_core::compensation::compensator::Evaluator;
use fog_core::model::format::{RbfModel, MAX_ENCODED_LEN};
use fog_firmware::app::AppConfig;
use fog_firmware::replay;

#[entry]
fn main() -> ! {
    // The application's big state and the model live in statics (zero-initialised
    // `.bss`: the `const` values are all zero bytes) and are set up there in place, never
    // on the stack; cortex-m-rt hands them out as `&'static mut` once (no unsafe here).
    static mut COMPENSATOR: Compensator = Compensator::unconfigured();
    static mut MODEL: RbfModel = RbfModel::empty();
    stack::paint();
    let code = match run(COMPENSATOR, MODEL) {
        Ok(()) => 0,
        Err(msg) => {
            semihosting::eprintln!("replay: {}", msg);
            1
        }
    };
    semihosting::process::exit(code)
}

fn run(compensator: &mut Compensator, model: &mut RbfModel) -> Result<(), &'static str> {
    let args = semi::Args::get()?;
    if args.len() < 6 {
        return Err("usage: replay MODEL GYRO_STREAM TABLE_LOG OUT RATE_HZ SEEKS [f32|fixed]");
    }
    load_model(args.path(0)?, model)?;
    // The decode's peak (argument parsing, file buffer, `decode_into`); painted again so
    // the construction below is measured on its own (tests/tests/qemu_replay.rs bounds
    // both: a large temporary in the construction path would otherwise hide under the
    // decode's file buffer).
    let decode_stack = stack::high_water_bytes();
    stack::paint();
    let rate_hz: f32 = args
        .str(4)?
        .parse()
        .map_err(|_| "RATE_HZ is not a number")?;
    let seeks: u16 = args.str(5)?.parse().map_err(|_| "SEEKS is not a number")?;
    let mut cfg = AppConfig::for_rate(rate_hz);
    cfg.seeks = seeks;
    cfg.compensator.evaluator = match args.str(6).unwrap_or("f32") {
        "fixed" => Evaluator::Fixed,
        _ => Evaluator::F32,
    };
    let gyro = semi::HostReader::open(args.path(1)?)?;
    let table = semi::HostReader::open(args.path(2)?)?;
    let mut out = semi::HostWriter::create(args.path(3)?)?;
    let mut construct_stack = 0;
    let on_ready = || {
        construct_stack = stack::high_water_bytes();
        stack::paint();
    };
    let sum = replay::run_in(
        compensator,
        cfg,
        Some(model),
        gyro,
        table,
        &mut out,
        on_ready,
    );
    let sum = sum.map_err(|e| match e {
        replay::ReplayError::App(_) => "application rejected the configuration",
        replay::ReplayError::Output => "cannot write the output file",
    })?;
    let g = sum.gyro;
    let _ = writeln!(
        out,
        "# samples {} windows {} valid {} seeks_done {} seeks_failed {} frames_ok {} crc_errors {} bytes_skipped {} frames_lost {} flagged {}",
        sum.samples,
        sum.windows,
        sum.valid_windows,
        sum.seeks_done,
        sum.seeks_failed,
        g.frames.frames_ok,
        g.frames.crc_errors,
        g.frames.bytes_skipped,
        g.frames_lost,
        g.flagged_invalid
    );
    let _ = writeln!(
        out,
        "# stack_high_water_bytes {} boot_peak {} of {} decode_peak {} construct_peak {}",
        stack::high_water_bytes(),
        decode_stack.max(construct_stack),
        stack::size_bytes(),
        decode_stack,
        construct_stack
    );
    out.flush()
}

/// Read and decode the model file into `dst` (in place). Its own frame: the file buffer
/// is only on the stack while decoding.
#[inline(never)]
fn load_model(path: &CStr, dst: &mut RbfModel) -> Result<(), &'static str> {
    let mut buf = [0u8; MAX_ENCODED_LEN];
    let bytes = semi::read_file(path, &mut buf)?;
    dst.decode_into(bytes)
        .map_err(|_| "model file fails validation")
}
