//! The north-finder firmware on an STM32F407 (168 MHz Cortex-M4F, 1 MiB flash, 128 KiB
//! RAM): the same portable application as the QEMU build (`fog_firmware`: gyro frame
//! driver with its clock time base, 10 s windows, compensation, north seek, upload
//! server and A/B model store), on the chip's own peripherals:
//! - USART1 PA9/PA10, 115,200 Bd: link to the training PC (upload protocol);
//! - USART2 PA2/PA3, 460,800 Bd: the FOG's frame stream at 2 kHz;
//! - USART3 PB10/PB11, 115,200 Bd: the turntable controller;
//!   every USART receives by DMA into a circular ring (`dma_ring`), sends without
//!   blocking through the HAL;
//! - I2C1 PB6/PB7, 400 kHz: TMP117 at 0x48 (`fog_firmware::drivers::tmp117`), read at
//!   1 Hz as the model's temperature input;
//! - flash sectors 10 and 11: the model slots (`sector_flash`);
//! - IWDG, 3 s, fed only while the gyro ring is drained without loss (and before each
//!   sector erase); a silent or stuck gyro marks its windows invalid (`health`); panics and fatal boot errors record their reason in no-init RAM and
//!   reset (the QEMU build's `resets`), reported by the next boot and in `DeviceStatus`;
//!   after `SAFE_MODE_AFTER` faults in a row the board boots into the QEMU build's safe
//!   mode (`safe_loop`): host link and upload server only, until a good upload;
//! - clocks: 168 MHz from the 8 MHz crystal, or from the internal RC oscillator if the
//!   crystal does not start within 100 ms (`clocks`);
//! - SysTick at 1 kHz: the clock for timeouts and the gyro time base;
//! - defmt over RTT; flashed and run with `cargo board-run` (probe-rs).
#![no_std]
#![no_main]

mod clocks;
mod dma_ring;
#[path = "../../firmware/src/bin/target/millis.rs"]
mod millis;
#[path = "../../firmware/src/bin/target/panic_reset.rs"]
mod panic_reset;
#[path = "../../firmware/src/bin/target/resets.rs"]
mod resets;
// fog-app's safe mode, the same loop (its `log-semihosting` lines are QEMU-only and
// never built here).
#[allow(unexpected_cfgs)]
#[path = "../../firmware/src/bin/target/safe_loop.rs"]
mod safe_loop;
mod sector_flash;
#[path = "../../firmware/src/bin/target/upload_boot.rs"]
mod upload_boot;

use defmt_rtt as _;

use cortex_m_rt::entry;
use embedded_hal_nb::serial::{Read as _, Write as _};
use fog_core::compensation::compensator::Compensator;
use fog_core::hal::{Gyro, TemperatureSensor};
use fog_firmware::app::{App, AppConfig};
use fog_firmware::clock::Clock;
use fog_firmware::drivers::fog_serial::FogSerialGyro;
use fog_firmware::drivers::tmp117::Tmp117;
use fog_firmware::drivers::turntable::{SerialTurntable, TurntableConfig};
use fog_firmware::health::{GyroWatch, StuckEvent, DEFAULT_STUCK_RUN};
use fog_firmware::upload::UploadBuffers;
use resets::BootFault;
use stm32f4xx_hal::i2c::I2c;
use stm32f4xx_hal::pac::{self, interrupt, Interrupt};
use stm32f4xx_hal::prelude::*;
use stm32f4xx_hal::watchdog::IndependentWatchdog;

use clocks::ClockSource;
use dma_ring::{DmaRx, DmaSerial, Ring, USART1_RX, USART2_RX, USART3_RX};
use sector_flash::SectorFlash;

const GYRO_RATE_HZ: u32 = 2000;
const HOST_BAUD: u32 = 115_200;
const GYRO_BAUD: u32 = 460_800;
const TABLE_BAUD: u32 = 115_200;
/// TMP117 address with ADD0 to GND.
const TMP117_ADDRESS: u8 = 0x48;
/// Watchdog period: above the 2 s worst-case erase of a 128 KiB sector.
const WATCHDOG_MS: u32 = 3000;
const HOST_BYTES_PER_PASS: usize = 64;
const TX_QUEUE_LEN: usize = 512;
/// No gyro sample for this long marks the window invalid (dead sensor or cable), s.
const GYRO_SILENCE_S: f64 = 0.1;

const VERIFY_KEY: [u8; 32] = *include_bytes!(concat!(env!("OUT_DIR"), "/verify_key.bin"));
const GYRO_ID: &str = include_str!(concat!(env!("OUT_DIR"), "/gyro_id.txt"));

static HOST_RING: Ring = Ring::new();
static GYRO_RING: Ring = Ring::new();
static TABLE_RING: Ring = Ring::new();

type Server = upload_boot::StaticServer<SectorFlash>;

#[entry]
fn main() -> ! {
    static mut COMPENSATOR: Compensator = Compensator::unconfigured();
    static mut UPLOAD_BUFFERS: UploadBuffers = UploadBuffers::new();
    static mut TX_QUEUE: heapless::Deque<u8, TX_QUEUE_LEN> = heapless::Deque::new();
    let (compensator, upload_buffers, tx_queue) = (COMPENSATOR, UPLOAD_BUFFERS, TX_QUEUE);
    let record = resets::boot_record();
    let reset = record.reset;
    defmt::info!(
        "f407-app: boot {} after {} (detail {}), {} faults in a row",
        reset.boots,
        reset.cause,
        reset.detail,
        record.faults_in_a_row
    );
    let (Some(cp), Some(dp)) = (cortex_m::Peripherals::take(), pac::Peripherals::take()) else {
        resets::fatal_boot(BootFault::CorePeripherals)
    };
    // The watchdog first: it runs from its own oscillator, so a clock set-up that never
    // finishes (a PLL that does not lock) resets the chip instead of hanging it.
    let mut watchdog = IndependentWatchdog::new(dp.IWDG);
    // Paused while a debug probe halts the core (probe-rs breakpoints, RTT reads).
    watchdog.stop_on_debug(&dp.DBGMCU, true);
    watchdog.start(WATCHDOG_MS.millis());
    let (clock_config, clock_source) = clocks::choose();
    if clock_source == ClockSource::InternalRc {
        defmt::warn!("crystal did not start: PLL from the internal RC oscillator");
    }
    let mut rcc = dp.RCC.freeze(clock_config);
    millis::start_millis(cp.SYST, clocks::CORE_HZ);

    let gpioa = dp.GPIOA.split(&mut rcc);
    let gpiob = dp.GPIOB.split(&mut rcc);
    // The HAL sets up pins, baud rate and transmitter; reception is by DMA (`dma_ring`).
    let (host_tx, _) = or_reset(dp.USART1.serial::<u8>(
        (gpioa.pa9, gpioa.pa10),
        HOST_BAUD.bps(),
        &mut rcc,
    ))
    .split();
    let (_gyro_tx, _) = or_reset(dp.USART2.serial::<u8>(
        (gpioa.pa2, gpioa.pa3),
        GYRO_BAUD.bps(),
        &mut rcc,
    ))
    .split();
    let (table_tx, _) = or_reset(dp.USART3.serial::<u8>(
        (gpiob.pb10, gpiob.pb11),
        TABLE_BAUD.bps(),
        &mut rcc,
    ))
    .split();
    // SAFETY: each stream and ring is started once, here; the interrupts are unmasked
    // after their streams run.
    let (host_rx, gyro_rx, table_rx) = unsafe {
        (
            DmaRx::start(USART1_RX, &HOST_RING),
            DmaRx::start(USART2_RX, &GYRO_RING),
            DmaRx::start(USART3_RX, &TABLE_RING),
        )
    };
    // SAFETY: the handlers below touch only their own stream's flags and ring counter.
    unsafe {
        cortex_m::peripheral::NVIC::unmask(Interrupt::DMA2_STREAM5);
        cortex_m::peripheral::NVIC::unmask(Interrupt::DMA1_STREAM5);
        cortex_m::peripheral::NVIC::unmask(Interrupt::DMA1_STREAM1);
    }
    let mut host = DmaSerial {
        rx: host_rx,
        tx: host_tx,
    };
    let gyro_port = DmaSerial {
        rx: gyro_rx,
        tx: (),
    };
    let table_port = DmaSerial {
        rx: table_rx,
        tx: table_tx,
    };
    // SAFETY: the model sectors are taken once, here.
    let model_flash = unsafe { SectorFlash::take() };
    if model_flash.is_none() {
        defmt::error!("memory.x MODELS region is not flash sectors 10-11");
    }
    let server = if record.safe_mode() {
        // A reset loop (fault_record.rs): host link and upload server only, until a good
        // upload; the TMP117, the gyro path and the turntable are not started.
        let mut server = model_flash
            .and_then(|f| {
                upload_boot::try_new_upload_server(f, VERIFY_KEY, GYRO_ID, reset, upload_buffers)
                    .ok()
            })
            .map(keep_server);
        let faults = record.state(true);
        let feed = || watchdog.feed();
        safe_loop::run(&mut host, server.as_deref_mut(), tx_queue, faults, feed);
        // `run` returns only after a good upload, which needs the store.
        server.unwrap_or_else(|| resets::fatal_boot(BootFault::StoreGeometry))
    } else {
        let Some(model_flash) = model_flash else {
            resets::fatal_boot(BootFault::StoreGeometry)
        };
        keep_server(upload_boot::new_upload_server(
            model_flash,
            VERIFY_KEY,
            GYRO_ID,
            reset,
            upload_buffers,
        ))
    };

    let i2c = I2c::new(dp.I2C1, (gpiob.pb6, gpiob.pb7), 400.kHz(), &mut rcc);
    let mut tmp117 = match Tmp117::new(i2c, TMP117_ADDRESS, millis::MillisClock) {
        Ok(t) => Some(t),
        Err(e) => {
            defmt::error!("TMP117 not found ({}): windows without temperature", e);
            None
        }
    };

    let slot_report = server.boot_report();
    // Decoded in place into the server's model buffer (the compensator keeps its own copy).
    let model = server.load_active_model_in_place().unwrap_or_else(|e| {
        defmt::warn!("stored model not loaded ({}): running uncompensated", e);
        None
    });
    for (name, verdict) in ["A", "B"].into_iter().zip(slot_report) {
        defmt::info!("model slot {}: {}", name, verdict);
    }

    let table = SerialTurntable::new(table_port, millis::MillisClock, TurntableConfig::default());
    let cfg = AppConfig::for_rate(GYRO_RATE_HZ as f32);
    let mut app = match App::with_compensator(cfg, model, table, compensator) {
        Ok(a) => a,
        Err(e) => {
            defmt::error!("configuration rejected: {}", e);
            resets::fatal_boot(BootFault::Configuration)
        }
    };
    let mut gyro = FogSerialGyro::with_clock(gyro_port, GYRO_RATE_HZ, millis::MillisClock);
    let mut watch = GyroWatch::new(GYRO_SILENCE_S, DEFAULT_STUCK_RUN);
    let mut clean_run = fog_firmware::fault_record::CleanRun::new(&record);

    loop {
        let now_s = millis::MillisClock.now_s();
        if clean_run.due(now_s) {
            defmt::info!("clean run: faults in a row cleared");
            resets::clear_faults();
        }
        let drops_before = gyro.uart_mut().dropped();
        loop {
            match gyro.read() {
                Ok(Some(s)) => {
                    let health = watch.on_sample(now_s, s.t_s, s.rate_dph);
                    if health.resumed {
                        // A stall mid-seek restarts the seek, with its reason.
                        if let Some(why) = app.on_gyro_stall(s.t_s, health.gap_s).restarted {
                            defmt::warn!("north seek restarted: {}", why);
                        }
                    }
                    match health.stuck_event {
                        Some(StuckEvent::Stuck) => defmt::warn!("t={} s: gyro stuck", s.t_s),
                        Some(StuckEvent::Recovered) => defmt::info!("t={} s: gyro moving", s.t_s),
                        None => {}
                    }
                    if health.stuck {
                        app.on_fault(s.t_s);
                    }
                    if app.temp_due(s.t_s) {
                        let reading = tmp117.as_mut().and_then(|t| t.read_temp().ok());
                        app.on_temp(s.t_s, reading);
                    }
                    let step = app.on_gyro(s);
                    if let Some(w) = step.window {
                        defmt::info!(
                            "t={} s: {} deg/h ({}), T {} C",
                            w.t_end_s,
                            w.compensated_dph,
                            w.status,
                            w.temp_c
                        );
                    }
                }
                Ok(None) => break,
                Err(e) => {
                    defmt::warn!("gyro UART error {}", e);
                    app.on_fault(watch.last_t_s());
                }
            }
        }
        if watch.became_silent(now_s) {
            defmt::warn!("t={} s: gyro silent: window invalid", watch.last_t_s());
            app.on_fault(watch.last_t_s());
        }
        if gyro.uart_mut().dropped() == drops_before {
            watchdog.feed();
        }

        server.set_time_s(now_s);
        for _ in 0..HOST_BYTES_PER_PASS {
            let Ok(byte) = host.read() else { break };
            let Some(reply) = server.push_byte(byte) else {
                continue;
            };
            let changed = reply.model_changed;
            if reply.frame.len() <= TX_QUEUE_LEN - tx_queue.len() {
                reply.frame.iter().for_each(|&b| {
                    let _ = tx_queue.push_back(b);
                });
            } else {
                server.note_reply_dropped();
            }
            if changed {
                // A good upload clears the faults in a row (fault_record.rs).
                resets::clear_faults();
                let loaded = server.load_active_model_in_place();
                match loaded.map(|model| app.set_model_from(model)) {
                    Ok(Ok(())) => defmt::info!("new model in use"),
                    Ok(Err(e)) => defmt::error!("new model refused: {}", e),
                    Err(e) => defmt::error!("new model not loaded: {}", e),
                }
            }
        }
        while let Some(&b) = tx_queue.front() {
            if host.write(b).is_err() {
                break;
            }
            let _ = tx_queue.pop_front();
        }
    }
}

/// A peripheral the HAL refused to configure: a fatal boot error (recorded, reset).
fn or_reset<T, E>(r: Result<T, E>) -> T {
    r.unwrap_or_else(|_| resets::fatal_boot(BootFault::Configuration))
}

/// Moves the upload server (`upload_boot.rs` builds it) into its static (once).
fn keep_server(server: Server) -> &'static mut Server {
    let Some(server) = cortex_m::singleton!(: Server = server) else {
        resets::fatal_boot(BootFault::Singleton)
    };
    server
}

#[interrupt]
fn DMA2_STREAM5() {
    USART1_RX.on_interrupt(&HOST_RING);
}

#[interrupt]
fn DMA1_STREAM5() {
    USART2_RX.on_interrupt(&GYRO_RING);
}

#[interrupt]
fn DMA1_STREAM1() {
    USART3_RX.on_interrupt(&TABLE_RING);
}
