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
    /// Whether the rows are already in memory (holding them again would gain nothing).
    fn is_held(&self) -> bool {
        false
    }
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

    fn is_held(&self) -> bool {
        true
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

/// A design followed by a few held columns (a law plus a named cause's feature), rows
/// on demand: nothing of the design is copied.
#[derive(Debug)]
pub struct WithColumns<'a> {
    pub design: &'a dyn Design,
    pub extra: &'a [Vec<f64>],
}

impl Design for WithColumns<'_> {
    fn width(&self) -> usize {
        self.design.width() + self.extra.len()
    }

    fn row(&self, i: usize, out: &mut [f64]) {
        let p = self.design.width();
        self.design.row(i, &mut out[..p]);
        for (o, c) in out[p..].iter_mut().zip(self.extra) {
            *o = c[i];
        }
    }
}

/// Every column of a design, materialised (for the few fits that need columns: small
/// layouts only).
pub fn columns(design: &dyn Design, rows: usize) -> Vec<Vec<f64>> {
    let p = design.width();
    let mut cols: Vec<Vec<f64>> = (0..p).map(|_| Vec::with_capacity(rows)).collect();
    let mut z = vec![0.0; p];
    for i in 0..rows {
        design.row(i, &mut z);
        cols.iter_mut().zip(&z).for_each(|(c, v)| c.push(*v));
    }
    cols
}
