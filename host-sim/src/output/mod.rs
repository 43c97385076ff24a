//! What the tool shows a person: the JSON report structures and terminal tables
//! (`reports`) and the SVG charts (`plots`) shared by `compensate`, `north-seek`,
//! `reproduce`, `allan` and `demo`.

pub mod plots;
pub mod reports;
