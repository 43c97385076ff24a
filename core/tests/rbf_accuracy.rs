//! Evaluation paths against each other: f32 vs the f64 reference, fixed point vs f32,
//! and the fixed-point worst error over a realistic model's input range.

use fog_core::model::accuracy::worst_errors as worst_errors_in_box;
use fog_core::model::fixed::{exp_neg_q30, f32_to_fixed, fixed_to_f32, FixedModel};
use fog_core::model::format::{FeatureKind, FeatureSpec, RbfModel, TrainingMeta};
use fog_core::model::rbf::{predict_f32, predict_f64, RbfError};
use fog_core::model::synthetic::{random_warmup_point, warmup_model, SplitMix64};
use proptest::prelude::*;

/// A model from proptest-chosen parameters, already in normalised space.
fn model_from(
    n_inputs: usize,
    centers: &[([f32; 4], f32, f32)],
    offset: f32,
    scale: f32,
    bias: f32,
    linear: f32,
) -> RbfModel {
    let mut m = RbfModel {
        n_rbf_inputs: n_inputs as u8,
        bias_dph: bias,
        meta: TrainingMeta {
            gyro_id: heapless::String::new(),
            heldout_rms_dph: 0.0,
            n_train: 0,
        },
        ..RbfModel::empty()
    };
    for j in 0..n_inputs {
        m.inputs
            .push(FeatureSpec::plain(FeatureKind::AuxValue(j as u8)))
            .unwrap();
        m.input_offset.push(offset * (j + 1) as f32).unwrap();
        m.input_scale.push(scale).unwrap();
        m.input_min
            .push(offset * (j + 1) as f32 - 3.0 * scale)
            .unwrap();
        m.input_max
            .push(offset * (j + 1) as f32 + 3.0 * scale)
            .unwrap();
        m.linear.push(linear).unwrap();
    }
    for &(c, s, w) in centers {
        m.centers.push(c).unwrap();
        m.widths.push(s).unwrap();
        m.weights.push(w).unwrap();
    }
    m.validate().unwrap();
    m
}

/// Error scale of one evaluation: every term's magnitude, so the tolerance is relative
/// to what is summed (cancellation cannot hide in it).
fn magnitude(m: &RbfModel, x: &[f64]) -> f64 {
    let n = m.inputs.len();
    let xn: Vec<f64> = (0..n)
        .map(|j| (x[j] - m.input_offset[j] as f64) / m.input_scale[j] as f64)
        .collect();
    let mut s = (m.bias_dph as f64).abs();
    for (&l, &x) in m.linear.iter().zip(xn.iter()) {
        s += (l as f64 * x).abs();
    }
    for (c, (&w, &sig)) in m.centers.iter().zip(m.weights.iter().zip(m.widths.iter())) {
        let d2: f64 = (0..m.n_rbf_inputs as usize)
            .map(|j| (xn[j] - c[j] as f64).powi(2))
            .sum();
        let u = d2 / (2.0 * sig as f64 * sig as f64);
        // Gaussian term and the sensitivity of exp(-u) to rounding of u.
        s += (w as f64).abs() * (1.0 + u) * (-u).exp().max(1e-3);
    }
    s
}

fn centers_strategy() -> impl Strategy<Value = Vec<([f32; 4], f32, f32)>> {
    prop::collection::vec(
        (
            prop::array::uniform4(-2.0f32..2.0),
            0.05f32..3.0,
            -20.0f32..20.0,
        ),
        0..=64,
    )
}

/// One random case: a model (trailing inputs possibly linear-only), a raw f32 input point
/// and its f64 copy, and the f32 rounding tolerance for that point.
#[derive(Debug)]
struct Case {
    model: RbfModel,
    x32: Vec<f32>,
    x64: Vec<f64>,
    tol: f64,
}

fn case_strategy() -> impl Strategy<Value = Case> {
    (
        1usize..=4,
        0usize..=3,
        centers_strategy(),
        (-50.0f32..50.0, 0.001f32..100.0, -1.0f32..1.0, -1.0f32..1.0),
        prop::array::uniform4(-3.0f64..3.0),
    )
        .prop_map(
            |(n_inputs, linear_only, centers, (offset, scale, bias, linear), xn)| {
                let mut m = model_from(n_inputs, &centers, offset, scale, bias, linear);
                // Trailing inputs may be linear-only terms (diagnose adds causes that way).
                m.n_rbf_inputs = (n_inputs - linear_only.min(n_inputs - 1)) as u8;
                // Raw inputs as f32 (what the device has), evaluated by every path.
                let x32: Vec<f32> = (0..n_inputs)
                    .map(|j| (m.input_offset[j] as f64 + xn[j] * m.input_scale[j] as f64) as f32)
                    .collect();
                let x64: Vec<f64> = x32.iter().map(|&v| v as f64).collect();
                // f32 rounding: ~1e-7 relative per operation; normalisation of an input that is
                // large against its scale adds |x| ulp / scale.
                let cond: f64 = (0..n_inputs)
                    .map(|j| {
                        1.0 + (x64[j].abs() + (m.input_offset[j] as f64).abs())
                            / m.input_scale[j] as f64
                    })
                    .fold(1.0, f64::max);
                let tol = 2e-6 * magnitude(&m, &x64) * cond;
                Case {
                    model: m,
                    x32,
                    x64,
                    tol,
                }
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn f32_matches_f64_reference(c in case_strategy()) {
        let f = predict_f32(&c.model, &c.x32).unwrap() as f64;
        let r = predict_f64(&c.model, &c.x64).unwrap();
        prop_assert!((f - r).abs() <= c.tol, "f32 {f} f64 {r} tol {}", c.tol);
    }

    #[test]
    fn fixed_matches_f32(c in case_strategy()) {
        let fx = FixedModel::from_model(&c.model).unwrap();
        let q = fx.predict(&c.x32).unwrap() as f64;
        let f = predict_f32(&c.model, &c.x32).unwrap() as f64;
        let r = predict_f64(&c.model, &c.x64).unwrap();
        prop_assert!((q - f).abs() <= 2.0 * c.tol, "fixed {q} f32 {f} tol {}", c.tol);
        prop_assert!((q - r).abs() <= c.tol, "fixed {q} f64 {r} tol {}", c.tol);
    }

    #[test]
    fn fixed_boundary_conversions_are_exact(v in -1.0e6f64..1.0e6, frac in 0i32..40) {
        let x = v as f32;
        let q = f32_to_fixed(x, frac).unwrap();
        // Truncation toward zero to `frac` bits.
        let expect = ((x as f64) * 2f64.powi(frac)).trunc();
        if expect.abs() < 2f64.powi(41) {
            prop_assert_eq!(q as f64, expect);
        }
        let back = fixed_to_f32(q, frac as u32);
        prop_assert_eq!(back, (q as f64 / 2f64.powi(frac)) as f32);
    }
}

#[test]
fn exp_kernel_is_within_3e_9_of_exp() {
    let mut worst = 0.0f64;
    for k in 0..2_000_000u64 {
        let u_q28 = k * (23u64 << 28) / 2_000_000;
        let e = exp_neg_q30(u_q28) as f64 / (1u64 << 30) as f64;
        let r = (-(u_q28 as f64) / (1u64 << 28) as f64).exp();
        worst = worst.max((e - r).abs());
    }
    println!("exp_neg_q30 worst abs error {worst:.3e}");
    // Q.30 resolution is 9.3e-10; table, polynomial and truncations add a few LSB.
    assert!(worst < 3e-9, "{worst:e}");
    assert_eq!(exp_neg_q30(0), 1 << 30);
    assert_eq!(exp_neg_q30(23 << 28), 0);
}

/// Worst errors over the trained input box (grid + random points, `fog_core::model::accuracy`)
/// and along the warm-up trajectories the synthetic model was built from.
fn worst_errors(m: &RbfModel) -> (f64, f64) {
    let rep = worst_errors_in_box(m, 90_000, 50_000, 1234).unwrap();
    let fx = FixedModel::from_model(m).unwrap();
    let n = m.inputs.len();
    let (mut fixed, mut f32_err) = (rep.worst_fixed_dph, rep.worst_f32_dph);
    let mut rng = SplitMix64::new(1234);
    for _ in 0..50_000 {
        let x = random_warmup_point(&mut rng);
        let x32: Vec<f32> = x[..n].iter().map(|&v| v as f32).collect();
        let x64: Vec<f64> = x32.iter().map(|&v| v as f64).collect();
        let r = predict_f64(m, &x64).unwrap();
        fixed = fixed.max((fx.predict(&x32).unwrap() as f64 - r).abs());
        f32_err = f32_err.max((predict_f32(m, &x32).unwrap() as f64 - r).abs());
    }
    (fixed, f32_err)
}

#[test]
fn fixed_worst_error_35_centres_meets_1e_3_dph() {
    // Weights of +-500 deg/h mimic OLS models with wide, strongly overlapping Gaussians
    // (a model trained by `fogsim train` on a simulated campaign had |w| up to 464 deg/h).
    for (inputs, weight) in [(2, 2.0f32), (2, 50.0), (2, 500.0), (4, 2.0)] {
        let m = warmup_model(35, inputs, weight, 2013);
        let (fixed, f32_err) = worst_errors(&m);
        println!(
            "35 centres, {inputs} inputs, weights +-{weight} deg/h: worst |fixed - f64| = {fixed:.3e} deg/h, |f32 - f64| = {f32_err:.3e} deg/h"
        );
        assert!(fixed <= 1e-3, "{fixed:e}");
    }
}

#[test]
fn fixed_worst_error_64_centres_meets_1e_3_dph() {
    let m = warmup_model(64, 4, 2.0, 64);
    let (fixed, f32_err) = worst_errors(&m);
    println!(
        "64 centres, 4 inputs, weights +-2 deg/h: worst |fixed - f64| = {fixed:.3e} deg/h, |f32 - f64| = {f32_err:.3e} deg/h"
    );
    assert!(fixed <= 1e-3, "{fixed:e}");
}

#[test]
fn bad_inputs_are_errors() {
    let m = warmup_model(35, 2, 2.0, 1);
    let fx = FixedModel::from_model(&m).unwrap();
    assert_eq!(
        predict_f32(&m, &[20.0]),
        Err(RbfError::WrongInputCount {
            expected: 2,
            got: 1
        })
    );
    assert_eq!(
        predict_f32(&m, &[20.0, f32::NAN]),
        Err(RbfError::NonFiniteInput { index: 1 })
    );
    assert_eq!(
        fx.predict(&[f32::INFINITY, 0.0]),
        Err(RbfError::NonFiniteInput { index: 0 })
    );
    assert_eq!(
        fx.predict(&[1.0, 2.0, 3.0]),
        Err(RbfError::WrongInputCount {
            expected: 2,
            got: 3
        })
    );
    // Far outside the range: saturates, stays finite, no panic.
    let v = fx.predict(&[1e30, -1e30]).unwrap();
    assert!(v.is_finite());
}

#[test]
fn q16_output_agrees_with_f32_output() {
    let m = warmup_model(35, 2, 2.0, 9);
    let fx = FixedModel::from_model(&m).unwrap();
    let mut rng = SplitMix64::new(5);
    for _ in 0..1000 {
        let x = random_warmup_point(&mut rng);
        let x32 = [x[0] as f32, x[1] as f32];
        let a = fx.predict(&x32).unwrap() as f64;
        let b = fx.predict_q16(&x32).unwrap() as f64 / 65536.0;
        assert!((a - b).abs() <= 1.0 / 65536.0, "{a} {b}");
    }
}

/// The f32 path's exponential: relative error <= 1e-6 over the whole range a Gaussian
/// uses (u = d^2/(2 s^2) in [0, 87]; beyond it the result is 0, as f32 underflows).
#[test]
fn exp_neg_f32_relative_error() {
    use fog_core::model::rbf::exp_neg_f32;
    let mut worst = 0.0f64;
    for i in 0..=870_000 {
        let u = i as f32 * 1e-4;
        let want = (-f64::from(u)).exp();
        worst = worst.max((f64::from(exp_neg_f32(u)) - want).abs() / want);
    }
    println!("exp_neg_f32 worst relative error over [0, 87]: {worst:.3e}");
    assert!(worst <= 1e-6, "{worst:e}");
    assert_eq!(exp_neg_f32(0.0), 1.0);
    assert_eq!(exp_neg_f32(88.0), 0.0);
    assert_eq!(exp_neg_f32(f32::INFINITY), 0.0);
}

/// A model with a cubic polynomial base: f32 and fixed point against the f64 reference,
/// inside and outside the polynomial's (trained) domain.
#[test]
fn polynomial_base_agrees_across_paths() {
    let mut m = warmup_model(35, 2, 1.0, 9);
    m.poly.extend_from_slice(&[0.4, -0.08, 0.03]).unwrap();
    m.validate().unwrap();
    let fm = FixedModel::from_model(&m).unwrap();
    let mut worst_fixed = 0.0f64;
    for k in 0..=200 {
        let t = m.input_min[0] - 10.0 + k as f32 * (m.input_max[0] - m.input_min[0] + 20.0) / 200.0;
        let x = [t, 0.5 * (m.input_min[1] + m.input_max[1])];
        let want = predict_f64(&m, &[f64::from(x[0]), f64::from(x[1])]).unwrap();
        let f = f64::from(predict_f32(&m, &x).unwrap());
        let q = f64::from(fm.predict(&x).unwrap());
        assert!((f - want).abs() < 1e-4, "f32 {f} vs {want} at T={t}");
        worst_fixed = worst_fixed.max((q - want).abs());
    }
    assert!(worst_fixed < 1e-3, "fixed worst {worst_fixed}");
    // Held at the domain's edge, not extrapolated.
    let below = predict_f32(&m, &[m.input_min[0] - 50.0, 0.0]).unwrap();
    let edge = predict_f32(&m, &[m.input_min[0], 0.0]).unwrap();
    let rbf_only = {
        let mut r = m.clone();
        r.poly.clear();
        predict_f32(&r, &[m.input_min[0] - 50.0, 0.0]).unwrap()
            - predict_f32(&r, &[m.input_min[0], 0.0]).unwrap()
    };
    assert!((below - edge - rbf_only).abs() < 1e-4);
}

/// Temperature-coupled linear terms (coefficient of input 1 changing with t): f32 and
/// fixed point against the f64 reference, inside and outside input 0's trained range,
/// and against the term written out by hand (t held to the range, not extrapolated).
#[test]
fn temperature_coupled_linear_terms_agree_across_paths() {
    let mut m = warmup_model(35, 2, 1.0, 9);
    m.linear[1] = 0.7;
    m.linear_by_t.extend_from_slice(&[0.0, -0.25]).unwrap();
    m.validate().unwrap();
    let fm = FixedModel::from_model(&m).unwrap();
    let mut worst_fixed = 0.0f64;
    for k in 0..=200 {
        let t = m.input_min[0] - 10.0 + k as f32 * (m.input_max[0] - m.input_min[0] + 20.0) / 200.0;
        for r in [
            m.input_min[1],
            0.5 * (m.input_min[1] + m.input_max[1]),
            m.input_max[1],
        ] {
            let x = [t, r];
            let want = predict_f64(&m, &[f64::from(x[0]), f64::from(x[1])]).unwrap();
            let f = f64::from(predict_f32(&m, &x).unwrap());
            let q = f64::from(fm.predict(&x).unwrap());
            assert!(
                (f - want).abs() < 1e-4,
                "f32 {f} vs {want} at T={t}, rate={r}"
            );
            worst_fixed = worst_fixed.max((q - want).abs());
        }
    }
    assert!(worst_fixed < 1e-3, "fixed worst {worst_fixed}");
    // The term by hand: with and without it, at a row inside and one below the range.
    let without = {
        let mut r = m.clone();
        r.linear_by_t.clear();
        r
    };
    let norm = |j: usize, v: f32| f64::from((v - m.input_offset[j]) / m.input_scale[j]);
    let (lo, _) = m.poly_domain();
    for (t_raw, t_held) in [
        (0.5 * (m.input_min[0] + m.input_max[0]), None),
        (m.input_min[0] - 30.0, Some(f64::from(lo))),
    ] {
        let x = [t_raw, m.input_max[1]];
        let t = t_held.unwrap_or_else(|| norm(0, t_raw));
        let term = -0.25 * t * norm(1, x[1]);
        let xf = [f64::from(x[0]), f64::from(x[1])];
        let got = predict_f64(&m, &xf).unwrap() - predict_f64(&without, &xf).unwrap();
        assert!(
            (got - term).abs() < 1e-6,
            "term {got} vs {term} at T={t_raw}"
        );
    }
}
