//! Segmentation of a calibration log from its data for `calibrate six-position LOG` and
//! `thermal soak LOG` without `--manifest` ([`driftless::calib::segment`]): the options,
//! the table printed, the `--json` value and the manifest the calibrations read.

use anyhow::{Context, Result, bail};
use clap::Args;
use driftless::calib::protocol::ChamberManifest;
use driftless::calib::segment::{
    SegmentInput, SegmentOptions, Segmentation, SiteConstants, StaticRole, segment_log,
};
use driftless::io::{ImuLog, Quantity};
use std::path::Path;

/// Settings of the segmentation (used only without `--manifest`).
#[derive(Args, Debug, Clone)]
pub struct SegmentArgs {
    /// Without a manifest: the rate table's |ω|, deg/s (default: the measured rate
    /// rounded to 5 deg/s, reported as a finding).
    #[arg(long, value_name = "DEG_S", value_parser = crate::numbers::positive, allow_hyphen_values = true)]
    pub table_rate_deg_s: Option<f64>,
    /// Without a manifest: largest angle between a static reading and a body axis for a
    /// position, deg.
    #[arg(long, default_value_t = 15.0, value_parser = crate::numbers::positive, allow_hyphen_values = true)]
    pub orientation_tolerance_deg: f64,
    /// Without a manifest: largest temperature span over a plateau's positions and
    /// rotations for it to count as settled, °C.
    #[arg(long, default_value_t = 0.2, value_parser = crate::numbers::positive, allow_hyphen_values = true)]
    pub settled_band_c: f64,
}

impl SegmentArgs {
    fn options(&self) -> SegmentOptions {
        SegmentOptions {
            table_rate_deg_s: self.table_rate_deg_s,
            orientation_tolerance_deg: self.orientation_tolerance_deg,
            settled_band_c: self.settled_band_c,
            ..SegmentOptions::default()
        }
    }
}

/// A manifest found from the data, with the segmentation as JSON.
pub struct Detected {
    /// The segment manifest the calibration reads.
    pub manifest: ChamberManifest,
    /// `Segmentation` as JSON (for `--json`).
    pub json: serde_json::Value,
}

/// Segment `log` (read from `path`): SI columns by quantity, the temperature column when
/// there is one (else one plateau at `nominal_c`).
fn segment(log: &ImuLog, path: &Path, a: &SegmentArgs, nominal_c: f64) -> Result<Segmentation> {
    let need = |q: Quantity, what: &str| -> Result<[&[f64]; 3]> {
        log.triad_of(q).ok_or_else(|| {
            anyhow::anyhow!(
                "{}: segmenting without a manifest needs three {what} columns with units \
                 (found {}); name the units in the header, or pass --manifest",
                path.display(),
                log.indices_of(q).len()
            )
        })
    };
    let accel = need(Quantity::SpecificForce, "specific-force")?;
    let gyro = need(Quantity::AngularRate, "angular-rate")?;
    let Some(time) = log.time_s.as_deref() else {
        bail!(
            "{}: segmenting without a manifest needs a time column",
            path.display()
        );
    };
    let temps: Vec<&[f64]> = log
        .channels
        .iter()
        .filter(|c| c.quantity == Quantity::Temperature)
        .map(|c| c.values.as_slice())
        .collect();
    if temps.len() > 1 {
        bail!(
            "{}: {} temperature columns; segmenting uses one (drop the others with the \
             column options, or pass --manifest)",
            path.display(),
            temps.len()
        );
    }
    let inp = SegmentInput {
        time_s: time,
        accel_m_s2: accel,
        gyro_rad_s: gyro,
        temperature_c: temps.first().copied(),
        nominal_temperature_c: nominal_c,
    };
    segment_log(&inp, &a.options()).with_context(|| format!("{}", path.display()))
}

/// The segmentation as tables (segments, plateaus, findings).
fn print_table(seg: &Segmentation, path: &Path) {
    outln!(
        "segmentation of {} ({} samples at {} Hz, no manifest):",
        path.display(),
        seg.n_samples,
        seg.sample_rate_hz
    );
    let mut tab =
        crate::output::Table::new(["segment", "start [s]", "end [s]", "what", "up", "plateau"]);
    let plateau = |p: Option<usize>| p.map_or("–".to_string(), |p| p.to_string());
    let row = |kind: &str, start_s: f64, end_s: f64, what: String, up: String, p| {
        (
            start_s,
            vec![
                kind.to_string(),
                format!("{start_s:.2}"),
                format!("{end_s:.2}"),
                what,
                up,
                plateau(p),
            ],
        )
    };
    let mut rows: Vec<(f64, Vec<String>)> = Vec::new();
    for s in &seg.statics {
        let what = match s.role {
            StaticRole::Position => "position".to_string(),
            StaticRole::Soak => match s.position_tail {
                Some(t) => format!("soak, position from {:.2} s", t.start_s),
                None => "soak".into(),
            },
            StaticRole::Other => format!("static, {:.1}° off an axis", s.tilt_deg),
        };
        let up = s.up.map_or("other".into(), |u| u.to_string());
        rows.push(row(
            "static",
            s.span.start_s,
            s.span.end_s,
            what,
            up,
            s.plateau,
        ));
    }
    for r in &seg.rotations {
        let what = format!(
            "{} {:+.3} deg/s (table {}), {:.3} rev{}",
            ["x", "y", "z"][r.axis.index()],
            r.measured_rate_rad_s.to_degrees(),
            r.commanded_rate_rad_s
                .map_or("?".into(), |w| format!("{:+}", w.to_degrees())),
            r.revolutions,
            if r.usable { "" } else { ", not used" }
        );
        let up = r.up.map_or("other".into(), |u| u.to_string());
        rows.push(row(
            "rotation",
            r.span.start_s,
            r.span.end_s,
            what,
            up,
            r.plateau,
        ));
    }
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    for (_, r) in rows {
        tab.row(r);
    }
    out!("{}", tab.render());
    let mut tab = crate::output::Table::new([
        "plateau",
        "start [s]",
        "end [s]",
        "T [°C]",
        "spread [°C]",
        "settled",
        "positions -z +z +x -x +y -y",
        "rotations ±x ±y ±z",
    ]);
    for (i, p) in seg.plateaus.iter().enumerate() {
        tab.row(vec![
            i.to_string(),
            format!("{:.2}", p.span.start_s),
            format!("{:.2}", p.span.end_s),
            format!("{:.3}", p.temperature_c),
            format!("{:.3}", p.spread_c),
            if p.settled { "yes" } else { "no" }.into(),
            p.positions
                .iter()
                .map(|n| n.to_string())
                .collect::<Vec<_>>()
                .join(" "),
            p.rotations
                .iter()
                .map(|r| format!("{}/{}", r[0], r[1]))
                .collect::<Vec<_>>()
                .join(" "),
        ]);
    }
    out!("{}", tab.render());
    if seg.findings.is_empty() {
        outln!("findings: none");
    } else {
        outln!("findings:");
        for f in &seg.findings {
            outln!("  {:.2}–{:.2} s: {}", f.start_s, f.end_s, f.message);
        }
    }
    outln!();
}

/// The segmentation as JSON.
fn to_json(seg: &Segmentation) -> Result<serde_json::Value> {
    serde_json::to_value(seg).context("serialising the segmentation")
}

/// `calibrate six-position LOG` without a manifest: the step nearest `temperature_c`
/// (or the only one). Prints the table unless `json`. Returns the manifest and its set
/// temperature.
pub fn six_position_from_log(
    log: &ImuLog,
    path: &Path,
    a: &SegmentArgs,
    temperature_c: Option<f64>,
    site: &SiteConstants,
    json: bool,
) -> Result<(Detected, f64)> {
    let seg = segment(log, path, a, temperature_c.unwrap_or(25.0))?;
    if !json {
        print_table(&seg, path);
    }
    let (manifest, _) = seg
        .six_position_manifest(temperature_c, site)
        .with_context(|| format!("{}", path.display()))?;
    let set = manifest
        .set_temperatures_c()
        .first()
        .copied()
        .unwrap_or(25.0);
    Ok((
        Detected {
            manifest,
            json: to_json(&seg)?,
        },
        set,
    ))
}

/// `thermal soak LOG` without a manifest: every complete step. Prints the table unless
/// `json`; the steps left out (a position missing) are named on stderr.
pub fn soak_from_log(
    log: &ImuLog,
    path: &Path,
    a: &SegmentArgs,
    site: &SiteConstants,
    json: bool,
) -> Result<Detected> {
    let seg = segment(log, path, a, 25.0)?;
    if !json {
        print_table(&seg, path);
    }
    let (manifest, dropped) = seg
        .soak_manifest(site)
        .with_context(|| format!("{}", path.display()))?;
    for f in &dropped {
        eprintln!(
            "{}: plateau left out of the fit, {:.2}–{:.2} s: {}",
            path.display(),
            f.start_s,
            f.end_s,
            f.message
        );
    }
    Ok(Detected {
        manifest,
        json: to_json(&seg)?,
    })
}

/// The site of a log without a manifest: latitude and height are needed (gravity and
/// the Earth rate enter every scale factor).
pub fn site(
    lat_deg: Option<f64>,
    height_m: Option<f64>,
    gravity: Option<f64>,
    path: &Path,
) -> Result<SiteConstants> {
    let (Some(latitude_deg), Some(height_m)) = (lat_deg, height_m) else {
        bail!(
            "{}: without --manifest the site is needed for gravity and the Earth rate: give \
             --lat-deg and --height-m (and --gravity to override normal gravity)",
            path.display()
        );
    };
    Ok(SiteConstants {
        latitude_deg,
        longitude_deg: 0.0,
        height_m,
        gravity_m_s2: gravity,
    })
}
