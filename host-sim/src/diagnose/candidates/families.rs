//! Operator families of the within-run library (issue 38 item 4): which operator made a
//! candidate, so the report can say per family how many candidates it contributed, how
//! many the cap or the record cut and why, and what the test's power is for it. A family
//! is what a user would ask about ("are lags tried? could a step response be found?"),
//! coarser than a transform: rate and accel are one family, products are one family
//! (with T or dT/dt; products of two extra columns are another, `pairs`).

use crate::diagnose::candidates::transforms::{Candidate, Source, Transform};

/// One operator family of the within-run library.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum OperatorFamily {
    Value,
    Smooth,
    Derivative,
    Memory,
    Hysteresis,
    PowerOnDecay,
    Harmonic,
    Levels,
    Product,
    MetadataProduct,
    EventClock,
    PairProduct,
}

/// Every family, in the report's order.
pub const ALL: [OperatorFamily; 12] = [
    OperatorFamily::Value,
    OperatorFamily::Smooth,
    OperatorFamily::Derivative,
    OperatorFamily::Memory,
    OperatorFamily::Hysteresis,
    OperatorFamily::PowerOnDecay,
    OperatorFamily::Harmonic,
    OperatorFamily::Levels,
    OperatorFamily::Product,
    OperatorFamily::MetadataProduct,
    OperatorFamily::EventClock,
    OperatorFamily::PairProduct,
];

impl OperatorFamily {
    /// The family's name in the report.
    pub fn name(self) -> &'static str {
        match self {
            Self::Value => "value",
            Self::Smooth => "smooth (spline)",
            Self::Derivative => "derivative",
            Self::Memory => "memory (lag)",
            Self::Hysteresis => "hysteresis (play)",
            Self::PowerOnDecay => "power-on decay",
            Self::Harmonic => "angle harmonic",
            Self::Levels => "levels",
            Self::Product => "product with T or dT/dt",
            Self::MetadataProduct => "metadata product with T or dT/dt",
            Self::EventClock => "event clock",
            Self::PairProduct => "pairwise products",
        }
    }

    /// The family of a candidate.
    pub fn of(c: &Candidate) -> Self {
        if c.partner.is_some() {
            return Self::PairProduct;
        }
        if c.times.is_some() {
            return if c.source == Source::Meta {
                Self::MetadataProduct
            } else {
                Self::Product
            };
        }
        match c.transform {
            Transform::Value => Self::Value,
            Transform::Spline => Self::Smooth,
            Transform::Rate | Transform::Accel => Self::Derivative,
            Transform::Lag => Self::Memory,
            Transform::Hysteresis => Self::Hysteresis,
            Transform::Decay => Self::PowerOnDecay,
            Transform::Harmonic => Self::Harmonic,
            Transform::Levels => Self::Levels,
            Transform::Event => Self::EventClock,
        }
    }
}

/// Why candidates of a family are missing: the column (or `library`) and the reason.
#[derive(Clone, Debug, PartialEq)]
pub struct FamilyNote {
    pub family: OperatorFamily,
    pub note: String,
}
