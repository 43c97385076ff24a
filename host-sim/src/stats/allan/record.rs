//! The rate record an Allan analysis reads: samples at one period, split into segments
//! (runs, or stretches between non-finite values) that no difference may span, with a
//! hard memory bound. Past `MAX_SAMPLES` every stored segment is averaged in pairs and
//! later samples are averaged `decimation` at a time: the record's period doubles and the
//! shortest taus are lost, but memory stays bounded whatever the input length.

/// Most samples kept (f64 each: 32 MiB).
pub const MAX_SAMPLES: usize = 1 << 22;

/// Segmented, bounded record of rate samples.
#[derive(Clone, Debug)]
pub struct RateRecord {
    segments: Vec<Vec<f64>>,
    /// Raw samples averaged into one stored sample (a power of two).
    decimation: u64,
    /// Sum and count of raw samples still being averaged into the next stored sample.
    pending: (f64, u64),
    stored: usize,
    cap: usize,
    open: bool,
}

impl Default for RateRecord {
    fn default() -> Self {
        Self::with_cap(MAX_SAMPLES)
    }
}

impl RateRecord {
    /// A record keeping at most `cap` (>= 2) samples.
    pub fn with_cap(cap: usize) -> Self {
        Self {
            segments: Vec::new(),
            decimation: 1,
            pending: (0.0, 0),
            stored: 0,
            cap: cap.max(2),
            open: false,
        }
    }

    /// A one-segment record of `samples`.
    pub fn from_samples(samples: &[f64]) -> Self {
        let mut r = Self::default();
        for &x in samples {
            r.push(x);
        }
        r
    }

    /// Adds one raw sample; a non-finite value ends the segment (it is a gap, not data).
    pub fn push(&mut self, x: f64) {
        if !x.is_finite() {
            self.break_segment();
            return;
        }
        self.pending.0 += x;
        self.pending.1 += 1;
        if self.pending.1 < self.decimation {
            return;
        }
        let mean = self.pending.0 / self.pending.1 as f64;
        self.pending = (0.0, 0);
        if !self.open {
            self.segments.push(Vec::new());
            self.open = true;
        }
        if let Some(seg) = self.segments.last_mut() {
            seg.push(mean);
        }
        self.stored += 1;
        if self.stored > self.cap {
            self.halve();
        }
    }

    /// Ends the current segment: no difference spans what comes next.
    pub fn break_segment(&mut self) {
        self.open = false;
        self.pending = (0.0, 0);
    }

    /// Averages every stored segment in pairs (a trailing odd sample is dropped).
    fn halve(&mut self) {
        for seg in &mut self.segments {
            let pairs = seg.len() / 2;
            for i in 0..pairs {
                seg[i] = 0.5 * (seg[2 * i] + seg[2 * i + 1]);
            }
            seg.truncate(pairs);
            seg.shrink_to_fit();
        }
        self.segments.retain(|s| !s.is_empty());
        if self.segments.is_empty() {
            self.open = false;
        }
        self.stored = self.segments.iter().map(Vec::len).sum();
        self.decimation *= 2;
    }

    /// The stored segments (each at `decimation` times the raw period).
    pub fn segments(&self) -> &[Vec<f64>] {
        &self.segments
    }

    /// Raw samples per stored sample.
    pub fn decimation(&self) -> u64 {
        self.decimation
    }

    /// Stored samples over all segments.
    pub fn len(&self) -> usize {
        self.stored
    }

    /// No sample stored.
    pub fn is_empty(&self) -> bool {
        self.stored == 0
    }

    /// The longest segment, if any.
    pub fn longest(&self) -> Option<&[f64]> {
        self.segments
            .iter()
            .max_by_key(|s| s.len())
            .map(Vec::as_slice)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gaps_split_segments_and_the_cap_halves_the_rate() {
        let mut r = RateRecord::with_cap(8);
        for i in 0..4 {
            r.push(i as f64);
        }
        r.push(f64::NAN);
        for i in 0..4 {
            r.push(10.0 + i as f64);
        }
        assert_eq!(r.segments().len(), 2);
        assert_eq!((r.len(), r.decimation()), (8, 1));
        r.push(20.0); // the ninth sample: everything is averaged in pairs
        assert_eq!(r.decimation(), 2);
        assert_eq!(r.segments()[0], vec![0.5, 2.5]);
        assert_eq!(r.segments()[1], vec![10.5, 12.5]);
        r.push(22.0);
        r.push(24.0);
        assert_eq!(r.segments()[1], vec![10.5, 12.5, 23.0]);
        assert!(r.len() <= 8);
    }
}
