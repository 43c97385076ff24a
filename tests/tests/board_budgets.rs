//! The STM32F407 board binary (`board-f407/`, `f407-app`): built for the target as CI
//! builds it, linked to the F407's memory map, inside its budgets.
//!
//! - flash <= 128 KiB and static RAM <= 32 KiB (the per-binary budget);
//! - the image starts at 0x0800_0000 (the F407's flash, not mps2-an386's 0x0), ends
//!   below the model sectors 10/11 at 0x080C_0000, and its RAM is in 0x2000_0000 +
//!   128 KiB (the map is the board's own `memory.x`, not the QEMU build's).
//!
//! With `FOG_BUDGETS_BOARD_OUT=<file>` the test writes its budget rows there
//! (`scripts/budgets.sh`). Needs the thumbv7em target and llvm-tools (skips like the
//! QEMU tests, and fails under FOG_REQUIRE_QEMU=1).

use fog_tests::{build_board_elf, elf_sections, firmware_size, qemu_ready};

const FLASH_BUDGET_BYTES: u64 = 128 * 1024;
const STATIC_RAM_BUDGET_BYTES: u64 = 32 * 1024;
const FLASH_ORIGIN: u64 = 0x0800_0000;
const MODEL_SECTORS: u64 = 0x080C_0000;
const RAM_ORIGIN: u64 = 0x2000_0000;
const RAM_LEN: u64 = 128 * 1024;

#[test]
fn board_binary_fits_its_budgets_and_the_f407_memory_map() {
    if !qemu_ready("board_budgets") {
        return;
    }
    let elf = build_board_elf().unwrap_or_else(|e| panic!("{e}"));
    let size = firmware_size(&elf).expect("llvm-size");
    let sections = elf_sections(&elf).expect("llvm-size");
    let flash: Vec<_> = sections
        .iter()
        .filter(|s| [".vector_table", ".text", ".rodata"].contains(&s.name.as_str()))
        .collect();
    let ram: Vec<_> = sections
        .iter()
        .filter(|s| [".data", ".bss", ".uninit"].contains(&s.name.as_str()))
        .collect();
    assert_eq!(flash.len(), 3, "{sections:?}");
    let vectors = flash[0];
    assert_eq!(
        (vectors.name.as_str(), vectors.addr),
        (".vector_table", FLASH_ORIGIN),
        "the image starts at the F407's flash"
    );
    let flash_end = flash.iter().map(|s| s.addr + s.size).max().unwrap() + size_of_data(&ram);
    assert!(
        flash_end <= MODEL_SECTORS,
        "code/data end {flash_end:#x} reaches the model sectors"
    );
    for s in &ram {
        assert!(
            s.addr >= RAM_ORIGIN && s.addr + s.size <= RAM_ORIGIN + RAM_LEN,
            "{s:?} outside the F407's 128 KiB SRAM"
        );
    }
    eprintln!(
        "f407-app: flash {} B ({:.1} KiB), static RAM {} B ({:.1} KiB)",
        size.flash,
        size.flash as f64 / 1024.0,
        size.static_ram,
        size.static_ram as f64 / 1024.0
    );
    if let Ok(path) = std::env::var("FOG_BUDGETS_BOARD_OUT") {
        let rows = format!(
            "\n| STM32F407 `f407-app` (board-f407/, fw profile) | measured | budget |\n\
             |---|---:|---:|\n\
             | flash, bytes | {} | {FLASH_BUDGET_BYTES} |\n\
             | static RAM, bytes | {} | {STATIC_RAM_BUDGET_BYTES} |\n",
            size.flash, size.static_ram
        );
        std::fs::write(path, rows).expect("write board budget rows");
    }
    assert!(
        size.flash <= FLASH_BUDGET_BYTES,
        "flash {} B over {FLASH_BUDGET_BYTES}",
        size.flash
    );
    assert!(
        size.static_ram <= STATIC_RAM_BUDGET_BYTES,
        "static RAM {} B over {STATIC_RAM_BUDGET_BYTES}",
        size.static_ram
    );
}

/// Bytes of `.data` initial values, stored in flash after the code.
fn size_of_data(ram: &[&fog_tests::Section]) -> u64 {
    ram.iter()
        .filter(|s| s.name == ".data")
        .map(|s| s.size)
        .sum()
}
