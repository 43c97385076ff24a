//! UTC wall-clock stamps (`2026-11-25T09:41:07.123Z`, ISO 8601) for the registry and
//! `monitor`'s lines, from the system clock without a calendar crate: days since the Unix
//! epoch to a civil date (H. Hinnant's `civil_from_days`, proleptic Gregorian), and back
//! (`parse_iso8601`: a run's `# start_time:` metadata read as an instant, for `diagnose`).

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

/// Days since 1970-01-01 of a civil date (the inverse of `civil_from_days`).
fn days_from_civil(y: i64, m: i64, d: i64) -> i64 {
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y.rem_euclid(400);
    let doy = (153 * (if m > 2 { m - 3 } else { m + 9 }) + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

/// An ISO 8601 instant as seconds since the Unix epoch, and whether it carried a zone
/// (`Z` or an offset; without one it is a wall clock of unknown zone). Accepted: a date
/// `YYYY-MM-DD`, or a date, `T` (or one space) and `hh:mm[:ss[.fff]]`, then nothing, `Z`,
/// or an offset `+hh:mm`, `+hhmm`, `+hh` (or `-`). Anything else, or a field out of
/// range (month 13, Feb 30, hour 25), is `None`.
pub fn parse_iso8601(s: &str) -> Option<(f64, bool)> {
    let s = s.trim();
    let (date, rest) = (s.get(..10)?, &s[10..]);
    let days = parse_date(date)?;
    if rest.is_empty() {
        return Some((days as f64 * 86_400.0, false));
    }
    let rest = rest.strip_prefix('T').or_else(|| rest.strip_prefix(' '))?;
    let zone_at = rest.find(['Z', '+', '-']).unwrap_or(rest.len());
    let (clock, zone) = rest.split_at(zone_at);
    let secs = parse_clock(clock)?;
    let (offset_s, zoned) = parse_zone(zone)?;
    Some((days as f64 * 86_400.0 + secs - offset_s, zoned))
}

/// `YYYY-MM-DD` as days since the epoch.
fn parse_date(d: &str) -> Option<i64> {
    let b = d.as_bytes();
    if b.len() != 10 || b[4] != b'-' || b[7] != b'-' {
        return None;
    }
    let (y, m, day) = (digits(&d[..4])?, digits(&d[5..7])?, digits(&d[8..])?);
    let leap = y % 4 == 0 && (y % 100 != 0 || y % 400 == 0);
    let len = [
        31,
        if leap { 29 } else { 28 },
        31,
        30,
        31,
        30,
        31,
        31,
        30,
        31,
        30,
        31,
    ];
    ((1..=12).contains(&m) && day >= 1 && day <= len[(m - 1) as usize])
        .then(|| days_from_civil(y, m, day))
}

/// `hh:mm[:ss[.fff]]` as seconds of the day.
fn parse_clock(c: &str) -> Option<f64> {
    let mut parts = c.splitn(3, ':');
    let h = digits(parts.next()?).filter(|h| *h < 24)?;
    let m = digits(parts.next()?).filter(|m| *m < 60)?;
    let s = match parts.next() {
        None => 0.0,
        Some(sec) => {
            let (whole, frac) = sec.split_once('.').unwrap_or((sec, ""));
            let w = digits(whole).filter(|w| *w < 61 && whole.len() == 2)?;
            let f = if frac.is_empty() {
                0.0
            } else {
                digits(frac)? as f64 / 10f64.powi(frac.len() as i32)
            };
            w as f64 + f
        }
    };
    (c.as_bytes().get(2) == Some(&b':')).then_some((h * 3600 + m * 60) as f64 + s)
}

/// `` (no zone), `Z`, `+hh:mm`, `+hhmm` or `+hh` (or `-`) as (offset east of UTC in s, zoned).
fn parse_zone(z: &str) -> Option<(f64, bool)> {
    if z.is_empty() {
        return Some((0.0, false));
    }
    if z == "Z" {
        return Some((0.0, true));
    }
    let sign = match z.as_bytes()[0] {
        b'+' => 1.0,
        b'-' => -1.0,
        _ => return None,
    };
    let hm = z[1..].replace(':', "");
    let (h, m) = match hm.len() {
        2 => (digits(&hm)?, 0),
        4 => (digits(&hm[..2])?, digits(&hm[2..])?),
        _ => return None,
    };
    (h < 24 && m < 60).then(|| (sign * (h * 3600 + m * 60) as f64, true))
}

/// A non-empty string of ASCII digits as a number.
fn digits(s: &str) -> Option<i64> {
    (!s.is_empty() && s.len() <= 9 && s.bytes().all(|b| b.is_ascii_digit()))
        .then(|| s.parse().ok())
        .flatten()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn iso8601_instants_parse_to_the_epoch_seconds_they_name() {
        let at = |s| parse_iso8601(s).map(|(t, _)| t);
        // 2025-03-23T08:15:37Z, checked against `date -u -d ... +%s`: 1742717737
        assert_eq!(at("2025-03-23T08:15:37Z"), Some(1_742_717_737.0));
        assert_eq!(at("2025-03-23T09:15:37+01:00"), Some(1_742_717_737.0));
        assert_eq!(at("2025-03-23T03:15:37-0500"), Some(1_742_717_737.0));
        assert_eq!(at("2025-03-23 08:15:37.5Z"), Some(1_742_717_737.5));
        assert_eq!(at("2025-03-23T08:15Z"), Some(1_742_717_700.0));
        assert_eq!(parse_iso8601("2025-03-23"), Some((1_742_688_000.0, false)));
        assert_eq!(
            parse_iso8601("2025-03-23T08:15:37").map(|x| x.1),
            Some(false)
        );
        assert_eq!(at("2000-02-29"), Some(951_782_400.0));
        for bad in [
            "2025-02-29",
            "2025-13-01",
            "2025-03-23T24:00Z",
            "2025-03-23T08:15:37Q",
            "1.2.10",
            "A",
            "2025-3-23",
            "2025-03-23T8:15Z",
            "2025-03-23T08:15:37+1:00",
            "2025-03-23X08:15",
        ] {
            assert_eq!(at(bad), None, "{bad}");
        }
        for d in [-800_000, -1, 0, 59, 365 * 30 + 7, 2_000_000] {
            let (y, m, dd) = civil_from_days(d);
            assert_eq!(days_from_civil(y, m, dd), d);
        }
    }

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
