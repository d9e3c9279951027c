//! Temporary timing probe (to be deleted).
use std::time::Instant;
use flapssm_wing::virtual_wing::{SimulationConfig, simulate_dataset};
use flapssm_prssm::train::fit::{FitSpec, Preset, fit, predict_raw};
use flapssm_prssm::train::{Budget, TrainHooks, TrainEvent};
use flapssm_prssm::Sequence;

fn seq(t: &flapssm_data::Trajectory) -> Sequence {
    Sequence { inputs: t.inputs.iter().flatten().copied().collect(), outputs: t.outputs.as_ref().unwrap().iter().flatten().copied().collect() }
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let n: usize = a[1].parse().unwrap();
    let ntr: usize = a[2].parse().unwrap();
    let epochs: u64 = a[3].parse().unwrap();
    let particles: usize = a[4].parse().unwrap();
    let m: usize = a[5].parse().unwrap();
    let dx: usize = a[6].parse().unwrap();
    let lr: f64 = a[7].parse().unwrap();
    let batch: usize = a[8].parse().unwrap();
    let mut cfg = SimulationConfig::default();
    cfg.trajectories.n_trajectories = n;
    cfg.trajectories.n_train = ntr;
    cfg.trajectories.seed = 1;
    let t0 = Instant::now();
    let ds = if std::path::Path::new(&format!("/tmp/zz_ds_{n}.npz")).exists() { flapssm_data::Dataset::load(std::path::Path::new(&format!("/tmp/zz_ds_{n}.npz"))).unwrap() } else {
    let ds = simulate_dataset(&cfg, &|| {}).unwrap();
    ds.save(std::path::Path::new(&format!("/tmp/zz_ds_{n}.npz"))).unwrap(); ds };
    println!("simulate {n}: {:.1}s", t0.elapsed().as_secs_f64());
    let t0 = Instant::now();
    let q = flapssm_qs::lrqsm::fit_dataset(&ds, Default::default(), &Default::default(), "x").unwrap();
    let qp = flapssm_qs::lrqsm::predict_dataset(&q, &ds, flapssm_qs::InterceptMode::Fitted).unwrap();
    println!("lrqsm: {:.1}s test std rmse {:?} train {:?}", t0.elapsed().as_secs_f64(), qp.rmse_test.as_ref().unwrap().standardized, qp.rmse_train.as_ref().unwrap().standardized);
    let mut spec = FitSpec::preset(Preset::Paper, 7, 5);
    spec.model.n_state = dx; spec.model.n_inducing = m; spec.particles = particles; spec.eval_particles = particles;
    spec.train.budget = Budget::Epochs(epochs); spec.train.lr = lr;
    spec.train.eval_every = 25; spec.train.batch_size = batch;
    let train: Vec<Sequence> = ds.train().iter().map(seq).collect();
    let nv = (train.len() / 10).max(1);
    let t0 = Instant::now();
    let mut prog = |e: &TrainEvent<'_>| if let TrainEvent::Epoch(r) = e { println!("ep {} loss {:.4e} tr {:?} val {:?} t {:.1}", r.epoch, r.mean_loss, r.train_rmse, r.val_rmse, t0.elapsed().as_secs_f64()); };
    let out = fit(&spec, &train[..train.len()-nv], &train[train.len()-nv..], TrainHooks { progress: Some(&mut prog), ..Default::default() }, None).unwrap();
    println!("train: {:.1}s", t0.elapsed().as_secs_f64());
    let st = ds.standardization().unwrap();
    let mut sse = [0.0; 5]; let mut nn = 0.0;
    for t in ds.test() {
        let p = predict_raw(&out.best, &seq(t), 30, 1).unwrap();
        for (k, y) in t.outputs.as_ref().unwrap().iter().enumerate().skip(93) {
            for j in 0..5 { let e = (y[j] - p.output_mean[k*5+j]) / st.std_y[j]; sse[j] += e*e; }
            nn += 1.0;
        }
    }
    let r: Vec<f64> = sse.iter().map(|s| (s/nn).sqrt()).collect();
    println!("prssm test std rmse (from 93) {r:?}");
}
