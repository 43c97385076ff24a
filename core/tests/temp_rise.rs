//! The temperature rise since power-on (`FeatureKind::TempRiseC`): the row's temperature
//! minus the first row's, ready from the first row, whatever the row spacing, and cleared
//! with the extractor's history (a new power-on starts from its own first reading).

use fog_core::compensation::features::{features_for_series, FeatureExtractor, FeatureVector};
use fog_core::model::format::{FeatureKind, FeatureSpec, MAX_INPUTS};

fn rise_of(t_s: &[f64], temp_c: &[f32]) -> Vec<(bool, f32)> {
    let specs = [
        FeatureSpec::plain(FeatureKind::TempC),
        FeatureSpec::plain(FeatureKind::TempRiseC),
    ];
    let mut out = vec![
        FeatureVector {
            values: [0.0; MAX_INPUTS],
            len: 0,
            ready: false,
        };
        t_s.len()
    ];
    features_for_series(&specs, t_s, temp_c, &[], &mut out).unwrap();
    out.iter().map(|v| (v.ready, v.values[1])).collect()
}

#[test]
fn the_rise_is_the_temperature_minus_the_first_reading_from_the_first_row() {
    let temps = [-39.625f32, -39.5, -38.25, -30.0, -41.0];
    let rows = rise_of(&[10.0, 20.0, 35.0, 400.0, 401.0], &temps);
    for (k, &(ready, rise)) in rows.iter().enumerate() {
        assert!(ready, "row {k} ready");
        let want = (temps[k] as f64 - temps[0] as f64) as f32;
        assert_eq!(rise, want, "row {k}");
    }
    // A different start temperature shifts every later rise by the same amount.
    let warm: Vec<f32> = temps.iter().map(|t| t + 60.0).collect();
    let rows_warm = rise_of(&[10.0, 20.0, 35.0, 400.0, 401.0], &warm);
    for (a, b) in rows.iter().zip(&rows_warm) {
        assert!((a.1 - b.1).abs() < 1e-4, "{a:?} vs {b:?}");
    }
}

#[test]
fn a_new_power_on_starts_from_its_own_first_reading() {
    let specs = [FeatureSpec::plain(FeatureKind::TempRiseC)];
    let mut fx = FeatureExtractor::new(&specs).unwrap();
    fx.push(10.0, 20.0, &[]).unwrap();
    assert_eq!(fx.push(20.0, 23.0, &[]).unwrap().values[0], 3.0);
    // A rejected row changes nothing.
    assert!(fx.push(20.0, 99.0, &[]).is_err());
    assert_eq!(fx.push(30.0, 24.0, &[]).unwrap().values[0], 4.0);
    fx.reset_to(&specs).unwrap();
    assert_eq!(fx.push(10.0, -40.0, &[]).unwrap().values[0], 0.0);
    assert_eq!(fx.push(20.0, -39.0, &[]).unwrap().values[0], 1.0);
}
