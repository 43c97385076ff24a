//! The project's one CRC-32 (CRC-32/ISO-HDLC, the zlib/Ethernet CRC).
//!
//! Exists as its own file at the bottom of `model` because the model format is the lowest
//! code that checksums with it (the model body's CRC), and everything above uses the same
//! one: the host-port frames and the whole-model CRC of an upload (`link::upload`), the
//! field record (`seeking::field_record`), and the firmware's flash records. One copy, so
//! all of them agree.

/// CRC-32/ISO-HDLC, the checksum of model bodies, host-port frames and flash records.
pub const CRC32: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC);

/// CRC-32/ISO-HDLC of `bytes` (same value as zlib's `crc32`).
pub fn crc32(bytes: &[u8]) -> u32 {
    CRC32.checksum(bytes)
}
