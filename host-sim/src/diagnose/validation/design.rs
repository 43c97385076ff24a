//! A design matrix as rows computed on demand. The held-out fits need only per-unit Gram
//! matrices, cross products with candidate columns and predictions, all of which stream
//! over rows; so a design of many basis functions (an RBF's centres) is never held as
//! n x columns (issue 18 item 8: memory bounded per row whatever the campaign's length).

/// Rows of a design, computed when asked.
pub trait Design: std::fmt::Debug {
    /// Number of columns.
    fn width(&self) -> usize;
    /// Writes row `i` (raw: no run offsets removed) into `out` (`width()` long).
    fn row(&self, i: usize, out: &mut [f64]);
}

/// A design held as columns (a few: polynomials in T, the simulator's law).
#[derive(Clone, Debug)]
pub struct Columns(pub Vec<Vec<f64>>);

impl Design for Columns {
    fn width(&self) -> usize {
        self.0.len()
    }

    fn row(&self, i: usize, out: &mut [f64]) {
        self.0.as_slice().row(i, out);
    }
}

impl Design for [Vec<f64>] {
    fn width(&self) -> usize {
        self.len()
    }

    fn row(&self, i: usize, out: &mut [f64]) {
        for (o, c) in out.iter_mut().zip(self) {
            *o = c[i];
        }
    }
}
