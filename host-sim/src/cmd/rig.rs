//! `fogsim rig --gyro-port P --table-port P [--incl-port P] ...`: serve the simulated
//! gyro, turntable and base inclinometer on the firmware's links (`crate::device::rig`), for
//! `fog-app` under QEMU (`cargo fw-run`) or a board on the bench. Prints the truth
//! (azimuth of the table's zero) and the firmware arguments that must match the rig
//! (`gyro-rate=`; `tilt-mdeg=` only without an inclinometer link), then one summary line.

use std::sync::atomic::AtomicBool;
use std::time::Duration;

use anyhow::{bail, Result};
use fog_core::seeking::tilt::Tilt;

use crate::device::rig::{open_rig_link, Rig, RigConfig};
use crate::sim::{GyroParams, StartState, DEFAULT_LATITUDE_DEG};

/// Options of `fogsim rig`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The gyro link: `tcp:127.0.0.1:PORT` (listened on; QEMU's UART1 connects) or a
    /// serial device.
    #[arg(long)]
    pub gyro_port: String,
    /// The turntable link (UART2), same forms as --gyro-port.
    #[arg(long)]
    pub table_port: String,
    /// The inclinometer link (UART3), same forms as --gyro-port: the base tilt as
    /// 10 Hz frames. Without it the firmware must simulate its inclinometer (`tilt-mdeg=`).
    #[arg(long)]
    pub incl_port: Option<String>,
    /// Serial baud rate of the inclinometer link (ignored for tcp:); UART3 runs 115,200.
    #[arg(long, default_value_t = 115_200)]
    pub incl_baud: u32,
    /// Serial baud rate of the gyro link (ignored for tcp:); the firmware's UART1 runs 460,800.
    #[arg(long, default_value_t = 460_800)]
    pub gyro_baud: u32,
    /// Serial baud rate of the table link (ignored for tcp:); the firmware's UART2 runs 115,200.
    #[arg(long, default_value_t = 115_200)]
    pub table_baud: u32,
    /// Seed of every random draw (same seed, same frames).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Ambient (chamber) temperature, degC; the gyro starts cold, soaked at it.
    #[arg(long, default_value_t = 20.0, allow_negative_numbers = true)]
    pub ambient_c: f64,
    /// Site latitude, deg (north positive).
    #[arg(long, default_value_t = DEFAULT_LATITUDE_DEG, allow_negative_numbers = true)]
    pub latitude_deg: f64,
    /// True azimuth of the table's zero, deg from north: what a seek should find.
    #[arg(long, default_value_t = 108.4)]
    pub azimuth_deg: f64,
    /// Base tilt, pitch and roll, deg (served on --incl-port; without it give the
    /// firmware the same: `tilt-mdeg=`).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub pitch_deg: f64,
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub roll_deg: f64,
    /// A heading-dependent bias A cos(input axis azimuth), deg/h (-1..=1), as
    /// `fogsim campaign --heading-bias-dph` plants it: what `heading-cal` calibrates.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub heading_bias_dph: f64,
    /// Gyro frames per second of sample time (give the firmware the same: `gyro-rate=`).
    #[arg(long, default_value_t = 20)]
    pub rate_hz: u32,
    /// Sample time per real time (QEMU's serial link cannot take more than about 10x20 Hz).
    #[arg(long, default_value_t = 10.0)]
    pub speed: f64,
    /// Stop after this many seconds of sample time [default: until a link closes]
    #[arg(long)]
    pub duration_s: Option<f64>,
    /// Wait at most this many seconds for each link to connect.
    #[arg(long, default_value_t = 120)]
    pub connect_timeout_s: u64,
}

/// A link the rig can open: `tcp:` with a socket address, or a device that exists.
fn check_port(flag: &str, port: &str) -> Result<()> {
    match port.strip_prefix("tcp:") {
        Some(addr) if addr.parse::<std::net::SocketAddr>().is_err() => {
            bail!("{flag} {port}: not a tcp:IP:PORT address")
        }
        None if !std::path::Path::new(port).exists() => {
            bail!("{flag} {port}: no such serial device")
        }
        _ => Ok(()),
    }
}

/// Runs the subcommand.
pub fn run(a: Args) -> Result<()> {
    if !(a.speed.is_finite() && a.speed > 0.0 && a.speed <= 1000.0) {
        bail!("--speed {}: must be within (0, 1000]", a.speed);
    }
    if !(1..=2000).contains(&a.rate_hz) {
        bail!("--rate-hz {}: must be within 1..=2000", a.rate_hz);
    }
    if !(0.0..360.0).contains(&a.azimuth_deg) {
        bail!("--azimuth-deg {}: must be within [0, 360)", a.azimuth_deg);
    }
    if !(a.pitch_deg.abs() <= 10.0 && a.roll_deg.abs() <= 10.0) {
        bail!("--pitch-deg/--roll-deg: a base tilt is at most 10 deg per axis");
    }
    if !(a.heading_bias_dph.is_finite() && a.heading_bias_dph.abs() <= 1.0) {
        bail!(
            "--heading-bias-dph {}: must be within -1..=1 deg/h",
            a.heading_bias_dph
        );
    }
    if !(a.ambient_c.is_finite() && (-60.0..=100.0).contains(&a.ambient_c)) {
        bail!("--ambient-c {}: must be within -60..=100 degC", a.ambient_c);
    }
    if a.latitude_deg.is_nan() || a.latitude_deg.abs() > 90.0 {
        bail!(
            "--latitude-deg {}: must be within -90..=90 deg",
            a.latitude_deg
        );
    }
    if let Some(d) = a.duration_s.filter(|d| !(d.is_finite() && *d > 0.0)) {
        bail!("--duration-s {d}: must be a positive number of seconds");
    }
    // Both links named before either waits for its peer.
    check_port("--gyro-port", &a.gyro_port)?;
    check_port("--table-port", &a.table_port)?;
    if let Some(p) = &a.incl_port {
        check_port("--incl-port", p)?;
    }
    let tilt = Tilt {
        pitch_deg: a.pitch_deg as f32,
        roll_deg: a.roll_deg as f32,
    };
    let cfg = RigConfig {
        params: GyroParams::paper_default().with_heading_bias(a.heading_bias_dph),
        seed: a.seed,
        ambient_c: a.ambient_c,
        latitude_deg: a.latitude_deg,
        azimuth_deg: a.azimuth_deg,
        tilt,
        start: StartState::Soaked,
        rate_hz: f64::from(a.rate_hz),
        speed: a.speed,
        duration_s: a.duration_s,
    };
    let mut rig = Rig::new(cfg).map_err(|e| anyhow::anyhow!("rig: {e}"))?;
    let tilt_arg = if a.incl_port.is_some() {
        String::new()
    } else {
        format!(
            " tilt-mdeg={}:{}",
            (a.pitch_deg * 1000.0).round() as i64,
            (a.roll_deg * 1000.0).round() as i64
        )
    };
    println!(
        "rig truth azimuth_deg={:.4} latitude_deg={} ambient_c={} pitch_deg={} roll_deg={} heading_bias_dph={} seed={} | firmware arguments: gyro-rate={}{tilt_arg}",
        a.azimuth_deg,
        a.latitude_deg,
        a.ambient_c,
        a.pitch_deg,
        a.roll_deg,
        a.heading_bias_dph,
        a.seed,
        a.rate_hz,
    );
    let within = Duration::from_secs(a.connect_timeout_s);
    let mut gyro = open_rig_link(&a.gyro_port, a.gyro_baud, within)?;
    let mut table = open_rig_link(&a.table_port, a.table_baud, within)?;
    let mut incl = match &a.incl_port {
        Some(p) => Some(open_rig_link(p, a.incl_baud, within)?),
        None => None,
    };
    println!(
        "rig connected: gyro {} table {} inclinometer {}",
        a.gyro_port,
        a.table_port,
        a.incl_port.as_deref().unwrap_or("none")
    );
    let stop = AtomicBool::new(false);
    let sum = rig.serve(
        gyro.as_mut(),
        table.as_mut(),
        incl.as_mut()
            .map(|l| l.as_mut() as &mut dyn crate::device::upload::Link),
        &stop,
    )?;
    println!(
        "rig summary frames={} tilt_frames={} sample_time_s={:.1} table_commands={} moves={} ended=\"{}\"",
        sum.frames, sum.tilt_frames, sum.sample_time_s, sum.table_commands, sum.moves, sum.ended
    );
    Ok(())
}
