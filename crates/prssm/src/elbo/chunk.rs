//! One chunk of windows through the particle ELBO: the noise draws, the forward pass (states,
//! likelihood, the tape of the last segment) and the reverse pass (adjoints of the states, the
//! conditional's parameters and the noise variances), in that order.
//!
//! Columns are `window × particle` (`N = n_windows · P`), states row-major `N × D_x` per step.
//! The windows of a chunk are sorted by length, descending, so the active columns at step `t`
//! are a prefix.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

use super::{ChunkOut, ChunkScratch, Elbo, InitialStates};
use crate::conditional::{self, ConditionalGrads, ConditionalWorkspace, Posterior};
use crate::objective::Window;
use crate::params::Params;
use crate::tape::TapeMemory;

/// What every step of a chunk reads: sizes, the windows, the noise variances and the draws.
struct Chunk<'a> {
    elbo: &'a Elbo,
    post: &'a Posterior,
    batch: &'a [Window],
    chunk: &'a [usize],
    /// `(D_x, D_y, D_u, D = D_x + D_u)`.
    dims: (usize, usize, usize, usize),
    /// Particles per window.
    np: usize,
    /// `D_x · N`: values of one step's states.
    step: usize,
    /// Steps of the longest window, and its transitions (`t_max − 1`).
    t_max: usize,
    n_steps: usize,
    /// Active columns at step `t`.
    active: Vec<usize>,
    /// Burn-in steps of each window (no likelihood before them).
    burn: Vec<usize>,
    vx: &'a [f64],
    vy: &'a [f64],
    /// `½ ln(2π σ_y²)` per output.
    half_log_2pi_v: Vec<f64>,
    jitter: f64,
    lik_scale: f64,
    /// Values of one step's tape, and steps per recomputed segment.
    tape_step: usize,
    seg: usize,
}

/// The buffers a chunk writes (reused across chunks through the scratch pool).
struct Buffers {
    /// States, `t_max × D_x × N`.
    xs: Vec<f64>,
    /// Transition draws, `(t_max − 1) × D_x × N`.
    eps: Vec<f64>,
    /// Initial-state draws, `D_x × N`.
    eps0: Vec<f64>,
    /// Standard deviations √(σ² + σ_x² + δ), `(t_max − 1) × D_x × N`.
    sds: Vec<f64>,
    tape: TapeMemory,
    ws: ConditionalWorkspace,
}

/// The reverse pass's results.
struct Adjoints {
    cond: ConditionalGrads,
    vx_bar: Vec<f64>,
    vy_bar: Vec<f64>,
    /// `∂loss/∂x₀`, `D_x × N`.
    xbar: Vec<f64>,
}

impl Elbo {
    /// Loss and gradients of one chunk of `batch` (`chunk`: window indices, longest first).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn run_chunk(
        &self,
        post: &Posterior,
        p: &Params,
        batch: &[Window],
        chunk: &[usize],
        init: InitialStates<'_>,
        seed: u64,
        lik_scale: f64,
    ) -> ChunkOut {
        let c = Chunk::new(self, post, p, batch, chunk, lik_scale);
        let mut b = c.buffers(self.scratch.take());
        c.draw(seed, &init, &mut b);
        let nll = c.forward(&mut b);
        let adj = c.backward(&mut b);
        let (init_mean, init_std) = c.initial_state_grads(&adj.xbar, &b.eps0);
        self.scratch.put(ChunkScratch {
            tape: b.tape,
            xs: b.xs,
            eps: b.eps,
            sds: b.sds,
            ws: Some(b.ws),
        });
        ChunkOut {
            nll,
            cond: adj.cond,
            process_noise: adj.vx_bar,
            obs_noise: adj.vy_bar,
            init_mean,
            init_std,
        }
    }
}

impl<'a> Chunk<'a> {
    fn new(
        elbo: &'a Elbo,
        post: &'a Posterior,
        p: &'a Params,
        batch: &'a [Window],
        chunk: &'a [usize],
        lik_scale: f64,
    ) -> Self {
        let cfg = &elbo.config;
        let dims = (cfg.n_state, cfg.n_output, cfg.n_input, cfg.n_gp_input());
        let np = elbo.options.particles;
        let n = chunk.len() * np;
        let t_max = chunk.iter().map(|&i| batch[i].len).max().unwrap_or(0);
        let active = (0..t_max)
            .map(|t| chunk.iter().filter(|&&i| batch[i].len > t).count() * np)
            .collect();
        let burn = chunk
            .iter()
            .map(|&i| (elbo.options.burn_in_fraction * batch[i].len as f64).floor() as usize)
            .collect();
        let half_log_2pi_v = p
            .obs_noise_var
            .iter()
            .map(|v| 0.5 * (2.0 * std::f64::consts::PI * v).ln())
            .collect();
        // Per-step intermediates for the reverse mode: steps of segment `t / seg` share the
        // tape; the forward pass leaves the last segment in it, earlier segments are
        // recomputed from the stored states (identical arithmetic, so identical values).
        let tape_step = conditional::tape_len(post, n);
        let n_steps = t_max.saturating_sub(1);
        let seg = (elbo.tape_budget_bytes / (8 * tape_step.max(1))).clamp(1, n_steps.max(1));
        Self {
            elbo,
            post,
            batch,
            chunk,
            dims,
            np,
            step: dims.0 * n,
            t_max,
            n_steps,
            active,
            burn,
            vx: &p.process_noise_var,
            vy: &p.obs_noise_var,
            half_log_2pi_v,
            jitter: cfg.transition_jitter,
            lik_scale,
            tape_step,
            seg,
        }
    }

    /// The scratch buffers sized for this chunk.
    fn buffers(&self, mut scratch: ChunkScratch) -> Buffers {
        let n = self.step / self.dims.0.max(1);
        let mut xs = std::mem::take(&mut scratch.xs);
        xs.resize(self.t_max * self.step, 0.0);
        let mut eps = std::mem::take(&mut scratch.eps);
        eps.resize(self.n_steps * self.step, 0.0);
        let mut sds = std::mem::take(&mut scratch.sds);
        sds.resize(self.n_steps * self.step, 0.0);
        let mut ws = match scratch.ws.take() {
            Some(ws) if ws.fits(self.post, n) => ws,
            _ => ConditionalWorkspace::new(self.post, n),
        };
        ws.set_input_group(self.np);
        Buffers {
            xs,
            eps,
            eps0: vec![0.0; self.step],
            sds,
            tape: std::mem::take(&mut scratch.tape),
            ws,
        }
    }

    /// Draws `ε₀` and the transition noise of every window (stream = the window's index in the
    /// batch, so a window draws the same numbers in any chunk) and sets `x₀ = m₀ + s₀ ε₀`.
    fn draw(&self, seed: u64, init: &InitialStates<'_>, b: &mut Buffers) {
        let (dx, ..) = self.dims;
        let (np, step) = (self.np, self.step);
        let shared = self.elbo.config.shared_draws;
        for (k, &bi) in self.chunk.iter().enumerate() {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            rng.set_stream(bi as u64);
            let cols = k * np..(k + 1) * np;
            for c in cols.clone() {
                for dd in 0..dx {
                    b.eps0[c * dx + dd] = StandardNormal.sample(&mut rng);
                }
            }
            for t in 0..self.batch[bi].len - 1 {
                let e = &mut b.eps[t * step..(t + 1) * step];
                for c in cols.clone() {
                    if shared {
                        let v: f64 = StandardNormal.sample(&mut rng);
                        e[c * dx..(c + 1) * dx].fill(v);
                    } else {
                        for dd in 0..dx {
                            e[c * dx + dd] = StandardNormal.sample(&mut rng);
                        }
                    }
                }
            }
            for c in cols {
                for dd in 0..dx {
                    b.xs[c * dx + dd] =
                        init.mean[bi * dx + dd] + init.std[bi * dx + dd] * b.eps0[c * dx + dd];
                }
            }
        }
    }

    /// The GP input `[x, u_t]` of the first `na` columns.
    fn fill_input(&self, ws: &mut ConditionalWorkspace, x: &[f64], t: usize, na: usize) {
        let (dx, _, du, d) = self.dims;
        for c in 0..na {
            let w = self.batch[self.chunk[c / self.np]];
            let u = &self.elbo.data.sequences[w.sequence].inputs
                [(w.start + t) * du..(w.start + t + 1) * du];
            ws.input[c * d..c * d + dx].copy_from_slice(&x[c * dx..(c + 1) * dx]);
            ws.input[c * d + dx..(c + 1) * d].copy_from_slice(u);
        }
    }

    /// Likelihood at step `t` (scaled): its value, and with `adjoints = (x̄, σ̄_y²)` its
    /// adjoints added to them.
    fn likelihood(
        &self,
        x: &[f64],
        t: usize,
        mut adjoints: Option<(&mut [f64], &mut [f64])>,
    ) -> f64 {
        let (dx, dy, ..) = self.dims;
        let (vy, np, lik_scale) = (self.vy, self.np, self.lik_scale);
        let mut acc = 0.0;
        for (k, &bi) in self.chunk.iter().enumerate() {
            let w = self.batch[bi];
            if t >= w.len || t < self.burn[k] {
                continue;
            }
            let y = &self.elbo.data.sequences[w.sequence].outputs
                [(w.start + t) * dy..(w.start + t + 1) * dy];
            for c in k * np..(k + 1) * np {
                for dd in 0..dy {
                    let r = y[dd] - x[c * dx + dd];
                    acc += self.half_log_2pi_v[dd] + 0.5 * r * r / vy[dd];
                    if let Some((xb, vy_bar)) = adjoints.as_mut() {
                        xb[c * dx + dd] -= lik_scale * r / vy[dd];
                        vy_bar[dd] += lik_scale * 0.5 * (1.0 / vy[dd] - r * r / (vy[dd] * vy[dd]));
                    }
                }
            }
        }
        acc * lik_scale
    }

    /// Transition `t → t + 1`: `x_{t+1} = x_t + μ + sd·ε` with `sd = √(σ² + σ_x² + δ)`, the
    /// conditional's intermediates written to `tape`.
    fn propagate(
        &self,
        ws: &mut ConditionalWorkspace,
        tape: &mut [f64],
        xs: &mut [f64],
        sds: &mut [f64],
        eps: &[f64],
        t: usize,
    ) {
        let (dx, ..) = self.dims;
        let step = self.step;
        let (cur, next) = xs.split_at_mut((t + 1) * step);
        let x = &cur[t * step..];
        let na = self.active[t + 1];
        self.fill_input(ws, x, t, na);
        ws.forward_tape(self.post, na, tape);
        let e = &eps[t * step..];
        let xn = &mut next[..step];
        let sd_t = &mut sds[t * step..(t + 1) * step];
        let k = dx * na;
        let cols = sd_t[..k]
            .chunks_exact_mut(dx)
            .zip(xn[..k].chunks_exact_mut(dx))
            .zip(x[..k].chunks_exact(dx))
            .zip(ws.var[..k].chunks_exact(dx))
            .zip(ws.mean[..k].chunks_exact(dx))
            .zip(e[..k].chunks_exact(dx));
        for (((((sd, xn), x), var), mean), e) in cols {
            for dd in 0..dx {
                sd[dd] = (var[dd] + self.vx[dd] + self.jitter).sqrt();
                xn[dd] = x[dd] + mean[dd] + sd[dd] * e[dd];
            }
        }
    }

    /// Runs every step forward; returns the scaled negative log-likelihood.
    fn forward(&self, b: &mut Buffers) -> f64 {
        let (step, tape_step, seg) = (self.step, self.tape_step, self.seg);
        let tape = b.tape.reserve(seg.min(self.n_steps) * tape_step);
        let mut nll = 0.0;
        for t in 0..self.t_max {
            nll += self.likelihood(&b.xs[t * step..(t + 1) * step], t, None);
            if t < self.n_steps {
                let slot = (t % seg) * tape_step;
                self.propagate(
                    &mut b.ws,
                    &mut tape[slot..slot + tape_step],
                    &mut b.xs,
                    &mut b.sds,
                    &b.eps,
                    t,
                );
            }
        }
        nll
    }

    /// Runs every step backward from the last, recomputing earlier tape segments as needed.
    fn backward(&self, b: &mut Buffers) -> Adjoints {
        let (dx, dy, ..) = self.dims;
        let (step, tape_step, seg, n_steps) = (self.step, self.tape_step, self.seg, self.n_steps);
        let tape = b.tape.reserve(seg.min(n_steps) * tape_step);
        let mut adj = Adjoints {
            cond: ConditionalGrads::zeros(self.post),
            vx_bar: vec![0.0; dx],
            vy_bar: vec![0.0; dy],
            xbar: vec![0.0; step],
        };
        let mut mean_bar = vec![0.0; step];
        let mut var_bar = vec![0.0; step];
        let last_seg = n_steps.saturating_sub(1) / seg;
        for t in (0..self.t_max).rev() {
            if t < n_steps {
                let s = t / seg;
                if s != last_seg && (t + 1) % seg == 0 {
                    // Recompute segment s (steps s·seg ..= t) into the tape; the states it
                    // rewrites come out identical.
                    for r in s * seg..=t {
                        let slot = (r % seg) * tape_step;
                        self.propagate(
                            &mut b.ws,
                            &mut tape[slot..slot + tape_step],
                            &mut b.xs,
                            &mut b.sds,
                            &b.eps,
                            r,
                        );
                    }
                }
                let na = self.active[t + 1];
                let e = &b.eps[t * step..];
                let sd_t = &b.sds[t * step..];
                let k = dx * na;
                mean_bar[..k].copy_from_slice(&adj.xbar[..k]);
                // Elementwise (vectorizes), then the σ_x² adjoint summed in the same order.
                for (((vb, &xb), &ei), &sd) in
                    var_bar[..k].iter_mut().zip(&adj.xbar).zip(e).zip(sd_t)
                {
                    *vb = xb * ei / (2.0 * sd);
                }
                for vb in var_bar[..k].chunks_exact(dx) {
                    adj.vx_bar.iter_mut().zip(vb).for_each(|(a, b)| *a += b);
                }
                let slot = (t % seg) * tape_step;
                b.ws.backward_tape(
                    self.post,
                    na,
                    &mut tape[slot..slot + tape_step],
                    (&mean_bar[..dx * na], &var_bar[..dx * na]),
                    &mut adj.cond,
                    (&mut adj.xbar, dx),
                );
            }
            self.likelihood(
                &b.xs[t * step..(t + 1) * step],
                t,
                Some((&mut adj.xbar, &mut adj.vy_bar)),
            );
        }
        adj
    }

    /// `∂loss/∂m₀` and `∂loss/∂s₀` per window, `n_windows × D_x`: sums over its particles of
    /// `x̄₀` and `x̄₀ ε₀`.
    fn initial_state_grads(&self, xbar: &[f64], eps0: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let (dx, ..) = self.dims;
        let nb = self.chunk.len();
        let mut init_mean = vec![0.0; nb * dx];
        let mut init_std = vec![0.0; nb * dx];
        for k in 0..nb {
            for c in k * self.np..(k + 1) * self.np {
                for dd in 0..dx {
                    init_mean[k * dx + dd] += xbar[c * dx + dd];
                    init_std[k * dx + dd] += xbar[c * dx + dd] * eps0[c * dx + dd];
                }
            }
        }
        (init_mean, init_std)
    }
}
