//! The validation layout and the base, chosen together: on a single record the buffer
//! between time blocks is sized on the base's residual (`validation::buffer`), and the
//! base is then chosen again on the buffered layout. In the baseline stage because both
//! passes choose a base; the rule and the correlation length stay in `validation`.

use crate::diagnose::baseline::choice::{
    choose, choose_with_rate_window, device_rate_half_s, BaseChoice,
};
use crate::diagnose::baseline::models::Stacked;
use crate::diagnose::error::DiagnoseError;
use crate::diagnose::input::Campaign;
use crate::diagnose::memprobe;
use crate::diagnose::validation::buffer::{correlated_lag, BufferRule};
use crate::diagnose::validation::folds::{Folds, Offsets};

/// The validation layout, the stacked campaign and the base: buffers between time blocks
/// are sized on the base with the device's dT/dt span; the base and its dT/dt window are
/// then chosen on that layout (`choice::choose_with_rate_window`).
pub fn layout_and_base(
    campaign: &Campaign,
    rule: BufferRule,
) -> Result<(Folds, Stacked, BaseChoice), DiagnoseError> {
    let device_rate = Stacked::with_rate_half_width(campaign, device_rate_half_s());
    let run_lengths: Vec<usize> = campaign.runs.iter().map(|s| s.t_s.len()).collect();
    let (folds, device_choice) = choose_buffered(Folds::new(&run_lengths)?, &device_rate, rule)?;
    memprobe::stage("layout: device-rate stack + buffered folds");
    let (st, choice) = choose_with_rate_window(campaign, &folds, (device_rate, device_choice))?;
    memprobe::stage("layout_and_base");
    Ok((folds, st, choice))
}

/// Median row spacing of the stacked record, s.
fn row_spacing_s(folds: &Folds, t_s: &[f64]) -> f64 {
    let mut d: Vec<f64> = folds
        .run_rows
        .iter()
        .flat_map(|r| t_s[r.clone()].windows(2).map(|w| w[1] - w[0]))
        .collect();
    d.sort_by(f64::total_cmp);
    d.get(d.len() / 2).copied().unwrap_or(0.0)
}

/// The layout with its buffer and the base chosen on it.
pub fn choose_buffered(
    folds: Folds,
    st: &Stacked,
    rule: BufferRule,
) -> Result<(Folds, BaseChoice), DiagnoseError> {
    let mut choice = choose(&folds, st)?;
    if folds.offsets == Offsets::PerUnit || rule == BufferRule::None {
        return Ok((folds, choice));
    }
    let shortest_run = folds.run_rows.iter().map(|r| r.len()).min().unwrap_or(0);
    let spacing = row_spacing_s(&folds, &st.t_s);
    let original = folds.clone();
    let mut folds = folds;
    // A base whose neighbours trained it hides the noise's memory (its held-out residual
    // is high-passed); each pass measures it on the residual of the previous, buffered,
    // layout until the correlation length stops growing.
    let mut lag = 0;
    for _ in 0..MAX_PASSES {
        let next = correlated_lag(
            &folds.run_rows,
            &choice.chosen.cv.residual,
            shortest_run / 2,
        );
        if next <= lag {
            break;
        }
        lag = next;
        folds = original
            .clone()
            .with_min_block_len(lag)
            .with_buffer(lag, spacing);
        choice = choose(&folds, st)?;
    }
    Ok((folds, choice))
}

/// Passes of the correlation-length measurement (it grows as buffers unmask it).
pub const MAX_PASSES: usize = 4;
