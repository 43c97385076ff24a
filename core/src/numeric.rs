//! Small exact float helpers for the device paths, so the firmware does not link libm's
//! f64 `floor` (and its helpers) just to index windows and wrap angles, nor libm's
//! radian argument reduction (2.5 KB of `rem_pio2f`) for sines of angles given in degrees.

/// `floor(x)` as an integer, saturating at the `i64` range (NaN gives 0), i.e. exactly
/// `libm::floor(x) as i64`, from one truncating conversion and one compare.
pub fn floor_i64(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) > x {
        t.saturating_sub(1)
    } else {
        t
    }
}

/// Angle in degrees wrapped to [0, 360): `deg - 360 floor(deg / 360)`, with a result that
/// rounds up to 360 mapped to 0. Same values as with `libm::floor` for |deg| < 3e21 (the
/// `i64` range times 360; headings are far smaller); NaN stays NaN.
pub fn wrap_360_deg(deg: f64) -> f64 {
    let r = deg - 360.0 * floor_i64(deg / 360.0) as f64;
    if r >= 360.0 {
        0.0
    } else {
        r
    }
}

/// (sin, cos) of an angle in degrees, to about 2 f64 ulps for any |deg| < 3e21.
///
/// The angle is reduced exactly in degrees (to the nearest multiple of 90 deg, remainder in
/// [-45, 45]) before the conversion to radians, so there is no pi/2 argument reduction to
/// get wrong; the kernels are the Taylor series to x^15 (sin) and x^16 (cos), whose
/// truncation error at |x| = pi/4 is < 5e-17.
pub fn sin_cos_deg(deg: f64) -> (f64, f64) {
    let r = wrap_360_deg(deg);
    let q = floor_i64(r / 90.0 + 0.5);
    let x = (r - 90.0 * q as f64).to_radians();
    let x2 = x * x;
    // 1/k! for the odd (sin) and even (cos) terms, highest first.
    const SIN_C: [f64; 7] = [
        1.0 / 1_307_674_368_000.0,
        -1.0 / 6_227_020_800.0,
        1.0 / 39_916_800.0,
        -1.0 / 362_880.0,
        1.0 / 5_040.0,
        -1.0 / 120.0,
        1.0 / 6.0,
    ];
    const COS_C: [f64; 8] = [
        1.0 / 20_922_789_888_000.0,
        -1.0 / 87_178_291_200.0,
        1.0 / 479_001_600.0,
        -1.0 / 3_628_800.0,
        1.0 / 40_320.0,
        -1.0 / 720.0,
        1.0 / 24.0,
        -0.5,
    ];
    let s = SIN_C.iter().fold(0.0, |acc, &c| acc * x2 + c);
    // The last sin coefficient is +1/6 for a -x^3/6 term: sin = x - x^3 (1/6 - x^2/120 ...).
    let sin_x = x - x * x2 * s;
    let cos_x = 1.0 + x2 * COS_C.iter().fold(0.0, |acc, &c| acc * x2 + c);
    match q & 3 {
        0 => (sin_x, cos_x),
        1 => (cos_x, -sin_x),
        2 => (-sin_x, -cos_x),
        _ => (-cos_x, sin_x),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floor_i64_matches_libm_floor() {
        let cases = [
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            2.999_999_999,
            -2.999_999_999,
            1e15 + 0.5,
            -1e15 - 0.5,
            9.3e18,
            -9.3e18,
            1e300,
            -1e300,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
        ];
        for x in cases {
            assert_eq!(floor_i64(x), libm::floor(x) as i64, "x = {x}");
        }
    }

    #[test]
    fn wrap_360_deg_wraps_into_range() {
        for (x, want) in [
            (0.0, 0.0),
            (360.0, 0.0),
            (-90.0, 270.0),
            (725.0, 5.0),
            (-1e-20, 0.0),
            (359.5, 359.5),
            (-720.25, 359.75),
        ] {
            assert_eq!(wrap_360_deg(x), want, "x = {x}");
        }
        assert!(wrap_360_deg(f64::NAN).is_nan());
    }

    #[test]
    fn sin_cos_deg_matches_libm() {
        let mut worst = 0.0f64;
        for i in -20_000..=20_000 {
            let deg = i as f64 * 0.0371 + 0.3;
            let (s, c) = sin_cos_deg(deg);
            let x = deg.to_radians();
            worst = worst
                .max((s - libm::sin(x)).abs())
                .max((c - libm::cos(x)).abs());
        }
        // libm's own conversion to radians rounds (|x| up to 13 rad): allow a few ulps.
        assert!(worst < 2e-15, "worst difference {worst:e}");
        for (deg, s, c) in [
            (0.0, 0.0, 1.0),
            (90.0, 1.0, 0.0),
            (180.0, 0.0, -1.0),
            (270.0, -1.0, 0.0),
            (-90.0, -1.0, 0.0),
            (720.0, 0.0, 1.0),
        ] {
            assert_eq!(sin_cos_deg(deg), (s, c), "deg = {deg}");
        }
        let (s, c) = sin_cos_deg(30.0);
        assert!((s - 0.5).abs() < 2e-16 && (c - 0.75f64.sqrt()).abs() < 2e-16);
        assert!(sin_cos_deg(f64::NAN).0.is_nan());
    }
}
