//! Which averaging factors m (tau = m tau0) a curve is computed at, as allantools'
//! `tau_generator` picks them: octave (1, 2, 4, ...), decade (1, 2, 4, 10, 20, 40, ...,
//! Stable32's spacing) or all (every m), each cut to the factors the estimator can use.

use std::fmt;
use std::str::FromStr;

/// The tau spacing of a curve.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum TauSpacing {
    Octave,
    Decade,
    All,
}

impl FromStr for TauSpacing {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "octave" => Ok(Self::Octave),
            "decade" => Ok(Self::Decade),
            "all" => Ok(Self::All),
            _ => Err(format!("'{s}' is not a tau spacing (octave, decade, all)")),
        }
    }
}

impl fmt::Display for TauSpacing {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Octave => "octave",
            Self::Decade => "decade",
            Self::All => "all",
        })
    }
}

/// The averaging factors 1 <= m <= `max_m`, ascending.
pub fn factors(spacing: TauSpacing, max_m: usize) -> Vec<usize> {
    match spacing {
        TauSpacing::All => (1..=max_m).collect(),
        TauSpacing::Octave => std::iter::successors(Some(1usize), |m| m.checked_mul(2))
            .take_while(|&m| m <= max_m)
            .collect(),
        TauSpacing::Decade => {
            let mut out = Vec::new();
            let mut decade = 1usize;
            'outer: loop {
                for k in [1, 2, 4] {
                    let Some(m) = decade.checked_mul(k) else {
                        break 'outer;
                    };
                    if m > max_m {
                        break 'outer;
                    }
                    out.push(m);
                }
                match decade.checked_mul(10) {
                    Some(d) => decade = d,
                    None => break,
                }
            }
            out
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spacings() {
        assert_eq!(factors(TauSpacing::Octave, 40), vec![1, 2, 4, 8, 16, 32]);
        assert_eq!(factors(TauSpacing::Decade, 45), vec![1, 2, 4, 10, 20, 40]);
        assert_eq!(factors(TauSpacing::All, 3), vec![1, 2, 3]);
        assert!(factors(TauSpacing::Octave, 0).is_empty());
        assert_eq!("decade".parse::<TauSpacing>(), Ok(TauSpacing::Decade));
        assert!("weekly".parse::<TauSpacing>().is_err());
    }
}
