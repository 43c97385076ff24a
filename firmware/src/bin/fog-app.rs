//! The north-finder firmware for the MPS2-AN386 board (Cortex-M4F; QEMU in CI).
//!
//! Wiring (a real board changes only this file and `target/`):
//! - UART0 (0x4000_4000, QEMU's first `-serial`): link to the training PC, carrying the
//!   model-upload protocol, handled by `fog_firmware::upload::UploadServer`;
//! - UART1 (0x4000_5000): the FOG's RS-422 frame stream at 2 kHz (`FogSerialGyro`);
//!   the gyro's internal coil temperature comes with every frame and is read at 1 Hz
//!   (a board with a TMP117 on I2C uses `drivers::tmp117` instead);
//! - UART2 (0x4000_6000): the turntable controller (`SerialTurntable`);
//! - SysTick: 1 kHz time base for turntable timeouts;
//! - the last 16 KiB of flash: the two model slots.
//!
//! Main loop: upload bytes -> upload server (a committed model is swapped into the
//! compensator at once); gyro samples -> application (10 s windows, compensation,
//! north seeks on the table); results and faults -> defmt log.
#![no_std]
#![no_main]

#[path = "target/flash.rs"]
mod flash;
#[path = "target/millis.rs"]
mod millis;
#[path = "target/panic.rs"]
mod panic;
#[path = "target/uart.rs"]
mod uart;

#[cfg(feature = "log-rtt")]
use defmt_rtt as _;
#[cfg(feature = "log-semihosting")]
use defmt_semihosting as _;

use cortex_m_rt::entry;
use embedded_hal_nb::nb;
use embedded_hal_nb::serial::Write as _;
use fog_core::compensator::Compensator;
use fog_core::hal::Gyro;
use fog_core::model::RbfModel;
use fog_firmware::app::{App, AppConfig, SeekOutcome};
use fog_firmware::drivers::fog_serial::FogSerialGyro;
use fog_firmware::drivers::turntable::{SerialTurntable, TurntableConfig};
use fog_firmware::signature::TEST_PUBLIC_KEY;
use fog_firmware::upload::UploadServer;

#[cfg(not(any(feature = "log-semihosting", feature = "log-rtt")))]
compile_error!("fog-app needs a defmt logger: feature log-semihosting (QEMU) or log-rtt");

/// Gyro output rate, Hz.
const GYRO_RATE_HZ: u32 = 2000;
const UART1_BASE: usize = 0x4000_5000;
const UART2_BASE: usize = 0x4000_6000;
/// Host link and turntable baud rates; the gyro link runs at 460,800 baud.
const HOST_BAUD: u32 = 115_200;
const GYRO_BAUD: u32 = 460_800;
const TABLE_BAUD: u32 = 115_200;

#[entry]
fn main() -> ! {
    // The application's big state (the compensator, ~8 KB) and the model buffer live in
    // statics, set up there in place and never built on the stack. Their `const` values
    // are all zero bytes, so they go to `.bss` (no flash); cortex-m-rt hands them out
    // as `&'static mut` exactly once (no unsafe here).
    static mut COMPENSATOR: Compensator = Compensator::unconfigured();
    static mut MODEL: RbfModel = RbfModel::empty();
    let (compensator, model) = (COMPENSATOR, MODEL);
    let Some(cp) = cortex_m::Peripherals::take() else {
        semihosting::process::abort()
    };
    millis::start_millis(cp.SYST);
    // SAFETY: each UART block and the model region are taken exactly once, here.
    let (mut host, gyro_uart, table_uart, flash) = unsafe {
        (
            uart::CmsdkUart::new(uart::UART0_BASE, HOST_BAUD),
            uart::CmsdkUart::new(UART1_BASE, GYRO_BAUD),
            uart::CmsdkUart::new(UART2_BASE, TABLE_BAUD),
            flash::ModelFlash::take(),
        )
    };
    defmt::info!("fog-app: boot");

    // The long-lived state lives in statics (counted in the static-RAM budget by the
    // linker), not in main's stack frame.
    let server = start_upload_server(flash);
    // Decoded in place into `MODEL` (the compensator keeps its own copy).
    let stored = server.load_active_model_into(model).unwrap_or_else(|e| {
        defmt::warn!("stored model not loaded ({}): running uncompensated", e);
        false
    });
    defmt::info!("model active: {}", stored);

    let table = SerialTurntable::new(table_uart, millis::MillisClock, TurntableConfig::default());
    // Configured in place in `COMPENSATOR`; the `App` around it is a few hundred bytes.
    let cfg = AppConfig::for_rate(GYRO_RATE_HZ as f32);
    let mut app = match App::with_compensator(cfg, stored.then_some(&*model), table, compensator) {
        Ok(a) => a,
        Err(e) => {
            defmt::error!("configuration rejected: {}", e);
            semihosting::process::abort()
        }
    };
    let mut gyro = FogSerialGyro::new(gyro_uart, GYRO_RATE_HZ);
    let mut last_t_s = 0.0;

    loop {
        // 1. Host link: the upload hook.
        while let Ok(byte) = embedded_hal_nb::serial::Read::read(&mut host) {
            let Some(reply) = server.push_byte(byte) else {
                continue;
            };
            for &b in reply.frame {
                let _ = nb::block!(host.write(b));
            }
            if reply.model_changed {
                match server.load_active_model_into(model) {
                    Ok(stored) => match app.set_model_from(stored.then_some(&*model)) {
                        Ok(()) => defmt::info!("new model in use"),
                        Err(e) => defmt::error!("new model refused: {}", e),
                    },
                    Err(e) => defmt::error!("new model not loaded: {}", e),
                }
            }
        }

        // 2. Gyro samples: everything the UART has buffered.
        loop {
            match gyro.read() {
                Ok(Some(s)) => {
                    last_t_s = s.t_s;
                    if app.temp_due(s.t_s) {
                        let t = gyro.latest_temp();
                        if t.is_none() {
                            defmt::warn!("t={} s: gyro temperature invalid", s.t_s);
                        }
                        app.on_temp(s.t_s, t);
                    }
                    report(app.on_gyro(s));
                }
                Ok(None) => break,
                Err(e) => {
                    defmt::warn!("gyro UART error {}", e);
                    app.on_fault(last_t_s);
                }
            }
        }
    }
}

fn report<E: defmt::Format>(step: fog_firmware::app::Step<E>) {
    if let Some(w) = step.window {
        if w.status.is_valid() {
            defmt::info!(
                "t={} s compensated {} deg/h (drift {}, T {} C)",
                w.t_end_s,
                w.compensated_dph,
                w.drift_dph,
                w.temp_c
            );
        } else {
            defmt::warn!("t={} s window invalid: {}", w.t_end_s, w.status);
        }
    }
    match step.seek {
        Some(SeekOutcome::Done(r)) => defmt::info!(
            "north seek: azimuth {} deg +- {} deg ({} s)",
            r.azimuth_deg,
            r.sigma_deg,
            r.duration_s
        ),
        Some(SeekOutcome::Failed(f)) => defmt::error!(
            "north seek aborted at t={} s: {} (turntable: {})",
            f.t_s,
            f.error,
            f.table_error
        ),
        None => {}
    }
}

type Server = UploadServer<flash::ModelFlash>;

/// The upload server, in a static. Its own frame (never inlined into `main`): building it
/// (store scan, decoding the active model for its identity) needs ~10 KB of temporaries,
/// which are then given back instead of staying in `main`'s frame for good.
#[inline(never)]
fn start_upload_server(flash: flash::ModelFlash) -> &'static mut Server {
    // The repository's TEST key (keys/README.md): a product build embeds its own.
    let server = match UploadServer::new(flash, 0, TEST_PUBLIC_KEY) {
        Ok(s) => s,
        Err(e) => {
            defmt::error!("model store unusable: {}", e);
            semihosting::process::abort()
        }
    };
    let Some(server) = cortex_m::singleton!(: Server = server) else {
        semihosting::process::abort()
    };
    server
}
