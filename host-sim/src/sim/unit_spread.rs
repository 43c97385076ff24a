//! How the units of one gyro type differ: a 1-sigma spread per physical parameter
//! (`TypeSpread`), its defaults, and its text file (`fogsim campaign --unit-spread FILE`).
//! A module of its own because the spread is the type's statement of what varies; the
//! draw of a unit from it is `sim::fleet`, the runs of a fleet `pipeline::fleet`.
//!
//! Parameters that scale (heat capacities, conductances, dissipation, coefficients, noise
//! densities) spread relatively: a unit's value is the type's times exp(sigma z), z a
//! standard normal, so a unit is never of the other sign and the type's value is the
//! fleet's median; sigma is the standard deviation of ln(unit / type), about the relative
//! standard deviation for the spreads allowed here. Parameters that are offsets about
//! zero (the bias and its temperature coefficients) spread absolutely, in their own unit.

use super::params::GyroParams;

/// How a parameter varies from unit to unit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpreadLaw {
    /// unit = type x exp(sigma z): sigma is the standard deviation of ln(unit / type).
    Relative,
    /// unit = type + sigma z, sigma in the parameter's own unit.
    Absolute,
}

/// One parameter that varies between units: its name (as `GyroParams::validate` names
/// it), its law, the default 1-sigma spread and the largest one that is still one type.
pub struct SpreadEntry {
    pub key: &'static str,
    pub law: SpreadLaw,
    pub default_sigma: f64,
    pub max_sigma: f64,
    /// The parameter in a `GyroParams`.
    pub field: fn(&mut GyroParams) -> &mut f64,
}

/// Largest relative spread: at sigma 0.5 one unit in six is below 0.61 or above 1.65
/// times the type's value; wider than that the units are not one type.
pub const MAX_RELATIVE_SIGMA: f64 = 0.5;

const fn relative(
    key: &'static str,
    default_sigma: f64,
    field: fn(&mut GyroParams) -> &mut f64,
) -> SpreadEntry {
    SpreadEntry {
        key,
        law: SpreadLaw::Relative,
        default_sigma,
        max_sigma: MAX_RELATIVE_SIGMA,
        field,
    }
}

const fn absolute(
    key: &'static str,
    default_sigma: f64,
    max_sigma: f64,
    field: fn(&mut GyroParams) -> &mut f64,
) -> SpreadEntry {
    SpreadEntry {
        key,
        law: SpreadLaw::Absolute,
        default_sigma,
        max_sigma,
        field,
    }
}

/// Every parameter that varies between units, in the order a unit's draws are made (a
/// unit draws one normal per entry whatever its sigma, so changing one spread never
/// changes another parameter's draw). Defaults: docs/explain/simulator.md, "Fleets".
pub const SPREAD_ENTRIES: [SpreadEntry; 18] = [
    relative("thermal.coil_heat_capacity_j_per_k", 0.05, |p| {
        &mut p.thermal.coil_heat_capacity_j_per_k
    }),
    relative("thermal.housing_heat_capacity_j_per_k", 0.05, |p| {
        &mut p.thermal.housing_heat_capacity_j_per_k
    }),
    relative("thermal.coil_housing_w_per_k", 0.05, |p| {
        &mut p.thermal.coil_housing_w_per_k
    }),
    relative("thermal.housing_ambient_w_per_k", 0.05, |p| {
        &mut p.thermal.housing_ambient_w_per_k
    }),
    relative("thermal.power_w", 0.05, |p| &mut p.thermal.power_w),
    relative("thermal.coil_power_fraction", 0.05, |p| {
        &mut p.thermal.coil_power_fraction
    }),
    relative("thermal.tec_w_per_k", 0.10, |p| &mut p.thermal.tec_w_per_k),
    relative("sensor.lag_s", 0.10, |p| &mut p.sensor.lag_s),
    absolute("drift.bias_dph", 0.01, 1.0, |p| &mut p.drift.bias_dph),
    absolute("drift.bias_dph_per_c", 0.001, 0.1, |p| {
        &mut p.drift.bias_dph_per_c
    }),
    absolute("drift.bias_dph_per_c2", 1e-5, 1e-3, |p| {
        &mut p.drift.bias_dph_per_c2
    }),
    relative("drift.shupe_dph_per_cps", 0.10, |p| {
        &mut p.drift.shupe_dph_per_cps
    }),
    relative("drift.shupe_cold_gain_per_k", 0.20, |p| {
        &mut p.drift.shupe_cold_gain_per_k
    }),
    relative("drift.gradient_dph_per_cps", 0.10, |p| {
        &mut p.drift.gradient_dph_per_cps
    }),
    relative("drift.turn_on_bias_sigma_dph", 0.20, |p| {
        &mut p.drift.turn_on_bias_sigma_dph
    }),
    relative("noise.arw_dpsh", 0.10, |p| &mut p.noise.arw_dpsh),
    relative("noise.bias_instability_dph", 0.10, |p| {
        &mut p.noise.bias_instability_dph
    }),
    relative("noise.rrw_dph_per_sqrt_h", 0.10, |p| {
        &mut p.noise.rrw_dph_per_sqrt_h
    }),
];

/// Most bytes of a spread file.
pub const MAX_SPREAD_FILE_BYTES: u64 = 64 * 1024;

/// The 1-sigma unit-to-unit spread of every parameter of `SPREAD_ENTRIES`.
#[derive(Clone, Debug, PartialEq)]
pub struct TypeSpread {
    sigmas: [f64; SPREAD_ENTRIES.len()],
}

/// A line of a spread file that cannot be read: its 1-based number and why.
#[derive(Clone, Debug, PartialEq)]
pub struct SpreadError {
    pub line: usize,
    pub why: String,
}

impl std::fmt::Display for SpreadError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "line {}: {}", self.line, self.why)
    }
}

impl std::error::Error for SpreadError {}

impl TypeSpread {
    /// The stated default spread (docs/explain/simulator.md, "Fleets").
    pub fn default_spread() -> Self {
        Self {
            sigmas: SPREAD_ENTRIES.map(|e| e.default_sigma),
        }
    }

    /// No spread: every unit is the type (units differ only in their runs' noise, turn-on
    /// bias and soak).
    pub fn none() -> Self {
        Self {
            sigmas: [0.0; SPREAD_ENTRIES.len()],
        }
    }

    /// Each entry with its sigma, in draw order.
    pub fn entries(&self) -> impl Iterator<Item = (&'static SpreadEntry, f64)> + '_ {
        SPREAD_ENTRIES.iter().zip(self.sigmas.iter().copied())
    }

    /// The sigma of parameter `key` (None: not a parameter that varies).
    pub fn sigma(&self, key: &str) -> Option<f64> {
        self.entries().find(|(e, _)| e.key == key).map(|(_, s)| s)
    }

    /// This spread with parameter `key` at `sigma` (the file's rules: known key, finite,
    /// 0..=its largest); the error says why.
    pub fn with(mut self, key: &str, sigma: f64) -> Result<Self, String> {
        let i = entry_index(key)?;
        let e = &SPREAD_ENTRIES[i];
        if !(sigma.is_finite() && (0.0..=e.max_sigma).contains(&sigma)) {
            return Err(match e.law {
                SpreadLaw::Relative => format!(
                    "`{key}` spread {}%: must be within 0..={}%",
                    sigma * 100.0,
                    e.max_sigma * 100.0
                ),
                SpreadLaw::Absolute => format!(
                    "`{key}` spread {sigma:e}: must be within 0..={:e} (the parameter's own unit)",
                    e.max_sigma
                ),
            });
        }
        self.sigmas[i] = sigma;
        Ok(self)
    }

    /// Reads a spread file: `key: value` lines (blank lines and `#` comments skipped), a
    /// relative spread in percent (`drift.shupe_dph_per_cps: 10%`), an absolute one as a
    /// plain number in the parameter's unit (`drift.bias_dph: 0.01`). A parameter not
    /// named does not vary; a file that names none is refused (use `none`).
    pub fn parse(text: &str) -> Result<Self, SpreadError> {
        let mut spread = Self::none();
        let mut seen: Vec<String> = Vec::new();
        for (i, raw) in text.lines().enumerate() {
            let err = |why: String| SpreadError { line: i + 1, why };
            let line = raw.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let (key, value) = line.split_once(':').ok_or_else(|| {
                err("must be `parameter: spread` (e.g. `drift.shupe_dph_per_cps: 10%`)".into())
            })?;
            let (key, value) = (key.trim(), value.trim());
            if seen.iter().any(|k| k == key) {
                return Err(err(format!("`{key}` given twice")));
            }
            let law = SPREAD_ENTRIES[entry_index(key).map_err(err)?].law;
            let sigma = parse_sigma(key, value, law).map_err(err)?;
            spread = spread.with(key, sigma).map_err(err)?;
            seen.push(key.to_string());
        }
        if seen.is_empty() {
            return Err(SpreadError {
                line: 0,
                why: "names no parameter (for units without spread give `--unit-spread none`)"
                    .into(),
            });
        }
        Ok(spread)
    }
}

/// The index of parameter `key` in `SPREAD_ENTRIES`, or why there is none.
fn entry_index(key: &str) -> Result<usize, String> {
    SPREAD_ENTRIES.iter().position(|e| e.key == key).ok_or_else(|| {
        format!(
            "unknown parameter `{}` (the parameters that vary are listed in docs/reference/formats.md, \"Unit spread\")",
            crate::io::run_format::excerpt(key)
        )
    })
}

/// One spread value of a file: `N%` for a relative law, a plain number for an absolute one.
fn parse_sigma(key: &str, value: &str, law: SpreadLaw) -> Result<f64, String> {
    let shown = crate::io::run_format::excerpt(value);
    let number = |s: &str| {
        s.trim()
            .parse::<f64>()
            .map_err(|_| format!("`{key}` spread `{shown}`: not a number"))
    };
    match (law, value.strip_suffix('%')) {
        (SpreadLaw::Relative, Some(pct)) => Ok(number(pct)? / 100.0),
        (SpreadLaw::Relative, None) => Err(format!(
            "`{key}` spread `{shown}`: a relative spread, write it in percent (e.g. `10%`)"
        )),
        (SpreadLaw::Absolute, Some(_)) => Err(format!(
            "`{key}` spread `{shown}`: an absolute spread, write it in the parameter's own unit (no `%`)"
        )),
        (SpreadLaw::Absolute, None) => number(value),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_entry_names_a_validated_parameter_once_and_its_default_is_allowed() {
        let mut keys: Vec<&str> = SPREAD_ENTRIES.iter().map(|e| e.key).collect();
        keys.sort_unstable();
        keys.dedup();
        assert_eq!(keys.len(), SPREAD_ENTRIES.len(), "a key listed twice");
        for e in &SPREAD_ENTRIES {
            assert!((0.0..=e.max_sigma).contains(&e.default_sigma), "{}", e.key);
            // the accessor reaches the parameter validate() names: poison it, see the name
            let mut p = GyroParams::paper_default();
            *(e.field)(&mut p) = f64::NAN;
            match p.validate() {
                Err(crate::sim::SimError::BadParameter { name, .. }) => assert_eq!(name, e.key),
                other => panic!("{}: {other:?}", e.key),
            }
        }
    }

    #[test]
    fn the_default_spread_file_in_the_formats_page_is_the_default() {
        let page = include_str!("../../../docs/reference/formats.md");
        let block = page
            .split_once("The default spread, as a file:\n\n```text\n")
            .and_then(|(_, rest)| rest.split_once("```"))
            .expect("formats.md shows the default spread file")
            .0;
        assert_eq!(
            TypeSpread::parse(block).unwrap(),
            TypeSpread::default_spread()
        );
    }

    #[test]
    fn a_file_sets_what_it_names_and_nothing_else() {
        let s = TypeSpread::parse(
            "# two parameters\n\ndrift.shupe_dph_per_cps: 12.5%\n  drift.bias_dph : 0.02\n",
        )
        .unwrap();
        assert_eq!(s.sigma("drift.shupe_dph_per_cps"), Some(0.125));
        assert_eq!(s.sigma("drift.bias_dph"), Some(0.02));
        assert_eq!(s.sigma("noise.arw_dpsh"), Some(0.0));
        assert_eq!(s.sigma("no.such"), None);
    }

    #[test]
    fn bad_spread_files_name_the_line_and_the_fault() {
        for (text, line, needle) in [
            (
                "drift.bias_dph: 0.01\nfoo.bar: 10%\n",
                2,
                "unknown parameter `foo.bar`",
            ),
            ("drift.shupe_dph_per_cps: 0.1\n", 1, "write it in percent"),
            ("drift.bias_dph: 1%\n", 1, "no `%`"),
            ("drift.shupe_dph_per_cps: 80%\n", 1, "within 0..=50%"),
            ("drift.shupe_dph_per_cps: -1%\n", 1, "within 0..=50%"),
            ("drift.bias_dph: 5\n", 1, "within 0..=1e0"),
            ("drift.bias_dph: nan\n", 1, "within"),
            ("drift.bias_dph: abc\n", 1, "not a number"),
            ("drift.bias_dph 0.01\n", 1, "must be `parameter: spread`"),
            ("drift.bias_dph: 0\ndrift.bias_dph: 0\n", 2, "given twice"),
            ("# nothing\n\n", 0, "names no parameter"),
        ] {
            let e = TypeSpread::parse(text).unwrap_err();
            assert_eq!(e.line, line, "{text:?}: {e}");
            assert!(e.why.contains(needle), "{text:?}: {e}");
        }
    }
}
