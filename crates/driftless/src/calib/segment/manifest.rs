//! From a segmentation to segment manifests ([`super::super::protocol`]): one step, the
//! soak or the six-position subset, with a message naming what is missing.

use super::*;

impl Segmentation {
    /// Indices of the plateaus with static positions (the temperature steps).
    pub fn steps(&self) -> Vec<usize> {
        (0..self.plateaus.len())
            .filter(|&p| self.plateaus[p].has_positions())
            .collect()
    }

    /// The findings about plateau `p` (missing positions or rotations, unsettled).
    pub(crate) fn findings_of(&self, p: usize) -> Vec<&Finding> {
        self.findings
            .iter()
            .filter(|f| match f.kind {
                FindingKind::MissingPosition { plateau, .. }
                | FindingKind::MissingRotation { plateau, .. }
                | FindingKind::UnsettledPlateau { plateau, .. } => plateau == p,
                _ => false,
            })
            .collect()
    }

    /// The segment manifest of the plateaus `plateaus` (time axis: sample k at k/f_s,
    /// as a manifest's), each a temperature step at its temperature rounded to 1 m°C:
    /// its static positions and usable rotations in time order (no soak or move
    /// segments; the calibrations read only these). The site constants are `site`'s.
    pub fn manifest_of(
        &self,
        plateaus: &[usize],
        site: &SiteConstants,
    ) -> Result<ChamberManifest, SegmentError> {
        let site_ok = site.latitude_deg.abs() < 90.0
            && site.longitude_deg.is_finite()
            && site.height_m.is_finite()
            && site.gravity_m_s2.is_none_or(|g| (9.7..=9.9).contains(&g));
        if !site_ok {
            return Err(SegmentError::BadInput(format!(
                "site {site:?}: latitude within ±90°, finite longitude and height, gravity \
                 9.7–9.9 m/s²"
            )));
        }
        let fs = self.sample_rate_hz;
        let time = |k: usize| k as f64 / fs;
        let mut segments: Vec<Segment> = Vec::new();
        for &p in plateaus {
            let Some(pl) = self.plateaus.get(p) else {
                return Err(SegmentError::BadInput(format!(
                    "plateau {p}: the segmentation has {}",
                    self.plateaus.len()
                )));
            };
            let set_c = (pl.temperature_c * 1000.0).round() / 1000.0;
            let mut parts: Vec<(usize, usize, SegmentKind)> = Vec::new();
            for s in self.statics.iter().filter(|s| s.plateau == Some(p)) {
                if let (Some(sp), Some(up)) = (s.position_span(), s.up) {
                    parts.push((sp.start, sp.end, SegmentKind::Position { up }));
                }
            }
            for r in self
                .rotations
                .iter()
                .filter(|r| r.plateau == Some(p) && r.usable)
            {
                if let Some(w) = r.commanded_rate_rad_s {
                    parts.push((
                        r.span.start,
                        r.span.end,
                        SegmentKind::Rate {
                            axis: r.axis,
                            rate_rad_s: w,
                        },
                    ));
                }
            }
            parts.sort_by_key(|x| x.0);
            segments.extend(parts.into_iter().map(|(a, b, kind)| Segment {
                start_s: time(a),
                end_s: time(b),
                set_temperature_c: set_c,
                kind,
            }));
        }
        let lat = site.latitude_deg.to_radians();
        Ok(ChamberManifest {
            format_version: MANIFEST_VERSION,
            sample_rate_hz: fs,
            latitude_deg: site.latitude_deg,
            longitude_deg: site.longitude_deg,
            height_m: site.height_m,
            gravity_m_s2: site
                .gravity_m_s2
                .unwrap_or_else(|| earth::normal_gravity_m_s2(lat, site.height_m)),
            earth_rate_rad_s: earth::OMEGA_IE,
            lag_tau_s: 0.0,
            duration_s: time(self.n_samples),
            segments,
        })
    }

    /// The manifest of every complete step (all six positions): the input of a soak
    /// calibration. The incomplete steps left out are named in the returned findings
    /// (their missing positions); an error when no step is complete.
    pub fn soak_manifest(
        &self,
        site: &SiteConstants,
    ) -> Result<(ChamberManifest, Vec<&Finding>), SegmentError> {
        let steps = self.steps();
        let (complete, left): (Vec<usize>, Vec<usize>) =
            steps.iter().partition(|&&p| self.plateaus[p].complete());
        if complete.is_empty() {
            return Err(SegmentError::Incomplete(self.incomplete_message(&left)));
        }
        let dropped = left
            .iter()
            .flat_map(|&p| self.findings_of(p))
            .filter(|f| matches!(f.kind, FindingKind::MissingPosition { .. }))
            .collect();
        Ok((self.manifest_of(&complete, site)?, dropped))
    }

    /// The manifest of the one step to calibrate at room temperature: the only step, or
    /// the one whose temperature is nearest `temperature_c`. An incomplete step is an
    /// error naming its missing positions and time span.
    pub fn six_position_manifest(
        &self,
        temperature_c: Option<f64>,
        site: &SiteConstants,
    ) -> Result<(ChamberManifest, usize), SegmentError> {
        let steps = self.steps();
        let p = match (temperature_c, steps.as_slice()) {
            (_, []) => {
                return Err(SegmentError::Incomplete(
                    "no plateau holds a static position".into(),
                ));
            }
            (None, [p]) => *p,
            (None, _) => {
                let list: Vec<String> = steps
                    .iter()
                    .map(|&p| {
                        format!(
                            "{:.2} °C ({})",
                            self.plateaus[p].temperature_c,
                            self.plateaus[p].span.label()
                        )
                    })
                    .collect();
                return Err(SegmentError::Incomplete(format!(
                    "{} temperature plateaus with positions: {}; choose one by its temperature",
                    steps.len(),
                    list.join(", ")
                )));
            }
            (Some(t), _) => steps
                .iter()
                .copied()
                .min_by(|&a, &b| {
                    (self.plateaus[a].temperature_c - t)
                        .abs()
                        .total_cmp(&(self.plateaus[b].temperature_c - t).abs())
                })
                .unwrap_or(steps[0]),
        };
        if !self.plateaus[p].complete() {
            return Err(SegmentError::Incomplete(self.incomplete_message(&[p])));
        }
        Ok((self.manifest_of(&[p], site)?, p))
    }

    pub(super) fn incomplete_message(&self, plateaus: &[usize]) -> String {
        let lines: Vec<String> = plateaus
            .iter()
            .flat_map(|&p| self.findings_of(p))
            .filter(|f| matches!(f.kind, FindingKind::MissingPosition { .. }))
            .map(|f| f.message.clone())
            .collect();
        if lines.is_empty() {
            "no temperature plateau has all six static positions".into()
        } else {
            lines.join("; ")
        }
    }
}
