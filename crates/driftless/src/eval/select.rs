//! Choosing GNSS outage windows on a reference trajectory, and validating given ones.
//!
//! # Automatic selection ([`select_outages`])
//!
//! N windows of L s inside the **usable span** [t₀ + `converge_s`, t_end − `end_margin_s`]
//! of the reference, at least `min_gap_s` apart, starting on a grid of step ≤ `step_s`
//! (chosen so that L + gap is a whole number of steps, which makes the spacing test
//! exact). Deterministic: no randomness, ties broken by position.
//!
//! 1. Classify every reference epoch ([`super::dynamics`]). A class is **present** when
//!    it covers at least `min_class_s` of the usable span (a 1-s blip is not a
//!    manoeuvre).
//! 2. **Allocate** the N windows to classes: each present class one window, rarest class
//!    first (when N is smaller than the number of classes the most common ones go
//!    without a window of their own — they appear in every window's mix anyway); the
//!    rest by the D'Hondt rule on the classes' durations (the next window goes to the
//!    class with the largest duration/(windows + 1)), so a drive that is mostly straight
//!    gets mostly straight outages, as a random choice would on average.
//! 3. **Place** the windows in that order (rarest class first): each at the candidate
//!    start where its class has the largest share of the window's reference epochs,
//!    among starts that keep the gap to the windows already placed and still leave room
//!    for all the windows not yet placed (counted exactly by greedy left packing of the
//!    free stretches); on equal share, the start farthest from the windows already
//!    placed and from the ends of the usable span, then the earliest. A class that no
//!    remaining start contains gets the farthest start instead (`chosen_for` = `None`).
//!    A window may not contain a reference gap longer than `max_reference_gap_s`.
//!
//! Defaults and why:
//!
//! * `min_gap_s` = max(2·L, 120 s). After GNSS returns, position and velocity snap back
//!   within a few fixes, but the heading and the sensor-bias states the outage disturbed
//!   re-converge only as the vehicle manoeuvres (tens of seconds to minutes for a MEMS
//!   IMU); an outage starting before that would inherit the previous one's errors and
//!   the outages would not be independent samples. Twice the outage gives the filter
//!   longer to recover than the error had to grow; 120 s is the floor for short outages.
//!   With L = 60 s, nine outages need 9·60 + 8·120 = 1500 s of usable data.
//! * `converge_s` = 60 s, as `SessionConfig::converge_s`: the filter's own convergence
//!   after in-motion initialisation before the first outage.
//! * `end_margin_s` = 30 s: fixes after the last outage to measure its end error from,
//!   and smoothed estimates that are not at the end of the data.
//! * `min_class_s` = 5 s, `step_s` = 1 s, `max_reference_gap_s` = 2 s.
//!
//! # Checks
//!
//! Before anything else: count ≥ 1, L finite and > 0, L not longer than the reference,
//! N·L + (N − 1)·gap not longer than the usable span (the error says by how much and
//! what to change), options in range. Given windows ([`check_outages`]): positive
//! length, not longer than the reference, inside it, not overlapping (touching is
//! allowed, as in [`crate::nav::outage`]), reference epochs inside without a gap longer
//! than `max_reference_gap_s`. Given windows closer than `min_gap_s` or inside the
//! margins are accepted (the user chose them); [`SelectedOutage::gap_before_s`] shows it.

use serde::{Deserialize, Serialize};

use super::EvalError;
use super::dynamics::{ClassMix, Dynamics, DynamicsThresholds, classify};
use super::reference::{median_interval_s, validate};
use crate::io::nav::NavSolution;
use crate::nav::outage::{OutageSpec, OutageWindow, TimeSpan, resolve};

/// Options of the selection (module docs for the defaults and their rationale).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SelectOptions {
    /// Minimum time between the end of one outage and the start of the next, s;
    /// `None`: max(2·L, 120 s).
    pub min_gap_s: Option<f64>,
    /// Time after the first reference epoch kept free of outages, s (60).
    pub converge_s: f64,
    /// Time before the last reference epoch kept free of outages, s (30).
    pub end_margin_s: f64,
    /// Least duration for a class to count as present, s (5).
    pub min_class_s: f64,
    /// Largest spacing of candidate starts, s (1).
    pub step_s: f64,
    /// Largest reference gap allowed inside a window, s (2).
    pub max_reference_gap_s: f64,
    /// Classification thresholds.
    pub thresholds: DynamicsThresholds,
}

impl Default for SelectOptions {
    fn default() -> Self {
        SelectOptions {
            min_gap_s: None,
            converge_s: 60.0,
            end_margin_s: 30.0,
            min_class_s: 5.0,
            step_s: 1.0,
            max_reference_gap_s: 2.0,
            thresholds: DynamicsThresholds::default(),
        }
    }
}

impl SelectOptions {
    /// The gap used for outages of `length_s`: `min_gap_s` or max(2·L, 120 s).
    pub fn gap_s(&self, length_s: f64) -> f64 {
        self.min_gap_s.unwrap_or((2.0 * length_s).max(120.0))
    }

    fn check(&self, length_s: f64) -> Result<(), EvalError> {
        let bad = |name, value, reason| {
            Err(EvalError::BadOption {
                name,
                value,
                reason,
            })
        };
        let nonneg = "must be a finite number ≥ 0";
        for (name, v) in [
            ("min_gap_s", self.gap_s(length_s)),
            ("converge_s", self.converge_s),
            ("end_margin_s", self.end_margin_s),
            ("min_class_s", self.min_class_s),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(name, v, nonneg);
            }
        }
        for (name, v) in [
            ("step_s", self.step_s),
            ("max_reference_gap_s", self.max_reference_gap_s),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return bad(name, v, "must be a finite number > 0");
            }
        }
        self.thresholds.check()
    }
}

/// One outage window with the dynamics it covers.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SelectedOutage {
    /// The window, GPS s.
    pub window: OutageWindow,
    /// The class this window was placed to cover (automatic selection), `None` for given
    /// windows or when no start containing the class was left.
    pub chosen_for: Option<Dynamics>,
    /// The class with the largest share of the window.
    pub dominant: Dynamics,
    /// Class shares among the reference epochs inside the window.
    pub mix: ClassMix,
    /// Time from the previous window's end (or the first reference epoch) to this
    /// window's start, s: the filter's re-convergence time before it.
    pub gap_before_s: f64,
}

/// Reference epochs' times and classes, with per-class prefix counts.
struct Timeline {
    time_s: Vec<f64>,
    /// prefix[k][c]: epochs of class c among the first k.
    prefix: Vec<[usize; 5]>,
}

impl Timeline {
    fn new(reference: &NavSolution, thr: &DynamicsThresholds) -> Result<Timeline, EvalError> {
        let classes = classify(reference, thr)?;
        let mut prefix = Vec::with_capacity(classes.len() + 1);
        let mut c = [0usize; 5];
        prefix.push(c);
        for d in &classes {
            c[d.index()] += 1;
            prefix.push(c);
        }
        Ok(Timeline {
            time_s: reference.time_s.clone(),
            prefix,
        })
    }

    /// Epoch index range [i, j) inside the half-open window (a, b].
    fn range(&self, a: f64, b: f64) -> (usize, usize) {
        (
            self.time_s.partition_point(|&t| t <= a),
            self.time_s.partition_point(|&t| t <= b),
        )
    }

    fn counts(&self, i: usize, j: usize) -> [usize; 5] {
        let mut c = [0usize; 5];
        for (k, x) in c.iter_mut().enumerate() {
            *x = self.prefix[j][k] - self.prefix[i][k];
        }
        c
    }

    /// `None` when the window (a, b] has reference epochs covering it without a gap
    /// longer than `max_gap` (the window's ends count as gap ends), else the reason.
    fn gap_in(&self, a: f64, b: f64, max_gap: f64) -> Option<String> {
        let (i, j) = self.range(a, b);
        if i == j {
            return Some("no reference epoch inside it".into());
        }
        let mut prev = a;
        for &t in self.time_s[i..j].iter().chain(std::iter::once(&b)) {
            if t - prev > max_gap {
                return Some(format!(
                    "the reference has a gap of {:.3} s from {prev} s to {t} s inside it \
                     (more than {max_gap} s)",
                    t - prev
                ));
            }
            prev = t;
        }
        None
    }

    fn describe(
        &self,
        w: OutageWindow,
        chosen_for: Option<Dynamics>,
        prev_end: f64,
    ) -> SelectedOutage {
        let (i, j) = self.range(w.start_s, w.end_s);
        let mix = ClassMix::from_counts(self.counts(i, j));
        SelectedOutage {
            window: w,
            chosen_for,
            dominant: mix.dominant(),
            mix,
            gap_before_s: w.start_s - prev_end,
        }
    }
}

/// Span of a validated reference.
fn span_of(reference: &NavSolution) -> (f64, f64) {
    (
        reference.time_s[0],
        reference.time_s[reference.time_s.len() - 1],
    )
}

/// Chooses `count` outage windows of `length_s` seconds on `reference` (module docs).
/// Windows are returned in time order.
pub fn select_outages(
    reference: &NavSolution,
    count: usize,
    length_s: f64,
    opts: &SelectOptions,
) -> Result<Vec<SelectedOutage>, EvalError> {
    if count == 0 {
        return Err(EvalError::ZeroCount);
    }
    if !(length_s.is_finite() && length_s > 0.0) {
        return Err(EvalError::NonPositiveLength { length_s });
    }
    opts.check(length_s)?;
    validate(reference, "reference")?;
    let (t0, t1) = span_of(reference);
    if length_s > t1 - t0 {
        return Err(EvalError::LongerThanData {
            length_s,
            data_s: t1 - t0,
        });
    }
    let gap = opts.gap_s(length_s);
    let (u0, u1) = (t0 + opts.converge_s, t1 - opts.end_margin_s);
    let needed = count as f64 * length_s + (count - 1) as f64 * gap;
    let usable = u1 - u0;
    if needed > usable + 1e-9 {
        return Err(EvalError::NotEnoughData {
            count,
            length_s,
            gap_s: gap,
            needed_s: needed,
            usable_s: usable.max(0.0),
            usable_start_s: u0,
            usable_end_s: u1,
            converge_s: opts.converge_s,
            end_margin_s: opts.end_margin_s,
        });
    }
    let tl = Timeline::new(reference, &opts.thresholds)?;
    let grid = CandidateGrid::new(&tl, (u0, u1), length_s, gap, opts);
    let present = present_classes(reference, &tl, (u0, u1), opts.min_class_s);
    let targets = class_targets(&present, count);
    let chosen = place(&grid, &targets, length_s, opts)?;
    let mut prev_end = t0;
    Ok(chosen
        .into_iter()
        .map(|(i, d)| {
            let s = tl.describe(grid.window(i), d, prev_end);
            prev_end = s.window.end_s;
            s
        })
        .collect())
}

/// Candidate starts u0 + i·step, i = 0..=m, where windows i and j conflict iff
/// |i − j| < p; with each window's validity and class counts.
struct CandidateGrid {
    u0: f64,
    step: f64,
    length_s: f64,
    m: usize,
    p: usize,
    valid: Vec<bool>,
    /// next_valid[i]: first valid index ≥ i (m + 1 = none).
    next_valid: Vec<usize>,
    shares: Vec<[usize; 5]>,
}

impl CandidateGrid {
    /// The grid on the usable span `(u0, u1)`: a step of at most `opts.step_s` that
    /// divides `length_s + gap` exactly.
    fn new(
        tl: &Timeline,
        (u0, u1): (f64, f64),
        length_s: f64,
        gap: f64,
        opts: &SelectOptions,
    ) -> CandidateGrid {
        let p = ((length_s + gap) / opts.step_s).ceil().max(1.0) as usize;
        let step = (length_s + gap) / p as f64;
        let m = ((u1 - length_s - u0) / step + 1e-9).floor().max(0.0) as usize;
        let mut grid = CandidateGrid {
            u0,
            step,
            length_s,
            m,
            p,
            valid: Vec::new(),
            next_valid: Vec::new(),
            shares: Vec::new(),
        };
        grid.valid = (0..=m)
            .map(|i| {
                let w = grid.window(i);
                tl.gap_in(w.start_s, w.end_s, opts.max_reference_gap_s)
                    .is_none()
            })
            .collect();
        let mut next_valid = vec![m + 1; m + 2];
        for i in (0..=m).rev() {
            next_valid[i] = if grid.valid[i] { i } else { next_valid[i + 1] };
        }
        grid.next_valid = next_valid;
        grid.shares = (0..=m)
            .map(|i| {
                let w = grid.window(i);
                let (a, b) = tl.range(w.start_s, w.end_s);
                tl.counts(a, b)
            })
            .collect();
        grid
    }

    /// The window starting at candidate `i`.
    fn window(&self, i: usize) -> OutageWindow {
        let start_s = self.u0 + i as f64 * self.step;
        OutageWindow {
            start_s,
            end_s: start_s + self.length_s,
        }
    }

    /// Fraction of the reference epochs in window `i` of class `target` (0 for `None`
    /// or an empty window).
    fn share(&self, i: usize, target: Option<Dynamics>) -> f64 {
        match target {
            Some(d) => {
                let c = self.shares[i];
                let n: usize = c.iter().sum();
                if n == 0 {
                    0.0
                } else {
                    c[d.index()] as f64 / n as f64
                }
            }
            None => 0.0,
        }
    }
}

/// Classes present for at least `min_class_s` (and > 0 s) inside the usable span, with
/// their durations (epoch count × median interval), shortest first.
fn present_classes(
    reference: &NavSolution,
    tl: &Timeline,
    (u0, u1): (f64, f64),
    min_class_s: f64,
) -> Vec<(Dynamics, f64)> {
    let (ua, ub) = tl.range(u0, u1);
    let dt = median_interval_s(&reference.time_s);
    let totals = tl.counts(ua, ub);
    let mut present: Vec<(Dynamics, f64)> = Dynamics::ALL
        .iter()
        .map(|&d| (d, totals[d.index()] as f64 * dt))
        .filter(|&(_, s)| s >= min_class_s && s > 0.0)
        .collect();
    present.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
    present
}

/// The class each of the `count` windows is placed for: one each, rarest first, then
/// D'Hondt on the durations; `None` for windows left over.
fn class_targets(present: &[(Dynamics, f64)], count: usize) -> Vec<Option<Dynamics>> {
    let mut alloc: Vec<usize> = vec![0; present.len()];
    for a in alloc.iter_mut().take(count) {
        *a = 1;
    }
    let mut left = count.saturating_sub(present.len());
    while left > 0 && !present.is_empty() {
        let mut best = 0;
        for k in 1..present.len() {
            let q = |k: usize| present[k].1 / (alloc[k] + 1) as f64;
            if q(k) > q(best) {
                best = k;
            }
        }
        alloc[best] += 1;
        left -= 1;
    }
    let mut targets: Vec<Option<Dynamics>> = Vec::with_capacity(count);
    for (k, &(d, _)) in present.iter().enumerate() {
        targets.extend(std::iter::repeat_n(Some(d), alloc[k]));
    }
    targets.resize(count, None);
    targets
}

/// Places one window per target in turn: the valid, non-conflicting start with the
/// largest share of its class, then the most clearance, that leaves room for the
/// rest. Returns (candidate index, class covered) in time order.
fn place(
    grid: &CandidateGrid,
    targets: &[Option<Dynamics>],
    length_s: f64,
    opts: &SelectOptions,
) -> Result<Vec<(usize, Option<Dynamics>)>, EvalError> {
    let count = targets.len();
    let mut chosen: Vec<(usize, Option<Dynamics>)> = Vec::with_capacity(count);
    for (placed, &target) in targets.iter().enumerate() {
        let remaining = count - placed - 1;
        let Some((i, share, _)) = best_start(grid, &chosen, target, remaining) else {
            return Err(EvalError::NoRoom {
                placed,
                count,
                length_s,
                max_gap_s: opts.max_reference_gap_s,
            });
        };
        chosen.push((i, target.filter(|_| share > 0.0)));
    }
    chosen.sort_by_key(|c| c.0);
    Ok(chosen)
}

/// The best start for a window covering `target` next to the `chosen` ones, as
/// (index, share, clearance), keeping room for `remaining` more windows.
fn best_start(
    grid: &CandidateGrid,
    chosen: &[(usize, Option<Dynamics>)],
    target: Option<Dynamics>,
    remaining: usize,
) -> Option<(usize, f64, usize)> {
    let (m, p) = (grid.m, grid.p);
    let mut best: Option<(usize, f64, usize)> = None; // (index, share, clearance)
    for i in 0..=m {
        if !grid.valid[i] || chosen.iter().any(|&(c, _)| i.abs_diff(c) < p) {
            continue;
        }
        let share = grid.share(i, target);
        if let Some((_, s, _)) = best
            && share < s - 1e-12
        {
            continue;
        }
        let clearance = chosen
            .iter()
            .map(|&(c, _)| i.abs_diff(c))
            .chain([i, m - i])
            .min()
            .unwrap_or(0);
        let better = match best {
            None => true,
            Some((_, s, cl)) => share > s + 1e-12 || clearance > cl,
        };
        if !better {
            continue;
        }
        if remaining > 0 {
            let mut with: Vec<usize> = chosen.iter().map(|c| c.0).chain([i]).collect();
            with.sort_unstable();
            if capacity(&with, m, p, &grid.next_valid, remaining) < remaining {
                continue;
            }
        }
        best = Some((i, share, clearance));
    }
    best
}

/// How many more windows fit (up to `want`) between the sorted `placed` indices on the
/// grid 0..=m with conflict distance p, counting only valid starts: greedy leftmost
/// packing of each free stretch, which is optimal for equal-length intervals.
fn capacity(placed: &[usize], m: usize, p: usize, next_valid: &[usize], want: usize) -> usize {
    let mut total = 0;
    let mut lo = 0usize;
    let bounds = placed.iter().map(|&c| Some(c)).chain([None]);
    for b in bounds {
        // Free stretch [lo, hi] of starts.
        let hi = match b {
            Some(c) => c.checked_sub(p),
            None => Some(m),
        };
        if let Some(hi) = hi {
            let mut i = lo;
            while i <= hi {
                let v = next_valid[i.min(m + 1)];
                if v > hi {
                    break;
                }
                total += 1;
                if total >= want {
                    return total;
                }
                i = v + p;
            }
        }
        if let Some(c) = b {
            lo = c + p;
        }
    }
    total
}

/// Validates given windows on `reference` (module docs, Checks) and describes the
/// dynamics inside each. Returned in time order.
pub fn check_outages(
    reference: &NavSolution,
    windows: &[OutageWindow],
    opts: &SelectOptions,
) -> Result<Vec<SelectedOutage>, EvalError> {
    validate(reference, "reference")?;
    opts.check(1.0)?;
    let (t0, t1) = span_of(reference);
    let mut w: Vec<OutageWindow> = windows.to_vec();
    for x in &w {
        let len = x.duration_s();
        if !(x.start_s.is_finite() && x.end_s.is_finite() && len > 0.0) {
            return Err(EvalError::EmptyWindow { window: *x });
        }
        if len > t1 - t0 {
            return Err(EvalError::WindowLongerThanData {
                window: *x,
                length_s: len,
                data_s: t1 - t0,
            });
        }
        let outside = |reason| EvalError::OutsideData {
            window: *x,
            start_s: t0,
            end_s: t1,
            reason,
        };
        if x.start_s < t0 {
            return Err(outside("it starts before the first reference epoch"));
        }
        if x.end_s > t1 {
            return Err(outside("it ends after the last reference epoch"));
        }
    }
    w.sort_by(|a, b| a.start_s.total_cmp(&b.start_s));
    for pair in w.windows(2) {
        if pair[1].start_s < pair[0].end_s {
            return Err(EvalError::Overlap {
                first: pair[0],
                second: pair[1],
            });
        }
    }
    let tl = Timeline::new(reference, &opts.thresholds)?;
    let mut prev_end = t0;
    let mut out = Vec::with_capacity(w.len());
    for x in w {
        if let Some(reason) = tl.gap_in(x.start_s, x.end_s, opts.max_reference_gap_s) {
            return Err(EvalError::ReferenceGap { window: x, reason });
        }
        out.push(tl.describe(x, None, prev_end));
        prev_end = x.end_s;
    }
    Ok(out)
}

/// Windows of an `--outages` specification on `reference`: `auto:NxL` selects them
/// ([`select_outages`]); explicit windows and generators are resolved against the
/// reference's span (relative starts count from its first epoch) and checked
/// ([`check_outages`]); `none` gives none.
pub fn resolve_outages(
    spec: &OutageSpec,
    reference: &NavSolution,
    opts: &SelectOptions,
) -> Result<Vec<SelectedOutage>, EvalError> {
    match spec {
        OutageSpec::None => Ok(Vec::new()),
        OutageSpec::Auto { count, length_s } => select_outages(reference, *count, *length_s, opts),
        other => {
            validate(reference, "reference")?;
            let (t0, t1) = span_of(reference);
            let windows = resolve(
                other,
                TimeSpan {
                    start_s: t0,
                    end_s: t1,
                },
            )?;
            check_outages(reference, &windows, opts)
        }
    }
}
