//! The STM32F407 board binary (`f407-app`) has fog-app's reset-loop safe mode: the same
//! loop (`firmware/src/bin/target/safe_loop.rs`), linked into the board image.
//!
//! QEMU's `netduinoplus2` stops the board at its PLL wait (board_netduino.rs), before
//! the host USART exists, so the board's safe mode cannot be driven there; the loop
//! itself is driven under QEMU on fog-app (qemu_reset_loop.rs) and the rule that enters
//! it on the host (fw_fault_record.rs). What this test checks is that the board image
//! carries that loop: defmt keeps every log string a linked path can print as a symbol
//! of the ELF (`{"package":..,"data":"<format>",..,"crate_name":"<binary>"}`), and a
//! path the board never calls is removed by LTO with its strings. So the safe loop's
//! entry and exit strings must be there, attributed to the board's own crate.

use std::process::Command;

use fog_tests::{build_board_elf, llvm_tool, qemu_ready};

/// The safe loop's defmt lines (safe_loop.rs): entering and leaving safe mode.
const SAFE_LOOP_LINES: [&str; 2] = [
    "\"data\":\"SAFE MODE: {} faults in a row, last {} (detail {}): host link and upload only\"",
    "\"data\":\"safe mode left: a good model was uploaded\"",
];

#[test]
fn board_binary_links_the_reset_loop_safe_mode() {
    if !qemu_ready("board_safe_mode") {
        return;
    }
    let elf = build_board_elf().unwrap_or_else(|e| panic!("{e}"));
    let nm = llvm_tool("llvm-nm").unwrap_or_else(|e| panic!("{e}"));
    let out = Command::new(&nm).arg(&elf).output().expect("llvm-nm runs");
    assert!(out.status.success(), "llvm-nm {}", elf.display());
    let symbols = String::from_utf8_lossy(&out.stdout);
    let defmt: Vec<&str> = symbols
        .lines()
        .filter(|l| l.contains("\"crate_name\":\"f407_app\""))
        .collect();
    // The board's own boot line is there: the symbol format is what this test reads.
    assert!(
        defmt
            .iter()
            .any(|l| l.contains("f407-app: boot {} after {}")),
        "no defmt symbols of f407_app in {}",
        elf.display()
    );
    for line in SAFE_LOOP_LINES {
        assert!(
            defmt.iter().any(|l| l.contains(line)),
            "the board image has no safe-mode path: {line} missing"
        );
    }
}
