//! The held-out figures per ambient and the targets, from the compensated runs and seeks.

use super::results::*;
use crate::output::reports::NorthSeekReport;
use crate::pipeline::campaign_steps::CampaignRun;
use crate::pipeline::compensation_replay::{pooled_stats, CompensatedSeries};
use crate::pipeline::north_seek::PAPER_SEEK_DURATION_S;
use crate::stats::SPEC_DPH;

/// Held-out figures per ambient, the runs of one temperature pooled.
pub(super) fn per_ambient_results(
    ambients_c: &[f64],
    heldout: &[&CampaignRun],
    series: &[CompensatedSeries],
) -> Vec<AmbientResult> {
    ambients_c
        .iter()
        .map(|&a| {
            let idx: Vec<usize> = (0..heldout.len())
                .filter(|&i| heldout[i].ambient_c == a)
                .collect();
            let before: Vec<(&[f64], &[f64])> = idx
                .iter()
                .map(|&i| (&series[i].t_s[..], &series[i].before_dph[..]))
                .collect();
            let after: Vec<(&[f64], &[f64])> = idx
                .iter()
                .map(|&i| (&series[i].after_t_s[..], &series[i].after_dph[..]))
                .collect();
            AmbientResult {
                ambient_c: a,
                heldout_runs: idx.len(),
                before: pooled_stats(&before),
                after: pooled_stats(&after),
            }
        })
        .collect()
}

pub(super) fn measure_targets(per_ambient: &[AmbientResult], ns: &NorthSeekReport) -> Targets {
    let worst_after = per_ambient
        .iter()
        .map(|a| a.after.std_dph)
        .fold(0.0, f64::max);
    let worst_time = |f: fn(&AmbientResult) -> Option<f64>| {
        per_ambient
            .iter()
            .try_fold(0.0f64, |m, a| f(a).map(|t| m.max(t)))
    };
    let ratio = ns.compensated.std_deg / ns.noise_floor_deg;
    Targets {
        worst_heldout_after_std_dph: worst_after,
        heldout_std_within_spec_everywhere: worst_after <= SPEC_DPH,
        worst_time_to_spec_before_s: worst_time(|a| a.before.time_to_spec_s),
        worst_time_to_spec_after_s: worst_time(|a| a.after.time_to_spec_s),
        azimuth_std_over_floor: ratio,
        azimuth_within_1_2x_floor: ratio <= 1.2,
        first_seeks_uncomp_over_comp: (0..2.min(ns.compensated.per_seek_rms_error_deg.len()))
            .map(|k| {
                ns.uncompensated.per_seek_rms_error_deg[k]
                    / ns.compensated.per_seek_rms_error_deg[k]
            })
            .collect(),
        seek_time_within_paper: ns.max_seek_duration_s <= PAPER_SEEK_DURATION_S,
    }
}
