//! Streams fog-runs files of any rate into 10 s windows (`fog_sim::io::read_binned`) and
//! prints one line per file; used to measure the reader's peak memory on large files:
//! `/usr/bin/time -v target/release/examples/bin_runs BIG.csv`.

fn main() -> anyhow::Result<()> {
    let paths: Vec<String> = std::env::args().skip(1).collect();
    if paths.is_empty() {
        anyhow::bail!("usage: bin_runs RUN.csv...");
    }
    for run in fog_sim::io::read_runs_binned(&paths)? {
        let rate = run.rate_dph();
        let mean = rate.iter().sum::<f64>() / rate.len() as f64;
        println!(
            "{}: {} windows of 10 s, last ends at {} s, mean rate {mean:.6} deg/h",
            run.name(),
            run.len(),
            run.t_s()[run.len() - 1]
        );
    }
    Ok(())
}
