//! Per-row model misfit of runs, for decomposing seek error into the model's systematic
//! misfit (the mean over many runs of one ambient) and its input noise (the scatter about
//! that mean): prints `run,ambient_c,t_s,temp_c,before_dph,predicted_dph` for every
//! window the model compensated (fog-core's compensator replay, as the device runs it).
//! `target/release/examples/misfit_rows MODEL RUN.csv|DIR...`

use fog_sim::pipeline::compensation_replay::compensate_run;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (model_path, runs) = match args.split_first() {
        Some((m, r)) if !r.is_empty() => (m, r),
        _ => anyhow::bail!("usage: misfit_rows MODEL RUN.csv|DIR..."),
    };
    let model = fog_sim::io::model::read_model(std::path::Path::new(model_path))?;
    println!("run,ambient_c,t_s,temp_c,before_dph,predicted_dph");
    for run in fog_sim::io::read_runs(runs)? {
        let s = compensate_run(&run, Some(&model))?;
        let name = run.name();
        let ambient = run.ambient_c().unwrap_or(f64::NAN);
        for (k, &t) in s.after_t_s.iter().enumerate() {
            let i = s.t_s.partition_point(|&x| x < t);
            println!(
                "{name},{ambient},{t},{:.5},{:.6},{:.6}",
                s.temp_c[i], s.before_dph[i], s.predicted_dph[k]
            );
        }
    }
    Ok(())
}
