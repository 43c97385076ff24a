//! A/B model store in NOR flash: a power cut at any point leaves a complete model active.
//!
//! Two equal slots behind `embedded-storage`'s `NorFlash`. Slot layout (offsets in the slot):
//!
//! | offset | bytes | field |
//! |---|---|---|
//! | 0 | 4 | magic `"FOGS"` (0x5347_4F46 LE) |
//! | 4 | 2 | slot layout version (2) |
//! | 6 | 2 | reserved, 0xFFFF |
//! | 8 | 4 | sequence number (newest valid slot wins) |
//! | 12 | 4 | model length, bytes |
//! | 16 | 4 | CRC-32 of the model bytes |
//! | 20 | 64 | Ed25519 signature of `signed_prefix(counter, gyro) ++ model` |
//! | 84 | 4 | security counter the signature covers |
//! | 88 | 4 | CRC-32 of bytes 0..88 |
//! | 92 | 4 | 0xFF |
//! | 96 | 32 | commit marker, written LAST |
//! | 128 | len | model bytes (`RbfModel::encode`), padded to the write size with 0xFF |
//!
//! A commit erases the inactive slot, writes the model, then the header, then the
//! marker. A slot is valid only with the complete marker, a header with good magic,
//! version and CRC, and a body matching its CRC: every torn erase or write fails one
//! of these, so boot falls back to the other slot, which was never touched.

pub mod mirrored;
pub mod ram_flash;

use embedded_storage::nor_flash::NorFlash;
use fog_core::link::upload::SIGNATURE_LEN;
use fog_core::model::crc::CRC32;
use fog_core::model::format::MAX_ENCODED_LEN;

/// Slot magic "FOGS".
const SLOT_MAGIC: u32 = 0x5347_4F46;
/// Slot layout version.
const SLOT_VERSION: u16 = 2;
/// Bytes covered by the header CRC.
const HEADER_CRC_SPAN: usize = 88;
/// Header bytes written before the marker (header + padding).
const HEADER_LEN: usize = 96;
/// Offset and length of the commit marker.
const MARKER_OFFSET: usize = 96;
const MARKER_LEN: usize = 32;
/// Offset of the model bytes in a slot.
const BODY_OFFSET: usize = 128;
/// Largest flash write size the layout supports (marker and body alignment).
const MAX_WRITE_SIZE: usize = 32;
/// The commit marker pattern ("FOG-COMMITTED" repeated to 32 bytes, no 0xFF byte).
const COMMIT_MARKER: [u8; MARKER_LEN] = *b"FOG-COMMITTED-v1FOG-COMMITTED-v1";

/// Why the store failed; the previously active slot is unaffected in every case.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum StoreError {
    /// The flash does not hold two slots at `base`, or its write size exceeds 32 bytes.
    Geometry,
    /// Model longer than `MAX_ENCODED_LEN` or empty.
    ModelSize,
    /// A flash read, erase or write failed.
    Flash,
    /// The slot just written did not read back valid.
    Readback,
    /// The sequence counter is at u32::MAX.
    SequenceExhausted,
    /// The caller's buffer is shorter than the stored model.
    BufferTooSmall,
}

impl core::fmt::Display for StoreError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Geometry => write!(f, "flash too small for two slots or write size > 32 bytes"),
            Self::ModelSize => write!(f, "model must be 1..={MAX_ENCODED_LEN} bytes"),
            Self::Flash => write!(f, "flash operation failed"),
            Self::Readback => write!(f, "written slot did not read back valid"),
            Self::SequenceExhausted => write!(f, "slot sequence counter exhausted"),
            Self::BufferTooSmall => write!(f, "buffer shorter than the stored model"),
        }
    }
}

/// Why a slot holds no usable model (what `ModelStore::check` found).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SlotDefect {
    /// Erased: never written (not a fault).
    Empty,
    /// No complete commit marker: a commit was cut before its end, or the marker decayed.
    Incomplete,
    /// Committed, but the header's magic, version, CRC or length is wrong.
    HeaderCorrupt,
    /// Header intact, but the model bytes do not match its CRC-32.
    BodyCorrupt,
    /// The flash could not be read.
    Unreadable,
}

impl core::fmt::Display for SlotDefect {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::Empty => "empty",
            Self::Incomplete => "incomplete commit (no commit marker)",
            Self::HeaderCorrupt => "header corrupt (magic, version, CRC or length)",
            Self::BodyCorrupt => "model bytes do not match the header CRC-32",
            Self::Unreadable => "flash read failed",
        })
    }
}

/// The decoded, verified header of a valid slot.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SlotHeader {
    pub sequence: u32,
    pub model_len: u32,
    pub model_crc32: u32,
    pub signature: [u8; SIGNATURE_LEN],
    /// The security counter the signature covers (rollback floor).
    pub security_counter: u32,
}

impl SlotHeader {
    fn to_bytes(self) -> [u8; HEADER_LEN] {
        let mut b = [0xFFu8; HEADER_LEN];
        b[0..4].copy_from_slice(&SLOT_MAGIC.to_le_bytes());
        b[4..6].copy_from_slice(&SLOT_VERSION.to_le_bytes());
        b[8..12].copy_from_slice(&self.sequence.to_le_bytes());
        b[12..16].copy_from_slice(&self.model_len.to_le_bytes());
        b[16..20].copy_from_slice(&self.model_crc32.to_le_bytes());
        b[20..84].copy_from_slice(&self.signature);
        b[84..88].copy_from_slice(&self.security_counter.to_le_bytes());
        let crc = CRC32.checksum(&b[..HEADER_CRC_SPAN]);
        b[88..92].copy_from_slice(&crc.to_le_bytes());
        b
    }

    /// Parses a header; `None` unless magic, version, CRC and length are all right.
    fn from_bytes(b: &[u8; HEADER_LEN]) -> Option<Self> {
        let word = |at: usize| u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]]);
        let header_ok = word(0) == SLOT_MAGIC
            && u16::from_le_bytes([b[4], b[5]]) == SLOT_VERSION
            && CRC32.checksum(&b[..HEADER_CRC_SPAN]) == word(88);
        let model_len = word(12);
        if !header_ok || model_len == 0 || model_len as usize > MAX_ENCODED_LEN {
            return None;
        }
        let mut signature = [0u8; SIGNATURE_LEN];
        signature.copy_from_slice(&b[20..84]);
        Some(Self {
            sequence: word(8),
            model_len,
            model_crc32: word(16),
            signature,
            security_counter: word(84),
        })
    }
}

/// The slot in use and its header.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ActiveSlot {
    /// 0 = slot A, 1 = slot B.
    pub slot: u8,
    pub header: SlotHeader,
}

/// Two model slots in `flash` starting at `base`.
pub struct ModelStore<F> {
    flash: F,
    base: u32,
    slot_len: u32,
    active: Option<ActiveSlot>,
}

/// Bytes one slot occupies on a flash with `erase_size`-byte pages (header + largest
/// model, rounded up to whole pages).
pub const fn slot_len(erase_size: usize) -> usize {
    (BODY_OFFSET + MAX_ENCODED_LEN).div_ceil(erase_size) * erase_size
}

/// Bytes the two-slot store occupies on a flash with `erase_size`-byte pages.
pub const fn store_len(erase_size: usize) -> usize {
    2 * slot_len(erase_size)
}

/// The RAM-backed stand-in flash of the QEMU build (mps2-an386 has no flash
/// controller): 4-byte words, 256-byte pages, exactly one store (4,608 bytes).
pub type EmulatedModelFlash = ram_flash::RamNorFlash<{ store_len(256) }, 4, 256>;

impl<F: NorFlash> ModelStore<F> {
    /// Bytes one slot occupies for this flash.
    pub fn slot_len() -> usize {
        slot_len(F::ERASE_SIZE)
    }

    /// Opens the store (the boot path): scans both slots and picks the newest valid one.
    pub fn open(flash: F, base: u32) -> Result<Self, StoreError> {
        let slot_len = Self::slot_len();
        let fits = (base as usize)
            .checked_add(2 * slot_len)
            .is_some_and(|end| end <= flash.capacity());
        if !fits
            || F::WRITE_SIZE > MAX_WRITE_SIZE
            || !MAX_WRITE_SIZE.is_multiple_of(F::WRITE_SIZE)
            || !(base as usize).is_multiple_of(F::ERASE_SIZE)
        {
            return Err(StoreError::Geometry);
        }
        let mut store = Self {
            flash,
            base,
            slot_len: slot_len as u32,
            active: None,
        };
        store.active = store.scan();
        Ok(store)
    }

    /// The slot in use (`None`: no valid model stored).
    pub fn active(&self) -> Option<&ActiveSlot> {
        self.active.as_ref()
    }

    /// Gives the flash back (tests "reboot" by reopening it).
    pub fn into_flash(self) -> F {
        self.flash
    }

    /// Reads the active model's bytes into `buf`; `Ok(None)` if no model is stored.
    pub fn read_active<'b>(&mut self, buf: &'b mut [u8]) -> Result<Option<&'b [u8]>, StoreError> {
        let Some(active) = self.active else {
            return Ok(None);
        };
        let len = active.header.model_len as usize;
        let dest = buf.get_mut(..len).ok_or(StoreError::BufferTooSmall)?;
        let at = self.slot_base(active.slot) + BODY_OFFSET as u32;
        self.flash.read(at, dest).map_err(|_| StoreError::Flash)?;
        if CRC32.checksum(dest) != active.header.model_crc32 {
            return Err(StoreError::Readback);
        }
        Ok(Some(dest))
    }

    /// The other slot, if it holds a complete, intact model (the boot path falls back
    /// to it when the active slot's signature does not verify).
    pub fn inactive(&mut self) -> Option<ActiveSlot> {
        let slot = 1 - self.active?.slot;
        self.read_slot(slot)
            .map(|header| ActiveSlot { slot, header })
    }

    /// Makes `slot` (as returned by `inactive`) active, or none (`None`): the boot
    /// path's decision after re-checking signatures. Nothing is written to flash.
    pub fn select(&mut self, slot: Option<ActiveSlot>) {
        self.active = slot;
    }

    /// The highest security counter of the intact slots (0 if none): a new model must
    /// carry a higher one.
    pub fn security_floor(&mut self) -> u32 {
        let a = self.read_slot(0).map_or(0, |h| h.security_counter);
        let b = self.read_slot(1).map_or(0, |h| h.security_counter);
        a.max(b)
    }

    /// Writes `model` (already verified by the caller) to the inactive slot and makes it
    /// active. On any error the previously active slot stays active.
    pub fn commit(
        &mut self,
        model: &[u8],
        signature: &[u8; SIGNATURE_LEN],
        security_counter: u32,
    ) -> Result<ActiveSlot, StoreError> {
        if model.is_empty() || model.len() > MAX_ENCODED_LEN {
            return Err(StoreError::ModelSize);
        }
        let (slot, sequence) = match self.active {
            Some(a) => (1 - a.slot, a.header.sequence.checked_add(1)),
            None => (0, Some(1)),
        };
        let sequence = sequence.ok_or(StoreError::SequenceExhausted)?;
        let header = SlotHeader {
            sequence,
            model_len: model.len() as u32,
            model_crc32: CRC32.checksum(model),
            signature: *signature,
            security_counter,
        };
        let base = self.slot_base(slot);
        let flash_err = |_| StoreError::Flash;
        self.flash
            .erase(base, base + self.slot_len)
            .map_err(flash_err)?;
        self.write_body(base + BODY_OFFSET as u32, model)?;
        self.flash
            .write(base, &header.to_bytes())
            .map_err(flash_err)?;
        self.flash
            .write(base + MARKER_OFFSET as u32, &COMMIT_MARKER)
            .map_err(flash_err)?;
        match self.read_slot(slot) {
            Some(h) if h == header => {
                let active = ActiveSlot { slot, header };
                self.active = Some(active);
                Ok(active)
            }
            _ => Err(StoreError::Readback),
        }
    }

    /// Writes the body: whole words directly, the tail word padded with 0xFF.
    fn write_body(&mut self, at: u32, model: &[u8]) -> Result<(), StoreError> {
        let whole = model.len() / F::WRITE_SIZE * F::WRITE_SIZE;
        self.flash
            .write(at, &model[..whole])
            .map_err(|_| StoreError::Flash)?;
        let tail = &model[whole..];
        if !tail.is_empty() {
            let mut word = [0xFFu8; MAX_WRITE_SIZE];
            word[..tail.len()].copy_from_slice(tail);
            let word = &word[..F::WRITE_SIZE];
            self.flash
                .write(at + whole as u32, word)
                .map_err(|_| StoreError::Flash)?;
        }
        Ok(())
    }

    fn slot_base(&self, slot: u8) -> u32 {
        self.base + u32::from(slot) * self.slot_len
    }

    /// Newest valid slot; on a (never written) equal sequence slot A wins.
    fn scan(&mut self) -> Option<ActiveSlot> {
        let a = self
            .read_slot(0)
            .map(|header| ActiveSlot { slot: 0, header });
        let b = self
            .read_slot(1)
            .map(|header| ActiveSlot { slot: 1, header });
        match (a, b) {
            (Some(a), Some(b)) => Some(if b.header.sequence > a.header.sequence {
                b
            } else {
                a
            }),
            (a, b) => a.or(b),
        }
    }

    /// The header of `slot` if the slot is complete and intact (marker, header, body CRC).
    fn read_slot(&mut self, slot: u8) -> Option<SlotHeader> {
        self.check(slot).ok()
    }

    /// The header of `slot` (0 = A, 1 = B) if it is complete and intact, else what is
    /// wrong with it (the boot report). Reads only; the active slot is unchanged.
    pub fn check(&mut self, slot: u8) -> Result<SlotHeader, SlotDefect> {
        let base = self.slot_base(slot.min(1));
        let mut marker = [0u8; MARKER_LEN];
        let mut raw = [0u8; HEADER_LEN];
        self.flash
            .read(base + MARKER_OFFSET as u32, &mut marker)
            .and_then(|()| self.flash.read(base, &mut raw))
            .map_err(|_| SlotDefect::Unreadable)?;
        if marker != COMMIT_MARKER {
            let erased = marker.iter().chain(&raw).all(|&b| b == 0xFF);
            return Err(if erased {
                SlotDefect::Empty
            } else {
                SlotDefect::Incomplete
            });
        }
        let header = SlotHeader::from_bytes(&raw).ok_or(SlotDefect::HeaderCorrupt)?;
        let mut digest = CRC32.digest();
        let mut piece = [0u8; 64];
        let mut at = base + BODY_OFFSET as u32;
        let mut left = header.model_len as usize;
        while left > 0 {
            let n = left.min(piece.len());
            self.flash
                .read(at, &mut piece[..n])
                .map_err(|_| SlotDefect::Unreadable)?;
            digest.update(&piece[..n]);
            at += n as u32;
            left -= n;
        }
        if digest.finalize() == header.model_crc32 {
            Ok(header)
        } else {
            Err(SlotDefect::BodyCorrupt)
        }
    }
}
