//! The campaign at several headings (`fogsim campaign --headings-deg`): the same cold
//! power-ons as the paper's campaign, but with the input axis horizontal at each given
//! azimuth, so a heading-dependent bias (a cos(alpha) + b sin(alpha)) shows up between
//! runs and `fogsim heading-cal --from-runs` can fit it. Every run has its own derived
//! seed (ambient, heading, run), so the bytes never depend on the thread schedule.

use super::campaign::{CampaignError, CampaignRun, CampaignSpec};
use crate::sim::{simulate_run, GyroParams};

/// Most headings of one campaign.
pub const MAX_HEADINGS: usize = 360;

/// Checks the headings: finite, within [0, 360), distinct.
pub fn check_headings(headings_deg: &[f64]) -> Result<(), String> {
    if headings_deg.is_empty() || headings_deg.len() > MAX_HEADINGS {
        return Err(format!("give 1..={MAX_HEADINGS} headings"));
    }
    for (i, h) in headings_deg.iter().enumerate() {
        if !(h.is_finite() && (0.0..360.0).contains(h)) {
            return Err(format!("heading {h:.4e} deg: must be within 0..360"));
        }
        if headings_deg[..i].contains(h) {
            return Err(format!("heading {h} deg given twice"));
        }
    }
    Ok(())
}

/// File name of a run at heading index `k`; sorts by ambient, heading, run.
fn file_name(spec: &CampaignSpec, amb: usize, heading_deg: f64, run: usize) -> String {
    let a = spec.ambients_c[amb];
    let sign = if a < 0.0 { 'm' } else { 'p' };
    format!(
        "amb{amb:02}_{sign}{:03}c_h{:05.1}_run{}.csv",
        a.abs().round() as i64,
        heading_deg,
        run + 1
    )
}

/// Simulates every (ambient, heading, run) in file order, in parallel.
pub fn simulate_heading_campaign(
    params: &GyroParams,
    spec: &CampaignSpec,
    headings_deg: &[f64],
) -> Result<Vec<CampaignRun>, CampaignError> {
    check_headings(headings_deg).map_err(CampaignError::Spec)?;
    if spec.ambients_c.is_empty() || spec.runs_per_ambient == 0 {
        return Err(CampaignError::Spec(
            "campaign: needs ambients and runs".into(),
        ));
    }
    spec.check_record_size(headings_deg.len())?;
    let jobs: Vec<(usize, usize, usize)> = (0..spec.ambients_c.len())
        .flat_map(|a| {
            (0..headings_deg.len())
                .flat_map(move |k| (0..spec.runs_per_ambient).map(move |r| (a, k, r)))
        })
        .collect();
    let run_spec = |(a, k, r): (usize, usize, usize)| {
        let base = spec.run_spec(a, r);
        crate::sim::RunSpec {
            input_axis_vertical: false,
            heading_deg: headings_deg[k],
            seed: crate::seed::derive_seed(base.seed, k as u64, 0x4844_4e47),
            ..base
        }
    };
    run_spec(jobs[0]).validate().map_err(CampaignError::Sim)?;
    let results = crate::fanout::map_in_order(jobs.len(), crate::fanout::thread_count(None), |j| {
        simulate_run(params, &run_spec(jobs[j]))
    });
    jobs.iter()
        .zip(results)
        .map(|(&(a, k, r), res)| {
            let run = res.map_err(CampaignError::Sim)?;
            let name = file_name(spec, a, headings_deg[k], r);
            Ok(CampaignRun::named(spec, a, r, run, name))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headings_are_checked() {
        assert!(check_headings(&[0.0, 90.0, 180.0, 270.0]).is_ok());
        assert!(check_headings(&[]).is_err());
        assert!(check_headings(&[0.0, 0.0]).unwrap_err().contains("twice"));
        assert!(check_headings(&[360.0]).is_err());
        assert!(check_headings(&[f64::NAN]).is_err());
    }
}
