//! Ed25519 check of an uploaded model: only models signed by the training PC's key run.
//!
//! The device holds only the 32-byte public key; the signature covers exactly the model
//! bytes (`RbfModel::encode` output, which itself carries magic, version and CRC).
//! `verify_model` is also what the budget scripts time under QEMU (instruction count).

use ed25519_compact::{Error, PublicKey, Signature};
use fog_core::link::upload::SIGNATURE_LEN;

/// The repository's TEST public key (`keys/TEST-ONLY-public-key.bin`).
/// Its secret seed is public: a production build must pass its own key to the server.
pub const TEST_PUBLIC_KEY: [u8; 32] = *include_bytes!("../../keys/TEST-ONLY-public-key.bin");

/// Why a signature check failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SignatureError {
    /// The signature is not 64 bytes.
    Malformed,
    /// The public key is not a valid Ed25519 point.
    BadPublicKey,
    /// The signature does not verify for this key and message.
    Invalid,
}

impl core::fmt::Display for SignatureError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Malformed => write!(f, "signature is not {SIGNATURE_LEN} bytes"),
            Self::BadPublicKey => write!(f, "public key is not a valid Ed25519 key"),
            Self::Invalid => write!(f, "Ed25519 signature does not verify"),
        }
    }
}

/// Verifies the Ed25519 `signature` of `model_bytes` under `public_key`.
pub fn verify_model(
    public_key: &[u8; 32],
    model_bytes: &[u8],
    signature: &[u8],
) -> Result<(), SignatureError> {
    let signature = Signature::from_slice(signature).map_err(|_| SignatureError::Malformed)?;
    // `verify` decodes the key itself and refuses non-canonical or small-order points.
    PublicKey::new(*public_key)
        .verify(model_bytes, &signature)
        .map_err(|e| match e {
            Error::InvalidPublicKey | Error::WeakPublicKey => SignatureError::BadPublicKey,
            _ => SignatureError::Invalid,
        })
}
