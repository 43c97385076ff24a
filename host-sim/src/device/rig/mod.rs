//! `fogsim rig`: the bench around the device, simulated. The same `sim/` physics as the
//! campaign (a `SimGyro` cold-started at the rig's power-on, on a `SimTurntable`, on a
//! possibly tilted base) served on the firmware's own links: the FOG's 12-byte frames
//! (`fog_core::sensor_link::gyro_frame`, the one encoder) on the gyro link, the ASCII
//! turntable protocol (`table`) on the table link, and the base inclinometer's readings
//! of the same base (`sim::BaseMotion`, SCL3300-like noise) as 14-byte
//! `fog_core::sensor_link::tilt_frame`s at 10 Hz of sample time on the inclinometer link.
//! A link is a serial device (a board on the bench) or a TCP port the rig listens on
//! (QEMU's `-serial tcp:...` client). The QEMU tests drive `fog-app` through this same
//! server (`Rig::serve` on their sockets), so there is one simulated bench.
//!
//! Time: the firmware's time base is the frame count, so the rig sends `rate_hz` frames
//! per second of sample time, `speed` times faster than real time (QEMU cannot take a
//! 2 kHz stream in real time); the table moves in sample time (it shares the gyro's
//! clock). Power-on is the moment the gyro link is connected: frame 1 is the first
//! sample of the cold start. Deterministic: same seed, same frames.

mod table;

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use fog_core::hal::Turntable;
use fog_core::seeking::tilt::Tilt;
use fog_core::sensor_link::gyro_frame::GyroFrame;
use fog_core::sensor_link::tilt_frame::{TiltFrame, TILT_FRAME_RATE_HZ};

use crate::device::upload::Link;
use crate::sim::{rig, BaseMotion, GyroParams, RunSpec, SimGyro, StartState, TurntableParams};

pub use table::TableServer;

/// What the rig simulates.
#[derive(Clone, Debug)]
pub struct RigConfig {
    pub params: GyroParams,
    pub seed: u64,
    pub ambient_c: f64,
    pub latitude_deg: f64,
    /// True azimuth of the table's zero, deg from north (what a seek measures).
    pub azimuth_deg: f64,
    /// Base tilt: served on the inclinometer link, or given to the firmware's simulated
    /// inclinometer (`tilt-mdeg=`) when there is none.
    pub tilt: Tilt,
    /// The gyro's state at power-on: `Soaked` (a cold start, `fogsim rig`) or `Warm`
    /// (already at equilibrium, no warm-up drift).
    pub start: StartState,
    /// Gyro frames per second of sample time.
    pub rate_hz: f64,
    /// Sample time per real time.
    pub speed: f64,
    /// Stop after this much sample time, s (`None`: until a link closes or `stop`).
    pub duration_s: Option<f64>,
}

/// What a rig session did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RigSummary {
    pub frames: u64,
    /// Inclinometer frames sent.
    pub tilt_frames: u64,
    pub sample_time_s: f64,
    pub table_commands: u64,
    pub moves: u64,
    /// Why it ended.
    pub ended: String,
}

/// The simulated gyro on its table, ready to be served.
pub struct Rig {
    gyro: SimGyro,
    table: TableServer,
    cfg: RigConfig,
    cut: Option<Arc<GyroCut>>,
}

/// A pulled gyro cable, armed while the rig runs (a bench test of the device's stall
/// handling): the frames from `from` (frame index; `u64::MAX`: not armed) for `frames`
/// frames are sampled but never sent, so the counter in later frames goes on as if they
/// had been (the gyro kept sampling). `next` is the index of the next frame due, for
/// choosing `from`.
#[derive(Debug)]
pub struct GyroCut {
    pub from: AtomicU64,
    pub frames: u64,
    pub next: AtomicU64,
}

impl GyroCut {
    /// A cut of `frames` frames, not armed yet.
    pub fn new(frames: u64) -> Self {
        Self {
            from: AtomicU64::new(u64::MAX),
            frames,
            next: AtomicU64::new(0),
        }
    }

    fn drops(&self, n: u64) -> bool {
        let from = self.from.load(Ordering::Relaxed);
        (from..from.saturating_add(self.frames)).contains(&n)
    }
}

impl Rig {
    /// Builds the gyro (cold start at `ambient_c`) on its table and base.
    pub fn new(cfg: RigConfig) -> Result<Self> {
        let spec = RunSpec {
            ambient_c: cfg.ambient_c,
            // Only bounds the validation of the specification: the rig runs until stopped.
            minutes: 24.0 * 60.0,
            latitude_deg: cfg.latitude_deg,
            heading_deg: cfg.azimuth_deg,
            input_axis_vertical: false,
            raw_rate_hz: cfg.rate_hz,
            seed: cfg.seed,
            start: cfg.start,
        };
        let (mut gyro, table) = rig(&cfg.params, &spec, TurntableParams::default())?;
        let mut base = BaseMotion::tilted(0.0, 0.0);
        base.pitch_deg = f64::from(cfg.tilt.pitch_deg);
        base.roll_deg = f64::from(cfg.tilt.roll_deg);
        gyro.set_base(base)?;
        Ok(Self {
            gyro,
            table: TableServer::new(table),
            cfg,
            cut: None,
        })
    }

    /// The rig with a gyro cable the caller can pull (`GyroCut`).
    pub fn with_gyro_cut(mut self, cut: Arc<GyroCut>) -> Self {
        self.cut = Some(cut);
        self
    }

    /// The table, for tests that drive it directly.
    pub fn table_mut(&mut self) -> &mut impl Turntable {
        self.table.table_mut()
    }

    /// The next frame (sequence `n` mod 256) and the sample behind it.
    pub fn next_frame(&mut self, n: u64, temp_c: &mut f64) -> (GyroFrame, crate::sim::RawSample) {
        let s = self.gyro.next_sample();
        // The coil temperature sensor is read once per second of sample time.
        let per_s = self.cfg.rate_hz.round().max(1.0) as u64;
        if n.is_multiple_of(per_s) || temp_c.is_nan() {
            *temp_c = self.gyro.read_sensor_c();
        }
        let frame = GyroFrame::from_physical(n as u8, s.rate_dph, *temp_c, 1.0 / self.cfg.rate_hz);
        (frame, s)
    }

    /// The inclinometer's frame after gyro frame `n`, if one is due (10 Hz of sample time).
    pub fn tilt_frame_after(&mut self, n: u64) -> Option<TiltFrame> {
        let per_reading = (self.cfg.rate_hz / TILT_FRAME_RATE_HZ).max(1.0);
        let reading = |k: u64| (k as f64 / per_reading).floor() as u64;
        if reading(n + 1) == reading(n) {
            return None;
        }
        let t = self.gyro.read_inclinometer();
        Some(TiltFrame::from_physical(
            reading(n) as u8,
            f64::from(t.pitch_deg),
            f64::from(t.roll_deg),
        ))
    }

    /// Serves the gyro, table and (if given) inclinometer links until `stop`, the
    /// duration, or a link closing.
    pub fn serve(
        &mut self,
        gyro_link: &mut dyn Link,
        table_link: &mut dyn Link,
        mut incl_link: Option<&mut dyn Link>,
        stop: &AtomicBool,
    ) -> Result<RigSummary> {
        let mut sum = RigSummary::default();
        let period_s = 1.0 / self.cfg.rate_hz;
        let start = Instant::now();
        let mut temp_c = f64::NAN;
        let mut batch = Vec::new();
        let mut tilt_batch = Vec::new();
        loop {
            if stop.load(Ordering::Relaxed) {
                sum.ended = "stopped".into();
                break;
            }
            let mut due = (start.elapsed().as_secs_f64() * self.cfg.speed / period_s) as u64;
            if let Some(d) = self.cfg.duration_s {
                due = due.min((d / period_s) as u64);
                if sum.frames >= due {
                    sum.ended = format!("duration {d} s of sample time reached");
                    break;
                }
            }
            batch.clear();
            tilt_batch.clear();
            while sum.frames < due {
                let (frame, _) = self.next_frame(sum.frames, &mut temp_c);
                if !self.cut.as_ref().is_some_and(|c| c.drops(sum.frames)) {
                    batch.extend_from_slice(&frame.encode());
                }
                if let Some(t) = self.tilt_frame_after(sum.frames) {
                    tilt_batch.extend_from_slice(&t.encode());
                    sum.tilt_frames += 1;
                }
                sum.frames += 1;
            }
            if let Some(c) = &self.cut {
                c.next.store(sum.frames, Ordering::Relaxed);
            }
            if let Err(e) = gyro_link.write_all(&batch).and_then(|()| gyro_link.flush()) {
                sum.ended = format!("gyro link closed: {e}");
                break;
            }
            if let Some(link) = incl_link.as_deref_mut() {
                if let Err(e) = link.write_all(&tilt_batch).and_then(|()| link.flush()) {
                    sum.ended = format!("inclinometer link closed: {e}");
                    break;
                }
            }
            match self.table.serve(table_link) {
                Ok(n) => sum.table_commands += n,
                Err(e) => {
                    sum.ended = format!("table link closed: {e}");
                    break;
                }
            }
            std::thread::sleep(Duration::from_millis(2));
        }
        sum.moves = self.table.moves();
        sum.sample_time_s = sum.frames as f64 * period_s;
        Ok(sum)
    }
}

/// Opens a rig link: `tcp:HOST:PORT` is listened on (one connection accepted, waiting at
/// most `accept_within`), anything else is a serial device at `baud`.
pub fn open_rig_link(port: &str, baud: u32, accept_within: Duration) -> Result<Box<dyn Link>> {
    if let Some(addr) = port.strip_prefix("tcp:") {
        let listener =
            std::net::TcpListener::bind(addr).with_context(|| format!("{port}: cannot listen"))?;
        listener.set_nonblocking(true)?;
        let t0 = Instant::now();
        let stream = loop {
            match listener.accept() {
                Ok((s, _)) => break s,
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                    if t0.elapsed() > accept_within {
                        anyhow::bail!(
                            "{port}: nothing connected within {} s",
                            accept_within.as_secs()
                        );
                    }
                    std::thread::sleep(Duration::from_millis(20));
                }
                Err(e) => return Err(e).with_context(|| format!("{port}: accept")),
            }
        };
        tcp_link(stream)
    } else {
        let serial = serialport::new(port, baud)
            .timeout(Duration::from_millis(1))
            .open()
            .with_context(|| format!("opening serial port {port} at {baud} Bd"))?;
        Ok(Box::new(serial))
    }
}

/// A connected TCP stream as a rig link: blocking writes, reads that wait at most 1 ms
/// (the table server polls), no Nagle delay.
pub fn tcp_link(stream: std::net::TcpStream) -> Result<Box<dyn Link>> {
    stream.set_nonblocking(false)?;
    stream.set_nodelay(true)?;
    stream.set_read_timeout(Some(Duration::from_millis(1)))?;
    Ok(Box::new(stream))
}

#[cfg(test)]
mod tests {
    use super::*;
    use fog_core::sensor_link::gyro_frame::FrameDecoder;

    fn cfg(seed: u64) -> RigConfig {
        RigConfig {
            params: GyroParams::paper_default(),
            seed,
            ambient_c: 20.0,
            latitude_deg: 39.9,
            azimuth_deg: 108.4,
            tilt: Tilt {
                pitch_deg: 2.0,
                roll_deg: -1.5,
            },
            start: StartState::Soaked,
            rate_hz: 20.0,
            speed: 10.0,
            duration_s: None,
        }
    }

    fn frames(seed: u64, n: u64) -> Vec<u8> {
        let mut rig = Rig::new(cfg(seed)).unwrap();
        let mut temp = f64::NAN;
        (0..n)
            .flat_map(|i| rig.next_frame(i, &mut temp).0.encode())
            .collect()
    }

    #[test]
    fn same_seed_same_frames_and_the_firmware_decodes_them() {
        let a = frames(7, 400);
        assert_eq!(a, frames(7, 400));
        assert_ne!(a, frames(8, 400));
        let mut dec = FrameDecoder::new();
        let decoded: Vec<GyroFrame> = a.iter().filter_map(|&b| dec.push(b)).collect();
        assert_eq!(decoded.len(), 400);
        assert!(decoded.iter().all(|f| f.rate_ok() && f.temp_ok()));
        // A cold start soaked at 20 degC: the coil is within a few degC of the chamber.
        assert!(decoded.iter().all(|f| (f.temp_c() - 20.0).abs() < 5.0));
    }

    #[test]
    fn the_inclinometer_link_carries_the_base_tilt_at_10_hz_seeded() {
        use fog_core::sensor_link::tilt_frame::TiltFrameDecoder;
        let tilts = |seed: u64| -> Vec<u8> {
            let mut rig = Rig::new(cfg(seed)).unwrap();
            let mut temp = f64::NAN;
            let mut out = Vec::new();
            for n in 0..2000 {
                rig.next_frame(n, &mut temp);
                if let Some(t) = rig.tilt_frame_after(n) {
                    out.extend(t.encode());
                }
            }
            out
        };
        let a = tilts(3);
        assert_eq!(a, tilts(3));
        assert_ne!(a, tilts(4));
        let mut dec = TiltFrameDecoder::new();
        let frames: Vec<TiltFrame> = a.iter().filter_map(|&b| dec.push(b)).collect();
        // 2,000 gyro frames at 20 Hz = 100 s of sample time: 1,000 readings at 10 Hz.
        assert_eq!(frames.len(), 1000);
        let n = frames.len() as f64;
        let mean =
            |f: fn(&Tilt) -> f32| frames.iter().map(|x| f64::from(f(&x.tilt()))).sum::<f64>() / n;
        let (p, r) = (mean(|t| t.pitch_deg), mean(|t| t.roll_deg));
        // The base's tilt, with 0.003 deg per-reading noise: the mean of 1,000 within 4e-4.
        assert!((p - 2.0).abs() < 4e-4 && (r + 1.5).abs() < 4e-4, "{p} {r}");
        let sd = (frames
            .iter()
            .map(|x| (f64::from(x.tilt().pitch_deg) - p).powi(2))
            .sum::<f64>()
            / n)
            .sqrt();
        assert!((0.002..0.004).contains(&sd), "pitch noise {sd} deg");
    }

    #[test]
    fn the_table_answers_the_firmware_protocol_in_sample_time() {
        let mut rig = Rig::new(cfg(1)).unwrap();
        let mut temp = f64::NAN;
        assert_eq!(rig.table.answer(b"MOV abc").as_deref(), Some("NAK"));
        assert_eq!(rig.table.answer(b"MOV 400.000").as_deref(), Some("NAK"));
        assert_eq!(rig.table.answer(b"HELLO"), None);
        assert_eq!(rig.table.answer(b"MOV 90.000").as_deref(), Some("ACK"));
        assert!(rig.table.answer(b"POS?").unwrap().ends_with(" M"));
        // 20 deg/s and 2 s settling: settled after 6.5 s of sample time, not before.
        for n in 0..(6.0 * 20.0) as u64 {
            rig.next_frame(n, &mut temp);
        }
        assert!(rig.table.answer(b"POS?").unwrap().ends_with(" M"));
        for n in 0..20 {
            rig.next_frame(200 + n, &mut temp);
        }
        assert_eq!(rig.table.answer(b"POS?").as_deref(), Some("POS 90.000 S"));
        assert_eq!(rig.table.moves(), 1);
    }
}
