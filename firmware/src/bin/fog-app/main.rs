//! The north-finder firmware for the MPS2-AN386 board (Cortex-M4F; QEMU in CI).
//!
//! Wiring (a real board changes only this folder and `target/`):
//! - UART0 (0x4000_4000, QEMU's first `-serial`): the host port (RS-422 on the product),
//!   carrying `fog_core::link::messages::HostFrame`s: model uploads, handled by
//!   `fog_firmware::upload::UploadServer`, and north-finder commands (StartSeek,
//!   SetLatitude, Abort, GetStatus), answered by the application; the device sends a
//!   `Status` about once per second and after each command, and a `Result` per seek;
//! - UART1 (0x4000_5000): the FOG's RS-422 frame stream at 2 kHz (`FogSerialGyro`);
//!   the gyro's internal coil temperature comes with every frame and is read at 1 Hz
//!   (a board with a TMP117 on I2C uses `drivers::tmp117` instead);
//! - UART2 (0x4000_6000): the turntable controller (`SerialTurntable`);
//! - UART3 (0x4000_7000, QEMU's fourth `-serial`): the inclinometer's `tilt_frame`
//!   stream (`SerialInclinometer`; the MPS2 board has no SPI SCL3300), drained every pass
//!   and read at 1 Hz of sample time (the mean of the readings since the last one); with
//!   the semihosting argument `tilt-mdeg=PITCH:ROLL` a `SimulatedInclinometer` at that
//!   tilt instead (QEMU runs without an inclinometer link). Both are the `Inclinometer`
//!   trait the SCL3300 driver implements;
//! - SysTick: 1 kHz time base for turntable timeouts and the gyro's frame time base
//!   (counter wraps during a stall are recovered from it);
//! - the CMSDK watchdog (0x4000_8000): 500 ms, fed only while the gyro path is serviced;
//! - the last 16 KiB of flash: the two model slots; the 16 KiB below them: the
//!   field-record ring (`fog_firmware::field_log`), one record per completed
//!   two-position seek, sent on `GetFieldRecords`.
//!
//! Main loop, gyro path first: every gyro byte the RX interrupt put in its ring ->
//! samples -> application (10 s windows, compensation, north seeks on the table);
//! then at most `HOST_BYTES_PER_PASS` host bytes -> upload server, whose replies go to
//! a TX queue sent without blocking (a full queue drops the reply and counts it);
//! results and faults -> defmt log. The watchdog is fed only when the gyro ring was
//! drained and lost nothing in this pass. Any fatal error records its reason in no-init
//! RAM and resets; the next boot logs it and reports it in `DeviceStatus`.
//!
//! This file holds the wiring and the main loop; beside it, one job a file: `config` (rates,
//! baud rates, periods, the build-time key), `options` (the QEMU scenarios' arguments),
//! `boot` (what the boot found, logged), `console` (per-window and per-seek log lines),
//! `host` (the host port: upload server, link replies, status) and `field_records` (the
//! seek records' flash ring).
#![no_std]
#![no_main]

mod boot;
mod config;
mod console;
mod field_records;
mod host;
mod options;

#[path = "../target/flash.rs"]
mod flash;
#[cfg(feature = "log-semihosting")]
#[path = "../target/flash_file.rs"]
mod flash_file;
#[path = "../target/millis.rs"]
mod millis;
#[path = "../target/panic_reset.rs"]
mod panic_reset;
#[path = "../target/resets.rs"]
mod resets;
#[path = "../target/safe_loop.rs"]
mod safe_loop;
#[cfg(feature = "log-semihosting")]
#[path = "../target/semi.rs"]
mod semi;
#[cfg(feature = "log-semihosting")]
#[path = "../target/stack.rs"]
mod stack;
#[path = "../target/uart.rs"]
mod uart;
#[path = "../target/upload_boot.rs"]
mod upload_boot;
#[path = "../target/watchdog.rs"]
mod watchdog;

#[cfg(feature = "log-rtt")]
use defmt_rtt as _;
#[cfg(feature = "log-semihosting")]
use defmt_semihosting as _;

use cortex_m_rt::entry;
use embedded_hal_nb::serial::{Read as _, Write as _};
use fog_core::compensation::compensator::Compensator;
use fog_core::hal::Gyro;
use fog_core::link::messages::{Command, DeviceMessage, Refusal, ResetReason};
use fog_core::seeking::bit::BitLimits;
use fog_firmware::app::{App, AppConfig, SeekOutcome};
use fog_firmware::bit_monitor::{BitCounters, BitMonitor};
use fog_firmware::boot_args::Inject;
use fog_firmware::clock::Clock;
use fog_firmware::drivers::base_inclinometer::BaseInclinometer;
use fog_firmware::drivers::fog_serial::FogSerialGyro;
use fog_firmware::drivers::inclinometer::{
    Inclinometer, SimulatedInclinometer, SIMULATED_NOISE_DEG,
};
use fog_firmware::drivers::serial_inclinometer::SerialInclinometer;
use fog_firmware::drivers::turntable::{SerialTurntable, TurntableConfig};
use fog_firmware::fault_record::CleanRun;
use fog_firmware::health::{GyroWatch, StuckEvent, DEFAULT_STUCK_RUN};
use fog_firmware::link_out::queue_whole;
use fog_firmware::upload::UploadBuffers;
use resets::BootFault;

use boot::{announce_boot, announce_heading_correction, report_boot_stack, report_slots};
use config::{
    GYRO_BAUD, GYRO_ID, GYRO_SILENCE_S, HOST_BAUD, HOST_BYTES_PER_PASS, INCL_BAUD, STATUS_PERIOD_S,
    TABLE_BAUD, TILT_NOISE_SEED, TILT_PERIOD_S, VERIFY_KEY, WATCHDOG_TIMEOUT_MS,
};
use console::{report, seek_line, window_line};
use field_records::{append_field_record, open_field_log};
use host::{
    answer_link, board_status, clear_faults, keep_server, send_link, start_upload_server,
    swap_model, TxQueue,
};
use options::{inject_fault_at_boot, test_options};

#[cfg(not(any(feature = "log-semihosting", feature = "log-rtt")))]
compile_error!("fog-app needs a defmt logger: feature log-semihosting (QEMU) or log-rtt");

#[entry]
fn main() -> ! {
    // The application's big state (the compensator, ~8 KB) and the upload server's
    // (frames, model bytes and the model decoded from them, 4.5 KB) live in statics, set
    // up there in place and never built on the stack. Their `const` values are all zero
    // bytes, so they go to `.bss` (no flash); cortex-m-rt hands them out as
    // `&'static mut` exactly once (no unsafe here).
    static mut COMPENSATOR: Compensator = Compensator::unconfigured();
    static mut UPLOAD_BUFFERS: UploadBuffers = UploadBuffers::new();
    static mut TX_QUEUE: TxQueue = heapless::Deque::new();
    let (compensator, upload_buffers, tx_queue) = (COMPENSATOR, UPLOAD_BUFFERS, TX_QUEUE);
    // Under QEMU the boot's stack peak is measured: painted here, read before the loop.
    #[cfg(feature = "log-semihosting")]
    stack::paint();
    let record = resets::boot_record();
    let reset = record.reset;
    announce_boot(&record);
    let options = test_options(&reset);
    let Some(cp) =
        cortex_m::Peripherals::take().filter(|_| !options.injects(BootFault::CorePeripherals))
    else {
        resets::fatal_boot(BootFault::CorePeripherals)
    };
    millis::start_millis(cp.SYST, millis::CORE_HZ);
    watchdog::start(WATCHDOG_TIMEOUT_MS);
    inject_fault_at_boot(options);
    let gyro_rate_hz = options.gyro_rate_hz;
    // SAFETY: each UART block and the model region are taken exactly once, here.
    let (mut host, gyro_uart, table_uart, incl_uart, flash, field_flash) = unsafe {
        (
            uart::CmsdkUart::new(0, HOST_BAUD),
            uart::CmsdkUart::new(1, GYRO_BAUD),
            uart::CmsdkUart::new(2, TABLE_BAUD),
            uart::CmsdkUart::new(3, INCL_BAUD),
            flash::take_app_flash(),
            flash::take_field_flash(),
        )
    };

    // The long-lived state lives in statics (counted in the static-RAM budget by the
    // linker), not in main's stack frame.
    let mut faults = record.state(false);
    let server = if record.safe_mode() {
        // A reset loop: host link and upload server only, until a good upload.
        let server =
            upload_boot::try_new_upload_server(flash, VERIFY_KEY, GYRO_ID, reset, upload_buffers)
                .ok()
                .map(|s| keep_server(s, options));
        let mut server = server;
        safe_loop::run(
            &mut host,
            server.as_deref_mut(),
            tx_queue,
            faults,
            watchdog::feed,
        );
        faults = record.cleared().state(false);
        // `run` returns only after a good upload, which needs the store.
        server.unwrap_or_else(|| resets::fatal_boot(BootFault::StoreGeometry))
    } else {
        start_upload_server(flash, reset, options, upload_buffers)
    };
    let (slots_refused, slot_report) = (server.slots_refused_at_boot(), server.boot_report());
    // Decoded in place into the server's model buffer (the compensator keeps its own copy).
    let model = server.load_active_model_in_place().unwrap_or_else(|e| {
        defmt::warn!("stored model not loaded ({}): running uncompensated", e);
        None
    });
    defmt::info!(
        "model active: {} (slots refused at boot: {})",
        model.is_some(),
        slots_refused
    );
    report_slots(slot_report);
    let mut field_log = open_field_log(field_flash);

    let table = SerialTurntable::new(table_uart, millis::MillisClock, TurntableConfig::default());
    // Configured in place in `COMPENSATOR`; the `App` around it is a few hundred bytes.
    let mut cfg = AppConfig::for_rate(gyro_rate_hz as f32);
    if options.injects(BootFault::Configuration) {
        // The real path of a refused configuration: a gyro rate the compensator refuses.
        cfg.compensator.gyro_rate_hz = 0.0;
    }
    // Seeks run on the host's StartSeek only.
    cfg.seeks = 0;
    if let Some(d) = options.seek_dwell_s {
        cfg.seek.dwell_s = d as f32;
        cfg.seek.ambiguity_dwell_s = (d as f32 / 6.0).max(10.0);
    }
    let mut app = match App::with_compensator(cfg, model, table, compensator) {
        Ok(a) => a,
        Err(e) => {
            defmt::error!("configuration rejected: {}", e);
            resets::fatal_boot(BootFault::Configuration)
        }
    };
    announce_heading_correction(&app);
    let mut gyro = FogSerialGyro::with_clock(gyro_uart, gyro_rate_hz, millis::MillisClock);
    // Clock reading at the last gyro sample (`None` until the gyro starts).
    let mut watch = GyroWatch::new(GYRO_SILENCE_S, DEFAULT_STUCK_RUN);
    let mut inclinometer = match options.tilt {
        Some(tilt) => BaseInclinometer::Simulated(SimulatedInclinometer::new(
            tilt,
            SIMULATED_NOISE_DEG,
            TILT_NOISE_SEED,
        )),
        None => BaseInclinometer::Serial(SerialInclinometer::new(incl_uart)),
    };
    let mut tilt_ok = true;
    let mut next_tilt_s = 0.0;
    let mut last_tilt_clock_s: Option<f64> = None;
    let mut last_table_error_s: Option<f64> = None;
    let mut bit_monitor = BitMonitor::new(BitLimits::default());
    let mut next_status_s = 0.0;
    let reset_reason = ResetReason::from(reset.cause);
    let mut clean_run = CleanRun::new(&record);
    report_boot_stack();

    loop {
        let now_s = millis::MillisClock.now_s();
        if clean_run.due(now_s) {
            clear_faults(&mut faults, "clean run");
        }
        // 1. Gyro first: everything its ring holds.
        let drops_before = gyro.uart_mut().dropped();
        let mut drained = false;
        while !drained {
            match gyro.read() {
                Ok(Some(s)) => {
                    let health = watch.on_sample(now_s, s.t_s, s.rate_dph);
                    // A stall mid-seek restarts the seek, with its reason (or fails it).
                    let stalled = health.resumed.then(|| {
                        defmt::info!("t={} s: gyro samples again", s.t_s);
                        app.on_gyro_stall(s.t_s, health.gap_s)
                    });
                    match health.stuck_event {
                        Some(StuckEvent::Stuck) => {
                            defmt::warn!("t={} s: gyro output stuck: windows invalid", s.t_s)
                        }
                        Some(StuckEvent::Recovered) => {
                            defmt::info!("t={} s: gyro output moving again", s.t_s)
                        }
                        None => {}
                    }
                    if health.stuck {
                        app.on_fault(s.t_s);
                    }
                    if app.temp_due(s.t_s) {
                        let t = gyro.latest_temp();
                        if t.is_none() {
                            defmt::warn!("t={} s: gyro temperature invalid", s.t_s);
                        }
                        app.on_temp(s.t_s, t);
                    }
                    if s.t_s >= next_tilt_s {
                        next_tilt_s = s.t_s + TILT_PERIOD_S;
                        match inclinometer.read_tilt() {
                            Ok(t) => {
                                app.on_tilt(t);
                                last_tilt_clock_s = Some(now_s);
                                tilt_ok = true;
                            }
                            // Once per dropout; the BIT sees the silence.
                            Err(e) if tilt_ok => {
                                tilt_ok = false;
                                defmt::warn!("t={} s: inclinometer: {}", s.t_s, e)
                            }
                            Err(_) => {}
                        }
                    }
                    let step = app.on_gyro(s);
                    if let Some(w) = &step.window {
                        window_line(w, gyro.stats().frames_lost, gyro.uart_mut().dropped());
                    }
                    for step in stalled.into_iter().chain(core::iter::once(step)) {
                        match &step.seek {
                            Some(SeekOutcome::Failed(f)) => {
                                if f.table_error.is_some() {
                                    last_table_error_s = Some(now_s);
                                }
                                // The host hears why: a monitor would otherwise wait for
                                // a result that never comes.
                                let failure = app.failure_report(f);
                                send_link(tx_queue, DeviceMessage::SeekFailed(failure));
                                next_status_s = now_s;
                            }
                            Some(SeekOutcome::Done(r, v)) => {
                                let model_crc32 = server.active_info().map(|i| i.model_crc32);
                                if let Some(record) = app.field_record(r, *v, model_crc32) {
                                    append_field_record(field_log.as_mut(), record);
                                }
                                let report = app.report(r, *v);
                                send_link(tx_queue, DeviceMessage::Result(report));
                                seek_line(&report);
                                // The state changed: a status now.
                                next_status_s = now_s;
                            }
                            None => {}
                        }
                        report(step);
                    }
                }
                Ok(None) => drained = true,
                Err(e) => {
                    defmt::warn!("gyro UART error {}", e);
                    app.on_fault(watch.last_t_s());
                }
            }
        }
        inclinometer.poll();
        if watch.became_silent(now_s) {
            defmt::warn!(
                "t={} s: gyro silent (dead sensor or cable): window invalid",
                watch.last_t_s()
            );
            app.on_fault(watch.last_t_s());
        }
        // The gyro path is healthy when its ring was drained and lost nothing.
        if gyro.uart_mut().dropped() == drops_before {
            watchdog::feed();
        }

        // 2. BIT from the counters and the periodic status.
        if now_s >= next_status_s {
            next_status_s = now_s + STATUS_PERIOD_S;
            let stats = gyro.stats();
            let counters = BitCounters {
                now_s,
                last_gyro_s: watch.last_sample_clock_s(),
                frames_ok: stats.frames.frames_ok,
                frames_bad: stats.frames.crc_errors,
                temp: gyro.latest_temp().map(|t| (t.t_s, t.temp_c)),
                last_tilt_s: last_tilt_clock_s,
                last_table_error_s,
                model_valid: app.model().is_some() && server.active_info().is_some(),
                flash_ok: server.slots_refused_at_boot() == 0,
            };
            app.set_bit(bit_monitor.evaluate(&counters));
            let board = board_status(&watch, &gyro, server, reset_reason, faults);
            send_link(tx_queue, DeviceMessage::Status(app.status(board)));
        }

        // 3. Host link: a bounded number of bytes per pass, replies queued.
        server.set_time_s(now_s);
        for _ in 0..HOST_BYTES_PER_PASS {
            let Ok(byte) = host.read() else { break };
            let Some(reply) = server.push_byte(byte) else {
                continue;
            };
            let (frame, changed, command) = (reply.frame, reply.model_changed, reply.command);
            if !queue_whole(tx_queue, frame) {
                server.note_reply_dropped();
            }
            if let Some(cmd) = command {
                let answer = match cmd {
                    Command::GetFieldRecords {
                        from_sequence,
                        max_count,
                    } => Some(
                        field_log
                            .as_mut()
                            .map_or(DeviceMessage::Refused(Refusal::NoFieldLog), |log| {
                                DeviceMessage::FieldRecords(log.answer(from_sequence, max_count))
                            }),
                    ),
                    _ => app.command(cmd, watch.last_t_s()),
                };
                let board = board_status(&watch, &gyro, server, reset_reason, faults);
                let status = DeviceMessage::Status(app.status(board));
                for msg in answer.into_iter().chain(core::iter::once(status)) {
                    answer_link(server, tx_queue, msg);
                }
            }
            if changed {
                #[cfg(feature = "log-semihosting")]
                semihosting::eprintln!("FOG-COMMITTED flash_writes={}", flash_file::writes());
                clear_faults(&mut faults, "good upload");
                swap_model(server, &mut app);
                // The BIT's model item and the status follow at once.
                next_status_s = now_s;
                if options.inject == Inject::PanicAfterCommit {
                    core::panic!("injected panic after a commit");
                }
            }
        }
        // 4. Replies out, never waiting for the UART.
        while let Some(&b) = tx_queue.front() {
            if host.write(b).is_err() {
                break;
            }
            let _ = tx_queue.pop_front();
        }
    }
}
