//! The field-record ring in fog-app: opened on its flash region at boot, one record
//! appended per completed two-position seek (failures logged, the seek stands).

use crate::flash;
use fog_core::seeking::field_record::FieldRecord;
use fog_firmware::field_log::FieldLog;

/// Opens the field-record ring on its region (`None`: the region is unusable; seeks
/// run on, records are not kept, `GetFieldRecords` is refused). Under QEMU the boot scan
/// is also a plain `FOG-FIELD-LOG` line.
pub(crate) fn open_field_log(flash: flash::AppFlash) -> Option<FieldLog<flash::AppFlash>> {
    let capacity = embedded_storage::nor_flash::ReadNorFlash::capacity(&flash) as u32;
    match FieldLog::open(flash, 0, capacity) {
        Ok(log) => {
            let s = log.scan();
            defmt::info!("field log: {}", s);
            #[cfg(feature = "log-semihosting")]
            semihosting::eprintln!(
                "FOG-FIELD-LOG valid={} corrupt={} oldest={} newest={}",
                s.valid,
                s.corrupt,
                s.oldest_sequence.unwrap_or(0),
                s.newest_sequence.unwrap_or(0)
            );
            Some(log)
        }
        Err(e) => {
            defmt::error!("field log unusable: {}", e);
            #[cfg(feature = "log-semihosting")]
            semihosting::eprintln!("FOG-FIELD-LOG unusable: {}", e);
            None
        }
    }
}

/// Appends a finished seek's record (a failure is logged; the seek result stands).
pub(crate) fn append_field_record(
    log: Option<&mut FieldLog<flash::AppFlash>>,
    record: FieldRecord,
) {
    let Some(log) = log else { return };
    match log.append(record) {
        Ok(r) => {
            defmt::info!("field record {}: {} deg/h", r.sequence, r.residual_bias_dph);
            #[cfg(feature = "log-semihosting")]
            semihosting::eprintln!(
                "FOG-FIELD-RECORD sequence={} residual_udph={}",
                r.sequence,
                // Integer micro-deg/h: no float formatting code in the image.
                (r.residual_bias_dph * 1.0e6) as i64
            );
        }
        Err(e) => {
            defmt::error!("field record not kept: {}", e);
            #[cfg(feature = "log-semihosting")]
            semihosting::eprintln!("FOG-FIELD-RECORD failed: {}", e);
        }
    }
}
