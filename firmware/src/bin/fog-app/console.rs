//! The run's log lines: each closed window, each seek's end or restart (defmt, and under QEMU
//! plain semihosting lines the tests read).

use fog_firmware::app::SeekOutcome;

/// A closed window as one plain-text line on the semihosting console (QEMU tests).
pub(crate) fn window_line(
    w: &fog_core::compensation::compensator::WindowResult,
    frames_lost: u32,
    bytes_dropped: u32,
) {
    #[cfg(feature = "log-semihosting")]
    semihosting::eprintln!(
        "FOG-WINDOW t_end_ms={} status={:?} valid={} n_samples={} frames_lost={} gyro_bytes_dropped={}",
        // Integer ms: no f64 formatting code in the image.
        (w.t_end_s * 1000.0) as u64,
        w.status,
        w.status.is_valid(),
        w.n_samples,
        frames_lost,
        bytes_dropped
    );
    #[cfg(not(feature = "log-semihosting"))]
    let _ = (w, frames_lost, bytes_dropped);
}

/// A finished seek as one plain-text line on the semihosting console (QEMU tests).
pub(crate) fn seek_line(r: &fog_core::link::messages::SeekReport) {
    #[cfg(feature = "log-semihosting")]
    semihosting::eprintln!(
        "FOG-SEEK sequence={} azimuth_mdeg={} sigma_mdeg={} positions={}",
        r.sequence,
        // Integer millidegrees: no float formatting code in the image.
        (r.azimuth_deg * 1000.0) as i64,
        (r.sigma_deg * 1000.0) as i64,
        r.positions
    );
    #[cfg(not(feature = "log-semihosting"))]
    let _ = r;
}

pub(crate) fn report<E: defmt::Format>(step: fog_firmware::app::Step<E>) {
    if let Some(w) = step.window {
        if w.status.is_valid() {
            defmt::info!(
                "t={} s compensated {} deg/h (drift {}, T {} C)",
                w.t_end_s,
                w.compensated_dph,
                w.drift_dph,
                w.temp_c
            );
        } else {
            defmt::warn!("t={} s window invalid: {}", w.t_end_s, w.status);
        }
    }
    if let Some(why) = step.restarted {
        defmt::warn!("north seek restarted: {}", why);
        #[cfg(feature = "log-semihosting")]
        semihosting::eprintln!("FOG-SEEK-RESTART reason={:?}", why);
    }
    match step.seek {
        Some(SeekOutcome::Done(r, _)) => defmt::info!(
            "north seek: azimuth {} deg +- {} deg ({} s)",
            r.azimuth_deg,
            r.sigma_deg,
            r.duration_s
        ),
        Some(SeekOutcome::Failed(f)) => {
            defmt::error!(
                "north seek aborted at t={} s: {} (turntable: {})",
                f.t_s,
                f.error,
                f.table_error
            );
            #[cfg(feature = "log-semihosting")]
            semihosting::eprintln!("FOG-SEEK-FAILED t_ms={}", (f.t_s * 1000.0) as u64);
        }
        None => {}
    }
}
