//! What the boot found, logged (and under QEMU printed as plain lines the tests read): why
//! the last run ended, both model slots' verdicts, the heading correction in use, the
//! boot's stack peak.

#[cfg(feature = "log-semihosting")]
use crate::stack;
use fog_core::compensation::compensator::Compensator;
use fog_firmware::app::App;
use fog_firmware::fault_record::FaultRecord;

/// The boot line: why the previous run ended. Under QEMU also as plain text on the
/// semihosting console, where the fault tests count boots.
pub(crate) fn announce_boot(record: &FaultRecord) {
    let reset = record.reset;
    defmt::info!(
        "fog-app: boot {} after {} (detail {}), {} faults in a row",
        reset.boots,
        reset.cause,
        reset.detail,
        record.faults_in_a_row
    );
    #[cfg(feature = "log-semihosting")]
    semihosting::eprintln!(
        "FOG-BOOT {} reset={:?} faults_in_a_row={} detail={}",
        reset.boots,
        reset.cause,
        record.faults_in_a_row,
        reset.detail
    );
}

/// The boot check of both model slots (why a stored model is or is not used). Under
/// QEMU also as a plain `FOG-SLOT` line per slot on the semihosting console.
pub(crate) fn report_slots(report: [fog_firmware::upload::SlotVerdict; 2]) {
    for (name, verdict) in ["A", "B"].into_iter().zip(report) {
        if verdict.refused() {
            defmt::warn!("model slot {}: {}", name, verdict);
        } else {
            defmt::info!("model slot {}: {}", name, verdict);
        }
        #[cfg(feature = "log-semihosting")]
        semihosting::eprintln!("FOG-SLOT {} {}", name, verdict);
    }
}

/// The boot's painted stack peak (store scan, signature re-check, model decode,
/// configuration), under QEMU as a plain `FOG-STACK` line that `qemu_persist.rs` bounds
/// (docs/explain/stack.md). Hardware builds do not paint.
pub(crate) fn report_boot_stack() {
    #[cfg(feature = "log-semihosting")]
    semihosting::eprintln!(
        "FOG-STACK boot_peak_bytes={} of={}",
        stack::high_water_bytes(),
        stack::size_bytes()
    );
}

/// Logs the heading correction the active model brought (format v3 models carry it; the
/// App applies it on every model change). Under QEMU also as plain text, where the seek
/// scenario checks that an uploaded harmonic is in use.
pub(crate) fn announce_heading_correction<T, C>(app: &App<T, C>)
where
    T: fog_core::hal::Turntable,
    T::Error: Copy,
    C: core::borrow::BorrowMut<Compensator>,
{
    let n_headings = app.heading_correction().map_or(0, |h| h.n_headings);
    defmt::info!("heading correction: {} headings (0: none)", n_headings);
    #[cfg(feature = "log-semihosting")]
    semihosting::eprintln!("FOG-HEADING-CAL n_headings={}", n_headings);
}
