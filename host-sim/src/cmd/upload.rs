//! `fogsim upload`: sign a trained model and install it on the gyro over its UART.
//!
//! Checks the model file, the key and the registry locally first (a bad file never goes
//! out; every file read is size-bounded), checks that the device is the model's gyro,
//! takes the security counter from the calibration registry (the next one for this gyro,
//! or `--security-counter` checked against it: never 0, never reused, above the
//! device's), signs the model for that gyro and counter, uploads it in chunks (one
//! session), commits, asks the device for its status and confirms that the new model
//! (sequence, CRC, counter) is the one in use. The registry records the model, the
//! counter and the upload's outcome.

use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{bail, Context};
use ed25519_compact::KeyPair;
use fog_core::model::format::RbfModel;

use crate::device::upload::{
    describe_model, load_signing_key, open_link, sign_upload, test_key_path, UploadClient,
};
use crate::io::model::read_model_file;
use crate::registry::{self, ModelRecord, Registry};

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
    pub fn open(&self) -> anyhow::Result<Box<dyn crate::device::upload::Link>> {
        open_link(&self.port, self.baud).map_err(|e| e.context(format!("--port {}", self.port)))
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
    /// Security counter signed with the model. Default: the next one from the registry
    /// (above every counter issued for this gyro and above the device's). If given, it
    /// must be above both, and never 0.
    #[arg(long)]
    pub security_counter: Option<u32>,
    /// Calibration registry (SQLite). Default: $XDG_DATA_HOME/fogsim/registry.sqlite
    /// (~/.local/share/fogsim/registry.sqlite).
    #[arg(long)]
    pub registry: Option<PathBuf>,
    /// Only query and print the device status; no upload.
    #[arg(long)]
    pub status_only: bool,
    /// The model file written by `fogsim train --out` (`RbfModel::encode` bytes).
    #[arg(required_unless_present = "status_only")]
    pub model: Option<PathBuf>,
}

/// A model checked locally, with its signing key.
struct Prepared {
    bytes: Vec<u8>,
    model: RbfModel,
    key: KeyPair,
}

/// Runs the subcommand.
pub fn run(args: Args) -> anyhow::Result<()> {
    if !(args.timeout_s.is_finite() && args.timeout_s > 0.0) {
        bail!(
            "--timeout-s must be a positive number of seconds, got {}",
            args.timeout_s
        );
    }
    if args.security_counter == Some(0) {
        bail!("--security-counter 0: counter 0 is never accepted (counters start at 1; docs/reference/link-protocol.md)");
    }
    // Check everything local first: a bad file, key or registry never reaches the device.
    let prepared = match &args.model {
        Some(path) if !args.status_only => Some(prepare(path, args.key.clone())?),
        _ => None,
    };
    let mut reg = match &prepared {
        Some(_) => Some(Registry::open(&registry::resolve(
            args.registry.as_deref(),
        )?)?),
        None => None,
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
    let (Some(p), Some(reg)) = (prepared, reg.as_mut()) else {
        return Ok(());
    };
    let gyro_id = p.model.meta.gyro_id.as_str();
    if gyro_id != before.gyro_id.as_str() {
        bail!(
            "model is for gyro {gyro_id} but the device is gyro {}: not sent",
            before.gyro_id
        );
    }
    let record = ModelRecord::of(&p.model, &p.bytes);
    let device_counter = before.active.as_ref().map_or(0, |a| a.security_counter);
    let counter = reg
        .issue_counter(
            gyro_id,
            args.security_counter,
            device_counter,
            record.model_crc32,
        )
        .map_err(|e| {
            anyhow::anyhow!(
                "--security-counter: {e} (registry {})",
                reg.path().display()
            )
        })?;
    let signature = sign_upload(&p.key, counter, gyro_id, &p.bytes)?;
    reg.record_model(&record)?;
    let upload_id = reg.begin_upload(gyro_id, counter, record.model_crc32)?;
    println!(
        "security counter {counter} (registry {})",
        reg.path().display()
    );
    let outcome = send(&mut client, &p.bytes, counter, &signature);
    let result = match &outcome {
        Ok(_) => "committed".to_string(),
        Err(e) => format!("failed: {e:#}"),
    };
    reg.finish_upload(upload_id, &result)?;
    let active = outcome?;
    println!("device model now:    {}", describe_model(&active));
    Ok(())
}

/// Uploads, commits and confirms with a status that the committed model is active.
fn send(
    client: &mut UploadClient<Box<dyn crate::device::upload::Link>>,
    bytes: &[u8],
    counter: u32,
    signature: &[u8],
) -> anyhow::Result<fog_core::link::upload::ModelInfo> {
    let committed = client
        .upload(bytes, counter, signature, |done, total| {
            eprint!("\r  sent {done}/{total} bytes")
        })
        .context("upload")?;
    eprintln!();
    let after = client.status().context("status after commit")?;
    match after.active {
        Some(active) if active == committed => Ok(active),
        other => bail!("device committed {committed:?} but reports {other:?} as active"),
    }
}

/// Reads (size-bounded) and validates the model file and loads the key.
fn prepare(model_path: &Path, key: Option<PathBuf>) -> anyhow::Result<Prepared> {
    let (bytes, model) = read_model_file(model_path)?;
    let key_path = key.unwrap_or_else(test_key_path);
    if key_path == test_key_path() {
        eprintln!("fogsim upload: WARNING signing with the public TEST key (keys/README.md)");
    }
    let key = load_signing_key(&key_path)?;
    println!(
        "model {}: {} bytes, gyro {}, {} centres, {} inputs",
        model_path.display(),
        bytes.len(),
        model.meta.gyro_id,
        model.centers.len(),
        model.inputs.len()
    );
    Ok(Prepared { bytes, model, key })
}
