//! Placeholder, replaced below.
#![no_std]
#![no_main]
#[path = "target/panic.rs"]
mod panic;
#[cortex_m_rt::entry]
fn main() -> ! {
    semihosting::process::exit(0)
}
