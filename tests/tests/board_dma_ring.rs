//! The STM32F407 board's DMA receive rings (`fog_firmware::circular_dma`, used by
//! `board-f407/src/dma_ring.rs`) against a simulated circular DMA: NDTR counting down
//! and reloading, half/full-transfer interrupts delivered late (up to just under half a
//! ring), the reader at its own pace. Every byte read is the byte the sender sent at
//! that position; a reader that keeps up loses nothing; one that stalls loses bytes and
//! counts exactly the ones it skipped. Two reader laws: steady polling, and long stalls
//! followed by draining bursts.

use fog_firmware::circular_dma::{total_written, RingReader};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The byte the sender sends at stream position `i`.
fn sent(i: u32) -> u8 {
    (i.wrapping_mul(2_654_435_761) >> 24) as u8
}

#[test]
fn total_written_is_exact_with_the_boundary_interrupt_delivered_or_pending() {
    for len in [8u32, 64, 1024] {
        let half = len / 2;
        for t in 0..10 * len {
            let laps = t / half;
            let ndtr = len - t % len;
            assert_eq!(total_written(laps, ndtr, len), t, "len {len} t {t}");
            if laps > 0 && t % half < half - 1 {
                // The last boundary's interrupt not run yet (latency < half a ring).
                assert_eq!(total_written(laps - 1, ndtr, len), t, "pending, t {t}");
            }
        }
    }
}

/// A circular DMA writing `sent(i)` into a `len`-byte ring.
struct SimDma {
    ring: Vec<u8>,
    total: u32,
    /// Half laps whose interrupt has run.
    delivered: u32,
}

impl SimDma {
    fn new(len: usize) -> Self {
        Self {
            ring: vec![0; len],
            total: 0,
            delivered: 0,
        }
    }

    fn len(&self) -> u32 {
        self.ring.len() as u32
    }

    /// Receives `n` bytes; interrupts of crossed boundaries run now or stay pending
    /// (never more than one, and never beyond half a ring of latency).
    fn receive(&mut self, n: u32, rng: &mut ChaCha8Rng) {
        let half = self.len() / 2;
        for _ in 0..n {
            let at = (self.total % self.len()) as usize;
            self.ring[at] = sent(self.total);
            self.total += 1;
            let due = self.total / half;
            let late_ok = self.total % half < half / 2 && due == self.delivered + 1;
            if due > self.delivered && !(late_ok && rng.random_bool(0.5)) {
                self.delivered = due;
            }
        }
    }

    fn ndtr(&self) -> u32 {
        self.len() - self.total % self.len()
    }
}

/// Reads up to `n` bytes the way `DmaRx::read` does (catch up, then take one);
/// checks each; returns how many it got.
fn read_some(dma: &SimDma, reader: &mut RingReader, n: u32) -> u32 {
    let mut got = 0;
    for _ in 0..n {
        let written = total_written(dma.delivered, dma.ndtr(), dma.len());
        assert_eq!(written, dma.total, "the reader's view of the DMA");
        if reader.catch_up(written, dma.len()) == 0 {
            break;
        }
        let index = reader.read;
        let byte = dma.ring[reader.take(dma.len())];
        assert_eq!(byte, sent(index), "byte {index}");
        got += 1;
    }
    got
}

/// Runs `steps` of (DMA receives, reader reads) and returns (received, read, dropped).
fn run(len: usize, seed: u64, steps: u32, law: fn(&mut ChaCha8Rng, u32) -> u32) -> (u32, u32, u32) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut dma = SimDma::new(len);
    let mut reader = RingReader::default();
    let mut got = 0;
    for step in 0..steps {
        let n = rng.random_range(0..len as u32 / 8);
        dma.receive(n, &mut rng);
        let budget = law(&mut rng, step);
        got += read_some(&dma, &mut reader, budget);
    }
    got += read_some(&dma, &mut reader, u32::MAX);
    assert_eq!(reader.read, dma.total, "drained to the end");
    assert_eq!(
        got + reader.dropped,
        dma.total,
        "every byte read or counted lost"
    );
    (dma.total, got, reader.dropped)
}

#[test]
fn a_reader_that_keeps_up_gets_every_byte_in_order() {
    // Steady law: each pass reads at least what a pass can bring.
    let steady = |rng: &mut ChaCha8Rng, _| rng.random_range(128..512);
    for (len, seed) in [(1024, 1), (1024, 2), (256, 3)] {
        let (total, got, dropped) = run(len, seed, 5_000, steady);
        assert!(total > 100_000 * len as u32 / 1024, "{total}");
        assert_eq!((got, dropped), (total, 0), "len {len} seed {seed}");
    }
}

#[test]
fn a_stalling_reader_loses_bytes_and_counts_exactly_those() {
    // Bursty law: stalls of 20-200 passes (several rings), then drains in one go.
    let bursty = |rng: &mut ChaCha8Rng, step: u32| {
        if step % 211 < rng.random_range(20..200) {
            0
        } else {
            u32::MAX
        }
    };
    for (len, seed) in [(1024, 4), (256, 5)] {
        let (total, got, dropped) = run(len, seed, 5_000, bursty);
        assert!(dropped > 0, "stalls of several rings must lose bytes");
        assert_eq!(got + dropped, total);
    }
}
