//! The column and unit mapping of a logger import: which column is time, rate and
//! temperature, in which unit, and how each converts to fog-runs units (s, deg/h,
//! degC). Units are never guessed: a rate or temperature without a unit is refused,
//! because a deg/s column read as deg/h is silently wrong by 3600.

use std::fmt;

/// deg/s to deg/h.
const DPS_TO_DPH: f64 = 3600.0;
/// rad/s to deg/h.
const RPS_TO_DPH: f64 = 180.0 / std::f64::consts::PI * 3600.0;

/// How the time column is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimeUnit {
    S,
    Ms,
    Us,
    /// ISO 8601 date and time, `2024-03-05T14:02:07.25` (space instead of `T`, a trailing
    /// `Z` or `+hh:mm` offset and a decimal comma in the seconds accepted).
    Iso,
}

/// The gyro rate column's unit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RateUnit {
    Dph,
    Dps,
    Rps,
}

/// The temperature column's unit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TempUnit {
    C,
    F,
    K,
}

/// Where the input axis azimuth comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum Heading {
    /// Not known: no `heading_deg` column.
    Unknown,
    /// A column of the log, deg.
    Column(String),
    /// The same for the whole log, deg.
    Fixed(f64),
}

/// `--time COL[:s|ms|us|iso]`.
#[derive(Clone, Debug, PartialEq)]
pub struct TimeColumn {
    pub column: String,
    pub unit: TimeUnit,
}

/// `--rate COL:dph|dps|rps[*SCALE]`: deg/h = value * scale * (unit to deg/h).
#[derive(Clone, Debug, PartialEq)]
pub struct RateColumn {
    pub column: String,
    pub unit: RateUnit,
    pub scale: f64,
}

/// `--temp COL:c|f|k`.
#[derive(Clone, Debug, PartialEq)]
pub struct TempColumn {
    pub column: String,
    pub unit: TempUnit,
}

impl TimeUnit {
    /// Seconds per unit of a numeric time column (None for ISO text).
    pub fn seconds_per_unit(self) -> Option<f64> {
        match self {
            TimeUnit::S => Some(1.0),
            TimeUnit::Ms => Some(1e-3),
            TimeUnit::Us => Some(1e-6),
            TimeUnit::Iso => None,
        }
    }
}

impl RateColumn {
    /// A logged value in deg/h.
    pub fn to_dph(&self, value: f64) -> f64 {
        let per_unit = match self.unit {
            RateUnit::Dph => 1.0,
            RateUnit::Dps => DPS_TO_DPH,
            RateUnit::Rps => RPS_TO_DPH,
        };
        value * self.scale * per_unit
    }
}

impl TempColumn {
    /// A logged value in degC.
    pub fn to_c(&self, value: f64) -> f64 {
        match self.unit {
            TempUnit::C => value,
            TempUnit::F => (value - 32.0) * 5.0 / 9.0,
            TempUnit::K => value - 273.15,
        }
    }
}

/// Splits `COL:UNIT` at its last colon (column names may contain colons).
fn split_unit(spec: &str) -> (&str, Option<&str>) {
    match spec.rsplit_once(':') {
        Some((c, u)) if !c.is_empty() => (c, Some(u)),
        _ => (spec, None),
    }
}

fn column_name(spec: &str, flag: &str) -> Result<String, String> {
    let c = spec.trim();
    if c.is_empty() {
        Err(format!("{flag}: empty column name"))
    } else {
        Ok(c.to_owned())
    }
}

impl TimeColumn {
    pub fn parse(spec: &str) -> Result<Self, String> {
        let (col, unit) = split_unit(spec);
        let unit = match unit.map(str::to_ascii_lowercase).as_deref() {
            None | Some("s") => TimeUnit::S,
            Some("ms") => TimeUnit::Ms,
            Some("us") => TimeUnit::Us,
            Some("iso") => TimeUnit::Iso,
            Some(u) => return Err(format!("--time unit `{u}`: use s, ms, us or iso")),
        };
        Ok(TimeColumn {
            column: column_name(col, "--time")?,
            unit,
        })
    }
}

impl RateColumn {
    pub fn parse(spec: &str) -> Result<Self, String> {
        let (col, unit) = split_unit(spec);
        let Some(unit) = unit else {
            return Err(format!(
                "--rate {spec}: give the unit, COL:dph, COL:dps or COL:rps (optionally *SCALE)"
            ));
        };
        let (unit, scale) = match unit.split_once('*') {
            Some((u, s)) => {
                let scale: f64 = s
                    .trim()
                    .parse()
                    .ok()
                    .filter(|x: &f64| x.is_finite() && *x != 0.0)
                    .ok_or_else(|| format!("--rate scale `{s}` is not a finite non-zero number"))?;
                (u, scale)
            }
            None => (unit, 1.0),
        };
        let unit = match unit.trim().to_ascii_lowercase().as_str() {
            "dph" => RateUnit::Dph,
            "dps" => RateUnit::Dps,
            "rps" => RateUnit::Rps,
            u => {
                return Err(format!(
                    "--rate unit `{u}`: use dph (deg/h), dps (deg/s) or rps (rad/s)"
                ))
            }
        };
        Ok(RateColumn {
            column: column_name(col, "--rate")?,
            unit,
            scale,
        })
    }
}

impl TempColumn {
    pub fn parse(spec: &str) -> Result<Self, String> {
        let (col, unit) = split_unit(spec);
        let unit = match unit.map(str::to_ascii_lowercase).as_deref() {
            Some("c") => TempUnit::C,
            Some("f") => TempUnit::F,
            Some("k") => TempUnit::K,
            None => {
                return Err(format!(
                    "--temp {spec}: give the unit, COL:c, COL:f or COL:k"
                ))
            }
            Some(u) => return Err(format!("--temp unit `{u}`: use c, f or k")),
        };
        Ok(TempColumn {
            column: column_name(col, "--temp")?,
            unit,
        })
    }
}

impl fmt::Display for TimeUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            TimeUnit::S => "s",
            TimeUnit::Ms => "ms",
            TimeUnit::Us => "us",
            TimeUnit::Iso => "ISO 8601",
        })
    }
}

impl fmt::Display for RateColumn {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let unit = match self.unit {
            RateUnit::Dph => "deg/h",
            RateUnit::Dps => "deg/s",
            RateUnit::Rps => "rad/s",
        };
        if self.scale == 1.0 {
            write!(f, "{} in {unit}", self.column)
        } else {
            write!(f, "{} x {} in {unit}", self.column, self.scale)
        }
    }
}

impl fmt::Display for TempColumn {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let unit = match self.unit {
            TempUnit::C => "degC",
            TempUnit::F => "degF",
            TempUnit::K => "K",
        };
        write!(f, "{} in {unit}", self.column)
    }
}

/// A kept column's fog-runs name: lower case, anything but letters, digits and `_`
/// becomes `_`, runs of `_` become one (`Supply [V]` -> `supply_v`).
pub fn fog_runs_name(column: &str) -> String {
    let s: String = column
        .trim()
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect();
    let s = s
        .split('_')
        .filter(|part| !part.is_empty())
        .collect::<Vec<_>>()
        .join("_");
    if s.is_empty() {
        "column".into()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_convert_to_fog_runs_units() {
        let r = RateColumn::parse("gyro:dps").unwrap();
        assert_eq!(r.to_dph(1.0), 3600.0);
        let c = RateColumn::parse("cnt:dph*0.25").unwrap();
        assert_eq!((c.column.as_str(), c.to_dph(4.0)), ("cnt", 1.0));
        assert!((RateColumn::parse("w:rps").unwrap().to_dph(1.0) - 206_264.806).abs() < 1e-3);
        assert!((TempColumn::parse("T:f").unwrap().to_c(212.0) - 100.0).abs() < 1e-12);
        assert!((TempColumn::parse("T:k").unwrap().to_c(273.15)).abs() < 1e-12);
        assert_eq!(TimeColumn::parse("time").unwrap().unit, TimeUnit::S);
        assert_eq!(TimeColumn::parse("a:b:ms").unwrap().column, "a:b");
    }

    #[test]
    fn a_missing_or_unknown_unit_is_refused() {
        assert!(RateColumn::parse("gyro")
            .unwrap_err()
            .contains("give the unit"));
        assert!(RateColumn::parse("gyro:rpm").is_err());
        assert!(RateColumn::parse("gyro:dph*0").is_err());
        assert!(RateColumn::parse("gyro:dph*nan").is_err());
        assert!(TempColumn::parse("T").is_err());
        assert!(TimeColumn::parse("t:h").is_err());
    }

    #[test]
    fn kept_names_become_fog_runs_names() {
        assert_eq!(fog_runs_name(" Supply [V] "), "supply_v");
        assert_eq!(fog_runs_name("°"), "column");
    }
}
