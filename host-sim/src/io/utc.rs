//! UTC wall-clock stamps (`2026-11-25T09:41:07.123Z`, ISO 8601) for the registry and
//! `monitor`'s lines, from the system clock without a calendar crate: days since the Unix
//! epoch to a civil date (H. Hinnant's `civil_from_days`, proleptic Gregorian).

use std::time::{SystemTime, UNIX_EPOCH};

/// Now, as ISO 8601 UTC with milliseconds.
pub fn now_utc() -> String {
    let since = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .unwrap_or_default();
    format_utc_ms(since.as_millis() as i64)
}

/// Milliseconds since the Unix epoch as ISO 8601 UTC (`YYYY-MM-DDThh:mm:ss.mmmZ`).
pub fn format_utc_ms(ms: i64) -> String {
    let (days, ms_of_day) = (ms.div_euclid(86_400_000), ms.rem_euclid(86_400_000));
    let (y, m, d) = civil_from_days(days);
    let s = ms_of_day / 1000;
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}.{:03}Z",
        s / 3600,
        s / 60 % 60,
        s % 60,
        ms_of_day % 1000
    )
}

/// (year, month 1..=12, day 1..=31) of a day count since 1970-01-01.
fn civil_from_days(z: i64) -> (i64, i64, i64) {
    let z = z + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    (yoe + era * 400 + i64::from(m <= 2), m, d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_instants() {
        assert_eq!(format_utc_ms(0), "1970-01-01T00:00:00.000Z");
        // 2000-02-29 (a leap day of a century leap year) 12:34:56.789
        assert_eq!(format_utc_ms(951_827_696_789), "2000-02-29T12:34:56.789Z");
        // 2100-03-01: 2100 is not a leap year.
        assert_eq!(format_utc_ms(4_107_542_400_000), "2100-03-01T00:00:00.000Z");
        assert_eq!(format_utc_ms(-1), "1969-12-31T23:59:59.999Z");
    }
}
