//! Instruction-count benchmarks on the target, run under `qemu -icount shift=0` by
//! `tests/tests/fw_budgets.rs` (and `scripts/budgets.sh`). SysTick counts 1 tick per 40
//! instructions (see `target/icount.rs`). Prints `key value` lines on semihosting stdout:
//!
//! - `sample_instr`: one raw gyro sample at 2 kHz: 12 frame bytes through the UART
//!   driver and decoder, the 1 Hz temperature, the application's `on_gyro` (averager);
//! - `update_instr_<35|64>_<f32|fixed>`: the sample that closes a 10 s window (features,
//!   RBF drift, compensation, validity), with 35 or 64 centres over (T, dT/dt);
//! - `update_instr_35_f32_diffusion`: the same with dT/dt read in the diffusion clock
//!   (`FeatureKind::TempRateDiffusionCps`, tau 400 s; model format version 7);
//! - `predict_instr_<35|64>_<f32|fixed>`: one RBF evaluation alone;
//! - `verify_instr`: one Ed25519 model-signature verification (`signature::verify_model`)
//!   of MODEL with signature SIG if given as arguments (`verify_valid 1`), else of a
//!   synthetic model with a wrong signature (same work, `verify_valid 0`).
#![no_std]
#![no_main]

#[path = "target/icount.rs"]
mod icount;
#[path = "target/panic.rs"]
mod panic;
#[path = "target/semi.rs"]
mod semi;

use core::hint::black_box;

use cortex_m_rt::entry;
use embedded_hal_nb::nb;
use embedded_hal_nb::serial::{ErrorKind, ErrorType, Read};
use fog_core::compensation::compensator::Evaluator;
use fog_core::hal::{Gyro, GyroSample, TableState, TempSample, Turntable};
use fog_core::model::fixed::FixedModel;
use fog_core::model::format::{FeatureKind, FeatureSpec, RbfModel, MAX_ENCODED_LEN};
use fog_core::model::rbf::predict_f32;
use fog_core::model::synthetic::{warmup_inputs, warmup_model};
use fog_core::sensor_link::gyro_frame::{GyroFrame, FRAME_LEN};
use fog_firmware::app::{App, AppConfig};
use fog_firmware::drivers::fog_serial::FogSerialGyro;
use fog_firmware::signature::{verify_model, TEST_PUBLIC_KEY};

const RATE_HZ: u32 = 2000;
const CHUNK: usize = 100;
const AMBIENT_C: f64 = 20.0;

/// A table that is never used (no seeks during the benchmarks).
struct NoTable;

impl Turntable for NoTable {
    type Error = ();
    fn command_heading(&mut self, _: f32) -> Result<(), ()> {
        Err(())
    }
    fn poll(&mut self) -> Result<TableState, ()> {
        Err(())
    }
}

/// A UART whose receive buffer the benchmark refills between timed chunks.
struct ChunkUart {
    buf: [u8; CHUNK * FRAME_LEN],
    pos: usize,
}

impl ErrorType for ChunkUart {
    type Error = ErrorKind;
}

impl Read<u8> for ChunkUart {
    fn read(&mut self) -> nb::Result<u8, ErrorKind> {
        let b = *self.buf.get(self.pos).ok_or(nb::Error::WouldBlock)?;
        self.pos += 1;
        Ok(b)
    }
}

fn config(evaluator: Evaluator, rate_hz: u32) -> AppConfig {
    let mut cfg = AppConfig::for_rate(rate_hz as f32);
    cfg.seeks = 0;
    cfg.compensator.evaluator = evaluator;
    cfg
}

/// Rate (deg/h) and temperature (degC) of the synthetic warm-up at `t_s`.
fn signal(t_s: f64) -> (f64, f64) {
    let x = warmup_inputs(AMBIENT_C, t_s);
    (9.7 + 0.05 * libm::sin(t_s * 0.01), x[0])
}

/// Mean instructions per raw sample over 30 s of 2 kHz frames (windows excluded).
fn bench_sample(model: &RbfModel) -> u32 {
    let Ok(mut app) = App::new(
        config(Evaluator::F32, RATE_HZ),
        Some(model.clone()),
        NoTable,
    ) else {
        return 0;
    };
    let uart = ChunkUart {
        buf: [0; CHUNK * FRAME_LEN],
        pos: 0,
    };
    let mut gyro = FogSerialGyro::new(uart, RATE_HZ);
    let period = 1.0 / f64::from(RATE_HZ);
    let (mut ticks, mut n) = (0u64, 0u64);
    let mut index = 0u64;
    for _ in 0..(30 * RATE_HZ as usize / CHUNK) {
        let u = gyro.uart_mut();
        for k in 0..CHUNK {
            let t = (index + k as u64 + 1) as f64 * period;
            let (rate, temp) = signal(t);
            let f = GyroFrame::from_physical((index + k as u64) as u8, rate, temp, period);
            u.buf[k * FRAME_LEN..(k + 1) * FRAME_LEN].copy_from_slice(&f.encode());
        }
        u.pos = 0;
        index += CHUNK as u64;
        let (t, windows) = icount::ticks(|| {
            let mut windows = 0;
            while let Ok(Some(s)) = gyro.read() {
                if app.temp_due(s.t_s) {
                    app.on_temp(s.t_s, gyro.latest_temp());
                }
                windows += u32::from(black_box(app.on_gyro(s)).window.is_some());
            }
            windows
        });
        if windows == 0 {
            ticks += u64::from(t);
            n += CHUNK as u64;
        }
    }
    (ticks * u64::from(icount::INSTR_PER_TICK) / n.max(1)) as u32
}

/// Mean instructions of the window-closing sample over the valid, compensated windows
/// of a 5 min warm-up at 100 Hz.
fn bench_update(model: &RbfModel, evaluator: Evaluator) -> u32 {
    const RATE: u32 = 100;
    let Ok(mut app) = App::new(config(evaluator, RATE), Some(model.clone()), NoTable) else {
        return 0;
    };
    let (mut ticks, mut n) = (0u64, 0u64);
    for i in 1..=(300 * RATE) {
        let t_s = f64::from(i) / f64::from(RATE);
        let (rate, temp) = signal(t_s);
        if app.temp_due(t_s) {
            let temp_c = libm::round(temp * 256.0) as f32 / 256.0;
            app.on_temp(t_s, Some(TempSample { t_s, temp_c }));
        }
        let s = GyroSample {
            t_s,
            rate_dph: rate as f32,
        };
        let (t, step) = icount::ticks(|| app.on_gyro(black_box(s)));
        if let Some(w) = step.window {
            if w.status.is_valid() && w.model_applied {
                ticks += u64::from(t);
                n += 1;
            }
        }
    }
    (ticks * u64::from(icount::INSTR_PER_TICK) / n.max(1)) as u32
}

/// `model` with its dT/dt read in the diffusion clock (tau 400 s), over a range that keeps
/// the bench's windows valid (the clock's rate of this warm-up is not the slope's).
fn diffusion_clock(model: &RbfModel) -> RbfModel {
    let mut m = model.clone();
    for (j, spec) in m.inputs.iter_mut().enumerate() {
        if spec.kind == FeatureKind::TempRateCps {
            *spec = FeatureSpec {
                kind: FeatureKind::TempRateDiffusionCps,
                tau_s: 400.0,
            };
            if let (Some(lo), Some(hi)) = (m.input_min.get_mut(j), m.input_max.get_mut(j)) {
                (*lo, *hi) = (-1.0, 1.0);
            }
        }
    }
    m
}

/// Mean instructions of one evaluation over 200 points of the warm-up.
fn bench_predict(model: &RbfModel, fixed: Option<&FixedModel>) -> u32 {
    let mut ticks = 0u64;
    for k in 0..200 {
        let x = warmup_inputs(AMBIENT_C, f64::from(k) * 10.0);
        let xs = [x[0] as f32, x[1] as f32];
        let (t, _) = icount::ticks(|| match fixed {
            Some(f) => black_box(f.predict(black_box(&xs))),
            None => black_box(predict_f32(model, black_box(&xs))),
        });
        ticks += u64::from(t);
    }
    (ticks * u64::from(icount::INSTR_PER_TICK) / 200) as u32
}

#[entry]
fn main() -> ! {
    let Some(cp) = cortex_m::Peripherals::take() else {
        semihosting::process::abort()
    };
    icount::start_counter(cp.SYST);
    let m35 = warmup_model(35, 2, 0.05, 35);
    let m64 = warmup_model(64, 2, 0.05, 64);
    semihosting::println!("instr_per_tick {}", icount::INSTR_PER_TICK);
    semihosting::println!("sample_instr {}", bench_sample(&m35));
    for (name, m) in [("35", &m35), ("64", &m64)] {
        semihosting::println!(
            "update_instr_{}_f32 {}",
            name,
            bench_update(m, Evaluator::F32)
        );
        semihosting::println!(
            "update_instr_{}_fixed {}",
            name,
            bench_update(m, Evaluator::Fixed)
        );
        semihosting::println!("predict_instr_{}_f32 {}", name, bench_predict(m, None));
        match FixedModel::from_model(m) {
            Ok(f) => semihosting::println!(
                "predict_instr_{}_fixed {}",
                name,
                bench_predict(m, Some(&f))
            ),
            Err(_) => semihosting::println!("predict_instr_{}_fixed 0", name),
        }
    }
    semihosting::println!(
        "update_instr_35_f32_diffusion {}",
        bench_update(&diffusion_clock(&m35), Evaluator::F32)
    );
    bench_verify(&m35);
    semihosting::process::exit(0)
}

fn bench_verify(fallback: &RbfModel) {
    let mut model_buf = [0u8; MAX_ENCODED_LEN];
    let mut sig_buf = [0u8; 64];
    let from_files = semi::Args::get().ok().and_then(|a| {
        let m = semi::read_file(a.path(0).ok()?, &mut model_buf).ok()?.len();
        let s = semi::read_file(a.path(1).ok()?, &mut sig_buf).ok()?.len();
        Some((m, s))
    });
    let (len, valid_expected) = match from_files {
        Some((m, 64)) => (m, true),
        _ => (fallback.encode(&mut model_buf).unwrap_or(0), false),
    };
    let (t, r) = icount::ticks(|| verify_model(&TEST_PUBLIC_KEY, &model_buf[..len], &sig_buf));
    semihosting::println!(
        "verify_instr {}",
        u64::from(t) * u64::from(icount::INSTR_PER_TICK)
    );
    semihosting::println!("verify_valid {}", u8::from(valid_expected && r.is_ok()));
}
