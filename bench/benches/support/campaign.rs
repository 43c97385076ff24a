//! The simulated paper campaign the benches run on (11 ambients x 3 runs, 10 Hz raw so it
//! builds in seconds), shared so every bench measures on the same inputs.

use fog_sim::pipeline::campaign::{simulate_campaign, CampaignSpec};
use fog_sim::sim::GyroParams;
use fog_sim::train::{dataset_from_runs, default_specs, Dataset};

/// The paper's (T, dT/dt) training set of that campaign, one group per run.
pub fn paper_training_set() -> Dataset {
    let spec = CampaignSpec {
        runs_per_ambient: 3,
        raw_rate_hz: 10.0,
        ..CampaignSpec::paper(1)
    };
    let runs: Vec<_> = simulate_campaign(&GyroParams::paper_default(), &spec)
        .expect("campaign")
        .into_iter()
        .map(|c| c.run)
        .collect();
    dataset_from_runs(&runs, &default_specs()).expect("dataset")
}
