//! The same campaign as `fogsim campaign --runs R --seed S --ambient-c A,B,..` with some
//! of its random parts switched off, every random draw still made (`sim::quiet`): to
//! tell which part of one campaign makes a `diagnose` figure read as it does
//! (docs/record/diagnose.md, the d2T/dt2 ratio of seed 9). Parts: `gyro` (`arw`,
//! `bias-instability`, `rrw`, `quantisation`), `sensor`, `turn-on`, `power`, `soak`, or
//! `none`. `target/release/examples/quiet_twin OUT SEED RUNS AMBIENTS_C PART[,PART..]`

use fog_sim::pipeline::campaign::{simulate_campaign, write_campaign, CampaignSpec};
use fog_sim::sim::{GyroParams, RandomPart};

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [out, seed, runs, ambients, parts] = args.as_slice() else {
        anyhow::bail!("usage: quiet_twin OUT SEED RUNS AMBIENTS_C PART[,PART..]");
    };
    let mut spec = CampaignSpec::paper(seed.parse()?);
    spec.runs_per_ambient = runs.parse()?;
    spec.ambients_c = ambients
        .split(',')
        .map(str::parse)
        .collect::<Result<_, _>>()?;
    let mut p = GyroParams::paper_default();
    for name in parts.split(',').filter(|&n| n != "none") {
        let part = RandomPart::parse(name)
            .ok_or_else(|| anyhow::anyhow!("part {name}: not a random part (see the header)"))?;
        p = p.without(part);
    }
    let runs = simulate_campaign(&p, &spec)?;
    let files = write_campaign(std::path::Path::new(out), &runs)?;
    println!(
        "quiet_twin: wrote {} runs to {out} (off: {parts})",
        files.len()
    );
    Ok(())
}
