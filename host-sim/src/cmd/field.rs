//! `fogsim field pull --port P [--registry DB] --out DIR`: pulls the device's field records
//! (one per completed two-position seek: residual bias at a temperature state) over the
//! host link into `DIR/field_records.{json,csv}` (merged by sequence with what DIR holds)
//! and, when the calibration registry exists, into its `field_records` table.
//! `fogsim train --field DIR` then refines the chamber model with them.

use std::path::PathBuf;
use std::time::Duration;

use anyhow::Result;

use super::upload::LinkArgs;
use crate::device::field_pull::{pull_records, MAX_PULLED_RECORDS};
use crate::device::upload::device_gyro_id;
use crate::io::field_records::{merge_into_dir, StoredRecord, CSV_NAME, JSON_NAME};
use crate::registry::{self, Registry};

/// Options of `fogsim field`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(subcommand)]
    pub action: Action,
}

#[derive(clap::Subcommand, Debug)]
pub enum Action {
    /// Pull the device's field records into DIR (and the registry, if it exists).
    Pull(PullArgs),
    /// Measure what field refinement wins back on a simulated aged gyro (5/20/50 field seeks).
    Aging(super::field_aging::AgingArgs),
}

#[derive(clap::Args, Debug)]
pub struct PullArgs {
    #[command(flatten)]
    pub link: LinkArgs,
    /// Calibration registry (SQLite); used only if it exists. Default:
    /// $XDG_DATA_HOME/fogsim/registry.sqlite.
    #[arg(long)]
    pub registry: Option<PathBuf>,
    /// Directory of the record files (created; records already there are kept).
    #[arg(long)]
    pub out: PathBuf,
    /// First sequence number to ask for.
    #[arg(long, default_value_t = 0)]
    pub from: u32,
    /// Seconds to wait for each reply.
    #[arg(long, default_value_t = 10)]
    pub timeout_s: u64,
}

pub fn run(a: Args) -> Result<()> {
    match a.action {
        Action::Pull(p) => pull(p),
        Action::Aging(a) => super::field_aging::run(a),
    }
}

fn pull(a: PullArgs) -> Result<()> {
    if a.out.exists() && !a.out.is_dir() {
        anyhow::bail!("--out {}: exists and is not a directory", a.out.display());
    }
    let reg_path = registry::resolve(a.registry.as_deref())?;
    // An existing registry is opened (a bad one refused) before the link, as `monitor`
    // does: checked only after the pull, a directory, `/dev/zero` or a file that is not
    // SQLite was reported as the link's error, or (not a regular file) skipped as absent.
    let mut reg = if reg_path.exists() {
        Some(Registry::open(&reg_path)?)
    } else {
        None
    };
    let mut link = a.link.open()?;
    let gyro_id = device_gyro_id(&mut link)?;
    let records = pull_records(
        &mut link,
        a.from,
        Duration::from_secs(a.timeout_s),
        MAX_PULLED_RECORDS,
    )?;
    let stored: Vec<StoredRecord> = records
        .iter()
        .map(|r| StoredRecord::new(&gyro_id, r))
        .collect();
    let (in_dir, added_dir) = merge_into_dir(&a.out, &stored)?;
    let registry_note = if let Some(reg) = &mut reg {
        let added = reg.insert_field_records(&stored)?;
        format!("registry={} registry_added={added}", reg_path.display())
    } else {
        format!("registry=none ({} does not exist)", reg_path.display())
    };
    println!(
        "field pull gyro={gyro_id} pulled={} newest={} dir={} ({JSON_NAME}, {CSV_NAME}) \
         dir_records={in_dir} dir_added={added_dir} {registry_note}",
        records.len(),
        records
            .last()
            .map_or("none".to_string(), |r| r.sequence.to_string()),
        a.out.display(),
    );
    Ok(())
}
