//! `fogsim upload`: sign a trained model and install it on the gyro over its UART.
//!
//! Checks the model file locally first (a bad file never goes out), signs it with the
//! training PC's Ed25519 key for its gyro and the given security counter, checks that
//! the device is that gyro and runs a lower counter, uploads it in chunks (one
//! session), commits, then asks the device for its status and confirms that the new
//! model (sequence, CRC, counter) is the one in use.

use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{bail, Context};
use fog_core::link::upload::SIGNATURE_LEN;
use fog_core::model::format::RbfModel;

use crate::upload::{
    describe_model, load_signing_key, open_link, sign_upload, test_key_path, UploadClient,
};

/// Where the device is: shared by `upload` and `monitor`.
#[derive(clap::Args, Debug)]
pub struct LinkArgs {
    /// Link to the device: a serial port (`/dev/ttyUSB0`, `COM3`) or `tcp:127.0.0.1:PORT`
    /// (QEMU started with `-serial tcp:127.0.0.1:PORT,server`).
    #[arg(long)]
    pub port: String,
    /// Serial baud rate (ignored for tcp:).
    #[arg(long, default_value_t = 115_200)]
    pub baud: u32,
}

impl LinkArgs {
    /// Opens the link (see `upload::open_link`).
    pub fn open(&self) -> anyhow::Result<Box<dyn crate::upload::Link>> {
        open_link(&self.port, self.baud)
    }
}

/// Options of `fogsim upload`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub link: LinkArgs,
    /// Ed25519 signing seed (64 hex digits) [default: the repository's public TEST key].
    #[arg(long)]
    pub key: Option<PathBuf>,
    /// Seconds to wait for each response.
    #[arg(long, default_value_t = 5.0)]
    pub timeout_s: f64,
    /// Security counter signed with the model: must exceed the counter of the model the
    /// device runs (rollback protection); keep one increasing counter per gyro.
    #[arg(long, required_unless_present = "status_only")]
    pub security_counter: Option<u32>,
    /// Only query and print the device status; no upload.
    #[arg(long)]
    pub status_only: bool,
    /// The model file written by `fogsim train --out` (`RbfModel::encode` bytes).
    #[arg(required_unless_present = "status_only")]
    pub model: Option<PathBuf>,
}

/// Runs the subcommand.
pub fn run(args: Args) -> anyhow::Result<()> {
    if !(args.timeout_s.is_finite() && args.timeout_s > 0.0) {
        bail!(
            "--timeout-s must be a positive number of seconds, got {}",
            args.timeout_s
        );
    }
    // Check everything local first: a bad file or key never reaches the device.
    let prepared = match (&args.model, args.security_counter) {
        (Some(path), Some(counter)) => Some(prepare(path, args.key.clone(), counter)?),
        _ => None,
    };
    let link = args.link.open()?;
    let mut client = UploadClient::new(link, Duration::from_secs_f64(args.timeout_s));
    let before = client.hello().context("handshake (Hello)")?;
    match &before.active {
        Some(info) => println!("device model before: {}", describe_model(info)),
        None => println!("device model before: none"),
    }
    println!(
        "device: gyro {}, last reset {:?} (detail {}), boot {}",
        before.gyro_id, before.last_reset.cause, before.last_reset.detail, before.last_reset.boots
    );
    let Some((bytes, gyro_id, counter, signature)) = prepared else {
        return Ok(());
    };
    if gyro_id != before.gyro_id.as_str() {
        bail!(
            "model is for gyro {gyro_id} but the device is gyro {}: not sent",
            before.gyro_id
        );
    }
    if let Some(active) = before
        .active
        .as_ref()
        .filter(|a| a.security_counter >= counter)
    {
        if active.model_crc32 != fog_core::link::upload::crc32(&bytes) {
            bail!(
                "--security-counter {counter} is not above the device's {}: the device would refuse it as a rollback",
                active.security_counter
            );
        }
    }
    let committed = client
        .upload(&bytes, counter, &signature, |done, total| {
            eprint!("\r  sent {done}/{total} bytes")
        })
        .context("upload")?;
    eprintln!();
    let after = client.status().context("status after commit")?;
    match after.active {
        Some(active) if active == committed => {
            println!("device model now:    {}", describe_model(&active));
            Ok(())
        }
        other => bail!("device committed {committed:?} but reports {other:?} as active"),
    }
}

/// What `prepare` hands to the upload: model bytes, its gyro id, counter, signature.
type Prepared = (Vec<u8>, String, u32, [u8; SIGNATURE_LEN]);

/// Reads and validates the model file, loads the key and signs it for its gyro and
/// `counter`.
fn prepare(model_path: &Path, key: Option<PathBuf>, counter: u32) -> anyhow::Result<Prepared> {
    let bytes = std::fs::read(model_path)
        .with_context(|| format!("reading model {}", model_path.display()))?;
    let model = RbfModel::decode(&bytes)
        .map_err(|e| anyhow::anyhow!("{}: not a valid model file: {e}", model_path.display()))?;
    let key_path = key.unwrap_or_else(test_key_path);
    if key_path == test_key_path() {
        eprintln!("fogsim upload: WARNING signing with the public TEST key (keys/README.md)");
    }
    let gyro_id = model.meta.gyro_id.as_str();
    let signature = sign_upload(&load_signing_key(&key_path)?, counter, gyro_id, &bytes)?;
    println!(
        "model {}: {} bytes, gyro {}, {} centres, {} inputs",
        model_path.display(),
        bytes.len(),
        model.meta.gyro_id,
        model.centers.len(),
        model.inputs.len()
    );
    Ok((bytes, gyro_id.to_string(), counter, signature))
}
