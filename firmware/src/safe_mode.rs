//! What the device says while in safe mode (`fault_record`: after a reset loop): a
//! status that shows why, and a refusal of every command but `GetStatus`. Portable, so
//! the host tests check the messages the QEMU build sends.
//!
//! In safe mode the application (gyro path, compensation, seeks, turntable) is not
//! started: whatever faulted at every boot is not run again. The host link and the
//! upload server run, so the operator sees the reason and can install a good model,
//! which clears the record and lets the boot go on.

use fog_core::link::messages::{
    Command, DeviceMessage, FaultState, Refusal, ResetReason, Status, LINK_VERSION,
};
use fog_core::seeking::bit::{BitItem, BitWord};
use fog_core::seeking::quality::SeekState;
use fog_core::seeking::tilt::Tilt;

/// The safe-mode status at `t_s` (s since boot): not ready (the gyro is not read), the
/// model in flash if any, and the fault state with `safe_mode` set.
pub fn status(t_s: f64, model_crc32: Option<u32>, faults: FaultState) -> Status {
    let mut bit = BitWord::PASS;
    bit.set(BitItem::GyroLink, true);
    Status {
        link_version: LINK_VERSION,
        t_s: t_s as f32,
        state: SeekState::NotReady(BitItem::GyroLink),
        progress: 0.0,
        predicted_sigma_deg: f32::NAN,
        temp_c: f32::NAN,
        model_crc32,
        bit,
        reset_reason: ResetReason::from(faults.last_cause),
        latitude_deg: f32::NAN,
        tilt: Tilt::LEVEL,
        restarts: 0,
        last_restart: None,
        // The model is not loaded in safe mode.
        heading_cal: false,
        faults: FaultState {
            safe_mode: true,
            ..faults
        },
    }
}

/// The answer to a host command in safe mode (`None`: `GetStatus`, answered by the
/// status alone).
pub fn answer(cmd: Command) -> Option<DeviceMessage> {
    match cmd {
        Command::GetStatus => None,
        Command::StartSeek { .. }
        | Command::SetLatitude { .. }
        | Command::Abort
        | Command::GetFieldRecords { .. } => Some(DeviceMessage::Refused(Refusal::SafeMode)),
    }
}
