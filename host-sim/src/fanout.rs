//! The one way fogsim spreads independent jobs over threads.
//!
//! Policy: `count` jobs are cut into at most `threads` contiguous chunks of
//! ceil(count / threads) jobs; each chunk runs on one `std::thread::scope` thread; result
//! `i` is job `i`'s, whatever the thread count or scheduling (deterministic order). The
//! default thread count is the machine's available parallelism. A failing job stops the
//! others from starting new jobs; the error returned is that of the lowest-numbered job
//! that ran and failed (with one failing job, always its error).

use std::num::NonZeroUsize;
use std::sync::atomic::{AtomicBool, Ordering};

/// Worker threads: `requested`, else the machine's available parallelism; at least 1.
pub fn thread_count(requested: Option<usize>) -> usize {
    requested
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, NonZeroUsize::get))
        .max(1)
}

/// Runs `job(i)` for every `i` in `0..count` over `threads` threads; results in index order.
pub fn map_in_order<R: Send>(
    count: usize,
    threads: usize,
    job: impl Fn(usize) -> R + Sync,
) -> Vec<R> {
    match try_map_in_order(count, threads, |i| {
        Ok::<R, std::convert::Infallible>(job(i))
    }) {
        Ok(v) => v,
        Err(never) => match never {},
    }
}

/// Like `map_in_order` for fallible jobs: after the first failure no job is started, and
/// the error of the lowest-numbered job that ran and failed is returned.
pub fn try_map_in_order<R: Send, E: Send>(
    count: usize,
    threads: usize,
    job: impl Fn(usize) -> Result<R, E> + Sync,
) -> Result<Vec<R>, E> {
    let mut slots: Vec<Option<Result<R, E>>> = (0..count).map(|_| None).collect();
    if count == 0 {
        return Ok(Vec::new());
    }
    let per_chunk = count.div_ceil(threads.clamp(1, count));
    let failed = AtomicBool::new(false);
    std::thread::scope(|scope| {
        for (c, chunk) in slots.chunks_mut(per_chunk).enumerate() {
            let (job, failed) = (&job, &failed);
            scope.spawn(move || {
                for (k, slot) in chunk.iter_mut().enumerate() {
                    if failed.load(Ordering::Relaxed) {
                        break;
                    }
                    let r = job(c * per_chunk + k);
                    if r.is_err() {
                        failed.store(true, Ordering::Relaxed);
                    }
                    *slot = Some(r);
                }
            });
        }
    });
    // Without a failure every slot is filled and Ok; with one, an Err slot exists.
    let mut out = Vec::with_capacity(count);
    let mut first_error = None;
    for slot in slots {
        match slot {
            Some(Ok(r)) => out.push(r),
            Some(Err(e)) => {
                first_error = Some(e);
                break;
            }
            None => {}
        }
    }
    match first_error {
        Some(e) => Err(e),
        None => Ok(out),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn results_keep_index_order_for_any_thread_count() {
        let want: Vec<u64> = (0..37).map(|i| i * i).collect();
        for threads in [1, 2, 3, 8, 100] {
            assert_eq!(map_in_order(37, threads, |i| (i * i) as u64), want);
        }
        assert!(map_in_order(0, 4, |i| i).is_empty());
    }

    #[test]
    fn a_failed_job_is_reported_and_stops_the_rest() {
        for threads in [1, 2, 5] {
            let r = try_map_in_order(20, threads, |i| if i == 7 { Err(i) } else { Ok(i) });
            assert_eq!(r, Err(7), "threads {threads}");
        }
        let started = std::sync::atomic::AtomicUsize::new(0);
        let r = try_map_in_order(20, 1, |i| {
            started.fetch_add(1, Ordering::Relaxed);
            if i == 2 {
                Err(i)
            } else {
                Ok(i)
            }
        });
        assert_eq!((r, started.into_inner()), (Err(2), 3));
        assert_eq!(try_map_in_order(3, 2, Ok::<usize, ()>), Ok(vec![0, 1, 2]));
    }
}
