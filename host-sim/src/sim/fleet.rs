//! One unit of a gyro type: the type's parameters with every parameter of a
//! `TypeSpread` drawn for that unit. Each unit draws from its own seeded stream (the type
//! seed and the unit's index), so unit 3 is the same gyro however many units are made
//! and whichever others are; the runs of a unit are `pipeline::fleet`'s job.

use super::error::SimError;
use super::params::GyroParams;
use super::unit_spread::{SpreadLaw, TypeSpread};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

/// Index mixed into a unit's seed so its parameter stream is none of the run streams.
const UNIT_PARAMS_TAG: u64 = 0x5459_5045_554E_4954; // "TYPEUNIT"

/// The parameters of unit `unit_index` (0-based) of the type `type_params` with the
/// spread `spread`, drawn from the stream of (`type_seed`, `unit_index`): one standard
/// normal per spread entry, in the entries' order, whatever its sigma. Extra drift
/// terms are the type's. A draw that leaves the physical range (a spread that is too
/// wide for this type) is an error naming the parameter.
pub fn unit_params(
    type_params: &GyroParams,
    spread: &TypeSpread,
    type_seed: u64,
    unit_index: usize,
) -> Result<GyroParams, SimError> {
    let seed = crate::seed::derive_seed(type_seed, UNIT_PARAMS_TAG, unit_index as u64);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut unit = type_params.clone();
    for (entry, sigma) in spread.entries() {
        let z: f64 = rng.sample(StandardNormal);
        let value = (entry.field)(&mut unit);
        match entry.law {
            SpreadLaw::Relative => *value *= (sigma * z).exp(),
            SpreadLaw::Absolute => *value += sigma * z,
        }
    }
    unit.validate()?;
    Ok(unit)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::unit_spread::SPREAD_ENTRIES;

    /// Sample standard deviation and its standard error for a normal population.
    fn sd_and_se(v: &[f64]) -> (f64, f64) {
        let n = v.len() as f64;
        let mean = v.iter().sum::<f64>() / n;
        let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        (sd, sd / (2.0 * (n - 1.0)).sqrt())
    }

    #[test]
    fn drawn_units_have_the_stated_spread_about_the_type() {
        let ty = GyroParams::paper_default();
        let spread = TypeSpread::default_spread();
        let units: Vec<GyroParams> = (0..400)
            .map(|u| unit_params(&ty, &spread, 11, u).unwrap())
            .collect();
        for key in [
            "drift.shupe_dph_per_cps",
            "drift.bias_dph_per_c",
            "sensor.lag_s",
        ] {
            let e = SPREAD_ENTRIES.iter().find(|e| e.key == key).unwrap();
            let type_value = *(e.field)(&mut ty.clone());
            let dev: Vec<f64> = units
                .iter()
                .map(|u| {
                    let v = *(e.field)(&mut u.clone());
                    match e.law {
                        SpreadLaw::Relative => (v / type_value).ln(),
                        SpreadLaw::Absolute => v - type_value,
                    }
                })
                .collect();
            let (sd, se) = sd_and_se(&dev);
            let sigma = spread.sigma(key).unwrap();
            assert!(
                (sd - sigma).abs() < 3.0 * se,
                "{key}: sd {sd} vs {sigma} (se {se})"
            );
            let mean = dev.iter().sum::<f64>() / dev.len() as f64;
            let se_mean = sigma / (dev.len() as f64).sqrt();
            assert!(mean.abs() < 3.0 * se_mean, "{key}: centred at {mean}");
        }
    }

    #[test]
    fn a_unit_is_its_own_whatever_else_is_drawn_and_no_spread_is_the_type() {
        let ty = GyroParams::paper_default();
        let spread = TypeSpread::default_spread();
        let u3 = unit_params(&ty, &spread, 5, 3).unwrap();
        assert_eq!(u3, unit_params(&ty, &spread, 5, 3).unwrap());
        assert_ne!(u3, unit_params(&ty, &spread, 5, 4).unwrap());
        assert_ne!(u3, unit_params(&ty, &spread, 6, 3).unwrap());
        // one spread changed: every other parameter keeps its draw
        let wider = spread.clone().with("noise.arw_dpsh", 0.3).unwrap();
        let mut u3w = unit_params(&ty, &wider, 5, 3).unwrap();
        assert_ne!(u3w.noise.arw_dpsh, u3.noise.arw_dpsh);
        u3w.noise.arw_dpsh = u3.noise.arw_dpsh;
        assert_eq!(u3w, u3);
        assert_eq!(unit_params(&ty, &TypeSpread::none(), 5, 3).unwrap(), ty);
    }

    #[test]
    fn a_draw_outside_the_physical_range_names_the_parameter() {
        // the coil's share of the dissipation is a fraction: 0.5 x exp(0.5 z) > 1 for z > 1.39
        let mut ty = GyroParams::paper_default();
        ty.thermal.coil_power_fraction = 0.5;
        let spread = TypeSpread::none()
            .with("thermal.coil_power_fraction", 0.5)
            .unwrap();
        let errors: Vec<SimError> = (0..200)
            .filter_map(|u| unit_params(&ty, &spread, 1, u).err())
            .collect();
        assert!(!errors.is_empty() && errors.len() < 50, "{}", errors.len());
        assert!(errors
            .iter()
            .all(|e| e.to_string().contains("coil_power_fraction")));
    }
}
