//! The model's linear parameters the refit may change (centre weights, bias, polynomial and
//! linear terms), read and written by (slot, index), and one unit model per parameter.

use fog_core::model::format::RbfModel;

/// The model's linear parameters: (slot, index) of every nonzero one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Slot {
    Weight,
    Bias,
    Poly,
    Linear,
    LinearByT,
}

pub(super) fn parameters(m: &RbfModel) -> Vec<(Slot, usize)> {
    let mut out = Vec::new();
    let mut add = |slot: Slot, v: &[f32]| {
        out.extend(
            v.iter()
                .enumerate()
                .filter(|(_, x)| **x != 0.0)
                .map(|(i, _)| (slot, i)),
        )
    };
    add(Slot::Weight, &m.weights);
    add(Slot::Bias, &[m.bias_dph]);
    add(Slot::Poly, &m.poly);
    add(Slot::Linear, &m.linear);
    add(Slot::LinearByT, &m.linear_by_t);
    out
}

pub(super) fn get(m: &RbfModel, (slot, i): (Slot, usize)) -> f32 {
    match slot {
        Slot::Weight => m.weights[i],
        Slot::Bias => m.bias_dph,
        Slot::Poly => m.poly[i],
        Slot::Linear => m.linear[i],
        Slot::LinearByT => m.linear_by_t[i],
    }
}

pub(super) fn set(m: &mut RbfModel, (slot, i): (Slot, usize), v: f32) {
    match slot {
        Slot::Weight => m.weights[i] = v,
        Slot::Bias => m.bias_dph = v,
        Slot::Poly => m.poly[i] = v,
        Slot::Linear => m.linear[i] = v,
        Slot::LinearByT => m.linear_by_t[i] = v,
    }
}

/// One model per parameter: that parameter 1, every other 0.
pub(super) fn unit_models(model: &RbfModel, params: &[(Slot, usize)]) -> Vec<RbfModel> {
    let mut zero = model.clone();
    for &p in &parameters(model) {
        set(&mut zero, p, 0.0);
    }
    params
        .iter()
        .map(|&p| {
            let mut m = zero.clone();
            set(&mut m, p, 1.0);
            m
        })
        .collect()
}
