//! The STM32F407 board binary on QEMU 7.2's `netduinoplus2` (an STM32F405 model: same
//! memory map and core): how far it runs, as docs/firmware.md says.
//!
//! QEMU models that machine's USARTs, timers, SPI, ADC, SYSCFG and EXTI, and maps RCC,
//! the flash interface, IWDG, I2C, DMA and GPIO as unimplemented (reads 0, writes
//! ignored: `info mtree`, `-d unimp`). So the image boots from 0x0800_0000 (reset
//! vector, RAM init, `main`), reads the reset record, and the HAL's clock set-up writes
//! the real 168 MHz configuration, then waits for ever for the crystal (RCC_CR.HSERDY
//! never sets). This test checks that boot and the clock tree the firmware programs
//! (PLL from the 8 MHz crystal: 168 MHz core, 48 MHz USB/SDIO clock; 5 flash wait
//! states with prefetch and caches), and that QEMU saw no guest error on the way.
//! Everything after the clock set-up (UART DMA, TMP117, flash store, IWDG) is not run
//! by QEMU; the DMA ring arithmetic is tested on the host (board_dma_ring.rs).

use std::io::{BufRead, BufReader};
use std::time::{Duration, Instant};

use fog_tests::{build_board_elf, qemu_ready, spawn_qemu, QemuOptions};

const RCC_CR_OFFSET: u32 = 0x000;
const RCC_PLLCFGR_OFFSET: u32 = 0x004;
const HSE_HZ: f64 = 8e6;

/// `(device, offset, value)` of an "unimplemented device write" line of `-d unimp`.
fn unimp_write(line: &str) -> Option<(String, u32, u32)> {
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
    Some((device.trim().to_string(), field("offset")?, field("value")?))
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
    let mut writes = Vec::new();
    let mut cr_polls = 0u32;
    let mut guest_errors = Vec::new();
    let deadline = Instant::now() + Duration::from_secs(20);
    for line in BufReader::new(stderr).lines() {
        let Ok(line) = line else { break };
        if let Some(w) = unimp_write(&line) {
            writes.push(w);
        } else if line.starts_with("RCC: unimplemented device read  (size 4, offset 0x000)") {
            cr_polls += 1;
        } else if !line.contains("unimplemented device read") {
            guest_errors.push(line);
        }
        if cr_polls >= 10_000 || Instant::now() > deadline {
            break;
        }
    }
    drop(qemu);
    assert!(guest_errors.is_empty(), "QEMU reported {guest_errors:#?}");
    let rcc = |offset| {
        writes
            .iter()
            .find(|(d, o, _)| d == "RCC" && *o == offset)
            .map(|w| w.2)
    };
    let pllcfgr = rcc(RCC_PLLCFGR_OFFSET).expect("PLLCFGR written");
    let (m, n) = (pllcfgr & 0x3F, (pllcfgr >> 6) & 0x1FF);
    let p = 2 * (((pllcfgr >> 16) & 0b11) + 1);
    let q = (pllcfgr >> 24) & 0xF;
    assert_ne!(pllcfgr & (1 << 22), 0, "PLL source: the crystal (HSE)");
    let vco_hz = HSE_HZ / f64::from(m) * f64::from(n);
    assert_eq!(
        vco_hz / f64::from(p),
        168e6,
        "core clock from PLLCFGR {pllcfgr:#x}"
    );
    assert_eq!(vco_hz / f64::from(q), 48e6, "USB/SDIO clock");
    let acr = writes
        .iter()
        .find(|(d, o, _)| d == "Flash Int" && *o == 0)
        .map(|w| w.2)
        .expect("flash ACR written");
    assert_eq!(acr & 0xF, 5, "5 wait states at 168 MHz, 2.7-3.6 V");
    assert_eq!(
        acr & 0x700,
        0x700,
        "prefetch, instruction and data caches on"
    );
    assert_eq!(rcc(RCC_CR_OFFSET), Some(1 << 16), "HSEON, then");
    assert!(cr_polls >= 10_000, "waiting for HSERDY ({cr_polls} polls)");
}
