//! QEMU scenario (issue 20 item 4): the device learns from its seeks, and what it learnt
//! survives a power cut in the middle of writing it.
//!
//! The real `fog-app` keeps its models in `flash-file=models.img` and its field-record ring
//! in `field-file=field.img` (both written through at every flash write, so they survive
//! a QEMU restart). The world around it is the bench simulator's (`fog_sim::device::rig`, as in
//! qemu_seek.rs) with a gyro whose drift law is one constant: Earth rate on the level
//! input axis at the table heading + `BIAS_DPH` + white noise, at 25 degC with no self
//! heating, so the residual a record must carry is known exactly. Gyro on UART1,
//! turntable on UART2, inclinometer on UART3, the PC on UART0.
//!
//! Run 1: upload a model, two two-position seeks; `fogsim field pull`'s client pulls two
//! records (sequences 1, 2) whose residual bias is the generator's bias minus the model's
//! drift at 25 degC, dT/dt 0, within the noise of a seek. Run 2 (restart on the same
//! files, `flash-tear-at=1`): a third seek; its record's write to the image is torn in
//! half (the first write since boot; the firmware stops there) and QEMU is killed: a power
//! cut mid-append. Run 3 (restart): the boot scan finds 2 valid records and the torn
//! slot; the pull returns exactly records 1 and 2 as before (no torn record); a fourth
//! seek appends sequence 3 after the torn slot, and the pull returns 1, 2, 3.
//!
//! Skips loudly without QEMU / the target unless FOG_REQUIRE_QEMU=1. Every wait is
//! bounded; QEMU is killed when each run ends.

use crate::qemu_support;
use crate::upload_support;

use std::net::TcpStream;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::Receiver;
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

use fog_core::link::messages::{Command, DeviceMessage};
use fog_core::model::rbf::predict_f64;
use fog_core::seeking::field_record::FieldRecord;
use fog_core::seeking::tilt::Tilt;
use fog_sim::device::field_pull::pull_records;
use fog_sim::device::rig::{tcp_link, Rig, RigConfig};
use fog_sim::device::upload::UploadClient;
use fog_sim::sim::{GyroParams, StartState};
use fog_tests::console::{start_with_console, wait_line, wait_line_where};
use fog_tests::{firmware_elf, qemu_ready, scratch_dir, KillOnDrop, QemuOptions};
use qemu_support::{link_command, polled, wait_ready};
use upload_support::*;

const RATE_HZ: u32 = 20;
const SPEED: f64 = 10.0;
const DWELL_S: u32 = 30;
const LATITUDE_DEG: f64 = 39.9;
const TRUE_AZIMUTH_DEG: f64 = 61.0;
const ARW_DPSH: f64 = 0.0011;
const BIAS_DPH: f64 = 0.35;
const AMBIENT_C: f64 = 25.0;
const SEED: u64 = 20;
const WAIT: Duration = Duration::from_secs(40);

/// The rig's gyro: one constant bias, white noise, no temperature law, no heating.
fn constant_bias_gyro() -> GyroParams {
    let mut p = GyroParams::paper_default();
    p.thermal.power_w = 0.0;
    p.sensor.noise_c = 0.0;
    p.drift.bias_dph = BIAS_DPH;
    p.drift.bias_dph_per_c = 0.0;
    p.drift.bias_dph_per_c2 = 0.0;
    p.drift.shupe_dph_per_cps = 0.0;
    p.drift.shupe_cold_gain_per_k = 0.0;
    p.drift.gradient_dph_per_cps = 0.0;
    p.drift.turn_on_bias_sigma_dph = 0.0;
    p.noise.arw_dpsh = ARW_DPSH;
    p.noise.bias_instability_dph = 0.0;
    p.noise.rrw_dph_per_sqrt_h = 0.0;
    p.noise.quantization_arcsec = 0.0;
    p.variation.power_sigma_frac = 0.0;
    p.variation.start_temp_sigma_c = 0.0;
    p
}

/// One QEMU run on `dir`'s two flash images, with the simulated gyro and table.
struct Run {
    qemu: KillOnDrop,
    host: TcpStream,
    console: Receiver<String>,
    stop: Arc<AtomicBool>,
    threads: Vec<JoinHandle<()>>,
}

impl Run {
    fn start(dir: &Path, extra: &[&str]) -> Self {
        let mut args = vec![
            "flash-file=models.img".to_string(),
            "field-file=field.img".to_string(),
            format!("gyro-rate={RATE_HZ}"),
            format!("seek-dwell-s={DWELL_S}"),
        ];
        args.extend(extra.iter().map(|s| s.to_string()));
        let opts = QemuOptions {
            args,
            cwd: Some(dir.to_path_buf()),
            ..QemuOptions::default()
        };
        let (qemu, mut streams, console) = start_with_console(&firmware_elf("fog-app"), opts, 4);
        let incl_link = streams.pop().expect("inclinometer link");
        let table_link = streams.pop().expect("table link");
        let gyro_link = streams.pop().expect("gyro link");
        let host = polled(streams.pop().expect("host link"));
        let stop = Arc::new(AtomicBool::new(false));
        let rig = {
            let s = stop.clone();
            std::thread::spawn(move || {
                let mut rig = Rig::new(RigConfig {
                    params: constant_bias_gyro(),
                    seed: SEED,
                    ambient_c: AMBIENT_C,
                    latitude_deg: LATITUDE_DEG,
                    azimuth_deg: TRUE_AZIMUTH_DEG,
                    tilt: Tilt::LEVEL,
                    start: StartState::Warm,
                    rate_hz: f64::from(RATE_HZ),
                    speed: SPEED,
                    duration_s: None,
                })
                .expect("rig");
                let [mut gyro, mut table, mut incl] =
                    [gyro_link, table_link, incl_link].map(|l| tcp_link(l).expect("rig link"));
                let _ = rig.serve(gyro.as_mut(), table.as_mut(), Some(incl.as_mut()), &s);
            })
        };
        Run {
            qemu,
            host,
            console,
            stop,
            threads: vec![rig],
        }
    }

    /// Starts a two-position seek (latitude first) once the device says it is ready.
    fn start_seek(&mut self) {
        wait_ready(&mut self.host, WAIT);
        let lat = Command::SetLatitude {
            latitude_deg: LATITUDE_DEG as f32,
        };
        assert_eq!(
            link_command(&mut self.host, lat, WAIT),
            DeviceMessage::Accepted
        );
        let seek = Command::StartSeek { positions: 2 };
        assert_eq!(
            link_command(&mut self.host, seek, WAIT),
            DeviceMessage::Accepted
        );
    }

    /// Waits for the next field-record line (`FOG-FIELD-RECORD ...`), echoing the
    /// seek's console lines.
    fn wait_record(&self) -> String {
        wait_line_where(&self.console, "FOG-", WAIT, |l| {
            if !l.starts_with("FOG-WINDOW") {
                eprintln!("console: {l}");
            }
            l.starts_with("FOG-FIELD-RECORD")
        })
    }

    fn pull(&mut self) -> Vec<FieldRecord> {
        pull_records(&mut self.host, 0, Duration::from_secs(10), 1000).expect("field pull")
    }

    fn end(self) {
        self.stop.store(true, Ordering::Relaxed);
        drop(self.qemu);
        for t in self.threads {
            let _ = t.join();
        }
    }
}

#[test]
fn qemu_field_records_survive_a_power_cut_mid_append() {
    if !qemu_ready("qemu_field_log") {
        return;
    }
    let dir = scratch_dir("qemu_field_log");
    let model = sample_model(QEMU_GYRO, 8, 1.0);
    let bytes = encode(&model);
    // The residual a seek measures: the bias minus the model's drift at 25 degC, 0 degC/s.
    let expected_dph = BIAS_DPH - predict_f64(&model, &[25.0, 0.0]).unwrap();

    // Run 1: upload, two seeks, two records.
    let mut run = Run::start(&dir, &[]);
    wait_line(&run.console, "FOG-FIELD-LOG valid=0 corrupt=0", WAIT);
    let info = UploadClient::new(run.host.try_clone().unwrap(), Duration::from_secs(10))
        .upload(&bytes, 1, &sign_for_gyro(1, QEMU_GYRO, &bytes), |_, _| {})
        .expect("upload");
    for seq in 1..=2 {
        wait_line(&run.console, "FOG-WINDOW", WAIT);
        run.start_seek();
        let line = run.wait_record();
        assert!(
            line.starts_with(&format!("FOG-FIELD-RECORD sequence={seq} ")),
            "{line}"
        );
    }
    let first = run.pull();
    run.end();
    assert_eq!(
        first.iter().map(|r| r.sequence).collect::<Vec<_>>(),
        [1, 2],
        "{first:#?}"
    );
    for r in &first {
        assert_eq!(r.model_crc32, Some(info.model_crc32), "{r:?}");
        assert!(
            (r.temp_c - 25.0).abs() < 0.01 && r.temp_rate_cps.abs() < 1e-4,
            "{r:?}"
        );
        // One seek's half-sum: 2 x 3 windows of 10 s, window noise ARW*60/sqrt(10).
        let sigma_dph = ARW_DPSH * 60.0 / 10f64.sqrt() / 6f64.sqrt();
        let err = f64::from(r.residual_bias_dph) - expected_dph;
        assert!(
            err.abs() < 5.0 * sigma_dph,
            "residual {r:?}, expected {expected_dph}"
        );
        assert!(r.t_since_power_on_s > 0.0);
    }
    assert!(first[1].t_since_power_on_s > first[0].t_since_power_on_s);

    // Run 2: the third record's write is torn in half; the power goes there.
    let mut run = Run::start(&dir, &["flash-tear-at=1"]);
    wait_line(
        &run.console,
        "FOG-FIELD-LOG valid=2 corrupt=0 oldest=1 newest=2",
        WAIT,
    );
    wait_line(&run.console, "FOG-WINDOW", WAIT);
    run.start_seek();
    let torn = wait_line(&run.console, "FOG-FLASH-TEAR write=1 ", WAIT);
    run.end();
    assert!(
        torn.contains("bytes=16"),
        "half of a 36-byte record, whole words: {torn}"
    );

    // Run 3: the torn slot is found and skipped; records 1 and 2 are intact.
    let mut run = Run::start(&dir, &[]);
    wait_line(
        &run.console,
        "FOG-FIELD-LOG valid=2 corrupt=1 oldest=1 newest=2",
        WAIT,
    );
    let after_cut = run.pull();
    assert_eq!(
        after_cut, first,
        "no torn record, the earlier ones unchanged"
    );
    wait_line(&run.console, "FOG-WINDOW", WAIT);
    run.start_seek();
    let line = run.wait_record();
    assert!(line.starts_with("FOG-FIELD-RECORD sequence=3 "), "{line}");
    let all = run.pull();
    run.end();
    assert_eq!(
        all.iter().map(|r| r.sequence).collect::<Vec<_>>(),
        [1, 2, 3],
        "{all:#?}"
    );
    assert_eq!(&all[..2], &first[..]);
    eprintln!(
        "field records: residuals {:?} deg/h (expected {expected_dph:.4}); torn append skipped",
        all.iter().map(|r| r.residual_bias_dph).collect::<Vec<_>>()
    );
}
