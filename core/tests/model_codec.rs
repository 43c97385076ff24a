//! Model format: round trip, size budget, and rejection of every kind of corrupted model
//! with the matching typed error.

use fog_core::model::cold_start::{ColdStartEnvelope, MAX_COLD_START_POINTS};
use fog_core::model::crc::crc32;
use fog_core::model::error::{ModelError, ModelField};
use fog_core::model::format::{
    FeatureKind, FeatureSpec, RbfModel, MAX_CENTERS, MAX_ENCODED_LEN, MODEL_MAGIC, MODEL_VERSION,
    MODEL_VERSION_BASE,
};
use fog_core::model::heading::HeadingHarmonic;
use fog_core::model::synthetic::warmup_model;
use serde::Serialize;

fn encode(m: &RbfModel) -> Vec<u8> {
    let mut buf = [0u8; 4096];
    let n = m.encode(&mut buf).expect("encode");
    buf[..n].to_vec()
}

/// Same layout as `RbfModel::encode`, but without validation: lets the tests build
/// encodings of invalid models (std `Vec`s allow more than 64 centres).
#[derive(Serialize)]
struct LooseModel {
    n_rbf_inputs: u8,
    inputs: Vec<fog_core::model::format::FeatureSpec>,
    input_offset: Vec<f32>,
    input_scale: Vec<f32>,
    input_min: Vec<f32>,
    input_max: Vec<f32>,
    linear: Vec<f32>,
    centers: Vec<[f32; 4]>,
    widths: Vec<f32>,
    weights: Vec<f32>,
    bias_dph: f32,
    meta: fog_core::model::format::TrainingMeta,
    poly: Vec<f32>,
    heading: Option<HeadingHarmonic>,
    linear_by_t: Vec<f32>,
    cold_start: Option<ColdStartEnvelope>,
}

impl From<&RbfModel> for LooseModel {
    fn from(m: &RbfModel) -> Self {
        LooseModel {
            n_rbf_inputs: m.n_rbf_inputs,
            inputs: m.inputs.to_vec(),
            input_offset: m.input_offset.to_vec(),
            input_scale: m.input_scale.to_vec(),
            input_min: m.input_min.to_vec(),
            input_max: m.input_max.to_vec(),
            linear: m.linear.to_vec(),
            centers: m.centers.to_vec(),
            widths: m.widths.to_vec(),
            weights: m.weights.to_vec(),
            bias_dph: m.bias_dph,
            meta: m.meta.clone(),
            poly: m.poly.to_vec(),
            heading: m.heading,
            linear_by_t: m.linear_by_t.to_vec(),
            cold_start: m.cold_start.clone(),
        }
    }
}

#[derive(Serialize)]
struct Wire<'a> {
    magic: u32,
    version: u16,
    body: &'a [u8],
    crc32: u32,
}

fn encode_loose(m: &LooseModel, version: u16) -> Vec<u8> {
    let body = postcard::to_allocvec(&(m.inputs.len() as u16, m.centers.len() as u16, m)).unwrap();
    postcard::to_allocvec(&Wire {
        magic: MODEL_MAGIC,
        version,
        body: &body,
        crc32: crc32(&body),
    })
    .unwrap()
}

#[test]
fn round_trip_is_exact() {
    for (centers, inputs) in [(1, 1), (35, 2), (64, 4), (0, 2)] {
        let m = warmup_model(centers, inputs, 2.0, 7);
        let bytes = encode(&m);
        assert_eq!(RbfModel::decode(&bytes).unwrap(), m);
    }
}

#[test]
fn layout_is_postcard_of_the_wire_envelope() {
    let m = warmup_model(35, 2, 2.0, 3);
    assert_eq!(
        encode(&m),
        encode_loose(&LooseModel::from(&m), MODEL_VERSION_BASE)
    );
}

#[test]
fn a_diffusion_clock_rate_is_written_as_version_7_and_refused_under_an_older_number() {
    // the paper's inputs with dT/dt read in the diffusion clock: version 7, round trip
    let mut m = warmup_model(35, 2, 2.0, 3);
    assert_eq!(m.inputs[1].kind, FeatureKind::TempRateCps);
    m.inputs[1] = FeatureSpec {
        kind: FeatureKind::TempRateDiffusionCps,
        tau_s: 400.0,
    };
    assert_eq!((m.format_version(), MODEL_VERSION), (7, 7));
    let bytes = encode(&m);
    assert_eq!(bytes[5] as u16, 7, "version byte of {:?}", &bytes[..8]);
    assert_eq!(RbfModel::decode(&bytes), Ok(m.clone()));
    // every other model keeps version 6 and its bytes
    let plain = warmup_model(35, 2, 2.0, 3);
    assert_eq!(plain.format_version(), MODEL_VERSION_BASE);
    assert_eq!(encode(&plain)[5] as u16, 6);
    // the same body under version 6 (no writer makes it): refused, not misread
    assert_eq!(
        RbfModel::decode(&encode_version(&m, 6)),
        Err(ModelError::Malformed)
    );
    // its clock needs a time constant
    m.inputs[1].tau_s = 0.0;
    assert!(RbfModel::decode(&encode_version(&m, 7)).is_err());
}

#[test]
fn full_model_fits_in_2_kib() {
    let mut m = warmup_model(MAX_CENTERS, 4, 2.0, 11);
    m.meta.gyro_id.clear();
    m.meta.gyro_id.push_str("0123456789ABCDEF").unwrap();
    let bytes = encode(&m);
    println!("64 centres x 4 inputs: {} bytes", bytes.len());
    assert!(bytes.len() <= MAX_ENCODED_LEN, "{} bytes", bytes.len());
    assert!(bytes.len() <= 2048);
}

#[test]
fn small_buffer_is_an_error_not_a_panic() {
    let m = warmup_model(35, 2, 2.0, 3);
    let full = encode(&m).len();
    for len in 0..full {
        let mut buf = vec![0u8; len];
        assert!(
            matches!(m.encode(&mut buf), Err(ModelError::BufferTooSmall { .. })),
            "len {len}"
        );
    }
}

#[test]
fn every_truncation_is_rejected_as_truncated() {
    let bytes = encode(&warmup_model(35, 2, 2.0, 5));
    for len in 0..bytes.len() {
        assert_eq!(
            RbfModel::decode(&bytes[..len]),
            Err(ModelError::Truncated),
            "prefix of {len} bytes"
        );
    }
}

#[test]
fn every_flipped_byte_is_rejected() {
    let bytes = encode(&warmup_model(35, 2, 2.0, 5));
    // Envelope: magic varint (5 bytes), version (1), body length varint (2), body, crc varint.
    let body_len = bytes.len() - 8 - 5;
    let body = 8..8 + body_len;
    for i in 0..bytes.len() {
        let mut b = bytes.clone();
        b[i] ^= 0xFF;
        let err = RbfModel::decode(&b).expect_err("flipped byte accepted");
        let ok = match i {
            0..=4 => matches!(err, ModelError::BadMagic { .. } | ModelError::Malformed),
            5 => matches!(
                err,
                ModelError::UnsupportedVersion { .. } | ModelError::Malformed
            ),
            6 | 7 => matches!(
                err,
                ModelError::Truncated
                    | ModelError::CrcMismatch { .. }
                    | ModelError::TrailingBytes { .. }
                    | ModelError::Malformed
                    | ModelError::TooLarge { .. }
            ),
            i if body.contains(&i) => matches!(err, ModelError::CrcMismatch { .. }),
            _ => matches!(
                err,
                ModelError::CrcMismatch { .. }
                    | ModelError::Malformed
                    | ModelError::Truncated
                    | ModelError::TrailingBytes { .. }
            ),
        };
        assert!(ok, "byte {i}: unexpected {err:?}");
    }
}

#[test]
fn wrong_version_and_magic_are_named() {
    let m = LooseModel::from(&warmup_model(35, 2, 2.0, 5));
    assert_eq!(
        RbfModel::decode(&encode_loose(&m, MODEL_VERSION + 1)),
        Err(ModelError::UnsupportedVersion {
            found: MODEL_VERSION + 1
        })
    );
    let mut bytes = encode_loose(&m, MODEL_VERSION);
    bytes[0] = 0x01; // still a valid varint, different value
    assert!(matches!(
        RbfModel::decode(&bytes),
        Err(ModelError::BadMagic { .. })
    ));
    let mut long = encode_loose(&m, MODEL_VERSION);
    long.push(0);
    assert_eq!(
        RbfModel::decode(&long),
        Err(ModelError::TrailingBytes { count: 1 })
    );
}

#[test]
fn invalid_contents_get_their_typed_error() {
    let good = warmup_model(35, 2, 2.0, 5);
    type Corruption = Box<dyn Fn(&mut LooseModel)>;
    let cases: Vec<(Corruption, ModelError)> = vec![
        (
            Box::new(|m| m.weights[3] = f32::NAN),
            ModelError::NonFinite {
                field: ModelField::Weights,
                index: 3,
            },
        ),
        (
            Box::new(|m| m.widths[7] = 0.0),
            ModelError::NonPositiveWidth { center: 7 },
        ),
        (
            Box::new(|m| m.widths[2] = -1.0),
            ModelError::NonPositiveWidth { center: 2 },
        ),
        (
            Box::new(|m| {
                while m.centers.len() < 65 {
                    m.centers.push([0.1; 4]);
                    m.widths.push(0.3);
                    m.weights.push(0.1);
                }
            }),
            ModelError::TooManyCenters { count: 65 },
        ),
        (
            Box::new(|m| m.centers[4][1] = f32::INFINITY),
            ModelError::NonFinite {
                field: ModelField::Centers,
                index: 4,
            },
        ),
        (
            Box::new(|m| m.input_scale[1] = 0.0),
            ModelError::NonPositiveScale { input: 1 },
        ),
        (
            Box::new(|m| {
                m.input_min[0] = 50.0;
                m.input_max[0] = 10.0;
            }),
            ModelError::BadRange { input: 0 },
        ),
        (
            Box::new(|m| {
                m.weights.pop();
            }),
            ModelError::LengthMismatch {
                field: ModelField::Weights,
                expected: 35,
                found: 34,
            },
        ),
        (
            Box::new(|m| m.bias_dph = f32::NAN),
            ModelError::NonFinite {
                field: ModelField::Bias,
                index: 0,
            },
        ),
        (
            Box::new(|m| m.n_rbf_inputs = 3),
            ModelError::BadRbfInputCount {
                n_rbf_inputs: 3,
                n_inputs: 2,
            },
        ),
        (
            Box::new(|m| {
                m.inputs[1].kind = FeatureKind::TempLagC;
                m.inputs[1].tau_s = 0.0;
            }),
            ModelError::BadTimeConstant { input: 1 },
        ),
        (
            Box::new(|m| m.inputs[1].kind = FeatureKind::AuxValue(9)),
            ModelError::BadAuxChannel {
                input: 1,
                channel: 9,
            },
        ),
        (
            Box::new(|m| {
                m.inputs.clear();
                m.input_offset.clear();
                m.input_scale.clear();
                m.input_min.clear();
                m.input_max.clear();
                m.linear.clear();
                m.n_rbf_inputs = 0;
                m.centers.clear();
                m.widths.clear();
                m.weights.clear();
            }),
            ModelError::NoInputs,
        ),
    ];
    for (i, (corrupt, expected)) in cases.iter().enumerate() {
        let mut m = LooseModel::from(&good);
        corrupt(&mut m);
        let got = RbfModel::decode(&encode_loose(&m, MODEL_VERSION));
        assert_eq!(got, Err(*expected), "case {i}");
        // Display names the problem.
        assert!(!format!("{expected}").is_empty());
    }
}

#[test]
fn encode_refuses_invalid_models() {
    let mut m = warmup_model(35, 2, 2.0, 5);
    m.widths[0] = 0.0;
    let mut buf = [0u8; 4096];
    assert_eq!(
        m.encode(&mut buf),
        Err(ModelError::NonPositiveWidth { center: 0 })
    );
}

#[test]
fn random_bytes_never_panic() {
    let mut rng = fog_core::model::synthetic::SplitMix64::new(99);
    let good = encode(&warmup_model(35, 2, 2.0, 5));
    for _ in 0..20_000 {
        let len = (rng.next_u64() % 2100) as usize;
        let mut b: Vec<u8> = (0..len).map(|_| rng.next_u64() as u8).collect();
        if rng.unit() < 0.5 && len > 8 {
            b[..8].copy_from_slice(&good[..8]); // valid envelope start
        }
        assert!(RbfModel::decode(&b).is_err());
    }
}

/// An older format version's bytes: version 1 ends the body after `meta`, 2 after `poly`,
/// 3 after `heading`, 4 after `linear_by_t`, 5 and 6 after `cold_start` (postcard writes a struct as its fields back to back, so the body is
/// the older fields' bytes in order).
fn encode_version(m: &RbfModel, version: u16) -> Vec<u8> {
    let loose = LooseModel::from(m);
    let mut body = postcard::to_allocvec(&(
        m.inputs.len() as u16,
        m.centers.len() as u16,
        v1_fields(&loose),
    ))
    .unwrap();
    if version >= 2 {
        body.extend(postcard::to_allocvec(&loose.poly).unwrap());
    }
    if version >= 3 {
        body.extend(postcard::to_allocvec(&loose.heading).unwrap());
    }
    if version >= 4 {
        body.extend(postcard::to_allocvec(&loose.linear_by_t).unwrap());
    }
    if version >= 5 {
        body.extend(postcard::to_allocvec(&loose.cold_start).unwrap());
    }
    wrap(&body, version)
}

fn wrap(body: &[u8], version: u16) -> Vec<u8> {
    postcard::to_allocvec(&Wire {
        magic: MODEL_MAGIC,
        version,
        body,
        crc32: crc32(body),
    })
    .unwrap()
}

/// The fields every format version has, in order (postcard tuples and structs are
/// both their fields back to back).
#[allow(clippy::type_complexity)]
fn v1_fields(
    loose: &LooseModel,
) -> (
    u8,
    &Vec<fog_core::model::format::FeatureSpec>,
    &Vec<f32>,
    &Vec<f32>,
    &Vec<f32>,
    &Vec<f32>,
    &Vec<f32>,
    &Vec<[f32; 4]>,
    &Vec<f32>,
    &Vec<f32>,
    f32,
    &fog_core::model::format::TrainingMeta,
) {
    (
        loose.n_rbf_inputs,
        &loose.inputs,
        &loose.input_offset,
        &loose.input_scale,
        &loose.input_min,
        &loose.input_max,
        &loose.linear,
        &loose.centers,
        &loose.widths,
        &loose.weights,
        loose.bias_dph,
        &loose.meta,
    )
}

#[test]
fn version_1_models_still_decode_without_a_polynomial() {
    let mut m = warmup_model(35, 2, 2.0, 5);
    m.poly.clear();
    assert_eq!(RbfModel::decode(&encode_version(&m, 1)), Ok(m.clone()));
    // A version-2 body announced as version 1 has trailing bytes (the poly field).
    let mut with_poly = m.clone();
    with_poly.poly.extend_from_slice(&[0.1, -0.02]).unwrap();
    let v2_body_as_v1 = encode_loose(&LooseModel::from(&with_poly), 1);
    assert!(matches!(
        RbfModel::decode(&v2_body_as_v1),
        Err(ModelError::TrailingBytes { .. })
    ));
}

#[test]
fn polynomial_base_round_trips() {
    let mut m = warmup_model(35, 2, 2.0, 5);
    m.poly.extend_from_slice(&[0.3, -0.05, 0.01]).unwrap();
    assert_eq!(RbfModel::decode(&encode(&m)), Ok(m));
}

/// Issue 11 item 4: a model that decoded before the magnitude bounds and gave a huge or
/// infinite drift is now refused.
#[test]
fn models_that_could_give_huge_or_infinite_drift_are_refused() {
    use fog_core::model::rbf::predict_f32;
    let good = warmup_model(35, 2, 2.0, 5);
    let mut huge_weight = good.clone();
    huge_weight.weights[0] = 3.0e38;
    let mut tiny_scale = good.clone();
    tiny_scale.input_scale[0] = 1.0e-30;
    tiny_scale.linear[0] = 1.0e30;
    let mut wild_poly = good.clone();
    wild_poly
        .poly
        .extend_from_slice(&[0.0, 0.0, 1.0e30])
        .unwrap();
    for (name, m) in [
        ("weight", &huge_weight),
        ("scale", &tiny_scale),
        ("poly", &wild_poly),
    ] {
        // Before: finite parameters, inf/huge output at some input.
        let x = [m.input_max[0], m.input_max[1]];
        let y = predict_f32(m, &x).unwrap();
        assert!(y.is_nan() || y.abs() >= 1.0e6, "{name}: {y}");
        let got = RbfModel::decode(&encode_loose(&LooseModel::from(m), MODEL_VERSION));
        assert!(
            matches!(
                got,
                Err(ModelError::OutOfBounds { .. } | ModelError::OutputUnbounded { .. })
            ),
            "{name}: {got:?}"
        );
    }
}

/// A calibrated magnetic harmonic as `heading_cal::calibrate` returns it (8 headings).
fn harmonic() -> HeadingHarmonic {
    HeadingHarmonic {
        cos_dph: 0.031,
        sin_dph: -0.022,
        cos_sigma_dph: 0.0011,
        sin_sigma_dph: 0.0012,
        correlation: -0.05,
        n_headings: 8,
    }
}

#[test]
fn heading_harmonic_round_trips_and_old_versions_decode_without_it() {
    let mut m = warmup_model(35, 2, 2.0, 5);
    m.poly.extend_from_slice(&[0.1, -0.02]).unwrap();
    let plain = m.clone();
    m.heading = Some(harmonic());
    assert_eq!(RbfModel::decode(&encode(&m)), Ok(m.clone()));
    // Version 2 bytes (no heading field) decode with none.
    assert_eq!(RbfModel::decode(&encode_version(&m, 2)), Ok(plain.clone()));
    // A version-3 body announced as version 2 has trailing bytes (the heading field).
    assert!(matches!(
        RbfModel::decode(&encode_loose(&LooseModel::from(&m), 2)),
        Err(ModelError::TrailingBytes { .. })
    ));
    // The harmonic costs 1 + 5 x 4 + 1 bytes over "none" (1 byte).
    assert_eq!(encode(&m).len(), encode(&plain).len() + 21);
}

#[test]
fn full_model_with_every_field_fits_the_limit() {
    let mut m = warmup_model(MAX_CENTERS, 4, 2.0, 11);
    m.meta.gyro_id.clear();
    m.meta.gyro_id.push_str("0123456789ABCDEF").unwrap();
    m.poly.extend_from_slice(&[0.3, -0.05, 0.01]).unwrap();
    m.heading = Some(HeadingHarmonic {
        n_headings: u16::MAX,
        ..harmonic()
    });
    m.linear_by_t
        .extend_from_slice(&[0.0, 0.02, -0.01, 0.005])
        .unwrap();
    m.cold_start = Some(envelope(MAX_COLD_START_POINTS));
    let bytes = encode(&m);
    println!(
        "64 centres x 4 inputs + poly + heading + linear_by_t + cold_start: {} bytes",
        bytes.len()
    );
    assert!(bytes.len() <= MAX_ENCODED_LEN, "{} bytes", bytes.len());
}

#[test]
fn every_truncation_and_flipped_byte_of_a_heading_model_is_rejected() {
    let mut m = warmup_model(35, 2, 2.0, 5);
    m.heading = Some(harmonic());
    let bytes = encode(&m);
    for len in 0..bytes.len() {
        assert!(RbfModel::decode(&bytes[..len]).is_err(), "{len} bytes");
    }
    // The harmonic (22 bytes) ends the body, just before the CRC varint: flipping any of
    // its bytes is a CRC error.
    let loose = LooseModel::from(&m);
    let body =
        postcard::to_allocvec(&(m.inputs.len() as u16, m.centers.len() as u16, &loose)).unwrap();
    let crc_len = postcard::to_allocvec(&crc32(&body)).unwrap().len();
    let heading_end = bytes.len() - crc_len;
    for i in heading_end - 22..heading_end {
        let mut b = bytes.clone();
        b[i] ^= 0xFF;
        assert!(
            matches!(RbfModel::decode(&b), Err(ModelError::CrcMismatch { .. })),
            "byte {i}"
        );
    }
}

#[test]
fn implausible_heading_harmonics_get_their_typed_error() {
    let good = warmup_model(35, 2, 2.0, 5);
    type Corruption = fn(&mut HeadingHarmonic);
    // (corruption, index of the harmonic field, non-finite rather than out of bounds)
    let cases: [(Corruption, u16, bool); 7] = [
        (|h| h.cos_dph = f32::NAN, 0, true),
        (|h| h.sin_sigma_dph = f32::INFINITY, 3, true),
        (|h| h.sin_dph = -10.5, 1, false),
        (|h| h.cos_dph = 36.0, 0, false),
        (|h| h.cos_sigma_dph = -0.001, 2, false),
        (|h| h.correlation = 1.5, 4, false),
        (|h| h.n_headings = 3, 5, false),
    ];
    for (corrupt, index, non_finite) in cases {
        let field = ModelField::Heading;
        let want = if non_finite {
            ModelError::NonFinite { field, index }
        } else {
            ModelError::OutOfBounds { field, index }
        };
        let mut h = harmonic();
        corrupt(&mut h);
        let mut loose = LooseModel::from(&good);
        loose.heading = Some(h);
        assert_eq!(
            RbfModel::decode(&encode_loose(&loose, MODEL_VERSION)),
            Err(want)
        );
        let mut m = good.clone();
        m.heading = Some(h);
        assert_eq!(
            m.encode(&mut [0u8; 4096]),
            Err(want),
            "encode must refuse too"
        );
    }
    // The bound itself is accepted.
    let mut m = good.clone();
    m.heading = Some(HeadingHarmonic {
        cos_dph: 10.0,
        sin_dph: -10.0,
        ..harmonic()
    });
    assert_eq!(RbfModel::decode(&encode(&m)), Ok(m));
}

#[test]
fn temperature_coupled_linear_terms_round_trip_and_old_versions_decode_without_them() {
    let mut m = warmup_model(35, 2, 2.0, 5);
    m.poly.extend_from_slice(&[0.1, -0.02]).unwrap();
    m.heading = Some(harmonic());
    let plain = m.clone();
    m.linear_by_t.extend_from_slice(&[0.0, -0.031]).unwrap();
    assert_eq!(RbfModel::decode(&encode(&m)), Ok(m.clone()));
    // Version 3 bytes (no linear_by_t field) decode with none.
    assert_eq!(RbfModel::decode(&encode_version(&m, 3)), Ok(plain.clone()));
    // A version-4 body announced as version 3 has trailing bytes (the new field).
    assert!(matches!(
        RbfModel::decode(&encode_loose(&LooseModel::from(&m), 3)),
        Err(ModelError::TrailingBytes { .. })
    ));
    // One length byte and one f32 per input over "none" (the length byte alone).
    assert_eq!(encode(&m).len(), encode(&plain).len() + 2 * 4);
    // Neither empty nor one per input: refused, naming the field.
    let mut short = m.clone();
    short.linear_by_t.truncate(1);
    assert_eq!(
        short.validate(),
        Err(ModelError::LengthMismatch {
            field: ModelField::LinearByT,
            expected: 2,
            found: 1
        })
    );
    let mut nan = m.clone();
    nan.linear_by_t[1] = f32::NAN;
    assert!(matches!(
        RbfModel::decode(&encode_loose(&LooseModel::from(&nan), MODEL_VERSION)),
        Err(ModelError::NonFinite {
            field: ModelField::LinearByT,
            index: 1
        })
    ));
}

/// A cold-start envelope of `n` points (rise growing with time).
fn envelope(n: usize) -> ColdStartEnvelope {
    let mut e = ColdStartEnvelope {
        t_s: heapless::Vec::new(),
        min_rise_c: heapless::Vec::new(),
    };
    for k in 0..n {
        e.t_s.push(30.0 * (1 << k) as f32).unwrap();
        e.min_rise_c.push(0.4 * k as f32).unwrap();
    }
    e
}

#[test]
fn the_cold_start_envelope_round_trips_and_old_versions_decode_without_it() {
    let mut m = warmup_model(35, 2, 2.0, 5);
    m.linear_by_t.extend_from_slice(&[0.0, -0.031]).unwrap();
    let plain = m.clone();
    m.cold_start = Some(envelope(6));
    assert_eq!(RbfModel::decode(&encode(&m)), Ok(m.clone()));
    // Version 4 bytes (no cold_start field) decode with none.
    assert_eq!(RbfModel::decode(&encode_version(&m, 4)), Ok(plain.clone()));
    // A version-5 body announced as version 4 has trailing bytes (the new field).
    assert!(matches!(
        RbfModel::decode(&encode_loose(&LooseModel::from(&m), 4)),
        Err(ModelError::TrailingBytes { .. })
    ));
    // "None" is one byte; 6 points cost the tag, two length bytes and 12 f32.
    assert_eq!(encode(&m).len(), encode(&plain).len() + 2 + 12 * 4);
    // A malformed envelope is refused by the decoder, naming the field.
    let mut bad = m.clone();
    bad.cold_start.as_mut().unwrap().t_s[3] = 10.0;
    assert!(matches!(
        RbfModel::decode(&encode_loose(&LooseModel::from(&bad), MODEL_VERSION)),
        Err(ModelError::NonFinite {
            field: ModelField::ColdStart,
            index: 3
        })
    ));
    let mut short = m.clone();
    short.cold_start.as_mut().unwrap().min_rise_c.truncate(4);
    assert!(matches!(
        short.validate(),
        Err(ModelError::LengthMismatch {
            field: ModelField::ColdStart,
            ..
        })
    ));
}

/// `m` with the warm-up law's two linear-only inputs appended (a clock and its stretch).
fn with_law_clock(mut m: RbfModel) -> RbfModel {
    for kind in [FeatureKind::PowerOnDecay, FeatureKind::PowerOnDecayStretch] {
        m.inputs
            .push(fog_core::model::format::FeatureSpec { kind, tau_s: 300.0 })
            .unwrap();
        m.input_offset.push(0.5).unwrap();
        m.input_scale.push(0.5).unwrap();
        m.input_min.push(0.0).unwrap();
        m.input_max.push(1.0).unwrap();
        m.linear.push(-0.1).unwrap();
    }
    m
}

#[test]
fn six_inputs_fit_the_limit_and_version_5_bytes_decode_as_before() {
    // the largest model version 6 allows: 64 centres on 4 Gaussian inputs, two more
    // linear-only inputs, every optional field
    let mut m = with_law_clock(warmup_model(MAX_CENTERS, 4, 2.0, 11));
    m.meta.gyro_id.clear();
    m.meta.gyro_id.push_str("0123456789ABCDEF").unwrap();
    m.poly.extend_from_slice(&[0.3, -0.05, 0.01]).unwrap();
    m.heading = Some(harmonic());
    m.linear_by_t
        .extend_from_slice(&[0.0, 0.02, -0.01, 0.005, 0.001, -0.002])
        .unwrap();
    m.cold_start = Some(envelope(MAX_COLD_START_POINTS));
    let bytes = encode(&m);
    println!("64 centres x 6 inputs + every field: {} bytes", bytes.len());
    assert!(bytes.len() <= MAX_ENCODED_LEN, "{} bytes", bytes.len());
    assert_eq!(RbfModel::decode(&bytes), Ok(m.clone()));
    // version 6 keeps version 5's layout: the same body under either version number, so
    // every version-5 file decodes to what it meant
    for model in [&m, &warmup_model(35, 2, 2.0, 5)] {
        assert_eq!(encode_version(model, 6), encode(model));
        assert_eq!(
            RbfModel::decode(&encode_version(model, 5)),
            Ok(model.clone())
        );
    }
    // a centre is four wide: a fifth input in the Gaussians is refused, as is a seventh input
    let mut five = with_law_clock(warmup_model(8, 4, 2.0, 1));
    five.n_rbf_inputs = 5;
    assert!(matches!(
        RbfModel::decode(&encode_loose(&LooseModel::from(&five), MODEL_VERSION)),
        Err(ModelError::BadRbfInputCount {
            n_rbf_inputs: 5,
            n_inputs: 6
        })
    ));
    let mut seven = LooseModel::from(&with_law_clock(warmup_model(8, 4, 2.0, 1)));
    seven.inputs.push(seven.inputs[5]);
    for v in [
        &mut seven.input_offset,
        &mut seven.input_scale,
        &mut seven.input_min,
        &mut seven.input_max,
        &mut seven.linear,
    ] {
        v.push(v[5]);
    }
    assert_eq!(
        RbfModel::decode(&encode_loose(&seven, MODEL_VERSION)),
        Err(ModelError::TooManyInputs { count: 7 })
    );
}
