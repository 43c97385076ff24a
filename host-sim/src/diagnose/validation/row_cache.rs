//! A design's rows held in memory while a small, fixed budget allows it. Held-out
//! validation walks the same rows many times (the per-unit means, the Grams, every
//! ridge's predictions, every screened candidate's cross products), and an RBF row costs
//! one `exp` per centre: on a single 6-hour record most of `diagnose` was those `exp`s.
//! Long campaigns keep computing rows on demand (memory bounded per row, issue 18 item 8);
//! the budget is one process-wide count, so memory stays bounded whatever the input.
//! Held rows are the same numbers the design computes, so results do not depend on
//! whether a design was held.

use crate::diagnose::validation::design::Design;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

/// Bytes of held rows the whole process may keep at once: 2 MiB. A single 6-hour record
/// at 10 s (2,160 rows x 30 columns, 0.5 MB) fits several times; the memory test's
/// campaigns (15,840 rows and up, 3.8 MB and up) never do, so its per-row slope measures
/// the on-demand path.
pub const HELD_ROWS_BUDGET_BYTES: usize = 2 << 20;

static HELD_BYTES: AtomicUsize = AtomicUsize::new(0);

/// `design`'s `rows` rows, held if the budget allows, else `design` itself.
pub fn held_or_on_demand(design: Arc<dyn Design>, rows: usize) -> Arc<dyn Design> {
    held_within(design, rows, &HELD_BYTES, HELD_ROWS_BUDGET_BYTES)
}

/// [`held_or_on_demand`] against the count `held` and its `budget` (tests give their own).
fn held_within(
    design: Arc<dyn Design>,
    rows: usize,
    held: &'static AtomicUsize,
    budget: usize,
) -> Arc<dyn Design> {
    if design.is_held() {
        return design;
    }
    let p = design.width();
    let Some(bytes) = rows.checked_mul(p).and_then(|v| v.checked_mul(8)) else {
        return design;
    };
    let reserved = held.fetch_update(Ordering::Relaxed, Ordering::Relaxed, |now| {
        now.checked_add(bytes).filter(|&total| total <= budget)
    });
    if reserved.is_err() {
        return design;
    }
    let mut values = vec![0.0; rows * p];
    if p > 0 {
        for (i, row) in values.chunks_exact_mut(p).enumerate() {
            design.row(i, row);
        }
    }
    Arc::new(HeldRows {
        values,
        p,
        bytes,
        held,
    })
}

/// Rows computed once and kept, row-major; their bytes are returned to `held` on drop.
#[derive(Debug)]
struct HeldRows {
    values: Vec<f64>,
    p: usize,
    bytes: usize,
    held: &'static AtomicUsize,
}

impl Design for HeldRows {
    fn width(&self) -> usize {
        self.p
    }

    fn row(&self, i: usize, out: &mut [f64]) {
        out[..self.p].copy_from_slice(&self.values[i * self.p..(i + 1) * self.p]);
    }

    fn is_held(&self) -> bool {
        true
    }
}

impl Drop for HeldRows {
    fn drop(&mut self) {
        self.held.fetch_sub(self.bytes, Ordering::Relaxed);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::validation::design::Columns;

    /// A design that computes its rows (so it is not held already).
    #[derive(Debug)]
    struct Computed(usize);

    impl Design for Computed {
        fn width(&self) -> usize {
            3
        }
        fn row(&self, i: usize, out: &mut [f64]) {
            for (j, o) in out.iter_mut().enumerate() {
                *o = (-((i * 7 + j) as f64) / self.0 as f64).exp();
            }
        }
    }

    #[test]
    fn held_rows_are_the_designs_rows_and_the_budget_is_returned() {
        static HELD: AtomicUsize = AtomicUsize::new(0);
        let n = 1000;
        let design: Arc<dyn Design> = Arc::new(Computed(n));
        let held = held_within(design.clone(), n, &HELD, 1 << 20);
        assert!(held.is_held());
        let (mut a, mut b) = ([0.0; 3], [0.0; 3]);
        for i in [0, 1, 499, 999] {
            design.row(i, &mut a);
            held.row(i, &mut b);
            assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits), "row {i}");
        }
        assert_eq!(HELD.load(Ordering::Relaxed), n * 3 * 8);
        drop(held);
        assert_eq!(HELD.load(Ordering::Relaxed), 0);
    }

    #[test]
    fn a_design_over_the_budget_is_computed_on_demand() {
        static HELD: AtomicUsize = AtomicUsize::new(0);
        let n = 1000;
        let design: Arc<dyn Design> = Arc::new(Computed(n));
        let first = held_within(design.clone(), n, &HELD, 30_000);
        assert!(first.is_held());
        // the second would pass the budget while the first is alive
        assert!(!held_within(design.clone(), n, &HELD, 30_000).is_held());
        drop(first);
        assert!(held_within(design, n, &HELD, 30_000).is_held());
        let columns: Arc<dyn Design> = Arc::new(Columns(vec![vec![1.0; 4]]));
        assert!(Arc::ptr_eq(
            &held_or_on_demand(columns.clone(), 4),
            &columns
        ));
    }
}
