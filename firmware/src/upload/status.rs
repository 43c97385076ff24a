//! The upload's session state and counters, and what is reported from them: the
//! `DeviceStatus` of a status request and the `ModelInfo` identity of a stored model.

use fog_core::link::upload::{
    DeviceStatus, ModelInfo, ResetRecord, UploadPhase, GYRO_ID_LEN, PROTOCOL_VERSION,
};
use fog_core::model::format::RbfModel;
use heapless::String;

use crate::store::ActiveSlot;

#[derive(Clone, Copy)]
pub(super) enum Session {
    Idle,
    Receiving {
        id: u32,
        model_len: u32,
        model_crc32: u32,
        received: u32,
        last_activity_s: f64,
    },
}

#[derive(Clone, Copy, Default)]
pub(super) struct Counters {
    pub(super) frames_rejected: u32,
    pub(super) uploads_rejected: u32,
    pub(super) replies_suppressed: u32,
}

pub(super) fn device_status(
    session: &Session,
    active_info: &Option<ModelInfo>,
    counters: &Counters,
    gyro_id: &String<GYRO_ID_LEN>,
    last_reset: ResetRecord,
) -> DeviceStatus {
    DeviceStatus {
        protocol_version: PROTOCOL_VERSION,
        active: active_info.clone(),
        upload: match *session {
            Session::Idle => UploadPhase::Idle,
            Session::Receiving {
                model_len,
                received,
                ..
            } => UploadPhase::Receiving {
                received,
                model_len,
            },
        },
        frames_rejected: counters.frames_rejected,
        uploads_rejected: counters.uploads_rejected,
        replies_suppressed: counters.replies_suppressed,
        gyro_id: gyro_id.clone(),
        last_reset,
    }
}

pub(super) fn model_info(slot: &ActiveSlot, model: &RbfModel) -> ModelInfo {
    ModelInfo {
        slot: slot.slot,
        sequence: slot.header.sequence,
        model_len: slot.header.model_len,
        model_crc32: slot.header.model_crc32,
        security_counter: slot.header.security_counter,
        gyro_id: model.meta.gyro_id.clone(),
        n_centers: model.centers.len() as u16,
        n_inputs: model.inputs.len() as u8,
        heldout_rms_dph: model.meta.heldout_rms_dph,
    }
}
