//! `fog-app`'s panic handler: records the reason (and source line) in no-init RAM and
//! resets the chip (`resets::fatal`); the next boot reports it. Release builds are
//! checked for panicking paths (tests/tests/fw_budgets.rs); this is the last line.
//! (The QEMU tools `replay` and `bench` use `panic.rs`: a failing exit, not a reset.)

use fog_core::link::upload::ResetCause;

use super::resets;

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    let line = info.location().map_or(0, |l| l.line());
    resets::fatal(ResetCause::Panic, line)
}
