//! The firmware's panic handler. Release builds are checked to contain no panicking
//! paths (see scripts/budgets.sh); should one remain, a panic ends the program with a
//! failing semihosting exit under QEMU (and halts on hardware) instead of hanging.

#[panic_handler]
fn panic(_info: &core::panic::PanicInfo) -> ! {
    semihosting::process::abort()
}
