//! The GMM fit, the model selection and the parametric bootstrap (see the module
//! docs of [`super`] for the method).

use rayon::prelude::*;

use super::{
    CRITERION, CandidateScore, GmwmConfig, GmwmFit, GmwmTerm, Process, ProcessParams,
    WaveletVariance, raw_wavelet_variance,
};
use crate::allan::AllanError;
use crate::allan::fit::{Term, normal_quantile};
use crate::sim::noise::{GaussMarkovConfig, StaticNoiseConfig, generate};
use crate::sim::rng::splitmix64;

/// Bounds of a transformed amplitude coordinate ln(value²).
const LN_AMP_MIN: f64 = -600.0;
const LN_AMP_MAX: f64 = 600.0;
/// Correlation-time grid points of the variable-projection starts.
const T_GRID: usize = 10;
/// Starts polished by Levenberg–Marquardt.
const N_STARTS: usize = 3;
/// Reweighting rounds after the data-weighted one.
const REWEIGHT_ROUNDS: usize = 2;

/// A model structure: processes in the order Q, N, K, R, then the Gauss–Markov terms.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Spec {
    pub procs: Vec<Process>,
}

impl Spec {
    pub fn n_params(&self) -> usize {
        self.procs
            .iter()
            .map(|p| if *p == Process::GaussMarkov { 2 } else { 1 })
            .sum()
    }

    pub(crate) fn n_gm(&self) -> usize {
        self.procs
            .iter()
            .filter(|p| **p == Process::GaussMarkov)
            .count()
    }

    pub fn label(&self) -> String {
        let mut parts: Vec<String> = self
            .procs
            .iter()
            .filter(|p| **p != Process::GaussMarkov)
            .map(|p| p.label().to_string())
            .collect();
        match self.n_gm() {
            0 => {}
            1 => parts.push("GM".into()),
            g => parts.push(format!("{g}GM")),
        }
        parts.join("+")
    }

    /// Parameters from the transformed vector θ (ln amplitude², ln T).
    pub fn decode(&self, th: &[f64]) -> Vec<ProcessParams> {
        let mut out = Vec::with_capacity(self.procs.len());
        let mut i = 0;
        for p in &self.procs {
            let a = (0.5 * th[i]).exp();
            out.push(match p {
                Process::Quantization => ProcessParams::Quantization { q: a },
                Process::White => ProcessParams::White { n: a },
                Process::RandomWalk => ProcessParams::RandomWalk { k: a },
                Process::Drift => ProcessParams::Drift { r: a },
                Process::GaussMarkov => {
                    i += 1;
                    ProcessParams::GaussMarkov {
                        sigma: a,
                        tau_c_s: th[i].exp(),
                    }
                }
            });
            i += 1;
        }
        out
    }

    /// Sort the Gauss–Markov (ln σ², ln T) pairs of θ by increasing T (they are
    /// exchangeable; the order makes replicates comparable).
    pub(crate) fn sort_gm(&self, th: &mut [f64]) {
        let first = self.n_params() - 2 * self.n_gm();
        let mut pairs: Vec<(f64, f64)> = th[first..].chunks(2).map(|c| (c[0], c[1])).collect();
        pairs.sort_by(|a, b| a.1.total_cmp(&b.1));
        for (k, (s, t)) in pairs.into_iter().enumerate() {
            th[first + 2 * k] = s;
            th[first + 2 * k + 1] = t;
        }
    }
}

/// Every candidate structure the configuration allows (at least one process, fewer
/// parameters than scales).
pub(crate) fn candidates(cfg: &GmwmConfig, n_scales: usize) -> Vec<Spec> {
    let allowed = [
        (cfg.quantization, Process::Quantization),
        (cfg.white, Process::White),
        (cfg.random_walk, Process::RandomWalk),
        (cfg.drift, Process::Drift),
    ];
    let mut out = Vec::new();
    for mask in 0u32..16 {
        if allowed
            .iter()
            .enumerate()
            .any(|(i, (on, _))| mask & (1 << i) != 0 && !on)
        {
            continue;
        }
        for g in 0..=cfg.max_gauss_markov.min(super::MAX_GAUSS_MARKOV) {
            let mut procs: Vec<Process> = allowed
                .iter()
                .enumerate()
                .filter(|(i, _)| mask & (1 << i) != 0)
                .map(|(_, (_, p))| *p)
                .collect();
            procs.extend(std::iter::repeat_n(Process::GaussMarkov, g));
            let spec = Spec { procs };
            if !spec.procs.is_empty() && spec.n_params() < n_scales {
                out.push(spec);
            }
        }
    }
    out
}

/// One GMM problem: the measured WV and its η₃ EDFs at averaging lengths `ms`.
pub(crate) struct Problem<'a> {
    pub ms: Vec<f64>,
    pub tau0_s: f64,
    pub nu: &'a [f64],
    pub edf: &'a [f64],
    pub ln_t_min: f64,
    pub ln_t_max: f64,
    pub span_s: f64,
}

impl Problem<'_> {
    fn model(&self, spec: &Spec, th: &[f64]) -> Vec<f64> {
        let params = spec.decode(th);
        self.ms
            .iter()
            .map(|&m| params.iter().map(|p| p.wv(m, self.tau0_s)).sum())
            .collect()
    }

    /// Ω_jj = η_j/(2ν_j²) at WV values `v` (the inverse χ² variance).
    fn weights(&self, v: &[f64]) -> Vec<f64> {
        v.iter()
            .zip(self.edf)
            .map(|(&v, &e)| {
                let v = v.max(f64::MIN_POSITIVE);
                e / (2.0 * v * v)
            })
            .collect()
    }

    fn residuals(&self, spec: &Spec, th: &[f64], w: &[f64]) -> Vec<f64> {
        self.model(spec, th)
            .iter()
            .zip(self.nu)
            .zip(w)
            .map(|((m, n), w)| w.sqrt() * (n - m))
            .collect()
    }

    fn cost(&self, spec: &Spec, th: &[f64], w: &[f64]) -> f64 {
        let c: f64 = self.residuals(spec, th, w).iter().map(|r| r * r).sum();
        if c.is_finite() { c } else { f64::INFINITY }
    }

    fn clamp(&self, spec: &Spec, th: &mut [f64]) {
        let mut i = 0;
        for p in &spec.procs {
            th[i] = th[i].clamp(LN_AMP_MIN, LN_AMP_MAX);
            if *p == Process::GaussMarkov {
                i += 1;
                th[i] = th[i].clamp(self.ln_t_min, self.ln_t_max);
            }
            i += 1;
        }
    }

    /// Levenberg–Marquardt on the weighted residuals, weights fixed.
    fn lm(&self, spec: &Spec, th0: &[f64], w: &[f64], max_iter: usize) -> (Vec<f64>, f64) {
        let p = th0.len();
        let mut th = th0.to_vec();
        self.clamp(spec, &mut th);
        let mut r = self.residuals(spec, &th, w);
        let mut cost: f64 = r.iter().map(|v| v * v).sum();
        if !cost.is_finite() {
            return (th, f64::INFINITY);
        }
        let mut lambda = 1e-3;
        let h = 1e-5;
        for _ in 0..max_iter {
            // Jacobian of the residuals, central differences.
            let mut jac = vec![vec![0.0; p]; r.len()];
            for i in 0..p {
                let mut tp = th.clone();
                let mut tm = th.clone();
                tp[i] += h;
                tm[i] -= h;
                let rp = self.residuals(spec, &tp, w);
                let rm = self.residuals(spec, &tm, w);
                for j in 0..r.len() {
                    jac[j][i] = (rp[j] - rm[j]) / (2.0 * h);
                }
            }
            let mut a = vec![vec![0.0; p]; p];
            let mut g = vec![0.0; p];
            for (row, rj) in jac.iter().zip(&r) {
                for i in 0..p {
                    g[i] += row[i] * rj;
                    for k in 0..p {
                        a[i][k] += row[i] * row[k];
                    }
                }
            }
            let dmax = (0..p).map(|i| a[i][i]).fold(0.0, f64::max);
            if !(dmax.is_finite() && dmax > 0.0) {
                break;
            }
            let mut improved = None;
            while lambda < 1e12 {
                let mut m = a.clone();
                for (i, row) in m.iter_mut().enumerate() {
                    row[i] += lambda * row[i].max(1e-12 * dmax);
                }
                let neg_g: Vec<f64> = g.iter().map(|v| -v).collect();
                let Some(step) = solve_linear(m, neg_g) else {
                    lambda *= 4.0;
                    continue;
                };
                let mut tn: Vec<f64> = th.iter().zip(&step).map(|(t, s)| t + s).collect();
                self.clamp(spec, &mut tn);
                let rn = self.residuals(spec, &tn, w);
                let cn: f64 = rn.iter().map(|v| v * v).sum();
                if cn.is_finite() && cn < cost {
                    improved = Some((tn, rn, cn));
                    lambda = (lambda / 3.0).max(1e-12);
                    break;
                }
                lambda *= 4.0;
            }
            match improved {
                Some((tn, rn, cn)) => {
                    let done = cost - cn <= 1e-12 * cost;
                    th = tn;
                    r = rn;
                    cost = cn;
                    if done {
                        break;
                    }
                }
                None => break,
            }
        }
        (th, cost)
    }

    /// Starting points: correlation times on a log grid, amplitudes by weighted
    /// non-negative least squares for each grid combination; the best `N_STARTS`.
    fn starts(&self, spec: &Spec, w: &[f64]) -> Vec<Vec<f64>> {
        let g = spec.n_gm();
        let t_lo = 2.0 * self.tau0_s;
        let t_hi = (self.span_s / 2.0).max(4.0 * t_lo);
        let grid: Vec<f64> = (0..T_GRID)
            .map(|i| t_lo * (t_hi / t_lo).powf(i as f64 / (T_GRID - 1) as f64))
            .collect();
        let mut combos: Vec<Vec<usize>> = vec![Vec::new()];
        for _ in 0..g {
            combos = combos
                .into_iter()
                .flat_map(|c| {
                    let start = c.last().map_or(0, |&l| l + 1);
                    (start..T_GRID).map(move |i| {
                        let mut n = c.clone();
                        n.push(i);
                        n
                    })
                })
                .collect();
        }
        let mut scored: Vec<(f64, Vec<f64>)> = combos
            .iter()
            .map(|combo| {
                let mut taus = combo.iter().map(|&i| grid[i]);
                let cols: Vec<Vec<f64>> = spec
                    .procs
                    .iter()
                    .map(|p| {
                        let unit = match p {
                            Process::Quantization => ProcessParams::Quantization { q: 1.0 },
                            Process::White => ProcessParams::White { n: 1.0 },
                            Process::RandomWalk => ProcessParams::RandomWalk { k: 1.0 },
                            Process::Drift => ProcessParams::Drift { r: 1.0 },
                            Process::GaussMarkov => ProcessParams::GaussMarkov {
                                sigma: 1.0,
                                tau_c_s: taus.next().unwrap_or(t_lo),
                            },
                        };
                        self.ms.iter().map(|&m| unit.wv(m, self.tau0_s)).collect()
                    })
                    .collect();
                let (amp2, cost) = nnls_cd(&cols, self.nu, w);
                let mut th = Vec::with_capacity(spec.n_params());
                let mut taus = combo.iter().map(|&i| grid[i]);
                for ((p, a), col) in spec.procs.iter().zip(&amp2).zip(&cols) {
                    // A zero amplitude cannot be a log: start it small instead.
                    let single = single_ls(col, self.nu, w);
                    th.push(a.max(1e-6 * single).max(1e-300).ln());
                    if *p == Process::GaussMarkov {
                        th.push(taus.next().unwrap_or(t_lo).ln());
                    }
                }
                (cost, th)
            })
            .collect();
        scored.sort_by(|a, b| a.0.total_cmp(&b.0));
        scored.into_iter().take(N_STARTS).map(|s| s.1).collect()
    }

    /// Full fit of one structure: data-weighted multi-start, then model-weighted
    /// refinement. Returns θ̂ (Gauss–Markov terms sorted by T) and J(θ̂).
    pub fn fit(&self, spec: &Spec) -> (Vec<f64>, f64) {
        let w0 = self.weights(self.nu);
        let mut best = (Vec::new(), f64::INFINITY);
        for s in self.starts(spec, &w0) {
            let (th, c) = self.lm(spec, &s, &w0, 300);
            if c < best.1 || best.0.is_empty() {
                best = (th, c);
            }
        }
        self.refine(spec, best.0, REWEIGHT_ROUNDS)
    }

    /// `rounds` × (weights from the model at θ, LM from θ); returns θ and J with the
    /// weights of the final θ.
    pub(crate) fn refine(&self, spec: &Spec, mut th: Vec<f64>, rounds: usize) -> (Vec<f64>, f64) {
        for _ in 0..rounds {
            let w = self.weights(&self.model(spec, &th));
            th = self.lm(spec, &th, &w, 300).0;
        }
        spec.sort_gm(&mut th);
        let w = self.weights(&self.model(spec, &th));
        let j = self.cost(spec, &th, &w);
        (th, j)
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Weighted least-squares amplitude of one column alone.
fn single_ls(col: &[f64], y: &[f64], w: &[f64]) -> f64 {
    let (num, den) = col
        .iter()
        .zip(y)
        .zip(w)
        .fold((0.0, 0.0), |(n, d), ((c, y), w)| {
            (n + w * c * y, d + w * c * c)
        });
    if den > 0.0 { (num / den).max(0.0) } else { 0.0 }
}

/// Non-negative weighted least squares by cyclic coordinate descent (each coordinate
/// minimised exactly in turn, clamped at zero): min Σ w_j (y_j − Σ a_i c_ij)², a ≥ 0.
fn nnls_cd(cols: &[Vec<f64>], y: &[f64], w: &[f64]) -> (Vec<f64>, f64) {
    let mut a = vec![0.0; cols.len()];
    let mut r: Vec<f64> = y.to_vec();
    let den: Vec<f64> = cols
        .iter()
        .map(|c| c.iter().zip(w).map(|(c, w)| w * c * c).sum())
        .collect();
    for _ in 0..300 {
        let mut change = 0.0f64;
        for (i, c) in cols.iter().enumerate() {
            if den[i].is_nan() || den[i] <= 0.0 {
                continue;
            }
            let num: f64 = c.iter().zip(&r).zip(w).map(|((c, r), w)| w * c * r).sum();
            let new = (a[i] + num / den[i]).max(0.0);
            let d = new - a[i];
            if d != 0.0 {
                for (rj, cj) in r.iter_mut().zip(c) {
                    *rj -= d * cj;
                }
                change = change.max((d / new.max(f64::MIN_POSITIVE)).abs());
                a[i] = new;
            }
        }
        if change < 1e-8 {
            break;
        }
    }
    let cost = r.iter().zip(w).map(|(r, w)| w * r * r).sum();
    (a, cost)
}

/// Solve a small dense system by Gaussian elimination with partial pivoting.
fn solve_linear(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Option<Vec<f64>> {
    let n = b.len();
    for col in 0..n {
        let piv = (col..n).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if !(a[piv][col].abs() > 0.0 && a[piv][col].is_finite()) {
            return None;
        }
        a.swap(col, piv);
        b.swap(col, piv);
        let (top, bottom) = a.split_at_mut(col + 1);
        let pivot = &top[col];
        for (k, row) in bottom.iter_mut().enumerate() {
            let f = row[col] / pivot[col];
            for (x, p) in row[col..].iter_mut().zip(&pivot[col..]) {
                *x -= f * p;
            }
            b[col + 1 + k] -= f * b[col];
        }
    }
    let mut x = vec![0.0; n];
    for i in (0..n).rev() {
        let s: f64 = (i + 1..n).map(|k| a[i][k] * x[k]).sum();
        x[i] = (b[i] - s) / a[i][i];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// Simulate one realisation of `params` with the given segment lengths (independent
/// segments, rate samples at `tau0_s`), using the product's noise simulator
/// ([`crate::sim::noise::generate`]; quantization noise is uniform there, every other
/// process Gaussian). Reproducible from `seed`.
pub fn simulate(
    params: &[ProcessParams],
    segment_samples: &[usize],
    tau0_s: f64,
    seed: u64,
) -> Result<Vec<Vec<f64>>, AllanError> {
    let mut segs = Vec::with_capacity(segment_samples.len());
    for (s, &n) in segment_samples.iter().enumerate() {
        let base = StaticNoiseConfig {
            sample_rate_hz: 1.0 / tau0_s,
            duration_s: n as f64 * tau0_s,
            ..StaticNoiseConfig::default()
        };
        let mut main = base.clone();
        let mut extra_gm = Vec::new();
        for p in params {
            match *p {
                ProcessParams::Quantization { q } => main.quantization = q,
                ProcessParams::White { n } => main.white = n,
                ProcessParams::RandomWalk { k } => main.rate_random_walk = k,
                ProcessParams::Drift { r } => main.rate_ramp = r,
                ProcessParams::GaussMarkov { sigma, tau_c_s } => {
                    let gm = Some(GaussMarkovConfig { sigma, tau_c_s });
                    if main.gauss_markov.is_none() {
                        main.gauss_markov = gm;
                    } else {
                        extra_gm.push(StaticNoiseConfig {
                            gauss_markov: gm,
                            ..base.clone()
                        });
                    }
                }
            }
        }
        let mut st = seed ^ (s as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        let sim_err = |e: crate::sim::noise::SimError| {
            AllanError::Invalid(format!("GMWM bootstrap simulation: {e}"))
        };
        let mut y = generate(&main, splitmix64(&mut st)).map_err(sim_err)?;
        for c in &extra_gm {
            let z = generate(c, splitmix64(&mut st)).map_err(sim_err)?;
            for (a, b) in y.iter_mut().zip(z) {
                *a += b;
            }
        }
        segs.push(y);
    }
    Ok(segs)
}

/// Fit the GMWM model to a wavelet variance: every candidate structure of `cfg`, the
/// lowest WIC selected, bootstrap intervals for its parameters.
pub fn fit_gmwm(wv: &WaveletVariance, cfg: &GmwmConfig) -> Result<GmwmFit, AllanError> {
    if !(cfg.confidence > 0.0 && cfg.confidence < 1.0) {
        return Err(AllanError::Invalid(format!(
            "confidence level must be between 0 and 1, got {}",
            cfg.confidence
        )));
    }
    if let Some(j) = wv.wv.iter().position(|v| !(v.is_finite() && *v > 0.0)) {
        return Err(AllanError::Invalid(format!(
            "the wavelet variance is {} at tau = {} s: the data do not vary over that \
             scale (constant or stuck at one quantization step); GMWM needs noise at every \
             scale",
            wv.wv[j], wv.tau_s[j]
        )));
    }
    let longest = wv.segment_samples.iter().copied().max().unwrap_or(0);
    let span_s = longest as f64 * wv.tau0_s;
    let prob = Problem {
        ms: wv.m.iter().map(|&m| m as f64).collect(),
        tau0_s: wv.tau0_s,
        nu: &wv.wv,
        edf: &wv.edf,
        ln_t_min: (0.05 * wv.tau0_s).ln(),
        ln_t_max: (1e3 * span_s).ln(),
        span_s,
    };
    let specs = candidates(cfg, wv.m.len());
    if specs.is_empty() {
        return Err(AllanError::Invalid(format!(
            "no GMWM candidate model fits in {} wavelet scales (enable a process or use a \
             longer log)",
            wv.m.len()
        )));
    }
    let fits: Vec<(Vec<f64>, f64)> = specs.par_iter().map(|s| prob.fit(s)).collect();
    let mut scores: Vec<(usize, CandidateScore)> = specs
        .iter()
        .zip(&fits)
        .enumerate()
        .map(|(i, (s, (_, j)))| {
            (
                i,
                CandidateScore {
                    model: s.label(),
                    n_params: s.n_params(),
                    objective: *j,
                    wic: j + 2.0 * s.n_params() as f64,
                },
            )
        })
        .collect();
    scores.sort_by(|a, b| a.1.wic.total_cmp(&b.1.wic));
    let best = scores[0].0;
    if !scores[0].1.wic.is_finite() {
        return Err(AllanError::Invalid(
            "the GMWM fit did not converge for any candidate model".into(),
        ));
    }
    let spec = &specs[best];
    let (th, objective) = fits[best].clone();

    // Parametric bootstrap of θ̂.
    let params = spec.decode(&th);
    let replicates: Vec<Vec<f64>> = (0..cfg.bootstrap)
        .into_par_iter()
        .filter_map(|b| {
            // Replicate b of seed s: unrelated streams for every (s, b), so fits with
            // neighbouring seeds do not share replicates.
            let mut st = cfg.seed ^ (b as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
            let seed = splitmix64(&mut st) ^ splitmix64(&mut st).rotate_left(17);
            let segs = simulate(&params, &wv.segment_samples, wv.tau0_s, seed).ok()?;
            let refs: Vec<&[f64]> = segs.iter().map(Vec::as_slice).collect();
            let (nu_b, _) = raw_wavelet_variance(&refs, wv.tau0_s, &wv.m);
            if nu_b.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
                return None;
            }
            // The replicate goes through the same estimator as the data (multi-start,
            // reweighting), so optimiser-dependent spread is reproduced too.
            let pb = Problem {
                nu: &nu_b,
                ..prob.clone_shape()
            };
            let (tb, jb) = pb.fit(spec);
            (jb.is_finite() && tb.iter().all(|v| v.is_finite())).then_some(tb)
        })
        .collect();
    let z = normal_quantile(0.5 + cfg.confidence / 2.0);
    // Robust spread: 1.4826 × the median absolute deviation, so the few replicates whose
    // fit drops a term (ln amplitude² at its lower bound) or swaps two Gauss–Markov
    // terms do not dominate the interval.
    let sd: Vec<f64> = (0..th.len())
        .map(|i| {
            if replicates.len() < 2 {
                return 0.0;
            }
            let v: Vec<f64> = replicates.iter().map(|r| r[i]).collect();
            let med = median(v.clone());
            1.482_6 * median(v.iter().map(|x| (x - med).abs()).collect())
        })
        .collect();
    let mut terms = Vec::with_capacity(spec.procs.len());
    let mut i = 0;
    for p in &spec.procs {
        let amp = |k: usize| Term {
            value: (0.5 * th[k]).exp(),
            lo: (0.5 * (th[k] - z * sd[k])).exp(),
            hi: (0.5 * (th[k] + z * sd[k])).exp(),
        };
        let value = amp(i);
        let tau_c_s = if *p == Process::GaussMarkov {
            i += 1;
            Some(Term {
                value: th[i].exp(),
                lo: (th[i] - z * sd[i]).exp(),
                hi: (th[i] + z * sd[i]).exp(),
            })
        } else {
            None
        };
        terms.push(GmwmTerm {
            process: *p,
            value,
            tau_c_s,
        });
        i += 1;
    }
    let model = prob.model(spec, &th);
    let rms_log10_residual = (model
        .iter()
        .zip(&wv.wv)
        .map(|(m, v)| (m / v).log10().powi(2))
        .sum::<f64>()
        / model.len() as f64)
        .sqrt();
    Ok(GmwmFit {
        model: spec.label(),
        terms,
        criterion: CRITERION.to_string(),
        objective,
        wic: scores[0].1.wic,
        n_params: spec.n_params(),
        n_scales: wv.m.len(),
        candidates: scores.into_iter().map(|s| s.1).collect(),
        confidence: cfg.confidence,
        bootstrap: replicates.len(),
        tau0_s: wv.tau0_s,
        rms_log10_residual,
    })
}

impl<'a> Problem<'a> {
    /// The same scales, EDFs and bounds (for a bootstrap replicate's own ν̂).
    fn clone_shape(&self) -> Problem<'a> {
        Problem {
            ms: self.ms.clone(),
            tau0_s: self.tau0_s,
            nu: self.nu,
            edf: self.edf,
            ln_t_min: self.ln_t_min,
            ln_t_max: self.ln_t_max,
            span_s: self.span_s,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn candidates_respect_the_config_and_the_scale_count() {
        let cfg = GmwmConfig::default();
        let c = candidates(&cfg, 18);
        // 16 subsets of {Q, N, K, R} × 0..=3 GM, minus the empty model.
        assert_eq!(c.len(), 16 * 4 - 1);
        assert!(c.iter().any(|s| s.label() == "QN+WN+RW+DR+3GM"));
        let few = candidates(&cfg, 4);
        assert!(few.iter().all(|s| s.n_params() < 4));
        let only_white: GmwmConfig = "n".parse().unwrap();
        let c = candidates(&only_white, 18);
        assert_eq!(c.len(), 1);
        assert_eq!(c[0].label(), "WN");
    }

    #[test]
    fn nnls_recovers_a_nonnegative_combination() {
        let cols = vec![vec![1.0, 0.5, 0.25, 0.125], vec![0.1, 0.2, 0.4, 0.8]];
        let y: Vec<f64> = (0..4)
            .map(|j| 3.0 * cols[0][j] + 2.0 * cols[1][j])
            .collect();
        let (a, cost) = nnls_cd(&cols, &y, &[1.0; 4]);
        assert!(
            (a[0] - 3.0).abs() < 1e-6 && (a[1] - 2.0).abs() < 1e-6,
            "{a:?}"
        );
        assert!(cost < 1e-10);
        // A target that wants a negative second coefficient gets zero there.
        let y: Vec<f64> = (0..4)
            .map(|j| 3.0 * cols[0][j] - 2.0 * cols[1][j])
            .collect();
        let (a, _) = nnls_cd(&cols, &y, &[1.0; 4]);
        assert_eq!(a[1], 0.0);
    }

    #[test]
    fn sort_gm_orders_by_correlation_time() {
        let spec = Spec {
            procs: vec![Process::White, Process::GaussMarkov, Process::GaussMarkov],
        };
        let mut th = vec![1.0, 2.0, 5.0, 3.0, 1.0];
        spec.sort_gm(&mut th);
        assert_eq!(th, vec![1.0, 3.0, 1.0, 2.0, 5.0]);
    }
}
