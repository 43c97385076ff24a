//! The STM32F407 board binary on QEMU 7.2's `netduinoplus2` (an STM32F405 model: same
//! memory map and core): how far it runs, as docs/guide/firmware.md says.
//!
//! QEMU models that machine's USARTs, timers, SPI, ADC, SYSCFG and EXTI, and maps RCC,
//! the flash interface, IWDG, I2C, DMA and GPIO as unimplemented (reads 0, writes
//! ignored: `info mtree`, `-d unimp`, which logs every access to them). So the image
//! boots from 0x0800_0000 (reset vector, RAM init, `main`, reset record), starts the
//! IWDG (3 s), tries the crystal with a bounded wait (HSERDY never sets in QEMU), gives
//! it up, programs the PLL from the internal RC oscillator for 168 MHz, and then waits
//! for PLLRDY, which QEMU never sets either (on a chip the running IWDG would reset it).
//! This test checks that sequence from the register writes: the watchdog period, the
//! crystal attempt being bounded, the clock tree (168 MHz core, 48 MHz USB clock, 5 flash
//! wait states with prefetch and caches), and that QEMU saw no guest error (but for the
//! debug-freeze register DBGMCU_APB1_FZ, which it does not model). Everything
//! after the clock set-up (UART DMA, TMP117, flash store) is not run by QEMU; the DMA
//! ring arithmetic is tested on the host (board_dma_ring.rs).

use std::io::{BufRead, BufReader};
use std::time::{Duration, Instant};

use fog_tests::{build_board_elf, qemu_ready, spawn_qemu, QemuOptions};

/// DBGMCU_APB1_FZ (0xE004_2008: the IWDG paused while a probe halts the core), which
/// QEMU does not model: logged as an unassigned PPB access, ignored on a chip without
/// a debugger.
const DBGMCU_FZ: &str = "unassigned area of PPB: offset 0x42008";
const HSI_HZ: f64 = 16e6;
const LSI_HZ: f64 = 32e3;
/// CR reads the firmware may spend on the crystal (320,000 polls, +1 to clear HSEON).
const HSE_POLL_LIMIT: usize = 320_001;
/// CR polls after PLLON that show the PLL wait does not end.
const PLL_WAIT_POLLS: usize = 100_000;

/// One access logged by `-d unimp`.
#[derive(Debug, PartialEq)]
enum Access {
    Write {
        device: String,
        offset: u32,
        value: u32,
    },
    /// A read of RCC_CR (the oscillator and PLL ready flags).
    RccCrPoll,
}

/// `(device, offset, value)` of an "unimplemented device write" line of `-d unimp`.
fn unimp_write(line: &str) -> Option<Access> {
    let (device, rest) = line.split_once(": unimplemented device write")?;
    let field = |name: &str| {
        let at = rest.find(name)? + name.len();
        let text: String = rest[at..]
            .trim_start()
            .trim_start_matches("0x")
            .chars()
            .take_while(char::is_ascii_hexdigit)
            .collect();
        u32::from_str_radix(&text, 16).ok()
    };
    Some(Access::Write {
        device: device.trim().to_string(),
        offset: field("offset")?,
        value: field("value")?,
    })
}

/// Index and value of the first write to `device` (one of the names) at `offset`
/// matching `pred`.
fn find_write(
    log: &[Access],
    devices: &[&str],
    at: u32,
    pred: impl Fn(u32) -> bool,
) -> Option<(usize, u32)> {
    log.iter().enumerate().find_map(|(i, a)| match a {
        Access::Write {
            device,
            offset,
            value,
        } if devices.contains(&device.as_str()) && *offset == at && pred(*value) => {
            Some((i, *value))
        }
        _ => None,
    })
}

#[test]
fn board_binary_boots_on_netduinoplus2_up_to_the_clock_setup() {
    if !qemu_ready("board_netduino") {
        return;
    }
    let elf = build_board_elf().unwrap_or_else(|e| panic!("{e}"));
    let opts = QemuOptions {
        machine: Some("netduinoplus2"),
        extra: vec!["-d".into(), "unimp,guest_errors".into()],
        ..QemuOptions::default()
    };
    let mut qemu = spawn_qemu(&elf, &opts).expect("start QEMU");
    let stderr = qemu.0.stderr.take().expect("piped");
    let mut log = Vec::new();
    let mut guest_errors = Vec::new();
    let mut polls_since_write = 0;
    let mut pll_on_seen = false;
    let deadline = Instant::now() + Duration::from_secs(30);
    for line in BufReader::new(stderr).lines() {
        let Ok(line) = line else { break };
        if let Some(w) = unimp_write(&line) {
            if let Access::Write {
                device,
                offset: 0,
                value,
            } = &w
            {
                pll_on_seen |= device == "RCC" && value & (1 << 24) != 0;
            }
            log.push(w);
            polls_since_write = 0;
        } else if line.starts_with("RCC: unimplemented device read  (size 4, offset 0x000)") {
            log.push(Access::RccCrPoll);
            polls_since_write += 1;
        } else if !line.contains("unimplemented device read") && !line.contains(DBGMCU_FZ) {
            guest_errors.push(line);
        }
        // Past the crystal wait and stuck on the PLL: done.
        if (pll_on_seen && polls_since_write > PLL_WAIT_POLLS) || Instant::now() > deadline {
            break;
        }
    }
    drop(qemu);
    assert!(guest_errors.is_empty(), "QEMU reported {guest_errors:#?}");

    // IWDG (QEMU names its unimplemented region IWDG or I2S2ext): prescaler, reload,
    // start, before any clock register is touched.
    let iwdg = ["IWDG", "I2S2ext"];
    let (start_at, _) = find_write(&log, &iwdg, 0x0, |v| v == 0xCCCC).expect("IWDG started");
    let (_, pr) = find_write(&log, &iwdg, 0x4, |_| true).expect("IWDG prescaler");
    let (_, rlr) = find_write(&log, &iwdg, 0x8, |_| true).expect("IWDG reload");
    let period_s = f64::from(rlr) * f64::from(4u32 << pr) / LSI_HZ;
    assert!((2.9..=3.1).contains(&period_s), "IWDG period {period_s} s");

    // The crystal: HSEON, a bounded wait, HSEON cleared.
    let (hse_on, _) = find_write(&log, &["RCC"], 0x0, |v| v == 1 << 16).expect("HSEON");
    let (hse_off, _) = find_write(&log, &["RCC"], 0x0, |v| v & (1 << 16) == 0).expect("HSE off");
    assert!(
        start_at < hse_on && hse_on < hse_off,
        "IWDG, then HSEON, then HSE off"
    );
    let waited = log[hse_on..hse_off]
        .iter()
        .filter(|a| **a == Access::RccCrPoll)
        .count();
    assert!(
        (1_000..=HSE_POLL_LIMIT).contains(&waited),
        "crystal wait bounded: {waited} polls"
    );

    // The PLL from the internal RC oscillator: 168 MHz core, 48 MHz USB clock.
    let (_, pllcfgr) = find_write(&log, &["RCC"], 0x4, |_| true).expect("PLLCFGR written");
    assert_eq!(pllcfgr & (1 << 22), 0, "PLL source: HSI");
    let (m, n) = (pllcfgr & 0x3F, (pllcfgr >> 6) & 0x1FF);
    let p = 2 * (((pllcfgr >> 16) & 0b11) + 1);
    let q = (pllcfgr >> 24) & 0xF;
    let vco_hz = HSI_HZ / f64::from(m) * f64::from(n);
    assert_eq!(
        vco_hz / f64::from(p),
        168e6,
        "core clock, PLLCFGR {pllcfgr:#x}"
    );
    assert_eq!(vco_hz / f64::from(q), 48e6, "USB/SDIO clock");
    let (_, acr) = find_write(&log, &["Flash Int"], 0x0, |_| true).expect("flash ACR");
    assert_eq!(acr & 0xF, 5, "5 wait states at 168 MHz, 2.7-3.6 V");
    assert_eq!(
        acr & 0x700,
        0x700,
        "prefetch, instruction and data caches on"
    );
    let (pll_on, _) = find_write(&log, &["RCC"], 0x0, |v| v & (1 << 24) != 0).expect("PLLON");
    assert!(pll_on > hse_off);
    assert!(
        polls_since_write > PLL_WAIT_POLLS,
        "then waits for PLLRDY (which QEMU never sets)"
    );
}
