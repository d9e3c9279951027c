//! Where does the generated wing move trailing-edge first (|AoA| > 90°)?
//!
//! `cargo run --release -p flapssm-wing --example te_first [N] [SEED]`
//!
//! Samples every generated trajectory at 250 Hz over the analysed part (dataset sample ≥ 93,
//! i.e. after the published transient) and reports the TE-first share of samples and of the
//! |v|²-weight, split by family and by phase from the nearest stroke reversal (φ̇ = 0), plus
//! the length of TE-first episodes in cycles.

use flapssm_wing::kinematics::{EulerState, WingKinematics};
use flapssm_wing::trajectories::{Family, GeneratorConfig};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(548);
    let seed: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(2021);
    let cfg = GeneratorConfig {
        n_trajectories: n,
        n_train: n.saturating_sub(1).max(1),
        seed,
        ..Default::default()
    };
    let specs = cfg.generate().expect("generator");
    let raw = &cfg.sampling;
    let dt = raw.raw_dt_s();
    let start = 93 * raw.decimation;
    // Bins of |phase from nearest reversal| in cycles: 0–0.05, …, 0.20–0.25.
    let mut by_phase = [[0.0f64; 2]; 5];
    let mut by_family = vec![[0.0f64; 4]; Family::ALL.len()];
    let (mut te, mut all, mut te_w, mut all_w) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut episodes: Vec<f64> = Vec::new();
    let mut states = vec![EulerState::default(); raw.n_raw()];
    for spec in &specs {
        spec.sample_into(dt, &mut states);
        let fam = Family::ALL.iter().position(|f| *f == spec.family).unwrap();
        let period = 1.0 / spec.frequency_hz;
        let mut run = 0usize;
        for (k, st) in states.iter().enumerate().skip(start) {
            let kin = WingKinematics::from_euler(st);
            let w = kin.speed * kin.speed;
            let is_te = kin.aoa_rad.abs() > std::f64::consts::FRAC_PI_2;
            // Nearest reversal: scan φ̇ sign changes within ±¼ cycle.
            let reach = (0.25 * period / dt) as usize;
            let sign = st.rates_rad_s[0].signum();
            let mut d = reach;
            for j in 1..reach {
                let changed = |i: usize| states[i].rates_rad_s[0].signum() != sign;
                if (k + j < states.len() && changed(k + j)) || (k >= j && changed(k - j)) {
                    d = j;
                    break;
                }
            }
            let phase = d as f64 * dt / period;
            let bin = ((phase / 0.05) as usize).min(4);
            all += 1.0;
            all_w += w;
            by_phase[bin][1] += 1.0;
            by_family[fam][1] += 1.0;
            by_family[fam][3] += w;
            if is_te {
                te += 1.0;
                te_w += w;
                by_phase[bin][0] += 1.0;
                by_family[fam][0] += 1.0;
                by_family[fam][2] += w;
                run += 1;
            } else if run > 0 {
                episodes.push(run as f64 * dt / period);
                run = 0;
            }
        }
        if run > 0 {
            episodes.push(run as f64 * dt / period);
        }
    }
    println!(
        "{} trajectories, seed {seed}: TE-first {:.1} % of samples, {:.1} % of |v|²-weight",
        specs.len(),
        100.0 * te / all,
        100.0 * te_w / all_w
    );
    for (i, b) in by_phase.iter().enumerate() {
        println!(
            "  phase from reversal {:.2}-{:.2} cycle: {:.1} % of its samples TE-first ({:.1} % of all TE-first)",
            0.05 * i as f64,
            0.05 * (i + 1) as f64,
            100.0 * b[0] / b[1].max(1.0),
            100.0 * b[0] / te.max(1.0)
        );
    }
    for (f, b) in Family::ALL.iter().zip(&by_family) {
        println!(
            "  {:>12}: TE-first {:.1} % of samples, {:.1} % of |v|²-weight",
            f.label(),
            100.0 * b[0] / b[1].max(1.0),
            100.0 * b[2] / b[3].max(1e-300)
        );
    }
    episodes.sort_by(f64::total_cmp);
    let q = |p: f64| episodes[((episodes.len() - 1) as f64 * p) as usize];
    if !episodes.is_empty() {
        println!(
            "  TE-first episodes: {} , length in cycles: median {:.3}, 90 % {:.3}, max {:.3}",
            episodes.len(),
            q(0.5),
            q(0.9),
            q(1.0)
        );
    }
}
