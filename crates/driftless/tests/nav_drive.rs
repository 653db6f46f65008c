//! The real drive (`shared/data/drive/drive_0708`: ICM-45686 at ~100 Hz, u-blox RTK at
//! 4 Hz): full-RTK accuracy and 60-s outages, against the RTK fixes themselves.

use driftless::io::nav::kfgins::GnssReadOptions;
use driftless::nav::filter::model::FilterConfig;
use driftless::nav::outage::OutageSpec;
use driftless::nav::pipeline::{
    GnssOutsideImu, TaggedCsvOptions, imu_from_tagged_csv_files, read_gnss_file, select_gnss,
};
use driftless::nav::session::{SessionConfig, consumer_mems_noise, run_session};
use std::path::PathBuf;

fn data(rel: &str) -> PathBuf {
    match std::env::var_os("DRIFTLESS_DATA") {
        Some(p) => PathBuf::from(p),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"),
    }
    .join(rel)
}

/// Antenna relative to the IMU, vehicle FRD: IMU 0.65 m above the origin, antenna at
/// (0, −0.05, −0.65) m from it (data README).
const LEVER_ARM_B_M: [f64; 3] = [0.0, -0.05, 0.0];

#[test]
#[ignore = "needs shared data"]
fn drive_0708_full_rtk_and_outages() {
    let d = data("drive/drive_0708");
    let imu = imu_from_tagged_csv_files(
        d.join("imu_1934.csv"),
        d.join("imu_1934.csv.tag"),
        &TaggedCsvOptions::drive_0708(),
    )
    .unwrap();
    let gnss = read_gnss_file(d.join("gnss_1934_sf.pos"), &GnssReadOptions::default()).unwrap();
    let all = select_gnss(&gnss, &imu, &OutageSpec::None, GnssOutsideImu::Drop).unwrap();
    let cfg = SessionConfig::new(FilterConfig::new(consumer_mems_noise(), LEVER_ARM_B_M));

    if std::env::var_os("DRIVE_DEBUG").is_some() {
        for floor in [0.02, 0.03, 0.05, 0.1] {
            let mut g2 = all.fixes.clone();
            for s in &mut g2.sigma_ned_m {
                s[0] = s[0].max(floor);
                s[1] = s[1].max(floor);
                s[2] = s[2].max(2.0 * floor);
            }
            let r = run_session(&imu, &g2, &cfg).unwrap();
            eprintln!(
                "floor {floor}: rms {:?} rejected {}",
                r.horizontal_rms_m, r.run.gnss_rejected
            );
        }
        let mut c2 = cfg.clone();
        c2.filter.chi2_gate = None;
        let r = run_session(&imu, &all.fixes, &c2).unwrap();
        eprintln!("no gate: rms {:?}", r.horizontal_rms_m);
        for u in r.run.updates.iter().take(12) {
            for o in &u.outcomes {
                eprintln!(
                    "t {:.2} innov {:?} nis {:.1}",
                    o.time_s, o.innovation, o.nis
                );
            }
        }
        let e0 = &r.run.epochs[0];
        eprintln!("init {:?}", e0.nav);
        for k in [100usize, 1000, 5000, 20000] {
            if let Some(e) = r.run.epochs.get(k) {
                eprintln!(
                    "k {k} t {:.2} v {:?} bg {:?} ba {:?}",
                    e.nav.time_s,
                    e.nav.vel_ned_m_s,
                    e.sensors.gyro_bias_rad_s,
                    e.sensors.accel_bias_m_s2
                );
            }
        }
    }
    let full = run_session(&imu, &all.fixes, &cfg).unwrap();
    let (rms, n) = full.horizontal_rms_m.unwrap();
    eprintln!(
        "full RTK: horizontal one-step prediction RMS {:.3} m over {n} fixes; accepted {}, rejected {}; start {:.1} s; primed gyro bias {:?}",
        rms,
        full.run.gnss_accepted,
        full.run.gnss_rejected,
        full.init.nav.time_s,
        full.primed_gyro_bias_rad_s
    );
    assert!(rms.is_finite());

    let spec: OutageSpec = "6x60s every 85s from 50s".parse().unwrap();
    let sel = select_gnss(&gnss, &imu, &spec, GnssOutsideImu::Drop).unwrap();
    let mut ocfg = cfg.clone();
    ocfg.outages = sel.windows.clone();
    let out = run_session(&imu, &all.fixes, &ocfg).unwrap();
    let ends: Vec<f64> = out
        .outages
        .iter()
        .filter_map(|o| o.end_horizontal_m)
        .collect();
    for o in &out.outages {
        eprintln!(
            "outage {:.0}–{:.0} s: end {:?} m, max {:.2} m",
            o.window.start_s, o.window.end_s, o.end_horizontal_m, o.max_horizontal_m
        );
    }
    let mean = ends.iter().sum::<f64>() / ends.len().max(1) as f64;
    eprintln!(
        "mean end-of-outage horizontal error {mean:.2} m over {} outages",
        ends.len()
    );
    assert_eq!(ends.len(), 6);
}
