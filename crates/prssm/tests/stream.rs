//! Streaming predictor: identical to the batch prediction draw for draw, and no allocation
//! per step (counted by a per-thread counting global allocator).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use flapssm_prssm::params::{ModelConfig, ParamInit, Params};
use flapssm_prssm::predict;
use flapssm_prssm::stream::StreamPredictor;
use flapssm_prssm::{Normalization, PrssmModel, Sequence};

struct Counting;

thread_local! {
    static ALLOCS: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCS.with(|c| c.set(c.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCS.with(|c| c.set(c.get() + 1));
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations() -> usize {
    ALLOCS.with(|c| c.get())
}

fn model(dx: usize, dy: usize, du: usize, m: usize, shared: bool) -> PrssmModel {
    let mut config = ModelConfig::new(dx, dy, du, m);
    config.shared_draws = shared;
    let init = ParamInit {
        q_mean_scale: 0.5,
        process_noise_var: 1e-3,
        ..ParamInit::default()
    };
    let params = Params::init(&config, &init, 11);
    PrssmModel {
        config,
        params,
        normalization: Some(Normalization {
            input_mean: (0..du).map(|i| 0.3 * i as f64).collect(),
            input_std: (0..du).map(|i| 1.0 + i as f64).collect(),
            output_mean: (0..dy).map(|i| -1.0 + i as f64).collect(),
            output_std: (0..dy).map(|i| 2.0 + i as f64).collect(),
        }),
        training: serde_json::Value::Null,
    }
}

fn inputs(t_n: usize, du: usize) -> Vec<f64> {
    (0..t_n * du)
        .map(|i| (0.37 * i as f64).sin() * 2.0 + 0.1 * (i % du) as f64)
        .collect()
}

#[test]
fn streaming_equals_batch_prediction_bit_for_bit() {
    for (dx, dy, du, shared) in [(4, 1, 1, false), (6, 2, 3, false), (5, 2, 2, true)] {
        let model = model(dx, dy, du, 12, shared);
        let t_n = 60;
        let u = inputs(t_n, du);
        let seq = Sequence {
            inputs: u.clone(),
            outputs: Vec::new(),
        };
        let batch = model.predict_sequence(seq.view(), 25, 99).unwrap();
        let mut stream =
            StreamPredictor::new(&model, 25, &vec![0.0; dx], &vec![0.0; dx], 99).unwrap();
        for t in 0..t_n {
            let (m, v) = stream.step(&u[t * du..(t + 1) * du]).unwrap();
            assert_eq!(
                m,
                &batch.output_mean[t * dy..(t + 1) * dy],
                "mean, step {t}"
            );
            assert_eq!(
                v,
                &batch.output_var[t * dy..(t + 1) * dy],
                "variance, step {t}"
            );
        }
    }
}

#[test]
fn streaming_from_a_gaussian_initial_state_matches_predict() {
    let model = model(4, 1, 2, 10, false);
    let mut nonorm = model.clone();
    nonorm.normalization = None;
    let m0 = [0.5, -0.2, 0.1, 0.0];
    let s0 = [0.3, 0.1, 0.2, 0.05];
    let u = inputs(40, 2);
    let batch = predict::predict(&nonorm.config, &nonorm.params, &u, &m0, &s0, 17, 5).unwrap();
    let mut stream = StreamPredictor::new(&nonorm, 17, &m0, &s0, 5).unwrap();
    for t in 0..40 {
        let (m, v) = stream.step(&u[t * 2..t * 2 + 2]).unwrap();
        assert_eq!(m[0], batch.output_mean[t]);
        assert_eq!(v[0], batch.output_var[t]);
    }
    let err = stream.step(&[1.0]).unwrap_err().to_string();
    assert!(err.contains("expected 2"), "{err}");
    assert!(stream.step(&[f64::NAN, 0.0]).is_err());
}

#[test]
fn a_streaming_step_does_not_allocate() {
    let model = model(12, 5, 7, 100, false);
    let u = inputs(50, 7);
    let mut stream = StreamPredictor::new(&model, 30, &[0.0; 12], &[0.0; 12], 1).unwrap();
    let mut mean_stream = StreamPredictor::mean_propagated(&model, &[0.0; 12]).unwrap();
    stream.step(&u[..7]).unwrap();
    mean_stream.step(&u[..7]).unwrap();
    let before = allocations();
    let mut acc = 0.0;
    for t in 1..50 {
        let (m, v) = stream.step(&u[t * 7..(t + 1) * 7]).unwrap();
        acc += m[0] + v[0];
        let (m, _) = mean_stream.step(&u[t * 7..(t + 1) * 7]).unwrap();
        acc += m[0];
    }
    stream.reset();
    mean_stream.reset();
    let after = allocations();
    assert!(acc.is_finite());
    assert_eq!(after - before, 0, "allocations during 147 streaming steps");
}

#[test]
fn reset_repeats_the_stream_from_its_first_draws() {
    let model = model(5, 2, 2, 10, false);
    let u = inputs(30, 2);
    let m0 = [0.2, 0.0, -0.1, 0.0, 0.3];
    let s0 = [0.1; 5];
    let mut stream = StreamPredictor::new(&model, 9, &m0, &s0, 3).unwrap();
    let run = |s: &mut StreamPredictor| {
        (0..30)
            .flat_map(|t| {
                let (m, v) = s.step(&u[t * 2..t * 2 + 2]).unwrap();
                [m.to_vec(), v.to_vec()]
            })
            .collect::<Vec<_>>()
    };
    let first = run(&mut stream);
    assert_ne!(first, run(&mut stream), "a stream goes on without reset");
    stream.reset();
    assert_eq!(first, run(&mut stream));
    let mut mean_only = StreamPredictor::mean_propagated(&model, &m0).unwrap();
    let first = run(&mut mean_only);
    mean_only.reset();
    assert_eq!(first, run(&mut mean_only));
}

/// The single-precision stream follows the double-precision one (same draws) on every kind of
/// model: kernels, covariance structures, parametrizations, shared draws. Over 200 steps the
/// output means stay within 1e-3 of the output's particle standard deviation scale.
#[test]
fn the_single_precision_stream_follows_the_double_precision_one() {
    use flapssm_prssm::KernelKind;
    use flapssm_prssm::params::{CovarianceStructure, Parametrization};
    let mut worst = 0.0f64;
    for kernel in [KernelKind::Matern32, KernelKind::SquaredExponential] {
        for cov in [CovarianceStructure::Diagonal, CovarianceStructure::Full] {
            for par in [Parametrization::Unwhitened, Parametrization::Whitened] {
                for shared in [false, true] {
                    let mut m = model(6, 2, 3, 16, shared);
                    m.config.kernel = kernel;
                    m.config.covariance = cov;
                    m.config.parametrization = par;
                    m.params = Params::init(
                        &m.config,
                        &ParamInit {
                            q_mean_scale: 0.5,
                            process_noise_var: 1e-3,
                            ..ParamInit::default()
                        },
                        11,
                    );
                    let u = inputs(200, 3);
                    let mut s64 = StreamPredictor::new(&m, 20, &[0.0; 6], &[0.0; 6], 9).unwrap();
                    let mut s32 =
                        StreamPredictor::<f32>::new(&m, 20, &[0.0; 6], &[0.0; 6], 9).unwrap();
                    for t in 0..200 {
                        let ut = &u[t * 3..t * 3 + 3];
                        let u32: Vec<f32> = ut.iter().map(|&v| v as f32).collect();
                        let (m64, v64) = s64.step(ut).unwrap();
                        let (m32, v32) = s32.step(&u32).unwrap();
                        for k in 0..2 {
                            let scale = v64[k].sqrt();
                            let e = (f64::from(m32[k]) - m64[k]).abs() / scale;
                            worst = worst.max(e);
                            assert!(
                                e < 1e-3,
                                "{kernel:?} {cov:?} {par:?} shared {shared}: step {t}, output \
                                 {k}: |Δmean| = {e:e} σ"
                            );
                            assert!(v32[k] > 0.0);
                            let rv = (f64::from(v32[k]) - v64[k]).abs() / v64[k];
                            assert!(rv < 1e-2, "variance {rv:e}");
                        }
                    }
                    // A reset repeats the stream from its first draws.
                    let mut fresh =
                        StreamPredictor::<f32>::new(&m, 20, &[0.0; 6], &[0.0; 6], 9).unwrap();
                    s32.reset();
                    for t in 0..5 {
                        let u32: Vec<f32> = u[t * 3..t * 3 + 3].iter().map(|&v| v as f32).collect();
                        let a = s32.step(&u32).unwrap().0.to_vec();
                        assert_eq!(a, fresh.step(&u32).unwrap().0);
                    }
                }
            }
        }
    }
    println!("f32 stream: largest |Δmean| {worst:e} output σ");
}

#[test]
fn a_single_precision_step_does_not_allocate() {
    let model = model(12, 5, 7, 100, false);
    let u: Vec<f32> = inputs(50, 7).iter().map(|&v| v as f32).collect();
    let mut stream = StreamPredictor::<f32>::new(&model, 30, &[0.0; 12], &[0.0; 12], 1).unwrap();
    stream.step(&u[..7]).unwrap();
    let before = allocations();
    let mut acc = 0.0;
    for t in 1..50 {
        let (m, v) = stream.step(&u[t * 7..(t + 1) * 7]).unwrap();
        acc += m[0] + v[0];
    }
    stream.reset();
    assert!(acc.is_finite());
    assert_eq!(allocations() - before, 0, "allocations during 49 f32 steps");
}

/// Keeping the particles changes nothing in the moments, and the kept particles are the ones
/// the moments are taken of.
#[test]
fn kept_particles_give_the_same_prediction() {
    let m = model(4, 2, 2, 10, false);
    let u = inputs(40, 2);
    let zero = [0.0; 4];
    let plain = predict::predict(&m.config, &m.params, &u, &zero, &zero, 7, 3).unwrap();
    let (kept, all) =
        predict::predict_particles(&m.config, &m.params, &u, (&zero, &zero), 7, 3).unwrap();
    assert_eq!(plain.output_mean, kept.output_mean);
    assert_eq!(plain.latent_var, kept.latent_var);
    assert_eq!(all.len(), 40 * 7 * 4);
    for t in 0..40 {
        for d in 0..4 {
            let mean = (0..7).map(|c| all[(t * 7 + c) * 4 + d]).sum::<f64>() / 7.0;
            assert!((mean - plain.latent_mean[t * 4 + d]).abs() < 1e-12);
        }
    }
}
