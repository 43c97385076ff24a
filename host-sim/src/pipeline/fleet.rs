//! Fleets in the simulated campaign (`fogsim campaign --units N`): N units of one gyro
//! type, each drawn by `sim::fleet` from the type and its spread, each with the
//! campaign's power-ons. The data a type model (what units share, how they differ) and a
//! unit calibration (K runs of unit U at ambients A, the type as prior) learn from.
//!
//! Unit `u`'s parameters come from (type seed, `u`) and its runs' seeds from (campaign
//! seed, `u`) alone, so unit 3 and its runs are the same whatever the fleet's size or its
//! other units. Its files are the campaign's prefixed by the unit
//! (`u003_amb06_p020c_run1.csv`) and carry `unit_id`, `type_id`, `type_seed` and
//! `unit_spread` metadata.

use super::campaign::{simulate_campaign, CampaignError, CampaignRun, CampaignSpec};
use super::heading_campaign::simulate_heading_campaign;
use crate::io::runs::Run;
use crate::sim::{unit_params, GyroParams, TypeSpread};
use std::path::PathBuf;

/// Most units of one fleet (the file names carry three digits).
pub const MAX_UNITS: usize = 999;
/// Index mixed into a unit's run seeds, so they are none of a single gyro's campaign.
const UNIT_RUNS_TAG: u64 = 0x464C_4545_5452_554E; // "FLEETRUN"

/// A gyro type: its parameters, how its units spread about them, and the seed its
/// units are drawn from.
#[derive(Clone, Debug, PartialEq)]
pub struct FleetType {
    /// The type's name (`type_id` in every run's metadata).
    pub type_id: String,
    pub params: GyroParams,
    pub spread: TypeSpread,
    /// How the spread was given (`unit_spread` metadata): `default`, `none` or a file name.
    pub spread_label: String,
    pub type_seed: u64,
}

impl FleetType {
    /// The paper's gyro as the type (`type_id: paper_default`).
    pub fn paper(spread: TypeSpread, spread_label: &str, type_seed: u64) -> Self {
        Self {
            type_id: "paper_default".into(),
            params: GyroParams::paper_default(),
            spread,
            spread_label: spread_label.into(),
            type_seed,
        }
    }

    /// The parameters of unit `unit_index` (0-based); an impossible draw names the unit.
    pub fn unit(&self, unit_index: usize) -> Result<GyroParams, CampaignError> {
        unit_params(&self.params, &self.spread, self.type_seed, unit_index)
            .map_err(|e| CampaignError::Spec(format!("unit {}: {e}", unit_id(unit_index))))
    }
}

/// The id of unit `unit_index` (0-based) in metadata and reports: `U1`, `U2`, ...
pub fn unit_id(unit_index: usize) -> String {
    format!("U{}", unit_index + 1)
}

/// The 0-based unit index of a fleet run (its `unit_id` metadata), None for a run of no fleet.
pub fn unit_index_of(run: &Run) -> Option<usize> {
    let n: usize = run
        .meta_value("unit_id")?
        .trim()
        .strip_prefix('U')?
        .parse()
        .ok()?;
    n.checked_sub(1)
}

/// The campaign seed of unit `unit_index` in a fleet campaign seeded `seed`.
pub fn unit_seed(seed: u64, unit_index: usize) -> u64 {
    crate::seed::derive_seed(seed, UNIT_RUNS_TAG, unit_index as u64)
}

/// The runs of unit `unit_index` of `fleet` under `plan` (its ambients, runs, length and
/// seed; at each of `headings_deg` with the input axis horizontal, if given), named and
/// tagged as a fleet campaign's.
pub fn fleet_runs(
    fleet: &FleetType,
    unit_index: usize,
    plan: &CampaignSpec,
    headings_deg: Option<&[f64]>,
) -> Result<Vec<CampaignRun>, CampaignError> {
    let params = fleet.unit(unit_index)?;
    let spec = CampaignSpec {
        seed: unit_seed(plan.seed, unit_index),
        ..plan.clone()
    };
    let mut runs = match headings_deg {
        Some(h) => simulate_heading_campaign(&params, &spec, h)?,
        None => simulate_campaign(&params, &spec)?,
    };
    for c in &mut runs {
        let name = format!("u{:03}_{}", unit_index + 1, c.run.name());
        c.run.path = PathBuf::from(name);
        c.run.set_meta("unit_id", unit_id(unit_index));
        c.run.set_meta("type_id", &fleet.type_id);
        c.run.set_meta("type_seed", fleet.type_seed);
        c.run.set_meta("unit_spread", &fleet.spread_label);
    }
    Ok(runs)
}

/// Units 1..=`units` of `fleet`, each with `plan`'s runs (see [`fleet_runs`]), in file
/// order (unit, ambient, heading, run). Every unit is drawn and the size checked before
/// anything is simulated.
pub fn simulate_fleet(
    fleet: &FleetType,
    units: usize,
    plan: &CampaignSpec,
    headings_deg: Option<&[f64]>,
) -> Result<Vec<CampaignRun>, CampaignError> {
    if !(1..=MAX_UNITS).contains(&units) {
        return Err(CampaignError::Spec(format!(
            "a fleet of {units} units: must be 1..={MAX_UNITS} units"
        )));
    }
    let headings = headings_deg.map_or(1, <[f64]>::len);
    plan.check_record_size_with(&[
        (headings, "headings", "--headings-deg"),
        (units, "units", "--units"),
    ])?;
    for u in 0..units {
        fleet.unit(u)?;
    }
    let mut all = Vec::new();
    for u in 0..units {
        all.extend(fleet_runs(fleet, u, plan, headings_deg)?);
    }
    Ok(all)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_ids_read_back_and_other_runs_have_none() {
        let plan = CampaignSpec {
            ambients_c: vec![20.0],
            runs_per_ambient: 1,
            minutes: 1.0,
            raw_rate_hz: 1.0,
            ..CampaignSpec::paper(3)
        };
        let fleet = FleetType::paper(TypeSpread::default_spread(), "default", 9);
        let runs = fleet_runs(&fleet, 11, &plan, None).unwrap();
        assert_eq!(runs[0].run.name(), "u012_amb00_p020c_run1.csv");
        assert_eq!(unit_index_of(&runs[0].run), Some(11));
        assert_eq!(runs[0].run.meta_value("type_id"), Some("paper_default"));
        assert_eq!(runs[0].run.meta_value("type_seed"), Some("9"));
        let single = simulate_campaign(&fleet.params, &plan).unwrap();
        assert_eq!(unit_index_of(&single[0].run), None);
    }

    #[test]
    fn a_fleet_too_large_for_memory_names_units() {
        let plan = CampaignSpec::paper(1);
        let fleet = FleetType::paper(TypeSpread::none(), "none", 1);
        let e = simulate_fleet(&fleet, 30, &plan, None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("x 30 units") && e.contains("--units"), "{e}");
        let e = simulate_fleet(&fleet, 0, &plan, None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("fleet of 0 units"), "{e}");
    }
}
