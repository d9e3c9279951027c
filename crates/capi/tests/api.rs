//! The C functions called as C calls them: every error is a status with a message naming the
//! fault, never a panic; stepping and resetting allocate nothing; the stream's memory
//! footprint for the paper's model (30 particles) is measured.

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::ffi::{CStr, CString};
use std::ptr::{null, null_mut};
use std::sync::atomic::{AtomicIsize, AtomicUsize, Ordering};

use common::{DU, inputs, published_model};
use flapssm_c::*;

/// Counts allocations and live bytes.
struct Counting;
static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);
static LIVE: AtomicIsize = AtomicIsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        LIVE.fetch_add(layout.size() as isize, Ordering::SeqCst);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size() as isize, Ordering::SeqCst);
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// The counts are process-wide: the tests run one at a time.
static SERIAL: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn last_error() -> String {
    unsafe { CStr::from_ptr(flapssm_last_error()) }
        .to_string_lossy()
        .into_owned()
}

fn load(path: &str) -> (FlapssmStatus, *mut FlapssmModel) {
    let c = CString::new(path).unwrap();
    let mut model = null_mut();
    let status = unsafe { flapssm_model_load(c.as_ptr(), &mut model) };
    (status, model)
}

#[test]
fn errors_are_statuses_with_messages() {
    let _serial = SERIAL.lock().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let (_, path) = published_model(dir.path());

    let (status, model) = load(dir.path().join("missing.json").to_str().unwrap());
    assert_eq!(status, FlapssmStatus::Io);
    assert!(model.is_null());
    assert!(last_error().contains("missing.json"), "{}", last_error());

    let not_model = dir.path().join("not-a-model.json");
    std::fs::write(&not_model, "{\"format\": \"flapssm-lrqsm\"}").unwrap();
    assert_eq!(
        load(not_model.to_str().unwrap()).0,
        FlapssmStatus::InvalidModel
    );
    assert!(last_error().contains("flapssm-lrqsm"), "{}", last_error());

    assert_eq!(
        unsafe { flapssm_model_load(null(), &mut null_mut()) },
        FlapssmStatus::NullArgument
    );
    let (status, model) = load(path.to_str().unwrap());
    assert_eq!(status, FlapssmStatus::Ok);
    unsafe {
        assert_eq!(flapssm_model_n_input(model), 7);
        assert_eq!(flapssm_model_n_output(model), 5);
        assert_eq!(flapssm_model_n_state(model), 12);
        assert_eq!(flapssm_model_n_input(null()), 0);
    }

    let mut stream = null_mut();
    assert_eq!(
        unsafe { flapssm_stream_new(model, 0, 0, &mut stream) },
        FlapssmStatus::InvalidValue
    );
    assert!(last_error().contains("particles"), "{}", last_error());
    assert_eq!(
        unsafe { flapssm_stream_new(model, 1 << 40, 0, &mut stream) },
        FlapssmStatus::InvalidValue
    );
    assert!(stream.is_null());
    assert_eq!(
        unsafe { flapssm_stream_new(model, 30, 0, &mut stream) },
        FlapssmStatus::Ok
    );
    unsafe { flapssm_model_free(model) };

    let (mut mean, mut var) = ([0.0; 5], [0.0; 5]);
    let u = [0.1; 7];
    let step = |u: &[f64], mean: &mut [f64], var: &mut [f64]| unsafe {
        flapssm_stream_step(
            stream,
            u.as_ptr(),
            u.len(),
            mean.as_mut_ptr(),
            var.as_mut_ptr(),
            mean.len(),
        )
    };
    assert_eq!(step(&u[..6], &mut mean, &mut var), FlapssmStatus::Shape);
    assert!(last_error().contains("6 inputs"), "{}", last_error());
    assert_eq!(
        step(&u, &mut mean[..4], &mut var[..4]),
        FlapssmStatus::Shape
    );
    let mut nan = u;
    nan[3] = f64::NAN;
    assert_eq!(step(&nan, &mut mean, &mut var), FlapssmStatus::InvalidValue);
    assert!(last_error().contains("input 3"), "{}", last_error());
    assert_eq!(
        unsafe { flapssm_stream_step(stream, null(), 7, mean.as_mut_ptr(), var.as_mut_ptr(), 5) },
        FlapssmStatus::NullArgument
    );
    assert_eq!(
        unsafe {
            flapssm_stream_step(
                null_mut(),
                u.as_ptr(),
                7,
                mean.as_mut_ptr(),
                var.as_mut_ptr(),
                5,
            )
        },
        FlapssmStatus::NullArgument
    );
    // A refused step leaves the stream where it was: the first accepted step is step 0
    // (every particle at x₀ = 0: mean exactly 0).
    assert_eq!(step(&u, &mut mean, &mut var), FlapssmStatus::Ok);
    assert_eq!(mean, [0.0; 5]);
    assert!(var.iter().all(|&v| v > 0.0));
    assert_eq!(
        unsafe { flapssm_stream_reset(null_mut()) },
        FlapssmStatus::NullArgument
    );
    let mut stream32 = null_mut();
    assert_eq!(
        unsafe { flapssm_single_stream_new(null(), 30, 0, &mut stream32) },
        FlapssmStatus::NullArgument
    );
    let u32 = [0.1f32; 7];
    let (mut m32, mut v32) = ([0.0f32; 5], [0.0f32; 5]);
    assert_eq!(
        unsafe {
            flapssm_single_stream_step(
                null_mut(),
                u32.as_ptr(),
                7,
                m32.as_mut_ptr(),
                v32.as_mut_ptr(),
                5,
            )
        },
        FlapssmStatus::NullArgument
    );
    assert_eq!(
        unsafe { flapssm_single_stream_reset(null_mut()) },
        FlapssmStatus::NullArgument
    );
    unsafe {
        flapssm_stream_free(stream);
        flapssm_stream_free(null_mut());
        flapssm_model_free(null_mut());
    }
}

#[test]
fn stepping_allocates_nothing_and_the_footprint_is_measured() {
    let _serial = SERIAL.lock().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let (_, path) = published_model(dir.path());
    let u = inputs();
    let (status, model) = load(path.to_str().unwrap());
    assert_eq!(status, FlapssmStatus::Ok);
    // The first GEMM on a thread reserves faer's thread-local packing buffer (private-gemm-x86:
    // 64 MiB of address space, pages resident only as touched); measured apart.
    for particles in [1, 1, 30, 100] {
        let live = LIVE.load(Ordering::SeqCst);
        let mut stream = null_mut();
        assert_eq!(
            unsafe { flapssm_stream_new(model, particles, 0, &mut stream) },
            FlapssmStatus::Ok
        );
        let footprint = LIVE.load(Ordering::SeqCst) - live;
        let live = LIVE.load(Ordering::SeqCst);
        let mut stream32 = null_mut();
        assert_eq!(
            unsafe { flapssm_single_stream_new(model, particles, 0, &mut stream32) },
            FlapssmStatus::Ok
        );
        let footprint32 = LIVE.load(Ordering::SeqCst) - live;
        let (mut mean, mut var) = ([0.0; 5], [0.0; 5]);
        let (mut mean32, mut var32) = ([0.0f32; 5], [0.0f32; 5]);
        let u32: Vec<f32> = u.iter().map(|&v| v as f32).collect();
        let before = ALLOCATIONS.load(Ordering::SeqCst);
        for (ut, ut32) in u.chunks_exact(DU).zip(u32.chunks_exact(DU)) {
            unsafe {
                let s = flapssm_stream_step(
                    stream,
                    ut.as_ptr(),
                    DU,
                    mean.as_mut_ptr(),
                    var.as_mut_ptr(),
                    5,
                );
                assert_eq!(s, FlapssmStatus::Ok);
                let s = flapssm_stream_step_f32_arrays(
                    stream,
                    ut32.as_ptr(),
                    DU,
                    mean32.as_mut_ptr(),
                    var32.as_mut_ptr(),
                    5,
                );
                assert_eq!(s, FlapssmStatus::Ok);
                let s = flapssm_single_stream_step(
                    stream32,
                    ut32.as_ptr(),
                    DU,
                    mean32.as_mut_ptr(),
                    var32.as_mut_ptr(),
                    5,
                );
                assert_eq!(s, FlapssmStatus::Ok);
                assert_eq!(flapssm_stream_reset(stream), FlapssmStatus::Ok);
                assert_eq!(flapssm_single_stream_reset(stream32), FlapssmStatus::Ok);
            }
        }
        assert_eq!(
            ALLOCATIONS.load(Ordering::SeqCst) - before,
            0,
            "allocations while stepping"
        );
        unsafe {
            flapssm_stream_free(stream);
            flapssm_single_stream_free(stream32);
        }
        let first = if footprint > 32 << 20 {
            " (the first on this thread: with the GEMM buffer)"
        } else {
            ""
        };
        println!(
            "stream of the paper's model (D_x 12, M 100), {particles} particles: \
             {footprint} bytes allocated{first}; single-precision stream {footprint32} bytes"
        );
    }
    unsafe { flapssm_model_free(model) };
}
