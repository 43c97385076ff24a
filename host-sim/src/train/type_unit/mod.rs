//! Type and unit calibration, the way instrument makers calibrate a production: a **type
//! model** learnt once per design from the cold starts of several units (`type_model`:
//! the shared drift model, and how units differ in a few physical unit terms), and for
//! every gyro a **unit calibration** from a few of its own cold starts with the type as
//! the prior (`calibrate`), tested first for belonging to its type (`misfit`). The result
//! is an ordinary device model (`terms::fold`): same format, same upload, same firmware.
//!
//! Why: a model trained from a unit's own few runs learns their turn-on scatter, and that
//! error only falls as 1/sqrt(runs); the type carries the warm-up law from many runs, and
//! the unit pays parameters only for what its runs show it differs in.

pub mod calibrate;
pub mod folds;
pub mod law;
pub mod misfit;
pub mod own;
pub mod resolved;
pub mod shape;
pub mod solve;
pub mod terms;
pub mod type_model;

pub use calibrate::{calibrate_unit, unit_id_of, MisfitPolicy, UnitCalibration, UnitPlan};
pub use own::{choose_own, ordinary_model, OwnChoice};
pub use shape::{
    resolve_shape, train_shared, ShapeChoice, ShapeScoring, SharedModel, SharedShape, TypeShape,
};
pub use type_model::{fit_type, runs_by_unit, TypeModel};
