//! `driftless nav --kf-gins`: a KF-GINS job run unchanged on a synthetic KF-GINS dataset
//! with known truth (ideal increments of a constant-rate turn, exact GNSS fixes with 2 cm
//! σ labels), checking KF-GINS's output files and the final position.

use driftless::io::nav::{GnssFixes, ImuIncrements, write_kfgins_gnss, write_kfgins_imu};
use driftless::nav::attitude::Euler;
use driftless::sim::ideal_imu::{ConstantTurn, Trajectory, ideal_increments};

mod common;
use common::bin;

fn turn() -> ConstantTurn {
    ConstantTurn {
        lat_rad: 30.5f64.to_radians(),
        lon_rad: 114.35f64.to_radians(),
        height_m: 20.0,
        speed_m_s: 10.0,
        yaw0_rad: 0.3,
        yaw_rate_rad_s: 2f64.to_radians(),
        roll_rad: 0.0,
        pitch_rad: 0.0,
    }
}

/// Fixes of the turn's exact positions at `t0 + s` for each `s`, 2 cm σ labels.
fn fixes_at(turn: &ConstantTurn, t0: f64, times: impl IntoIterator<Item = f64>) -> GnssFixes {
    let mut gnss = GnssFixes::default();
    for s in times {
        let p = turn.point(s);
        gnss.time_s.push(t0 + s);
        gnss.lat_rad.push(p.lat_rad);
        gnss.lon_rad.push(p.lon_rad);
        gnss.height_m.push(p.height_m);
        gnss.sigma_ned_m.push([0.02, 0.02, 0.04]);
        gnss.quality.push(0);
    }
    gnss
}

/// 1 Hz fixes of the turn's exact positions from `t0 + 1` to `t0 + 119` s.
fn turn_fixes(turn: &ConstantTurn, t0: f64) -> GnssFixes {
    fixes_at(turn, t0, (1..120).map(f64::from))
}

/// GPS seconds of week of the synthetic datasets.
const T0: f64 = 356_400.0;
/// IMU interval of the synthetic datasets, s.
const DT: f64 = 0.005;

/// A synthetic KF-GINS dataset in `dir`: ideal 200 Hz increments of `turn` (plus a
/// constant gyro bias [rad/s] and accelerometer bias [m/s²] when given) ending at
/// T0 + k·DT for k = 1..=n, the fixes `gnss`, and `kf-gins.yaml` whose initial state is
/// the truth at `start_s` after T0 (starttime T0 + start_s). Paths in the YAML are
/// `./data/…` and `./out` with `relative`, else absolute.
fn kfgins_dataset(
    dir: &std::path::Path,
    turn: &ConstantTurn,
    n: usize,
    start_s: f64,
    bias: Option<([f64; 3], [f64; 3])>,
    gnss: &GnssFixes,
    relative: bool,
) {
    std::fs::create_dir_all(dir.join("data")).unwrap();
    let incs: Vec<_> = ideal_increments(turn, DT, DT, n).collect();
    let (bg, ba) = bias.unwrap_or(([0.0; 3], [0.0; 3]));
    let imu = ImuIncrements {
        time_s: (0..n).map(|k| T0 + (k + 1) as f64 * DT).collect(),
        dtheta_rad: incs
            .iter()
            .map(|i| std::array::from_fn(|a| i.dtheta_rad[a] + bg[a] * DT))
            .collect(),
        dvel_m_s: incs
            .iter()
            .map(|i| std::array::from_fn(|a| i.dvel_m_s[a] + ba[a] * DT))
            .collect(),
        ..Default::default()
    };
    let file = |p: &str| std::fs::File::create(dir.join(p)).unwrap();
    write_kfgins_imu(file("data/imu.txt"), "imu.txt", &imu).unwrap();
    write_kfgins_gnss(file("data/gnss.txt"), "gnss.txt", gnss).unwrap();
    let p0 = turn.point(start_s);
    let e0 = Euler::from_dcm(&p0.c_bn);
    let root = if relative {
        ".".to_string()
    } else {
        dir.display().to_string()
    };
    let cfg = format!(
        "imupath: \"{root}/data/imu.txt\"\ngnsspath: \"{root}/data/gnss.txt\"\noutputpath: \"{root}/out\"\n\
         imudatalen: 7\nimudatarate: 200\nstarttime: {}\nendtime: -1\n\
         initpos: [{}, {}, {}]\ninitvel: [{}, {}, {}]\ninitatt: [{}, {}, {}]\n\
         initgyrbias: [0, 0, 0]\ninitaccbias: [0, 0, 0]\ninitgyrscale: [0, 0, 0]\n\
         initaccscale: [0, 0, 0]\ninitposstd: [0.05, 0.05, 0.05]\ninitvelstd: [0.05, 0.05, 0.05]\n\
         initattstd: [0.1, 0.1, 0.5]\n\
         imunoise:\n  arw: [0.2, 0.2, 0.2]\n  vrw: [0.1, 0.1, 0.1]\n  gbstd: [50.0, 50.0, 50.0]\n\
         \x20 abstd: [1000.0, 1000.0, 1000.0]\n  gsstd: [1000.0, 1000.0, 1000.0]\n\
         \x20 asstd: [1000.0, 1000.0, 1000.0]\n  corrtime: 1.0\n\
         antlever: [0.0, 0.0, 0.0]\n",
        T0 + start_s,
        p0.lat_rad.to_degrees(),
        p0.lon_rad.to_degrees(),
        p0.height_m,
        p0.vel_ned_m_s[0],
        p0.vel_ned_m_s[1],
        p0.vel_ned_m_s[2],
        e0.roll_rad.to_degrees(),
        e0.pitch_rad.to_degrees(),
        e0.yaw_rad.to_degrees(),
    );
    std::fs::write(dir.join("kf-gins.yaml"), cfg).unwrap();
}

/// The rows of a KF-GINS output file, as numbers.
fn rows(path: &std::path::Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect())
        .collect()
}

/// Horizontal distance of a `.nav` row (time, lat, lon in deg in columns 2–4) from the
/// turn's truth, m.
fn nav_row_error_m(turn: &ConstantTurn, row: &[f64]) -> f64 {
    let truth = turn.point(row[1] - T0);
    let d_n = (row[2].to_radians() - truth.lat_rad) * 6_378_137.0;
    let d_e = (row[3].to_radians() - truth.lon_rad) * 6_378_137.0 * truth.lat_rad.cos();
    d_n.hypot(d_e)
}

/// A fresh scratch folder for one test.
fn scratch(tag: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("driftless-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `driftless nav --kf-gins kf-gins.yaml` plus `extra` in `dir`; must succeed.
fn run_kf_gins_cli(dir: &std::path::Path, extra: &[&str]) -> String {
    let out = bin()
        .current_dir(dir)
        .args(["nav", "--kf-gins", "kf-gins.yaml"])
        .args(extra)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{stderr}");
    stderr
}

#[test]
fn kf_gins_config_runs_unchanged_and_writes_its_three_files() {
    let dir = scratch("kfgins");
    let turn = turn();
    kfgins_dataset(&dir, &turn, 24_000, 0.0, None, &turn_fixes(&turn, T0), true);
    let t0 = T0;
    let out = bin()
        .current_dir(&dir)
        .args(["nav", "--kf-gins", "kf-gins.yaml"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for f in [
        "KF_GINS_Navresult.nav",
        "KF_GINS_IMU_ERR.txt",
        "KF_GINS_STD.txt",
    ] {
        assert!(dir.join("out").join(f).exists(), "{f} missing");
    }
    // Last navigation line: week, time, lat, lon, h, vN, vE, vD, roll, pitch, yaw.
    let nav = rows(&dir.join("out/KF_GINS_Navresult.nav"));
    let last = nav.last().unwrap();
    assert_eq!(last.len(), 11);
    let t_end = last[1] - t0;
    assert!((t_end - 120.0).abs() < 0.01, "ends at {t_end} s");
    let err = nav_row_error_m(&turn, last);
    eprintln!("--kf-gins: final horizontal error {err:.4} m after 120 s");
    assert!(err < 0.05, "final horizontal error {err} m");

    // Three missing IMU samples: KF-GINS integrates across the gap; so does --kf-gins,
    // with a note naming it.
    let text = std::fs::read_to_string(dir.join("data/imu.txt")).unwrap();
    let kept: Vec<&str> = text
        .lines()
        .enumerate()
        .filter(|(i, _)| !(10_000..10_003).contains(i))
        .map(|(_, l)| l)
        .collect();
    std::fs::write(dir.join("data/imu.txt"), kept.join("\n")).unwrap();
    let stderr = run_kf_gins_cli(&dir, &[]);
    assert!(
        stderr.contains("IMU gap of 0.0200 s") && stderr.contains("as KF-GINS does"),
        "{stderr}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// KF-GINS writes one row per IMU epoch after the start, at the IMU time stamps, also
/// when the fixes fall between IMU samples (it interpolates, updates, and writes the
/// state at the IMU epoch), and gives yaw in [0°, 360°): a turn through north
/// (350° → 30°) with fixes 2.5 ms after each second.
#[test]
fn kf_gins_rows_are_the_imu_epochs_and_yaw_is_0_to_360() {
    let dir = scratch("kfgins-rows");
    let turn = ConstantTurn {
        yaw0_rad: 350f64.to_radians(),
        ..turn()
    };
    let n = 4_000; // 20 s
    let gnss = fixes_at(&turn, T0, (1..20).map(|s| f64::from(s) + 0.0025));
    // starttime on the first IMU epoch, as KF-GINS requires
    kfgins_dataset(&dir, &turn, n, DT, None, &gnss, true);
    run_kf_gins_cli(&dir, &[]);
    let imu_times: Vec<f64> = rows(&dir.join("data/imu.txt"))
        .iter()
        .map(|r| r[0])
        .collect();
    for f in [
        "KF_GINS_Navresult.nav",
        "KF_GINS_IMU_ERR.txt",
        "KF_GINS_STD.txt",
    ] {
        let r = rows(&dir.join("out").join(f));
        let col = usize::from(f.ends_with(".nav"));
        // every IMU epoch after the initial one, none added at the fix times
        assert_eq!(r.len(), n - 1, "{f}");
        for (row, t) in r.iter().zip(&imu_times[1..]) {
            assert!(
                (row[col] - t).abs() < 1e-9,
                "{f}: row at {} s, IMU epoch {t} s",
                row[col]
            );
        }
    }
    let nav = rows(&dir.join("out/KF_GINS_Navresult.nav"));
    let yaw: Vec<f64> = nav.iter().map(|r| r[10]).collect();
    assert!(
        yaw.iter().all(|y| (0.0..360.0).contains(y)),
        "yaw outside [0, 360)"
    );
    assert!(yaw.iter().any(|&y| y > 355.0) && yaw.iter().any(|&y| y < 5.0));
    let err = nav_row_error_m(&turn, nav.last().unwrap());
    assert!(
        err < 0.05,
        "final horizontal error {err} m with fixes between IMU samples"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// KF-GINS updates only with fixes strictly after `starttime`: a fix exactly at
/// starttime, 50 m off, changes nothing.
#[test]
fn kf_gins_fix_at_starttime_is_not_used() {
    let dir = scratch("kfgins-start");
    let turn = turn();
    let start_s = 10.0;
    let mut gnss = fixes_at(&turn, T0, (10..30).map(f64::from));
    gnss.lat_rad[0] += 50.0 / 6_378_137.0;
    kfgins_dataset(&dir, &turn, 6_000, start_s, None, &gnss, true);
    run_kf_gins_cli(&dir, &[]);
    let with_bad_fix = std::fs::read(dir.join("out/KF_GINS_Navresult.nav")).unwrap();
    let nav = rows(&dir.join("out/KF_GINS_Navresult.nav"));
    assert!(
        (nav[0][1] - (T0 + start_s + DT)).abs() < 1e-9,
        "first row {}",
        nav[0][1]
    );
    let worst = nav
        .iter()
        .map(|r| nav_row_error_m(&turn, r))
        .fold(0.0, f64::max);
    assert!(worst < 0.05, "worst horizontal error {worst} m");
    // The same without that fix: identical output.
    let rest = fixes_at(&turn, T0, (11..30).map(f64::from));
    let file = std::fs::File::create(dir.join("data/gnss.txt")).unwrap();
    write_kfgins_gnss(file, "gnss.txt", &rest).unwrap();
    run_kf_gins_cli(&dir, &[]);
    let without = std::fs::read(dir.join("out/KF_GINS_Navresult.nav")).unwrap();
    assert!(
        with_bad_fix == without,
        "the fix at starttime changed the output"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Without a gate a gross outlier is used, as in KF-GINS; with an explicit χ² gate it
/// is rejected (library job options).
#[test]
fn kf_gins_outlier_used_without_gate_rejected_with_one() {
    use driftless::nav::kfgins_job::{KfGinsJobOptions, run_kf_gins_job};
    let dir = scratch("kfgins-gate");
    let turn = turn();
    let mut gnss = fixes_at(&turn, T0, (1..60).map(f64::from));
    let bad = 30;
    gnss.lat_rad[bad - 1] += 30.0 / 6_378_137.0;
    kfgins_dataset(&dir, &turn, 12_000, 0.0, None, &gnss, false);
    let cfg = dir.join("kf-gins.yaml");
    let nav_at_bad = || {
        let nav = rows(&dir.join("out/KF_GINS_Navresult.nav"));
        let row = nav
            .iter()
            .find(|r| (r[1] - (T0 + bad as f64)).abs() < 1e-6)
            .unwrap()
            .clone();
        nav_row_error_m(&turn, &row)
    };
    let plain = run_kf_gins_job(&cfg, &KfGinsJobOptions::default()).unwrap();
    assert_eq!((plain.run.gnss_accepted, plain.run.gnss_rejected), (59, 0));
    let used = nav_at_bad();
    let gated = run_kf_gins_job(
        &cfg,
        &KfGinsJobOptions {
            gate: Some(driftless::nav::filter::model::Gate::Chi2 { p: 0.9999 }),
            ..KfGinsJobOptions::default()
        },
    )
    .unwrap();
    assert_eq!((gated.run.gnss_accepted, gated.run.gnss_rejected), (58, 1));
    let rejected = nav_at_bad();
    eprintln!("error at the outlier's epoch: {used:.3} m without gate, {rejected:.4} m with");
    assert!(used > 1.0, "outlier not used without gate: {used} m");
    assert!(
        rejected < 0.05,
        "outlier not rejected with the gate: {rejected} m"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--smooth` writes the smoothed solution in KF-GINS's formats beside the forward files,
/// on the same rows, and inside a GNSS outage it is closer to the truth.
#[test]
fn kf_gins_smooth_writes_smoothed_files_closer_inside_an_outage() {
    let dir = scratch("kfgins-smooth");
    let turn = turn();
    let n = 24_000;
    let bias = ([2e-5, -3e-5, 4e-5], [0.03, -0.02, 0.04]); // ~4–8 °/h, 2–4 mg
    kfgins_dataset(
        &dir,
        &turn,
        n,
        0.0,
        Some(bias),
        &turn_fixes(&turn, T0),
        true,
    );
    let (a, b) = (T0 + 60.0, T0 + 100.0);
    let window = format!("@{a}+40");
    let stdout_json = bin()
        .current_dir(&dir)
        .args([
            "nav",
            "--kf-gins",
            "kf-gins.yaml",
            "--smooth",
            "--json",
            "--outages",
            &window,
        ])
        .output()
        .unwrap();
    assert!(
        stdout_json.status.success(),
        "{}",
        String::from_utf8_lossy(&stdout_json.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&stdout_json.stdout).unwrap();
    assert_eq!(v["outputs"].as_array().unwrap().len(), 6, "{v}");
    // (60 s, 100 s]: the fixes at 61 … 100 s.
    assert_eq!(v["gnss_withheld"].as_u64(), Some(40), "{v}");
    let fwd = rows(&dir.join("out/KF_GINS_Navresult.nav"));
    let sm = rows(&dir.join("out/KF_GINS_Navresult_smoothed.nav"));
    for f in ["KF_GINS_IMU_ERR_smoothed.txt", "KF_GINS_STD_smoothed.txt"] {
        assert_eq!(rows(&dir.join("out").join(f)).len(), fwd.len(), "{f}");
    }
    assert_eq!(sm.len(), fwd.len());
    assert_eq!(fwd.len(), n);
    let max_in = |r: &[Vec<f64>]| {
        r.iter()
            .filter(|row| row[1] > a && row[1] < b)
            .map(|row| nav_row_error_m(&turn, row))
            .fold(0.0, f64::max)
    };
    for (x, y) in fwd.iter().zip(&sm) {
        assert!((x[1] - y[1]).abs() < 1e-9);
    }
    let (e_fwd, e_sm) = (max_in(&fwd), max_in(&sm));
    eprintln!("40-s outage: max horizontal error forward {e_fwd:.3} m, smoothed {e_sm:.4} m");
    assert!(e_fwd > 0.05, "the outage should show drift: {e_fwd} m");
    assert!(e_sm < 0.5 * e_fwd, "smoothed {e_sm} m vs forward {e_fwd} m");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The turn as a rates CSV (`imu.csv`, units in the header, GPS time first) and KF-GINS
/// GNSS (`gnss.txt`) in `dir`.
fn write_turn_csv(dir: &std::path::Path) {
    use std::fmt::Write as _;
    std::fs::create_dir_all(dir).unwrap();
    let t0 = 356_400.0;
    let turn = turn();
    let dt = 0.005;
    let mut csv = String::from(
        "time [s],gyro_x [deg/s],gyro_y [deg/s],gyro_z [deg/s],acc_x [m/s^2],acc_y [m/s^2],acc_z [m/s^2]\n",
    );
    for k in 0..=24_000 {
        let t = k as f64 * dt;
        // the rates over (t − Δt, t], taken at the interval midpoint
        let (w, f) = turn.point(t - 0.5 * dt).imu_rates();
        let d = |x: f64| x.to_degrees();
        writeln!(
            csv,
            "{:.3},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e}",
            t0 + t,
            d(w[0]),
            d(w[1]),
            d(w[2]),
            f[0],
            f[1],
            f[2]
        )
        .unwrap();
    }
    std::fs::write(dir.join("imu.csv"), csv).unwrap();
    write_kfgins_gnss(
        std::fs::File::create(dir.join("gnss.txt")).unwrap(),
        "gnss.txt",
        &turn_fixes(&turn, t0),
    )
    .unwrap();
}

/// The navigation configuration: `--print-config` reads back; a file gives the same run as
/// the flags; relative paths resolve against the file's folder; bad values name the file,
/// line and column or the flag; outages longer than the data are refused.
#[test]
fn configuration_file_and_flags() {
    let dir = std::env::temp_dir().join(format!("driftless-navconf-{}", std::process::id()));
    write_turn_csv(&dir);
    let run = |args: &[&str]| bin().current_dir(&dir).args(args).output().unwrap();
    let printed = run(&["nav", "--print-config"]);
    assert!(printed.status.success());
    let text = String::from_utf8(printed.stdout).unwrap();
    assert!(
        text.contains("[imu]") && text.contains("(--gate)"),
        "{text}"
    );
    // The printed default plus the files, in a sub-folder: paths relative to it.
    std::fs::create_dir_all(dir.join("conf")).unwrap();
    let conf = text
        .replace("# file = \"imu.txt\"", "file = \"../imu.csv\"")
        .replace("# file = \"gnss.pos\"", "file = \"../gnss.txt\"")
        .replace("format = \"auto\"", "format = \"csv\"");
    std::fs::write(dir.join("conf/nav.toml"), conf).unwrap();
    let a = run(&[
        "nav",
        "--config",
        "conf/nav.toml",
        "--outages",
        "60+20",
        "--json",
    ]);
    assert!(a.status.success(), "{}", String::from_utf8_lossy(&a.stderr));
    let b = run(&[
        "nav",
        "--imu",
        "imu.csv",
        "--imu-format",
        "csv",
        "--gnss",
        "gnss.txt",
        "--outages",
        "60+20",
        "--json",
    ]);
    assert!(b.status.success(), "{}", String::from_utf8_lossy(&b.stderr));
    let (va, vb): (serde_json::Value, serde_json::Value) = (
        serde_json::from_slice(&a.stdout).unwrap(),
        serde_json::from_slice(&b.stdout).unwrap(),
    );
    assert_eq!(va["outages"], vb["outages"]);
    assert_eq!(va["horizontal_rms_m"], vb["horizontal_rms_m"]);
    // A bad value in the file.
    std::fs::write(
        dir.join("bad.toml"),
        "[imu]\nfile = \"imu.csv\"\n\n[gnss]\nsigma_floor_m = -0.1\n",
    )
    .unwrap();
    let e = run(&["nav", "--config", "bad.toml"]);
    let msg = String::from_utf8_lossy(&e.stderr);
    assert!(!e.status.success());
    assert!(
        msg.contains("bad.toml:5:17 (key `gnss.sigma_floor_m`)") && msg.contains("≥ 0"),
        "{msg}"
    );
    // The same from a flag; an unknown quality name; a mounting in radians by mistake.
    for (args, want) in [
        (vec!["--gnss-sigma-floor", "-1"], "flag --gnss-sigma-floor"),
        (vec!["--gnss-accept", "fix,fixed"], "not a solution quality"),
        (vec!["--mounting-rpy-deg", "3.14,0,1000"], "±360"),
        (vec!["--gate", "chi2:1.5"], "not a gate"),
        (vec!["--outages", "100+60"], "outage"),
    ] {
        let mut all = vec![
            "nav",
            "--imu",
            "imu.csv",
            "--imu-format",
            "csv",
            "--gnss",
            "gnss.txt",
        ];
        all.extend(args.iter().copied());
        let e = run(&all);
        let msg = String::from_utf8_lossy(&e.stderr);
        assert!(!e.status.success(), "{args:?} succeeded");
        assert!(msg.contains(want), "{args:?}: {msg}");
        assert!(!msg.contains("panicked"), "{msg}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `driftless nav --imu-format csv`: a generic CSV of rates (units from the header) with
/// KF-GINS GNSS; the filter initialises in motion from the fixes and follows the turn.
#[test]
fn generic_rate_csv_runs() {
    let dir = std::env::temp_dir().join(format!("driftless-navcsv-{}", std::process::id()));
    write_turn_csv(&dir);
    let out = bin()
        .current_dir(&dir)
        .args([
            "nav",
            "--imu",
            "imu.csv",
            "--imu-format",
            "csv",
            "--gnss",
            "gnss.txt",
            "--outages",
            "60+20",
            "--smooth",
            "--json",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["imu_epochs"], 24_001);
    let rms = v["horizontal_rms_m"].as_f64().unwrap();
    let end = v["outages"][0]["end_horizontal_m"].as_f64().unwrap();
    let smoothed = v["smoothed_outages"][0]["max_horizontal_m"]
        .as_f64()
        .unwrap();
    eprintln!(
        "--imu-format csv: full-GNSS RMS {rms:.4} m, 20-s outage end error {end:.3} m \
         (smoothed max {smoothed:.3} m)"
    );
    assert!(rms < 0.05, "RMS {rms} m");
    // Error-free rates, but the default consumer-MEMS model (accel bias σ 30 mg) has
    // not separated accelerometer bias from tilt after 60 s of one constant turn:
    // ~6 mg left gives ~12 m in 20 s. The smoother, seeing the fixes after the outage,
    // must bridge it at the cm level.
    assert!(end < 20.0, "outage end error {end} m");
    assert!(smoothed < 0.1, "smoothed in-outage max {smoothed} m");
    // A calibration file: identity in SI changes nothing; one of raw counts is refused.
    let cal = |unit: &str| {
        format!(
            "format_version = 1\nmethod = \"test\"\nsource = \"t\"\ngravity_m_s2 = 9.8\n\
             [accel]\nraw_unit = \"{unit}\"\nbias = [0.0, 0.0, 0.0]\nbias_sigma = [0.0, 0.0, 0.0]\n\
             matrix = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]\n\
             matrix_sigma = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]\n\
             [gyro]\nraw_unit = \"rad/s\"\nbias = [0.0, 0.0, 0.0]\nbias_sigma = [0.0, 0.0, 0.0]\n\
             matrix = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]\n\
             matrix_sigma = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]\n"
        )
    };
    std::fs::write(dir.join("cal.toml"), cal("m/s^2")).unwrap();
    std::fs::write(dir.join("cal_counts.toml"), cal("counts")).unwrap();
    let base = [
        "nav",
        "--imu",
        "imu.csv",
        "--imu-format",
        "csv",
        "--gnss",
        "gnss.txt",
    ];
    let with = bin()
        .current_dir(&dir)
        .args(base)
        .args(["--outages", "60+20", "--json", "--calibration", "cal.toml"])
        .output()
        .unwrap();
    assert!(
        with.status.success(),
        "{}",
        String::from_utf8_lossy(&with.stderr)
    );
    let w: serde_json::Value = serde_json::from_slice(&with.stdout).unwrap();
    assert_eq!(w["horizontal_rms_m"], v["horizontal_rms_m"]);
    let bad = bin()
        .current_dir(&dir)
        .args(base)
        .args(["--calibration", "cal_counts.toml"])
        .output()
        .unwrap();
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(
        err.contains("cal_counts.toml") && err.contains("counts"),
        "{err}"
    );
    // A rate column without a unit cannot be used: its scale is unknown.
    std::fs::write(
        dir.join("bad.csv"),
        "time,gx,gy,gz,ax,ay,az\n0,0,0,0,0,0,9.8\n",
    )
    .unwrap();
    let out = bin()
        .current_dir(&dir)
        .args([
            "nav",
            "--imu",
            "bad.csv",
            "--imu-format",
            "csv",
            "--gnss",
            "gnss.txt",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    eprintln!("{err}");
    assert!(err.contains("bad.csv"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `driftless nav --outages auto:NxL`: windows chosen on the GNSS track before the
/// filter runs; a request that cannot fit fails at once with the arithmetic.
#[test]
fn auto_outages_are_chosen_on_the_track_or_refused() {
    let dir = std::env::temp_dir().join(format!("driftless-navauto-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let t0 = 356_400.0;
    let turn = turn();
    let dt = 0.005;
    let n = 24_000;
    let incs: Vec<_> = ideal_increments(&turn, dt, dt, n).collect();
    let imu = ImuIncrements {
        time_s: (0..n).map(|k| t0 + (k + 1) as f64 * dt).collect(),
        dtheta_rad: incs.iter().map(|i| i.dtheta_rad).collect(),
        dvel_m_s: incs.iter().map(|i| i.dvel_m_s).collect(),
        ..Default::default()
    };
    let file = |p: &str| std::fs::File::create(dir.join(p)).unwrap();
    write_kfgins_imu(file("imu.txt"), "imu.txt", &imu).unwrap();
    write_kfgins_gnss(file("gnss.txt"), "gnss.txt", &turn_fixes(&turn, t0)).unwrap();
    let base = ["nav", "--imu", "imu.txt", "--gnss", "gnss.txt", "--json"];

    // 118 s of fixes: nine 60-s outages cannot fit, and the message says why.
    let started = std::time::Instant::now();
    let bad = bin()
        .current_dir(&dir)
        .args(base)
        .args(["--outages", "auto:9x60"])
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(bad.stdout.is_empty());
    let err = String::from_utf8_lossy(&bad.stderr);
    eprintln!("{err}");
    assert!(
        err.contains("9 outages of 60 s") && err.contains("1500.0 s"),
        "{err}"
    );
    eprintln!("refused after {:.2} s", started.elapsed().as_secs_f64());

    // One 20-s outage fits in the usable [t0 + 61, t0 + 89] s.
    let ok = bin()
        .current_dir(&dir)
        .args(base)
        .args(["--outages", "auto:1x20"])
        .output()
        .unwrap();
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&ok.stdout).unwrap();
    let sel = v["outage_selection"].as_array().unwrap();
    assert_eq!(sel.len(), 1);
    let start = sel[0]["window"]["start_s"].as_f64().unwrap();
    let end = sel[0]["window"]["end_s"].as_f64().unwrap();
    assert!(
        start >= t0 + 61.0 - 1e-9 && end <= t0 + 89.0 + 1e-9,
        "{start} {end}"
    );
    // A 2°/s turn is below the 5°/s turn threshold: straight driving.
    assert_eq!(sel[0]["chosen_for"], "straight");
    assert_eq!(v["outages"].as_array().unwrap().len(), 1);
    assert_eq!(v["outages"][0]["start_s"].as_f64().unwrap(), start);
    assert!(v["outages"][0]["end_horizontal_m"].as_f64().is_some());
    let _ = std::fs::remove_dir_all(&dir);
}
