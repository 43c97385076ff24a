//! A second, independent campaign generator for `diagnose` tests (nothing shared with
//! `planted.rs` or the project's simulator): its own thermal law (a critically damped
//! second-order self-heating response on top of the chamber ambient, no exponential
//! modes), each run at ONE heading (turntable set between runs), 1 Hz rows, a
//! thermometer quantised to 0.0625 degC, decoy columns (a cabinet temperature random
//! walk and a supply with load steps), cold and warm restarts, turn-on bias offsets.
//! Two sizings of the heading bias: against the turn-on repeatability (its rms over
//! runs = k x 0.005 deg/h, a harsh power limit) and the issue's (amplitude = k x the white
//! noise sigma of 10 s means in a campaign at the issue's noise level, 0.03 deg/h: the
//! issue's "0.03 deg/h amplitude against ~0.005 deg/h turn-on repeatability").

use fog_sim::io::runs::Run;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// What is hidden in the campaign.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Hidden {
    Null,
    /// A cos(heading - phase), constant within a run (magnetic bias); its rms over
    /// headings is this many turn-on repeatability sigmas.
    HeadingBetweenRuns(f64),
    /// The issue's sizing: amplitude = this many white-noise sigmas of 10 s means, in a
    /// campaign whose 10 s noise is [`ISSUE_NOISE_10S_DPH`] (repeatability unchanged).
    #[allow(dead_code)] // only diagnose_between plants it; other tests share the module
    HeadingNoiseSigmas(f64),
    /// Nothing planted, at the issue's noise level (the null twin of `HeadingNoiseSigmas`).
    #[allow(dead_code)] // only diagnose_between uses it
    NullIssueNoise,
}

/// Turn-on repeatability (sd of run offsets), deg/h.
pub const REPEATABILITY_DPH: f64 = 0.005;
/// White noise of 10 s means, deg/h.
pub const NOISE_10S_DPH: f64 = 0.004;
/// White noise of 10 s means in the issue's campaigns (its 1-sigma heading amplitude), deg/h.
pub const ISSUE_NOISE_10S_DPH: f64 = 0.03;

/// 20 runs x 45 min at 1 Hz (4 ambients x 5 runs); the expected run-level label.
pub fn campaign(hidden: Hidden, seed: u64) -> (Vec<Run>, Option<&'static str>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_mul(0x2545_F491_4F6C_DD1D) ^ 0x51);
    let g = Normal::new(0.0, 1.0).unwrap();
    let ambients = [-25.0, 5.0, 25.0, 50.0];
    let rows = 45 * 60;
    let phase = rng.random_range(0.0..std::f64::consts::TAU);
    // rms of A cos(h - phase) over uniform headings is A / sqrt 2
    let (amp, noise_10s_dph) = match hidden {
        Hidden::HeadingBetweenRuns(s) => (
            s * REPEATABILITY_DPH * std::f64::consts::SQRT_2,
            NOISE_10S_DPH,
        ),
        Hidden::HeadingNoiseSigmas(s) => (s * ISSUE_NOISE_10S_DPH, ISSUE_NOISE_10S_DPH),
        Hidden::NullIssueNoise => (0.0, ISSUE_NOISE_10S_DPH),
        Hidden::Null => (0.0, NOISE_10S_DPH),
    };
    let (k1, k2) = (
        rng.random_range(-0.004..0.004),
        rng.random_range(-6e-5..6e-5),
    );
    let shupe = rng.random_range(2.0..6.0);
    let mut runs = Vec::new();
    let mut cabinet = 20.0;
    for (i, amb) in ambients.iter().flat_map(|a| [*a; 5]).enumerate() {
        let heading: f64 = rng.random_range(0.0..360.0);
        let warm = i % 3 == 2;
        let rise = rng.random_range(8.0..14.0);
        let tau = rng.random_range(300.0..700.0);
        let start = if warm {
            rng.random_range(0.4..0.8)
        } else {
            0.0
        };
        let offset = REPEATABILITY_DPH * g.sample(&mut rng);
        let mut supply = 24.0;
        let mut cols: Vec<Vec<f64>> = (0..6).map(|_| Vec::with_capacity(rows)).collect();
        for k in 0..rows {
            let t = (k + 1) as f64;
            let x = t / tau;
            // critically damped: 1 - (1 + x) e^-x, started part-way on a warm restart
            let frac = start + (1.0 - start) * (1.0 - (1.0 + x) * (-x).exp());
            let temp = amb + rise * frac;
            let dtemp = (1.0 - start) * rise * x * (-x).exp() / tau;
            let d = temp - 25.0;
            cabinet += 0.01 * g.sample(&mut rng);
            if rng.random::<f64>() < 0.002 {
                supply = 24.0 + rng.random_range(-0.5..0.5);
            }
            let mut drift = offset + k1 * d + k2 * d * d + shupe * dtemp;
            drift += amp * (heading.to_radians() - phase).cos();
            let rate = drift + noise_10s_dph * 10f64.sqrt() * g.sample(&mut rng);
            let temp_q = ((temp + 0.02 * g.sample(&mut rng)) / 0.0625).round() * 0.0625;
            for (c, v) in cols
                .iter_mut()
                .zip([t, rate, temp_q, heading, cabinet, supply])
            {
                c.push(v);
            }
        }
        runs.push(Run {
            path: format!("ind{seed}_run{i:02}.csv").into(),
            meta: vec![
                ("ambient_c".into(), format!("{amb}")),
                ("latitude_deg".into(), "40".into()),
            ],
            columns: [
                "t_s",
                "rate_dph",
                "temp_c",
                "heading_deg",
                "cabinet_c",
                "bus_v",
            ]
            .map(String::from)
            .to_vec(),
            data: cols,
        });
    }
    let expected = (amp > 0.0).then_some("heading_deg:run_harmonic");
    (runs, expected)
}
