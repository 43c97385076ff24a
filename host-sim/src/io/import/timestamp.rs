//! ISO 8601 timestamps as loggers write them, to seconds since 1970-01-01 UTC:
//! `YYYY-MM-DD[T| ]hh:mm:ss[.frac|,frac][Z|+hh:mm|-hh:mm|+hhmm]`. Whole seconds and the
//! fraction are kept apart so a microsecond survives the conversion.

/// Seconds since 1970-01-01T00:00:00Z, split as (whole, fraction in [0, 1)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instant {
    pub whole_s: i64,
    pub frac_s: f64,
}

impl Instant {
    /// `self - earlier`, s.
    pub fn since(self, earlier: Instant) -> f64 {
        (self.whole_s - earlier.whole_s) as f64 + (self.frac_s - earlier.frac_s)
    }
}

/// Days from 1970-01-01 to a proleptic Gregorian date (Howard Hinnant's algorithm).
fn days_from_civil(y: i64, m: i64, d: i64) -> i64 {
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let mp = (m + 9) % 12;
    let doy = (153 * mp + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

fn days_in_month(y: i64, m: i64) -> i64 {
    match m {
        2 if (y % 4 == 0 && y % 100 != 0) || y % 400 == 0 => 29,
        2 => 28,
        4 | 6 | 9 | 11 => 30,
        _ => 31,
    }
}

fn digits(s: &str, n: usize) -> Option<i64> {
    (s.len() == n && s.bytes().all(|b| b.is_ascii_digit())).then(|| s.parse().ok())?
}

/// Parses one timestamp; the error says which part is wrong.
pub fn parse_iso(text: &str) -> Result<Instant, String> {
    let s = text.trim();
    let bad = |what: &str| {
        format!(
            "`{}` is not an ISO 8601 time ({what})",
            crate::io::run_format::excerpt(s)
        )
    };
    if s.len() < 19 || !s.is_char_boundary(10) || !s.is_char_boundary(19) {
        return Err(bad("want YYYY-MM-DDThh:mm:ss"));
    }
    let (date, rest) = s.split_at(10);
    let sep = rest.as_bytes()[0];
    if sep != b'T' && sep != b' ' && sep != b't' {
        return Err(bad("date and time separated by T or a space"));
    }
    let (clock, tail) = rest[1..].split_at(8);
    let dp: Vec<&str> = date.split('-').collect();
    let tp: Vec<&str> = clock.split(':').collect();
    let (y, mo, d) = match dp[..] {
        [y, m, d] => (digits(y, 4), digits(m, 2), digits(d, 2)),
        _ => return Err(bad("date YYYY-MM-DD")),
    };
    let (h, mi, se) = match tp[..] {
        [h, m, s] => (digits(h, 2), digits(m, 2), digits(s, 2)),
        _ => return Err(bad("time hh:mm:ss")),
    };
    let (Some(y), Some(mo), Some(d), Some(h), Some(mi), Some(se)) = (y, mo, d, h, mi, se) else {
        return Err(bad("non-digit in the date or time"));
    };
    if !(1..=12).contains(&mo) || d < 1 || d > days_in_month(y, mo) {
        return Err(bad("no such date"));
    }
    if h > 23 || mi > 59 || se > 60 {
        return Err(bad("no such time of day"));
    }
    // Fraction of a second, then the zone.
    let zone_at = tail.find(['Z', 'z', '+', '-']).unwrap_or(tail.len());
    let (frac, zone) = tail.split_at(zone_at);
    let frac_s = if frac.is_empty() {
        0.0
    } else {
        let f = frac
            .strip_prefix(['.', ','])
            .filter(|f| !f.is_empty() && f.bytes().all(|b| b.is_ascii_digit()))
            .ok_or_else(|| bad("fraction of a second"))?;
        format!("0.{f}")
            .parse::<f64>()
            .map_err(|_| bad("fraction of a second"))?
    };
    let offset_s = match zone {
        "" | "Z" | "z" => 0,
        z => {
            let sign = if z.starts_with('-') { -1 } else { 1 };
            let hm = z[1..].replace(':', "");
            let (Some(oh), Some(om)) = (
                hm.get(..2).and_then(|x| digits(x, 2)),
                hm.get(2..).and_then(|x| digits(x, 2)),
            ) else {
                return Err(bad("zone Z, +hh:mm or -hh:mm"));
            };
            if oh > 23 || om > 59 {
                return Err(bad("zone offset"));
            }
            sign * (oh * 3600 + om * 60)
        }
    };
    let whole_s = days_from_civil(y, mo, d) * 86_400 + h * 3600 + mi * 60 + se - offset_s;
    Ok(Instant { whole_s, frac_s })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_instants() {
        assert_eq!(parse_iso("1970-01-01T00:00:00Z").unwrap().whole_s, 0);
        // 2000-03-01 is day 11017 (leap year 2000).
        assert_eq!(
            parse_iso("2000-03-01 00:00:01").unwrap().whole_s,
            11_017 * 86_400 + 1
        );
        let a = parse_iso("2024-02-29T23:59:59,75+01:00").unwrap();
        let b = parse_iso("2024-02-29T23:00:00.25Z").unwrap();
        assert!((a.since(b) + 0.5).abs() < 1e-12, "{}", a.since(b));
        let us = parse_iso("2024-01-01T00:00:00.000001").unwrap();
        let z = parse_iso("2024-01-01T00:00:00").unwrap();
        assert!((us.since(z) - 1e-6).abs() < 1e-15);
    }

    #[test]
    fn malformed_times_say_what_is_wrong() {
        assert!(parse_iso("2023-02-29T00:00:00")
            .unwrap_err()
            .contains("no such date"));
        assert!(parse_iso("2023-01-01T24:00:00")
            .unwrap_err()
            .contains("time of day"));
        assert!(parse_iso("12.5").is_err());
        assert!(parse_iso("2023-01-01T00:00:00.").is_err());
        assert!(parse_iso("2023-01-01T00:00:00+1").is_err());
        assert!(parse_iso("2023-01-01X00:00:00").is_err());
        assert!(parse_iso("2023-01-01T00:00:00éé").is_err());
    }
}
