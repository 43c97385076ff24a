//! Decoding an encoded model into existing storage: `RbfModel::decode` and
//! `RbfModel::decode_into` check the envelope (size, magic, version, CRC-32, counts) and
//! read the body straight into a `&mut RbfModel`.
//!
//! The derived `Deserialize` builds every field as a local, then the struct, then the
//! `Result`s around it: at `opt-level = "z"` that is an ~8 KB stack frame for a ~1.7 KB
//! model, the largest one at the firmware's boot. `ModelInPlace` reads the same postcard
//! wire format (the fields in declaration order, each vector as length + elements)
//! directly into a `&mut RbfModel`, element by element, so the decoder's frame holds
//! one element at a time.
//!
//! The decoder sits above `format` (whose layout, limits and envelope it reads) rather
//! than inside it, so that `format` does not reach back up into the reader: the files of
//! `model` import one way.

use core::fmt;

use heapless::Vec;
use serde::de::{self, DeserializeSeed, Deserializer, SeqAccess, Visitor};
use serde::Deserialize;

use crate::model::crc::crc32;
use crate::model::error::{check_len, ModelError, ModelField};
use crate::model::format::{
    BodyCounts, RbfModel, WireModel, MAX_CENTERS, MAX_ENCODED_LEN, MAX_INPUTS, MODEL_MAGIC,
    MODEL_VERSION, MODEL_VERSION_BASE, MODEL_VERSION_OLDEST,
};

impl RbfModel {
    /// Decode and fully validate an encoded model.
    pub fn decode(bytes: &[u8]) -> Result<RbfModel, ModelError> {
        let mut model = RbfModel::empty();
        model.decode_into(bytes)?;
        Ok(model)
    }

    /// `decode` into `self`, in place: the model is read element by element into the
    /// existing storage (`ModelInPlace`), never built on the stack, so a device can
    /// decode into a `static`. On error `self` holds a partly decoded model: decode again
    /// or discard it.
    pub fn decode_into(&mut self, bytes: &[u8]) -> Result<(), ModelError> {
        if bytes.len() > MAX_ENCODED_LEN {
            return Err(ModelError::TooLarge {
                len: bytes.len() as u32,
            });
        }
        // Magic and version first, so a foreign or newer file gets the precise error.
        let (magic, rest) = postcard::take_from_bytes::<u32>(bytes).map_err(map_postcard)?;
        if magic != MODEL_MAGIC {
            return Err(ModelError::BadMagic { found: magic });
        }
        let (version, _) = postcard::take_from_bytes::<u16>(rest).map_err(map_postcard)?;
        if !(MODEL_VERSION_OLDEST..=MODEL_VERSION).contains(&version) {
            return Err(ModelError::UnsupportedVersion { found: version });
        }
        let (wire, trailing) =
            postcard::take_from_bytes::<WireModel<'_>>(bytes).map_err(map_postcard)?;
        if !trailing.is_empty() {
            return Err(ModelError::TrailingBytes {
                count: trailing.len() as u16,
            });
        }
        let computed = crc32(wire.body);
        if computed != wire.crc32 {
            return Err(ModelError::CrcMismatch {
                stored: wire.crc32,
                computed,
            });
        }
        let (counts, model_bytes) = postcard::take_from_bytes::<BodyCounts>(wire.body)
            .map_err(|_| ModelError::Malformed)?;
        if counts.n_inputs as usize > MAX_INPUTS {
            return Err(ModelError::TooManyInputs {
                count: counts.n_inputs,
            });
        }
        if counts.n_centers as usize > MAX_CENTERS {
            return Err(ModelError::TooManyCenters {
                count: counts.n_centers,
            });
        }
        let mut de = postcard::Deserializer::from_bytes(model_bytes);
        ModelInPlace {
            model: self,
            version,
        }
        .deserialize(&mut de)
        .map_err(|_| ModelError::Malformed)?;
        let left = de.finalize().map_err(|_| ModelError::Malformed)?;
        let model = &*self;
        let needs = model.format_version();
        if needs > MODEL_VERSION_BASE && version < needs {
            // an input kind newer than the file's version: no writer makes it
            return Err(ModelError::Malformed);
        }
        if !left.is_empty() {
            return Err(ModelError::TrailingBytes {
                count: left.len() as u16,
            });
        }
        check_len(
            ModelField::Inputs,
            counts.n_inputs as usize,
            model.inputs.len(),
        )?;
        check_len(
            ModelField::Centers,
            counts.n_centers as usize,
            model.centers.len(),
        )?;
        model.validate()
    }
}

fn map_postcard(e: postcard::Error) -> ModelError {
    match e {
        postcard::Error::DeserializeUnexpectedEnd => ModelError::Truncated,
        _ => ModelError::Malformed,
    }
}

/// The struct's field names (postcard only uses their count).
const FIELDS: &[&str] = &[
    "n_rbf_inputs",
    "inputs",
    "input_offset",
    "input_scale",
    "input_min",
    "input_max",
    "linear",
    "centers",
    "widths",
    "weights",
    "bias_dph",
    "meta",
    "poly",
    "heading",
    "linear_by_t",
    "cold_start",
];

/// Seed that fills `model` with the model being deserialised in format `version`: 1 has
/// no `poly` (left empty), 1 and 2 no `heading` (left `None`), 1-3 no `linear_by_t` (left
/// empty), 1-4 no `cold_start` (left `None`).
struct ModelInPlace<'a> {
    model: &'a mut RbfModel,
    version: u16,
}

impl ModelInPlace<'_> {
    fn has_poly(&self) -> bool {
        self.version >= 2
    }

    fn has_heading(&self) -> bool {
        self.version >= 3
    }

    fn has_linear_by_t(&self) -> bool {
        self.version >= 4
    }

    fn has_cold_start(&self) -> bool {
        self.version >= 5
    }
}

impl<'de> DeserializeSeed<'de> for ModelInPlace<'_> {
    type Value = ();

    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        let n_fields = FIELDS.len()
            - usize::from(!self.has_poly())
            - usize::from(!self.has_heading())
            - usize::from(!self.has_linear_by_t())
            - usize::from(!self.has_cold_start());
        let fields = &FIELDS[..n_fields];
        d.deserialize_struct("RbfModel", fields, self)
    }
}

/// The next element of `seq`, or an `invalid_length` error naming its position.
fn next<'de, T: Deserialize<'de>, A: SeqAccess<'de>>(
    seq: &mut A,
    index: usize,
) -> Result<T, A::Error> {
    seq.next_element()?
        .ok_or_else(|| de::Error::invalid_length(index, &"an RbfModel"))
}

/// Fill `dst` in place from the next element of `seq` (a sequence).
fn next_vec<'de, T: Deserialize<'de>, const N: usize, A: SeqAccess<'de>>(
    seq: &mut A,
    index: usize,
    dst: &mut Vec<T, N>,
) -> Result<(), A::Error> {
    seq.next_element_seed(VecInPlace(dst))?
        .ok_or_else(|| de::Error::invalid_length(index, &"an RbfModel"))
}

impl<'de> Visitor<'de> for ModelInPlace<'_> {
    type Value = ();

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("an RbfModel")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<(), A::Error> {
        let (has_poly, has_heading, has_linear_by_t, has_cold_start) = (
            self.has_poly(),
            self.has_heading(),
            self.has_linear_by_t(),
            self.has_cold_start(),
        );
        let m = self.model;
        m.n_rbf_inputs = next(&mut seq, 0)?;
        next_vec(&mut seq, 1, &mut m.inputs)?;
        next_vec(&mut seq, 2, &mut m.input_offset)?;
        next_vec(&mut seq, 3, &mut m.input_scale)?;
        next_vec(&mut seq, 4, &mut m.input_min)?;
        next_vec(&mut seq, 5, &mut m.input_max)?;
        next_vec(&mut seq, 6, &mut m.linear)?;
        next_vec(&mut seq, 7, &mut m.centers)?;
        next_vec(&mut seq, 8, &mut m.widths)?;
        next_vec(&mut seq, 9, &mut m.weights)?;
        m.bias_dph = next(&mut seq, 10)?;
        m.meta = next(&mut seq, 11)?;
        if has_poly {
            next_vec(&mut seq, 12, &mut m.poly)?;
        } else {
            m.poly.clear();
        }
        m.heading = if has_heading {
            next(&mut seq, 13)?
        } else {
            None
        };
        if has_linear_by_t {
            next_vec(&mut seq, 14, &mut m.linear_by_t)?;
        } else {
            m.linear_by_t.clear();
        }
        // At most 2 x 8 floats: read whole, as `heading` is.
        m.cold_start = if has_cold_start {
            next(&mut seq, 15)?
        } else {
            None
        };
        Ok(())
    }
}

/// Seed that clears `.0` and pushes the sequence's elements into it.
struct VecInPlace<'a, T, const N: usize>(&'a mut Vec<T, N>);

impl<'de, T: Deserialize<'de>, const N: usize> DeserializeSeed<'de> for VecInPlace<'_, T, N> {
    type Value = ();

    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        d.deserialize_seq(self)
    }
}

impl<'de, T: Deserialize<'de>, const N: usize> Visitor<'de> for VecInPlace<'_, T, N> {
    type Value = ();

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "a sequence of at most {N} elements")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<(), A::Error> {
        self.0.clear();
        while let Some(v) = seq.next_element()? {
            if self.0.push(v).is_err() {
                return Err(de::Error::invalid_length(N + 1, &self));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::synthetic;

    /// The in-place reader and the derived `Deserialize` agree on the wire format.
    #[test]
    fn in_place_equals_derived() {
        let model = synthetic::warmup_model(64, 4, 2.0, 64);
        let mut buf = [0u8; 4096];
        let bytes = postcard::to_slice(&model, &mut buf).expect("encode");
        let derived: RbfModel = postcard::from_bytes(bytes).expect("derived");
        let mut target = RbfModel::empty();
        // Stale content must be replaced, not appended to.
        target.copy_from(&derived);
        let mut de = postcard::Deserializer::from_bytes(bytes);
        ModelInPlace {
            model: &mut target,
            version: crate::model::format::MODEL_VERSION,
        }
        .deserialize(&mut de)
        .expect("in place");
        assert!(de.finalize().expect("finalize").is_empty());
        assert_eq!(target, derived);
        assert_eq!(target, model);
    }

    /// Every truncation fails, as with the derived decoder.
    #[test]
    fn truncated_bodies_fail() {
        let model = synthetic::warmup_model(64, 4, 2.0, 64);
        let mut buf = [0u8; 4096];
        let bytes = postcard::to_slice(&model, &mut buf).expect("encode");
        for len in 0..bytes.len() {
            let mut target = RbfModel::empty();
            let mut de = postcard::Deserializer::from_bytes(&bytes[..len]);
            let seed = ModelInPlace {
                model: &mut target,
                version: crate::model::format::MODEL_VERSION,
            };
            assert!(
                seed.deserialize(&mut de).is_err(),
                "{len} of {} bytes accepted",
                bytes.len()
            );
        }
    }
}
