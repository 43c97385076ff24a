//! Seeds for the diagnose generator tests: a fast default set, others via `DIAG_SEEDS=1,2,3`.

/// Seeds run by default.
pub const SEEDS: [u64; 3] = [11, 22, 33];

/// `DIAG_SEEDS` if set (comma separated), else [`SEEDS`].
pub fn seeds() -> Vec<u64> {
    std::env::var("DIAG_SEEDS")
        .ok()
        .map(|s| {
            s.split(',')
                .filter_map(|x| x.trim().parse().ok())
                .collect::<Vec<u64>>()
        })
        .filter(|v| !v.is_empty())
        .unwrap_or_else(|| SEEDS.to_vec())
}

/// `case(seed)` for every seed of [`seeds`], one thread a seed, results in seed order.
pub fn per_seed_parallel<T: Send>(case: impl Fn(u64) -> T + Sync) -> Vec<T> {
    let case = &case;
    std::thread::scope(|s| {
        let handles: Vec<_> = seeds()
            .into_iter()
            .map(|seed| s.spawn(move || case(seed)))
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("seed thread"))
            .collect()
    })
}

/// One ranked candidate of a diagnosis, as the diagnose tests print it:
/// `column:transform(tau) +gain% p`.
pub fn candidate_line(c: &fog_sim::diagnose::report::CandidateRow) -> String {
    format!(
        "{}:{}({:?}) {:+.2}% p{:.4}",
        c.column,
        c.transform.name(),
        c.tau_s,
        c.gain_pct,
        c.p_value
    )
}
