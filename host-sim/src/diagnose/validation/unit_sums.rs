//! Sums of per-unit vectors (a unit's Gram matrix or X'y, flattened): the whole data set's
//! system is the sum of its units', so a fit on any subset of units (a fold, a bootstrap
//! draw, a score) is built from the same per-unit pieces without re-reading the rows.

/// Weighted sum of per-unit vectors: unit u counted `counts[u]` times (0 leaves it out,
/// 1 is the common case and skips the multiply).
pub(crate) fn counted_sum(v: &[Vec<f64>], counts: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; v.first().map_or(0, Vec::len)];
    for (x, &c) in v.iter().zip(counts) {
        if c == 1.0 {
            out.iter_mut().zip(x).for_each(|(o, a)| *o += a);
        } else if c != 0.0 {
            out.iter_mut().zip(x).for_each(|(o, a)| *o += c * a);
        }
    }
    out
}

/// Element-wise sum of per-unit vectors (Grams or X'y) over the units.
pub(crate) fn sum_all(v: &[Vec<f64>]) -> Vec<f64> {
    let mut out = vec![0.0; v.first().map_or(0, Vec::len)];
    for x in v {
        out.iter_mut().zip(x).for_each(|(o, a)| *o += a);
    }
    out
}
