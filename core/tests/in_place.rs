//! In-place construction (the firmware keeps the ~8 KB compensator and the model in
//! statics): `Compensator::unconfigured` + `configure` behaves exactly like `new`, a
//! refused `set_model_from` leaves the old model and its history untouched, and
//! `RbfModel::decode_into` replaces whatever the storage held before.

use fog_core::compensation::compensator::{
    Compensator, CompensatorConfig, CompensatorError, Evaluator,
};
use fog_core::hal::{GyroSample, TempSample};
use fog_core::model::fixed::FixedError;
use fog_core::model::format::RbfModel;
use fog_core::model::synthetic::{warmup_inputs, warmup_model};

const GYRO_HZ: f64 = 100.0;

fn config(evaluator: Evaluator) -> CompensatorConfig {
    CompensatorConfig {
        gyro_rate_hz: GYRO_HZ as f32,
        evaluator,
        ..CompensatorConfig::default()
    }
}

/// Feed a 20 degC warm-up from `t0_s` for `seconds` (gyro 100 Hz, temperature 1 Hz);
/// every window result, as `Debug` text (floats print as their shortest round-trip
/// form, so equal text is equal bits, NaN temperatures included).
fn feed(comp: &mut Compensator, t0_s: f64, seconds: f64) -> Vec<String> {
    let mut out = Vec::new();
    let n = (seconds * GYRO_HZ) as u64;
    let k0 = (t0_s * GYRO_HZ) as u64;
    for k in k0 + 1..=k0 + n {
        let t = k as f64 / GYRO_HZ;
        let x = warmup_inputs(20.0, t);
        if k % GYRO_HZ as u64 == 0 {
            comp.push_temp(TempSample {
                t_s: t,
                temp_c: x[0] as f32,
            });
        }
        let rate = 5.0 + 0.3 * x[1] as f32 + 1e-3 * (k % 7) as f32;
        if let Some(w) = comp.push_gyro(GyroSample {
            t_s: t,
            rate_dph: rate,
        }) {
            out.push(format!("{w:?}"));
        }
    }
    out
}

fn applied(results: &[String]) -> usize {
    results
        .iter()
        .filter(|r| r.contains("model_applied: true"))
        .count()
}

#[test]
fn configure_in_place_equals_new() {
    let model = warmup_model(35, 2, 1.5, 7);
    let other = warmup_model(20, 2, 0.5, 8);
    for evaluator in [Evaluator::F32, Evaluator::Fixed] {
        let mut fresh = Compensator::new(config(evaluator), Some(model.clone())).expect("new");
        let expected = feed(&mut fresh, 0.0, 300.0);
        assert!(applied(&expected) > 20, "{evaluator:?}: model not applied");

        let mut in_place = Compensator::unconfigured();
        in_place
            .configure(config(evaluator), Some(&model))
            .expect("configure");
        assert_eq!(feed(&mut in_place, 0.0, 300.0), expected, "{evaluator:?}");

        // Reconfiguring storage that was in use (other model, history, pending means)
        // gives a compensator indistinguishable from a new one.
        let mut reused = Compensator::new(config(evaluator), Some(other.clone())).expect("new");
        feed(&mut reused, 0.0, 95.5);
        reused
            .configure(config(evaluator), Some(&model))
            .expect("reconfigure");
        assert_eq!(reused.model(), Some(&model));
        assert_eq!(
            feed(&mut reused, 0.0, 300.0),
            expected,
            "{evaluator:?} reused"
        );
    }
}

#[test]
fn unconfigured_ignores_everything_until_configured() {
    let mut c = Compensator::unconfigured();
    assert!(feed(&mut c, 0.0, 30.0).is_empty());
    assert_eq!(c.poll(1e3), None);
    assert_eq!(c.model(), None);
    // A rejected configuration leaves it unconfigured (still ignoring samples).
    let bad = CompensatorConfig {
        min_fill: 0.0,
        ..config(Evaluator::F32)
    };
    assert_eq!(c.configure(bad, None), Err(CompensatorError::BadConfig));
    assert!(feed(&mut c, 30.0, 30.0).is_empty());
    c.configure(config(Evaluator::F32), None)
        .expect("configure");
    let results = feed(&mut c, 60.0, 30.0);
    let mut fresh = Compensator::new(config(Evaluator::F32), None).expect("new");
    assert!(results.len() >= 2);
    assert_eq!(results, feed(&mut fresh, 60.0, 30.0));
    assert_eq!(applied(&results), 0);
}

#[test]
fn refused_model_keeps_old_model_and_history() {
    let good = warmup_model(35, 2, 1.5, 7);
    // Valid for the f32 evaluator but too narrow for fixed point (gain >= 127).
    let mut narrow = good.clone();
    narrow.widths[3] = 1e-3;
    assert!(narrow.validate().is_ok());
    let mut reference = Compensator::new(config(Evaluator::Fixed), Some(good.clone())).unwrap();
    let mut refused = Compensator::new(config(Evaluator::Fixed), Some(good.clone())).unwrap();
    let head = feed(&mut reference, 0.0, 120.0);
    assert_eq!(feed(&mut refused, 0.0, 120.0), head);
    assert_eq!(
        refused.set_model_from(Some(&narrow)),
        Err(CompensatorError::Fixed(FixedError::WidthTooSmall {
            center: 3
        }))
    );
    let mut invalid = good.clone();
    invalid.widths[0] = -1.0;
    assert!(matches!(
        refused.set_model_from(Some(&invalid)),
        Err(CompensatorError::Model(_))
    ));
    assert_eq!(refused.model(), Some(&good));
    // Same fixed-point model, same feature history: bit-identical continuation.
    let tail = feed(&mut reference, 120.0, 180.0);
    assert!(applied(&tail) > 10);
    assert_eq!(feed(&mut refused, 120.0, 180.0), tail);
}

#[test]
fn decode_into_replaces_stale_storage() {
    let small = warmup_model(5, 1, 0.5, 1);
    let big = warmup_model(64, 4, 2.0, 2);
    let mut buf = [0u8; 4096];
    for (stored, stale) in [(&small, &big), (&big, &small)] {
        let n = stored.encode(&mut buf).expect("encode");
        let mut target = RbfModel::empty();
        target.copy_from(stale);
        target.decode_into(&buf[..n]).expect("decode_into");
        assert_eq!(&target, stored);
        assert_eq!(RbfModel::decode(&buf[..n]).expect("decode"), target);
    }
    // A corrupted file is still an error (CRC), as with `decode`.
    let n = small.encode(&mut buf).expect("encode");
    buf[n / 2] ^= 0x40;
    let mut target = RbfModel::empty();
    assert_eq!(
        target.decode_into(&buf[..n]).err(),
        RbfModel::decode(&buf[..n]).err()
    );
    assert!(target.decode_into(&buf[..n]).is_err());
}
