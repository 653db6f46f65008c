//! Classification of the quiet runs of a log ([`super::segment_log`]): static positions,
//! rotations about one body axis at a table rate, and steady spells that are neither, with
//! the findings about each.

use super::*;

/// The walk over the quiet runs: the log and options it reads, the segments and
/// findings it collects.
pub(super) struct RunClassifier<'a> {
    pub(super) inp: &'a SegmentInput<'a>,
    pub(super) opts: &'a SegmentOptions,
    /// Sample rate, Hz.
    pub(super) fs: f64,
    pub(super) sums: &'a Sums,
    /// Minimum static run, samples.
    pub(super) min_static: usize,
    /// Minimum rotation run, samples.
    pub(super) min_rot: usize,
    /// Samples cut from each end of a static run.
    pub(super) trim: usize,
    /// Orientation tolerance, degrees.
    pub(super) tol: f64,
    pub(super) findings: Vec<Finding>,
    pub(super) statics: Vec<StaticSegment>,
    pub(super) rotations: Vec<RotationSegment>,
    /// Table rates inferred so far, deg/s (each reported once).
    pub(super) inferred_rates: Vec<f64>,
}

impl RunClassifier<'_> {
    fn span(&self, a: usize, b: usize) -> Span {
        let t = self.inp.time_s;
        Span {
            start: a,
            end: b,
            start_s: t[a],
            end_s: t[b - 1],
        }
    }

    /// Classifies the quiet run `a..b` (grown at its ends by [`extend_run`]) by its mean
    /// rate and returns the end of the grown run.
    pub(super) fn classify(&mut self, a: usize, b: usize) -> usize {
        let (a, b) = extend_run(
            self.inp,
            a,
            b,
            (self.opts.window_s * self.fs).round() as usize,
        );
        let w = self.sums.gyro(a, b);
        let rate_deg_s = norm(w).to_degrees();
        if rate_deg_s < self.opts.static_max_rate_deg_s {
            self.static_run(a, b);
        } else if rate_deg_s >= self.opts.rotation_min_rate_deg_s {
            self.rotation_run(a, b, w, rate_deg_s);
        } else {
            self.steady_run(a, b, rate_deg_s);
        }
        b
    }

    /// A static run: a position when within the orientation tolerance of an axis.
    fn static_run(&mut self, a: usize, b: usize) {
        let tol = self.tol;
        if b - a < self.min_static {
            return;
        }
        let (a, b) = if b - a >= 2 * self.trim + self.min_static {
            (a + self.trim, b - self.trim)
        } else {
            (a, b)
        };
        let f = self.sums.accel(a, b);
        let (axis, tilt) = nearest_axis(f);
        let (up, role) = if tilt <= self.tol {
            (Some(axis), StaticRole::Position)
        } else {
            if tilt <= 2.0 * self.tol {
                self.findings.push(Finding {
                    kind: FindingKind::Ambiguous,
                    start_s: self.inp.time_s[a],
                    end_s: self.inp.time_s[b - 1],
                    message: format!(
                        "static {}: {tilt:.1}° from {axis} up, beyond the {tol}° \
                         orientation tolerance; not used (re-level the fixture or raise the \
                         tolerance)",
                        self.span(a, b).label()
                    ),
                });
            }
            (None, StaticRole::Other)
        };
        self.statics.push(StaticSegment {
            span: self.span(a, b),
            up,
            tilt_deg: tilt,
            mean_accel_m_s2: f,
            role,
            position_tail: None,
            plateau: None,
        });
    }

    /// A rotation run: usable when about one body axis, at the table rate, with that axis up.
    fn rotation_run(&mut self, a: usize, b: usize, w: Vec3, rate_deg_s: f64) {
        if b - a < self.min_rot {
            return;
        }
        let j = (0..3)
            .max_by(|&x, &y| w[x].abs().total_cmp(&w[y].abs()))
            .unwrap_or(2);
        let off = (0..3)
            .filter(|&i| i != j)
            .map(|i| w[i].abs())
            .fold(0.0, f64::max);
        let label = self.span(a, b).label();
        if off > 0.05 * w[j].abs() {
            self.findings.push(Finding {
                kind: FindingKind::Ambiguous,
                start_s: self.inp.time_s[a],
                end_s: self.inp.time_s[b - 1],
                message: format!(
                    "rotation {label} at {rate_deg_s:.2} deg/s is not about one body axis \
                     (cross-axis rate {:.1} % of it); not used (mount the IMU with an axis \
                     on the table axis)",
                    100.0 * off / w[j].abs()
                ),
            });
            return;
        }
        let axis = BodyAxis::ALL[j];
        let measured = w[j];
        let commanded_abs_deg = match self.opts.table_rate_deg_s {
            Some(r) => r,
            None => {
                let r = (measured.abs().to_degrees() / self.opts.rate_round_deg_s).round()
                    * self.opts.rate_round_deg_s;
                if r > 0.0 && !self.inferred_rates.contains(&r) {
                    self.inferred_rates.push(r);
                    self.findings.push(Finding {
                        kind: FindingKind::RateInferred { rate_deg_s: r },
                        start_s: self.inp.time_s[a],
                        end_s: self.inp.time_s[b - 1],
                        message: format!(
                            "rotation {label}: table rate taken as {r} deg/s (measured \
                             {:.3} deg/s rounded to {} deg/s); state it with the table \
                             rate option if it differs",
                            measured.abs().to_degrees(),
                            self.opts.rate_round_deg_s
                        ),
                    });
                }
                r
            }
        };
        let rel = (measured.abs().to_degrees() - commanded_abs_deg).abs() / commanded_abs_deg;
        let commanded = if commanded_abs_deg > 0.0 && rel <= self.opts.rate_tolerance {
            Some(commanded_abs_deg.to_radians() * measured.signum())
        } else {
            self.findings.push(Finding {
                kind: FindingKind::Ambiguous,
                start_s: self.inp.time_s[a],
                end_s: self.inp.time_s[b - 1],
                message: format!(
                    "rotation {label} about {}: measured {:.3} deg/s differs from the table \
                     rate {commanded_abs_deg} deg/s by {:.1} % (> {:.1} %); not used (state \
                     the table rate, or raise the rate tolerance)",
                    ['x', 'y', 'z'][j],
                    measured.to_degrees(),
                    100.0 * rel,
                    100.0 * self.opts.rate_tolerance
                ),
            });
            None
        };
        // Whole revolutions of the commanded rate about the centre when the run is
        // longer (ramp tails cut symmetrically); a run shorter than its nearest whole
        // number of revolutions (the centred variance window shortens a run by up to
        // half a window at each abrupt edge) is kept whole.
        let (a, b) = match commanded {
            Some(wc) => {
                let rev_samples = std::f64::consts::TAU / wc.abs() * self.fs;
                let have = (b - a) as f64;
                let revs = (have / rev_samples).round();
                let len = (revs * rev_samples).round() as usize;
                if revs >= 1.0 && len <= b - a && len >= self.min_rot {
                    let a2 = a + (b - a - len) / 2;
                    (a2, a2 + len)
                } else {
                    (a, b)
                }
            }
            None => (a, b),
        };
        let f = self.sums.accel(a, b);
        let (up_axis, tilt) = nearest_axis(f);
        let up = (tilt <= self.tol).then_some(up_axis);
        let measured = self.sums.gyro(a, b)[j];
        let usable = commanded.is_some() && up == Some(SignedAxis::new(axis, true));
        if commanded.is_some() && !usable {
            self.findings.push(Finding {
                kind: FindingKind::Ambiguous,
                start_s: self.inp.time_s[a],
                end_s: self.inp.time_s[b - 1],
                message: format!(
                    "rotation {} about {}: {} up during it, the calibration needs +{} up \
                     (the tested axis on the vertical table axis); not used",
                    self.span(a, b).label(),
                    ['x', 'y', 'z'][j],
                    up.map_or("no axis".to_string(), |u| u.to_string()),
                    ['x', 'y', 'z'][j]
                ),
            });
        }
        self.rotations.push(RotationSegment {
            span: self.span(a, b),
            axis,
            up,
            measured_rate_rad_s: measured,
            commanded_rate_rad_s: commanded,
            revolutions: measured.abs() * (b - a) as f64 * (1.0 / self.fs) / std::f64::consts::TAU,
            usable,
            plateau: None,
        });
    }

    /// A steady spell that is neither static nor a rotation: reported, not used.
    fn steady_run(&mut self, a: usize, b: usize, rate_deg_s: f64) {
        if b - a < self.min_static.min(self.min_rot) {
            return;
        }
        self.findings.push(Finding {
            kind: FindingKind::Ambiguous,
            start_s: self.inp.time_s[a],
            end_s: self.inp.time_s[b - 1],
            message: format!(
                "steady spell {} at {rate_deg_s:.2} deg/s: neither static (< {} deg/s) nor \
                 a rotation (≥ {} deg/s); not used",
                self.span(a, b).label(),
                self.opts.static_max_rate_deg_s,
                self.opts.rotation_min_rate_deg_s
            ),
        });
    }
}
