//! TEMPORARY diagnostics (to be deleted).
use flapssm_wing::vortex::{Ldvm, LdvmParams, PlateState, VortexKind};
use std::f64::consts::PI;

fn eldredge(t: f64) -> (f64, f64) {
    let (amp, k, sigma) = (PI / 4.0, 0.4, 0.8);
    let a = PI * PI * k / (2.0 * amp * (1.0 - sigma));
    let (t1, t2) = (1.0, 1.0 + amp / (2.0 * k));
    let lc = |x: f64| x.abs() + (1.0 + (-2.0 * x.abs()).exp()).ln() - 2f64.ln();
    let al = 0.5 * amp * (1.0 + (lc(a * (t - t1)) - lc(a * (t - t2))) / (a * (t2 - t1)));
    let ad = 0.5 * amp * ((a * (t - t1)).tanh() - (a * (t - t2)).tanh()) / (t2 - t1);
    (al, ad)
}

#[test]
fn diag_eldredge() {
    let core: f64 = std::env::var("CORE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0.02);
    let nch: usize = std::env::var("NCH")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(24);
    let p = LdvmParams {
        chord_m: 1.0,
        u_ref_m_s: 1.0,
        rho_kg_m3: 1.0,
        pivot_frac: 0.0,
        lesp_crit: std::env::var("LESP")
            .ok()
            .map(|s| s.parse().unwrap())
            .or(Some(0.11))
            .filter(|&x: &f64| x > 0.0),
        lev_decay_chords: None,
        tev_decay_chords: None,
        far_field_chords: None,
        max_vortices: 400,
        core_radius_frac: core,
        n_chord: nch,
        ..LdvmParams::default()
    };
    let dt = 0.015;
    let mut l = Ldvm::new(p).unwrap();
    let mut i_prev = [0.0f64; 2];
    for k in 0..((5.0 / dt) as usize) {
        let t = k as f64 * dt;
        let (a, ad) = eldredge(t);
        let plate = PlateState {
            pivot_m: [-t, 0.0],
            pivot_vel_m_s: [-1.0, 0.0],
            angle_rad: -a,
            angle_rate_rad_s: -ad,
        };
        let ld = l.step(&plate, dt).unwrap();
        let d = *l.diagnostics();
        let th = -a;
        let (s, c) = th.sin_cos();
        let (tx, tz, nx, nz) = (c, s, -s, c);
        let cl = ld.normal_n_m * nz + ld.chord_n_m * tz;
        let w = l.wake();
        let le = [plate.pivot_m[0], plate.pivot_m[1]];
        let bb = d.fourier_m_s;
        let gb = -PI * (bb[0] + 0.5 * bb[1]);
        let mb = -PI * (0.25 * bb[0] + 0.25 * bb[1] - 0.125 * bb[2]);
        let mut imp = [gb * le[1] + mb * tz, -gb * le[0] - mb * tx];
        for i in 0..w.len() {
            imp[0] += w.gamma_m2_s()[i] * w.z_m()[i];
            imp[1] -= w.gamma_m2_s()[i] * w.x_m()[i];
        }
        let f = [-(imp[0] - i_prev[0]) / dt, -(imp[1] - i_prev[1]) / dt];
        i_prev = imp;
        let cn_imp = 2.0 * (f[0] * nx + f[1] * nz);
        let cl_imp = 2.0 * f[1];
        let (mut nl, mut gl, mut dmin, mut xcen, mut gsum) = (0, 0.0, f64::INFINITY, 0.0, 0.0);
        for i in 0..w.len() {
            if w.kinds()[i] == VortexKind::Lev {
                nl += 1;
                gl += w.gamma_m2_s()[i];
                let (dx, dz) = (w.x_m()[i] - plate.pivot_m[0], w.z_m()[i] - plate.pivot_m[1]);
                let xn = dx * nx + dz * nz;
                let xt = dx * tx + dz * tz;
                if xt < 1.2 {
                    dmin = dmin.min(xn);
                }
                xcen += xt * w.gamma_m2_s()[i];
                gsum += w.gamma_m2_s()[i];
            }
        }
        if std::env::var("DUMP").is_ok() && (k == 80 || k == 133) {
            for i in 0..w.len() {
                let (dx, dz) = (w.x_m()[i] - plate.pivot_m[0], w.z_m()[i] - plate.pivot_m[1]);
                println!(
                    "  V {:?} xt {:7.4} xn {:7.4} g {:7.4}",
                    w.kinds()[i],
                    dx * tx + dz * tz,
                    dx * nx + dz * nz,
                    w.gamma_m2_s()[i]
                );
            }
        }
        if k % 5 == 0 || std::env::var("ALL").is_ok() {
            println!(
                "CNimp {cn_imp:7.3} CNcor {:7.3} CN {:7.3} t {t:.3} a {:5.1} CL {cl:7.3} CN [{:7.3} {:7.3} {:7.3}] A0 {:6.3} A0u {:6.3} nlev {nl} GL {gl:7.3} dmin {dmin:6.3} xc {:6.3}",
                2.0 * d.normal_terms_n_m[3],
                2.0 * ld.normal_n_m,
                a.to_degrees(),
                2.0 * d.normal_terms_n_m[0],
                2.0 * d.normal_terms_n_m[1],
                2.0 * d.normal_terms_n_m[2],
                d.lesp,
                d.lesp_unshed,
                if gsum != 0.0 { xcen / gsum } else { 0.0 }
            );
        }
    }
}

#[test]
fn diag_hover() {
    let (c, a, w) = (0.06, 0.24, 1.25);
    let u_ref = 2.0 / PI * a * w;
    let mut l = Ldvm::new(LdvmParams { chord_m: c, u_ref_m_s: u_ref, ..LdvmParams::default() }).unwrap();
    let n = 600;
    let dt = 2.0 * PI / w / n as f64;
    let q = 0.5 * 800.0 * u_ref * u_ref * c;
    for k in 0..(2 * n) {
        let t = k as f64 * dt;
        let th = PI / 2.0 - PI / 4.0 * (w * t).sin();
        let thd = -PI / 4.0 * w * (w * t).cos();
        let p = PlateState {
            pivot_m: [a * (w * t).cos(), 0.5 * c * (2.0 * w * t).sin()],
            pivot_vel_m_s: [-a * w * (w * t).sin(), c * w * (2.0 * w * t).cos()],
            angle_rad: th,
            angle_rate_rad_s: thd,
        };
        let ld = l.step(&p, dt).unwrap();
        let d = *l.diagnostics();
        if k % 10 == 0 || (ld.normal_n_m / q).abs() > 10.0 {
            println!("k {k} CN {:8.3} terms {:8.3} {:8.3} {:8.3} {:8.3} lesp {:6.3} lev {:8.5} nv {}", ld.normal_n_m / q,
                d.normal_terms_n_m[0] / q, d.normal_terms_n_m[1] / q, d.normal_terms_n_m[2] / q, d.normal_terms_n_m[3] / q, d.lesp, d.lev_m2_s, d.n_vortices);
        }
    }
}
