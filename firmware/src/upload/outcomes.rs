//! What the upload server hands back: a received frame's reply, why the active model could
//! not be loaded, and the boot check's verdict on each model slot.

use fog_core::link::messages::Command;
use fog_core::model::error::ModelError;

use crate::store::{SlotDefect, StoreError};

/// What one received frame produced: an upload response to send back, whether the active
/// model just changed (then call
/// [`UploadServer::load_active_model`](crate::upload::UploadServer::load_active_model) and
/// swap it into the compensator), or a north-finder command for the application (`frame`
/// empty; the application answers it, paying with
/// [`UploadServer::spend_reply_credit`](crate::upload::UploadServer::spend_reply_credit)).
pub struct Reply<'a> {
    /// A complete wire frame (COBS, ends with 0x00; a `DeviceFrame::Upload`).
    pub frame: &'a [u8],
    pub model_changed: bool,
    pub command: Option<Command>,
}

/// Why the active model could not be handed to the application.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LoadError {
    /// An upload is using the model buffer; retry once it ends.
    UploadInProgress,
    Store(StoreError),
    /// The stored bytes are intact but not a model this build reads.
    Model(ModelError),
}

impl core::fmt::Display for LoadError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::UploadInProgress => write!(f, "an upload is in progress"),
            Self::Store(e) => write!(f, "model store: {e}"),
            Self::Model(e) => write!(f, "{e}"),
        }
    }
}

/// What the boot check found in one slot (`UploadServer::boot_report`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SlotVerdict {
    /// Intact, signature verified, decoded for this gyro: the model in use.
    InUse,
    /// Intact (marker, header and body CRC) but not the model in use; its signature
    /// is not re-checked while the other slot verifies.
    Standby,
    /// Not usable as stored (`SlotDefect::Empty` for a slot never written).
    Defect(SlotDefect),
    /// Intact, but the signature does not verify with this build's key.
    SignatureInvalid,
    /// Signed and intact, but a model this build cannot decode or for another gyro.
    ModelRefused,
}

impl SlotVerdict {
    /// A slot that holds something but was refused (an empty slot is not refused).
    pub fn refused(self) -> bool {
        !matches!(
            self,
            Self::InUse | Self::Standby | Self::Defect(SlotDefect::Empty)
        )
    }
}

impl core::fmt::Display for SlotVerdict {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::InUse => f.write_str("in use"),
            Self::Standby => f.write_str("standby (intact, older)"),
            Self::Defect(SlotDefect::Empty) => f.write_str("empty"),
            Self::Defect(d) => write!(f, "refused: {d}"),
            Self::SignatureInvalid => f.write_str("refused: signature does not verify"),
            Self::ModelRefused => f.write_str("refused: not a model for this build and gyro"),
        }
    }
}
