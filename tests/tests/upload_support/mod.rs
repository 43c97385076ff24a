//! Shared by the upload/store/protocol tests: a valid sample model, its signed bytes,
//! hand-made faulty variants, and an in-memory link that runs the real client against
//! the real `UploadServer`.
#![allow(dead_code)]

use std::collections::VecDeque;
use std::io::{Read, Write};
use std::time::Duration;

use fog_core::model::format::{RbfModel, TrainingMeta, MAX_ENCODED_LEN};
use fog_firmware::signature::TEST_PUBLIC_KEY;
use fog_firmware::store::EmulatedModelFlash;
use fog_firmware::upload::UploadServer;
use fog_sim::device::upload::{load_signing_key, sign_upload, test_key_path, UploadClient};

/// The gyro the host-test device is bound to.
pub const TEST_GYRO: &str = "FOG-A17";

/// A valid 2-input model (T, dT/dt) with `n_centers` centres for gyro `gyro_id`.
pub fn sample_model(gyro_id: &str, n_centers: usize, weight_scale: f32) -> RbfModel {
    let inputs = fog_core::model::format::PAPER_INPUTS;
    let mut m = RbfModel {
        n_rbf_inputs: 2,
        inputs: inputs.iter().copied().collect(),
        input_offset: [10.0, 0.0].into_iter().collect(),
        input_scale: [50.0, 0.05].into_iter().collect(),
        input_min: [-40.0, -0.01].into_iter().collect(),
        input_max: [60.0, 0.08].into_iter().collect(),
        linear: [0.0, 0.0].into_iter().collect(),
        centers: Default::default(),
        widths: Default::default(),
        weights: Default::default(),
        bias_dph: 0.012,
        meta: TrainingMeta {
            gyro_id: gyro_id.try_into().expect("gyro id fits 16 bytes"),
            heldout_rms_dph: 0.0042,
            n_train: 1350,
        },
        poly: Default::default(),
        heading: None,
        linear_by_t: Default::default(),
        cold_start: None,
    };
    for i in 0..n_centers {
        let u = i as f32 / n_centers.max(1) as f32;
        m.centers.push([2.0 * u - 1.0, 1.0 - u, 0.0, 0.0]).unwrap();
        m.widths.push(0.3 + 0.2 * u).unwrap();
        m.weights.push(weight_scale * (0.05 - 0.1 * u)).unwrap();
    }
    m
}

/// `RbfModel::encode` bytes.
pub fn encode(model: &RbfModel) -> Vec<u8> {
    let mut buf = vec![0u8; MAX_ENCODED_LEN + 64];
    let n = model.encode(&mut buf).expect("sample model encodes");
    buf.truncate(n);
    buf
}

/// Upload signature of `bytes` for `TEST_GYRO` and `counter` with the repository's
/// TEST key.
pub fn sign_with_test_key(counter: u32, bytes: &[u8]) -> [u8; 64] {
    sign_for_gyro(counter, TEST_GYRO, bytes)
}

/// Upload signature of `bytes` for `gyro` and `counter` with the TEST key.
pub fn sign_for_gyro(counter: u32, gyro: &str, bytes: &[u8]) -> [u8; 64] {
    let key = load_signing_key(&test_key_path()).expect("test key loads");
    sign_upload(&key, counter, gyro, bytes).expect("gyro id fits")
}

/// Rewrites the body of an encoded model (the envelope is postcard of
/// `(magic, version, body bytes, crc32(body))`) and fixes the CRC, so only the
/// body's content is wrong.
pub fn patch_body(encoded: &[u8], patch: impl FnOnce(&mut Vec<u8>)) -> Vec<u8> {
    let (magic, version, body, _crc): (u32, u16, &[u8], u32) =
        postcard::from_bytes(encoded).expect("envelope decodes");
    let mut body = body.to_vec();
    patch(&mut body);
    let crc = fog_core::model::crc::crc32(&body);
    postcard::to_allocvec(&(magic, version, body.as_slice(), crc)).expect("re-encodes")
}

/// The gyro id of the QEMU test build of `fog-app` (firmware/build.rs).
pub const QEMU_GYRO: &str = "QEMU-FOG-1";

/// A model for `TEST_GYRO` whose first weight is NaN but whose envelope CRC is right.
pub fn nan_weight_model_bytes() -> Vec<u8> {
    nan_weight_model_bytes_for(TEST_GYRO)
}

/// `nan_weight_model_bytes` for another gyro.
pub fn nan_weight_model_bytes_for(gyro: &str) -> Vec<u8> {
    let marker = 1234.5f32;
    let mut model = sample_model(gyro, 8, 1.0);
    model.weights[0] = marker;
    patch_body(&encode(&model), |body| {
        let at = body
            .windows(4)
            .position(|w| w == marker.to_le_bytes())
            .expect("marker weight in body");
        body[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    })
}

pub type Server = UploadServer<EmulatedModelFlash>;

/// A fresh device: erased emulated flash, the TEST public key, bound to `TEST_GYRO`.
pub fn fresh_server() -> Server {
    reboot(EmulatedModelFlash::new())
}

/// A device booting on `flash` (TEST key, `TEST_GYRO`).
pub fn reboot(flash: EmulatedModelFlash) -> Server {
    UploadServer::new(flash, 0, TEST_PUBLIC_KEY, TEST_GYRO.try_into().unwrap())
        .expect("store opens")
}

/// Bytes written by the client go straight into the server; its replies queue for reading.
pub struct InMemoryLink<'s> {
    pub server: &'s mut Server,
    replies: VecDeque<u8>,
    pub model_changes: u32,
}

impl<'s> InMemoryLink<'s> {
    pub fn new(server: &'s mut Server) -> Self {
        Self {
            server,
            replies: VecDeque::new(),
            model_changes: 0,
        }
    }
}

impl Write for InMemoryLink<'_> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        for &b in buf {
            if let Some(reply) = self.server.push_byte(b) {
                self.replies.extend(reply.frame);
                self.model_changes += u32::from(reply.model_changed);
            }
        }
        Ok(buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

impl Read for InMemoryLink<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        if self.replies.is_empty() {
            return Err(std::io::ErrorKind::WouldBlock.into());
        }
        let n = buf.len().min(self.replies.len());
        for (slot, b) in buf.iter_mut().zip(self.replies.drain(..n)) {
            *slot = b;
        }
        Ok(n)
    }
}

/// The real client over an in-memory link to `server`.
pub fn client(server: &mut Server) -> UploadClient<InMemoryLink<'_>> {
    UploadClient::new(InMemoryLink::new(server), Duration::from_millis(200))
}
