//! The seek modes as position sequences: at which table heading each dwell of a seek is,
//! for how long, and in what order. The north finder's state machine walks the table; its
//! solution reads the per-heading means, so a new sequence is a new table, not new code.
//!
//! Why time-symmetric sequences: a two-position seek (0, 180 deg) differences two dwells
//! taken one after the other, so any drift left after compensation that changes during
//! the seek, d(t) = d0 + d1 t + d2 t^2 / 2, enters the difference as d1 times the time
//! between the dwells, and that is azimuth error (d1 / (2 Omega_H sin psi) per second of
//! separation). Visiting every heading twice, in a sequence that reads the same forwards
//! and backwards in time (`TwoPositionSymmetric`: 0, 180, 90, 180, 0 deg), gives each
//! heading's mean the same mean time, the middle of the seek, so the d1 term cancels in
//! every difference without any model of the drift; what is left is the curvature d2
//! (and the white noise). The price: twice the turns, so less measuring time in the same
//! seek time.
//!
//! The two visits of a heading count as one position (one `PositionMean`); their windows
//! are averaged together, which weights the visits equally because each visit collects
//! the same number of valid windows. The heading at the turning point of a symmetric
//! sequence is visited once for twice the dwell (`Dwell::Double`): the same mean time,
//! and no turn onto the heading the table is already at.
//!
//! Why the Thue-Morse order (`TwoPositionThueMorse`: 0, 180, 180, 0, 180, 0, 0, 180 deg,
//! a repeated heading one double dwell, the ambiguity dwell in the middle): what the
//! time-symmetric seek leaves is the curvature d2, and after a model it is most of the
//! first seek's bias (docs/record/fleet.md). The signs + - - + - + + - have equal sums of
//! t^0, t^1 and t^2 over both headings, and the turns fall mirrored about the middle, so
//! the parabola cancels too; the price is six turns instead of four, 80 s per heading
//! instead of 100 s in about the same seek time.

/// The seek modes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SeekMode {
    /// h0, h0+180, then a short dwell at h0+90 to resolve the acos ambiguity.
    TwoPosition,
    /// h0, h0+90, h0+180, h0+270 with atan2 (cancels bias and scale factor).
    FourPosition,
    /// The two positions in time-symmetric order: h0, h0+180, the ambiguity dwell at
    /// h0+90 in the middle, h0+180, h0: a drift linear in time cancels.
    TwoPositionSymmetric,
    /// The four positions there and back: h0, +90, +180, +270 (twice the dwell), +180, +90,
    /// h0: a drift linear in time cancels.
    FourPositionSymmetric,
    /// The two positions in Thue-Morse order, 0, 180, 180, 0, 180, 0, 0, 180 (the repeated
    /// headings one double dwell; the ambiguity dwell in the middle): signs + - - + - + + -,
    /// so a constant, a slope and a parabola in time cancel, with the turns' windows.
    TwoPositionThueMorse,
}

/// How long one step of a sequence measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dwell {
    /// `SeekConfig::dwell_s`.
    Main,
    /// Twice `dwell_s`: the turning point of a symmetric sequence.
    Double,
    /// `SeekConfig::ambiguity_dwell_s`.
    Ambiguity,
}

/// One dwell of a sequence: the position (index of the heading, see `offsets_deg`) and
/// how long.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Step {
    pub position: u8,
    pub dwell: Dwell,
}

const fn step(position: u8, dwell: Dwell) -> Step {
    Step { position, dwell }
}

/// Most steps of a sequence.
pub const MAX_STEPS: usize = 7;

const TWO: [Step; 3] = [
    step(0, Dwell::Main),
    step(1, Dwell::Main),
    step(2, Dwell::Ambiguity),
];
const TWO_SYMMETRIC: [Step; 5] = [
    step(0, Dwell::Main),
    step(1, Dwell::Main),
    step(2, Dwell::Ambiguity),
    step(1, Dwell::Main),
    step(0, Dwell::Main),
];
const FOUR: [Step; 4] = [
    step(0, Dwell::Main),
    step(1, Dwell::Main),
    step(2, Dwell::Main),
    step(3, Dwell::Main),
];
const FOUR_SYMMETRIC: [Step; 7] = [
    step(0, Dwell::Main),
    step(1, Dwell::Main),
    step(2, Dwell::Main),
    step(3, Dwell::Double),
    step(2, Dwell::Main),
    step(1, Dwell::Main),
    step(0, Dwell::Main),
];

const TWO_THUE_MORSE: [Step; 7] = [
    step(0, Dwell::Main),
    step(1, Dwell::Double),
    step(0, Dwell::Main),
    step(2, Dwell::Ambiguity),
    step(1, Dwell::Main),
    step(0, Dwell::Double),
    step(1, Dwell::Main),
];

/// The high bit of the link's `positions` byte that marks a time-symmetric sequence.
pub const SYMMETRIC_CODE_BIT: u8 = 0x80;
/// The bit below it that marks the Thue-Morse order (with `SYMMETRIC_CODE_BIT`: 0xC2).
pub const THUE_MORSE_CODE_BIT: u8 = 0x40;

impl SeekMode {
    /// The dwells in time order.
    pub const fn steps(self) -> &'static [Step] {
        match self {
            SeekMode::TwoPosition => &TWO,
            SeekMode::TwoPositionSymmetric => &TWO_SYMMETRIC,
            SeekMode::FourPosition => &FOUR,
            SeekMode::FourPositionSymmetric => &FOUR_SYMMETRIC,
            SeekMode::TwoPositionThueMorse => &TWO_THUE_MORSE,
        }
    }

    /// Table heading of each position, deg from the start heading (two positions: 0, 180
    /// and the ambiguity dwell's 90).
    pub const fn offsets_deg(self) -> &'static [f64] {
        match self.forward() {
            SeekMode::TwoPosition => &[0.0, 180.0, 90.0],
            _ => &[0.0, 90.0, 180.0, 270.0],
        }
    }

    /// The mode with the same positions in one pass: the geometry the solution uses.
    pub const fn forward(self) -> SeekMode {
        match self {
            SeekMode::TwoPosition
            | SeekMode::TwoPositionSymmetric
            | SeekMode::TwoPositionThueMorse => SeekMode::TwoPosition,
            SeekMode::FourPosition | SeekMode::FourPositionSymmetric => SeekMode::FourPosition,
        }
    }

    /// True for the time-symmetric sequences.
    pub const fn is_symmetric(self) -> bool {
        matches!(
            self,
            SeekMode::TwoPositionSymmetric
                | SeekMode::FourPositionSymmetric
                | SeekMode::TwoPositionThueMorse
        )
    }

    /// Main table positions: 2 or 4 (what `StartSeek` and the CLI call `positions`).
    pub const fn main_positions(self) -> u8 {
        match self.forward() {
            SeekMode::TwoPosition => 2,
            _ => 4,
        }
    }

    /// Measuring time at each main position, in units of `dwell_s` (2 for the symmetric
    /// sequences: two visits, or one double dwell; 4 for the Thue-Morse order).
    pub const fn main_dwells_per_position(self) -> u8 {
        if matches!(self, SeekMode::TwoPositionThueMorse) {
            4
        } else if self.is_symmetric() {
            2
        } else {
            1
        }
    }

    /// The mode as the link's `positions` byte: 2 or 4, with `SYMMETRIC_CODE_BIT` set for
    /// a symmetric sequence (0x82, 0x84) and `THUE_MORSE_CODE_BIT` too for the Thue-Morse
    /// order (0xC2). 2 and 4 keep their meaning, so old bytes decode the same; a device
    /// without these sequences refuses their bytes.
    pub const fn code(self) -> u8 {
        let sym = if self.is_symmetric() {
            SYMMETRIC_CODE_BIT
        } else {
            0
        };
        let thue_morse = if matches!(self, SeekMode::TwoPositionThueMorse) {
            THUE_MORSE_CODE_BIT
        } else {
            0
        };
        self.main_positions() | sym | thue_morse
    }

    /// The mode of a `positions` byte (`code`), `None` for any other byte.
    pub const fn from_code(code: u8) -> Option<SeekMode> {
        match code {
            2 => Some(SeekMode::TwoPosition),
            4 => Some(SeekMode::FourPosition),
            0x82 => Some(SeekMode::TwoPositionSymmetric),
            0x84 => Some(SeekMode::FourPositionSymmetric),
            0xC2 => Some(SeekMode::TwoPositionThueMorse),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ALL: [SeekMode; 5] = [
        SeekMode::TwoPosition,
        SeekMode::FourPosition,
        SeekMode::TwoPositionSymmetric,
        SeekMode::FourPositionSymmetric,
        SeekMode::TwoPositionThueMorse,
    ];

    #[test]
    fn codes_round_trip_and_the_old_bytes_keep_their_modes() {
        for m in ALL {
            assert_eq!(SeekMode::from_code(m.code()), Some(m));
        }
        assert_eq!(SeekMode::TwoPosition.code(), 2);
        assert_eq!(SeekMode::FourPosition.code(), 4);
        assert_eq!(SeekMode::from_code(3), None);
        assert_eq!(SeekMode::from_code(0x80), None);
        assert_eq!(SeekMode::from_code(0xC4), None);
    }

    /// The Thue-Morse order: whatever the dwell (in 10 s windows) and the turns' cost (one
    /// or two windows for a half turn, one for a quarter), the windows at 0 and at 180 deg
    /// have the same count, mean time and mean squared time, so a drift d0 + d1 t + d2 t^2
    /// cancels in their difference; the cubic does not.
    #[test]
    fn the_thue_morse_order_cancels_a_parabola_with_its_turns() {
        let s = SeekMode::TwoPositionThueMorse.steps();
        assert!(s.len() <= MAX_STEPS);
        for dwell in 1..6usize {
            for half_turn in 1..3usize {
                // each window's heading (None: turning), in time order
                let mut windows: Vec<Option<u8>> = Vec::new();
                for (k, st) in s.iter().enumerate() {
                    if k > 0 && s[k - 1].position != st.position {
                        let half = (s[k - 1].position + st.position) == 1;
                        windows
                            .extend(core::iter::repeat_n(None, if half { half_turn } else { 1 }));
                    }
                    let n = match st.dwell {
                        Dwell::Main => dwell,
                        Dwell::Double => 2 * dwell,
                        Dwell::Ambiguity => 1,
                    };
                    windows.extend(core::iter::repeat_n(Some(st.position), n));
                }
                let moment = |p: u8, d: i32| -> (usize, f64) {
                    let t: Vec<f64> = (0..windows.len())
                        .filter(|&i| windows[i] == Some(p))
                        .map(|i| i as f64 - windows.len() as f64 / 2.0)
                        .collect();
                    (
                        t.len(),
                        t.iter().map(|t| t.powi(d)).sum::<f64>() / t.len() as f64,
                    )
                };
                for d in 0..3 {
                    let (n0, m0) = moment(0, d);
                    let (n1, m1) = moment(1, d);
                    assert_eq!(n0, n1);
                    assert!(
                        (m0 - m1).abs() < 1e-9,
                        "dwell {dwell} turn {half_turn} d {d}"
                    );
                }
                assert!((moment(0, 3).1 - moment(1, 3).1).abs() > 1.0);
            }
        }
    }

    /// Each position's mean time (dwell-weighted step index, turns taken as one step)
    /// is the middle of a symmetric sequence; every position is measured as long as every
    /// other main one.
    #[test]
    fn symmetric_sequences_centre_every_position_and_weigh_them_alike() {
        for m in [
            SeekMode::TwoPositionSymmetric,
            SeekMode::FourPositionSymmetric,
        ] {
            let s = m.steps();
            assert!(s.len() <= MAX_STEPS);
            let mid = (s.len() - 1) as f64 / 2.0;
            for p in 0..m.offsets_deg().len() as u8 {
                let at: Vec<usize> = (0..s.len()).filter(|&k| s[k].position == p).collect();
                let mean = at.iter().sum::<usize>() as f64 / at.len() as f64;
                assert_eq!(mean, mid, "{m:?} position {p}");
                let units: u8 = at
                    .iter()
                    .map(|&k| match s[k].dwell {
                        Dwell::Main => 1,
                        Dwell::Double => 2,
                        Dwell::Ambiguity => 0,
                    })
                    .sum();
                assert!(units == 0 || units == m.main_dwells_per_position(), "{m:?}");
            }
            // Palindromic: the dwells read the same backwards (equal turns both ways).
            assert!(s.iter().eq(s.iter().rev()), "{m:?}");
        }
    }
}
