//! Placeholder, replaced below.
#![no_std]
#![no_main]
#[path = "target/panic.rs"]
mod panic;
use core::hint::black_box as bb;
#[cortex_m_rt::entry]
fn main() -> ! {
    let xs: [f32; 10] = [19.98046875, 19.984375, 19.98828125, 19.9921875, 19.98828125, 19.99609375, 20.0, 19.9921875, 19.98828125, 19.984375];
    let mut s = 0.0f64;
    for &x in bb(&xs).iter() { s += bb(x) as f64; }
    let m = s / bb(10u32) as f64;
    semihosting::println!("sum {:016x} mean {:016x}", s.to_bits(), m.to_bits());
    let a = bb(1.0f64) / bb(3.0f64);
    let b = bb(0.1f64) + bb(0.2f64);
    let c = bb(20.0437512f64) - bb(19.9875f64);
    let d = bb(c) * bb(0.1f64);
    let e = bb(5.0f64) * bb(c) / bb(50.0f64);
    semihosting::println!("{:016x} {:016x} {:016x} {:016x} {:016x}", a.to_bits(), b.to_bits(), c.to_bits(), d.to_bits(), e.to_bits());
    semihosting::process::exit(0)
}
