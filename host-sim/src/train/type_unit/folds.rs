//! Folds of whole units: a type's choices (the law's clocks, the shared model's shape) are
//! scored on units left out, as the type will meet a unit it has never seen.
//!
//! Why: runs of one unit share its unit terms, so a run left out beside its unit's other
//! runs scores the unit's own fit, not the type's; leaving whole units out does not.

/// The unit of each run: the index of its `unit_id` in order of first appearance, or a
/// unit of its own (after every named unit) when it names none.
pub fn unit_of_runs(runs: &[crate::io::runs::Run]) -> Vec<usize> {
    let mut units: Vec<&str> = Vec::new();
    let named: Vec<Option<usize>> = runs
        .iter()
        .map(|r| {
            let u = r.meta_value("unit_id").map(str::trim)?;
            (!u.is_empty()).then(|| {
                units.iter().position(|x| *x == u).unwrap_or_else(|| {
                    units.push(u);
                    units.len() - 1
                })
            })
        })
        .collect();
    let mut next = units.len();
    named
        .into_iter()
        .map(|k| {
            k.unwrap_or_else(|| {
                next += 1;
                next - 1
            })
        })
        .collect()
}

/// The fold of each run: whole units dealt to `folds` folds in order of first appearance
/// (a run naming no unit is a unit of its own).
pub fn run_folds(runs: &[crate::io::runs::Run], folds: usize) -> Vec<usize> {
    unit_of_runs(runs).into_iter().map(|u| u % folds).collect()
}
