//! The indexing turntable's ASCII line protocol, both sides: the firmware's driver
//! encodes commands and decodes replies, the host's rig (a simulated controller)
//! decodes commands and encodes replies, so the two read one definition of a line.
//!
//! One command or reply per line, terminated by CR (LF tolerated); angles in degrees
//! with at most three decimals, carried as integer millidegrees:
//!
//! | host -> table | table -> host | meaning |
//! |---|---|---|
//! | `MOV 180.000` | `ACK` / `NAK` | start a move to an absolute heading (0..360) |
//! | `POS?` | `POS 179.998 M` | position and state: `M` moving, `S` settled, `F<n>` fault n |
//! | | `F<n>` | an unsolicited controller fault n |
//!
//! Numbers are written and read by hand: exact digits, no `core::fmt` machinery or
//! float parsing in the firmware.

use heapless::Vec;

/// Longest line either side keeps, bytes without the terminator (`MOV 359.999` is 11,
/// `POS -359.999 F255` is 17).
pub const TABLE_LINE_MAX: usize = 32;

/// A line as it is built or received.
pub type TableLine = Vec<u8, TABLE_LINE_MAX>;

/// What the host asks of the table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TableCommand {
    /// `MOV d.ddd`: move to this absolute heading, millidegrees in 0..360,000.
    Move { heading_mdeg: u32 },
    /// `POS?`: report position and state.
    QueryPosition,
}

/// The table's state in a `POS` reply.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TableMotion {
    Moving,
    Settled,
    /// Controller fault code (255: unreadable code).
    Fault(u8),
}

/// What the table answers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TableReply {
    /// The move was started.
    Ack,
    /// The command was not a heading.
    Nak,
    /// Position, millidegrees (may be negative or beyond 360 on a free-running encoder),
    /// and state.
    Position {
        angle_mdeg: i32,
        motion: TableMotion,
    },
    /// An unsolicited fault.
    Fault(u8),
}

/// Why a received line is not a command the table carries out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CommandError {
    /// Not a command at all: ignored, no reply.
    NotACommand,
    /// A `MOV` whose heading is not one (unreadable, or outside 0..360): answered `NAK`.
    NotAHeading,
}

/// Largest heading a `MOV` carries, exclusive, millidegrees.
const FULL_TURN_MDEG: u32 = 360_000;

impl TableCommand {
    /// The command line, without its terminator.
    pub fn encode(&self) -> TableLine {
        let mut line = Vec::new();
        match *self {
            TableCommand::Move { heading_mdeg } => {
                push(&mut line, b"MOV ");
                push_mdeg(&mut line, i64::from(heading_mdeg % FULL_TURN_MDEG));
            }
            TableCommand::QueryPosition => push(&mut line, b"POS?"),
        }
        line
    }

    /// A received command line (surrounding spaces ignored).
    pub fn parse(line: &[u8]) -> Result<Self, CommandError> {
        let line = trim(line);
        if line == b"POS?" {
            return Ok(TableCommand::QueryPosition);
        }
        let heading = match line.strip_prefix(b"MOV") {
            Some(rest) if rest.is_empty() || rest[0] == b' ' => rest,
            _ => return Err(CommandError::NotACommand),
        };
        let heading_mdeg = parse_mdeg(trim(heading))
            .and_then(|h| u32::try_from(h).ok())
            .filter(|&h| h < FULL_TURN_MDEG)
            .ok_or(CommandError::NotAHeading)?;
        Ok(TableCommand::Move { heading_mdeg })
    }
}

impl TableReply {
    /// The reply line, without its terminator.
    pub fn encode(&self) -> TableLine {
        let mut line = Vec::new();
        match *self {
            TableReply::Ack => push(&mut line, b"ACK"),
            TableReply::Nak => push(&mut line, b"NAK"),
            TableReply::Position { angle_mdeg, motion } => {
                push(&mut line, b"POS ");
                push_mdeg(&mut line, i64::from(angle_mdeg));
                match motion {
                    TableMotion::Moving => push(&mut line, b" M"),
                    TableMotion::Settled => push(&mut line, b" S"),
                    TableMotion::Fault(code) => {
                        push(&mut line, b" F");
                        push_uint(&mut line, u32::from(code));
                    }
                }
            }
            TableReply::Fault(code) => {
                push(&mut line, b"F");
                push_uint(&mut line, u32::from(code));
            }
        }
        line
    }

    /// A received reply line; `None` if it is garbled.
    pub fn parse(line: &[u8]) -> Option<Self> {
        match line {
            b"ACK" => Some(TableReply::Ack),
            b"NAK" => Some(TableReply::Nak),
            [b'P', b'O', b'S', b' ', rest @ ..] => {
                let space = rest.iter().position(|&b| b == b' ')?;
                let angle_mdeg = parse_mdeg(&rest[..space])?;
                let motion = match &rest[space + 1..] {
                    b"M" => TableMotion::Moving,
                    b"S" => TableMotion::Settled,
                    [b'F', code @ ..] => TableMotion::Fault(parse_code(code)),
                    _ => return None,
                };
                Some(TableReply::Position { angle_mdeg, motion })
            }
            [b'F', code @ ..] if !code.is_empty() => Some(TableReply::Fault(parse_code(code))),
            _ => None,
        }
    }
}

/// Degrees as the nearest millidegree (saturating; NaN is 0), for a controller that
/// reports a float angle.
pub fn deg_to_mdeg(deg: f64) -> i32 {
    let m = libm::round(deg * 1000.0);
    if m.is_nan() {
        0
    } else {
        m.clamp(f64::from(i32::MIN), f64::from(i32::MAX)) as i32
    }
}

fn push(line: &mut TableLine, bytes: &[u8]) {
    // Every line built here is at most 17 bytes, well inside TABLE_LINE_MAX.
    let _ = line.extend_from_slice(bytes);
}

/// `[-]d+.ddd` for a value in millidegrees.
fn push_mdeg(line: &mut TableLine, mdeg: i64) {
    if mdeg < 0 {
        push(line, b"-");
    }
    let m = mdeg.unsigned_abs();
    push_uint(line, (m / 1000).min(u64::from(u32::MAX)) as u32);
    push(line, b".");
    let frac = (m % 1000) as u32;
    for div in [100, 10, 1] {
        push(line, &[b'0' + (frac / div % 10) as u8]);
    }
}

/// Decimal digits of `v`, no leading zeros.
fn push_uint(line: &mut TableLine, v: u32) {
    let mut digits = [0u8; 10];
    let mut n = 0;
    let mut rest = v;
    loop {
        digits[n] = b'0' + (rest % 10) as u8;
        n += 1;
        rest /= 10;
        if rest == 0 {
            break;
        }
    }
    for &d in digits[..n].iter().rev() {
        push(line, &[d]);
    }
}

fn trim(s: &[u8]) -> &[u8] {
    let start = s.iter().position(|&b| b != b' ').unwrap_or(s.len());
    let end = s.iter().rposition(|&b| b != b' ').map_or(start, |e| e + 1);
    &s[start..end]
}

/// Controller fault code; 255 if the code itself is unreadable.
fn parse_code(s: &[u8]) -> u8 {
    parse_uint(s)
        .and_then(|v| u8::try_from(v).ok())
        .unwrap_or(u8::MAX)
}

/// `[-]d+[.d{1,3}]` (at most 4 integer digits) as integer millidegrees.
fn parse_mdeg(s: &[u8]) -> Option<i32> {
    let (neg, s) = match s.split_first() {
        Some((b'-', rest)) => (true, rest),
        _ => (false, s),
    };
    let (int, frac) = match s.iter().position(|&b| b == b'.') {
        Some(p) => (&s[..p], &s[p + 1..]),
        None => (s, &s[..0]),
    };
    if int.is_empty() || frac.len() > 3 {
        return None;
    }
    let mut frac_m = if frac.is_empty() {
        0
    } else {
        i32::from(parse_uint(frac)?)
    };
    for _ in frac.len()..3 {
        frac_m *= 10;
    }
    let v = i32::from(parse_uint(int)?) * 1000 + frac_m;
    Some(if neg { -v } else { v })
}

/// 1 to 4 decimal digits as a number; `None` if empty, longer or not all digits.
fn parse_uint(s: &[u8]) -> Option<u16> {
    if s.is_empty() || s.len() > 4 {
        return None;
    }
    s.iter().try_fold(0u16, |acc, &b| {
        b.is_ascii_digit().then(|| acc * 10 + u16::from(b - b'0'))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn commands_round_trip_and_read_as_written() {
        for mdeg in [0, 1, 999, 1000, 90_000, 180_000, 359_999] {
            let cmd = TableCommand::Move { heading_mdeg: mdeg };
            assert_eq!(TableCommand::parse(&cmd.encode()), Ok(cmd));
        }
        assert_eq!(
            &TableCommand::Move {
                heading_mdeg: 180_000
            }
            .encode()[..],
            b"MOV 180.000"
        );
        assert_eq!(
            &TableCommand::Move { heading_mdeg: 5 }.encode()[..],
            b"MOV 0.005"
        );
        assert_eq!(&TableCommand::QueryPosition.encode()[..], b"POS?");
        assert_eq!(
            TableCommand::parse(b" POS? "),
            Ok(TableCommand::QueryPosition)
        );
        assert_eq!(
            TableCommand::parse(b"MOV 90"),
            Ok(TableCommand::Move {
                heading_mdeg: 90_000
            })
        );
    }

    #[test]
    fn bad_headings_are_refused_and_other_lines_are_not_commands() {
        for bad in [
            &b"MOV 360.000"[..],
            b"MOV -1.000",
            b"MOV 1.0000",
            b"MOV 1e2",
            b"MOV ",
            b"MOV 12345.0",
            b"MOV abc",
        ] {
            let text = core::str::from_utf8(bad);
            assert_eq!(
                TableCommand::parse(bad),
                Err(CommandError::NotAHeading),
                "{text:?}"
            );
        }
        for other in [&b"MOVE 1.0"[..], b"POS", b"HELLO", b""] {
            let text = core::str::from_utf8(other);
            assert_eq!(
                TableCommand::parse(other),
                Err(CommandError::NotACommand),
                "{text:?}"
            );
        }
    }

    #[test]
    fn replies_round_trip_and_read_as_written() {
        let replies = [
            TableReply::Ack,
            TableReply::Nak,
            TableReply::Fault(7),
            TableReply::Position {
                angle_mdeg: 179_998,
                motion: TableMotion::Moving,
            },
            TableReply::Position {
                angle_mdeg: -1_500,
                motion: TableMotion::Settled,
            },
            TableReply::Position {
                angle_mdeg: 0,
                motion: TableMotion::Fault(255),
            },
        ];
        for r in replies {
            assert_eq!(TableReply::parse(&r.encode()), Some(r), "{r:?}");
        }
        assert_eq!(&replies[3].encode()[..], b"POS 179.998 M");
        assert_eq!(&replies[4].encode()[..], b"POS -1.500 S");
        assert_eq!(&replies[5].encode()[..], b"POS 0.000 F255");
    }

    #[test]
    fn garbled_replies_are_none_and_bad_fault_codes_read_255() {
        for bad in [
            &b"POS 1.0"[..],
            b"POS 1.0 X",
            b"POS x S",
            b"POS  S",
            b"ACK ",
            b"F",
            b"",
        ] {
            assert_eq!(
                TableReply::parse(bad),
                None,
                "{:?}",
                core::str::from_utf8(bad)
            );
        }
        assert_eq!(TableReply::parse(b"F999"), Some(TableReply::Fault(255)));
        assert_eq!(TableReply::parse(b"Fx"), Some(TableReply::Fault(255)));
    }

    #[test]
    fn degrees_round_to_the_nearest_millidegree() {
        assert_eq!(deg_to_mdeg(90.0), 90_000);
        assert_eq!(deg_to_mdeg(179.9984), 179_998);
        assert_eq!(deg_to_mdeg(-0.0006), -1);
        assert_eq!(deg_to_mdeg(f64::NAN), 0);
        assert_eq!(deg_to_mdeg(1e12), i32::MAX);
    }
}
