//! PX4 ULog and ArduPilot DataFlash readers on the real logs in `../shared/data/logs`.
//!
//! Every expected number below was read independently with the reference Python readers
//! (pyulog 1.x `ULog(...)`, pymavlink `DFReader.DFReader_binary`, installed from PyPI on
//! the development machine), not with this reader:
//! * ULog (`px4_ulog/sample_log_small.ulg`, from pyulog's own test suite): 3 instances of
//!   `sensor_gyro` and `sensor_accel` with 6 rows each (logged at 1 Hz), gyro instance 0
//!   first `timestamp` 21 312 030 µs and x = −0.04130321 rad/s, accel instance 0 first
//!   21 312 085 µs, x = 0.6821298, z = −9.696953 m/s², temperatures 40.02537–40.36083 °C
//!   (instance 0), 28.246023–28.368422 (1), 29.434422–29.721958 (2); accelerometer norm
//!   medians (numpy) 9.758297, 9.921783, 9.836068 m/s²; 980 parameters,
//!   `ver_hw` = CUBEPILOT_CUBEORANGE, one 30 ms drop-out, 3 logged strings. All 18 gyro and
//!   18 accel rows × (x, y, z, temperature) were also compared value by value against pyulog
//!   through `driftless convert … --instance N out.csv`: identical to f32 precision (max
//!   difference 0, the CSV prints the f32 → f64 value exactly).
//! * DataFlash (`ardupilot_dataflash/backend_log_80k.bin`, 81 920 bytes, cut mid-message):
//!   pymavlink reads 184 FMT, 1077 PARM and 20 IMU messages (10 per instance `I` = 0, 1);
//!   instance 0 first `TimeUS` 140 209 868, GyrX 0.005344705190509558 rad/s,
//!   AccZ −9.763680458068848 m/s², T 37.3057975769043 °C; instance 1 T = 28.5 °C
//!   throughout; last IMU `TimeUS` 140 575 610; accelerometer norm medians (numpy)
//!   9.817251951826298 and 9.803149146330014 m/s². pymavlink stops at byte 81 918 as well
//!   (its `offset`), without reporting the cut. Both instances' 10 rows × (TimeUS, Gyr, Acc,
//!   T) compared value by value through `driftless convert`: max difference 0.

#![cfg(feature = "autopilot-logs")]

use std::path::PathBuf;

use driftless::io::{
    AutopilotFormat, Quantity, detect_format, imu_logs_from_dataflash, imu_logs_from_ulog,
    parse_dataflash, parse_ulog,
};

/// Shared reference data: `$DRIFTLESS_DATA`, else `../shared/data` beside the project.
fn data(rel: &str) -> PathBuf {
    match std::env::var_os("DRIFTLESS_DATA") {
        Some(p) => PathBuf::from(p),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"),
    }
    .join(rel)
}

fn read(rel: &str) -> (Vec<u8>, String) {
    let p = data(rel);
    (std::fs::read(&p).unwrap(), p.display().to_string())
}

const ULOG: &str = "logs/px4_ulog/sample_log_small.ulg";
const DATAFLASH: &str = "logs/ardupilot_dataflash/backend_log_80k.bin";

fn range(v: &[f64]) -> (f64, f64) {
    v.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        })
}

/// Median as numpy computes it (mean of the middle two for an even count).
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// pyulog's sample_log_small.ulg: generic topic access (values cross-checked with pyulog).
#[test]
#[ignore = "needs shared data"]
fn px4_ulog_topics_match_pyulog() {
    let (bytes, name) = read(ULOG);
    assert_eq!(detect_format(&bytes), Some(AutopilotFormat::ULog));
    let u = parse_ulog(&bytes, &name).unwrap();
    assert_eq!(u.truncated_at_byte, None);
    assert_eq!(u.instances("sensor_gyro").len(), 3);
    assert_eq!(u.instances("sensor_accel").len(), 3);
    let g = u.topic("sensor_gyro", 0).unwrap();
    assert_eq!(g.len(), 6);
    assert_eq!(g.timestamps_us().unwrap()[0], 21_312_030);
    assert_eq!(g.column("x").unwrap()[0], f64::from(-0.041_303_21_f32));
    let a = u.topic("sensor_accel", 0).unwrap();
    assert_eq!(a.timestamps_us().unwrap()[0], 21_312_085);
    assert!(a.field_names().any(|f| f == "clip_counter[2]"));
    assert!(!a.field_names().any(|f| f.starts_with("_padding")));
    assert_eq!(u.parameters.len(), 980);
    assert_eq!(
        u.info["ver_hw"],
        vec![driftless::io::ulog::InfoValue::Text(
            "CUBEPILOT_CUBEORANGE".into()
        )]
    );
    assert_eq!(u.dropouts.len(), 1);
    assert_eq!(u.dropouts[0].duration_ms, 30);
    assert_eq!(u.log_messages.len(), 3);
    // pyulog lists 70 topic instances with data.
    assert_eq!(u.topics.iter().filter(|t| !t.is_empty()).count(), 70);
}

/// pyulog's sample_log_small.ulg: one IMU log per instance, gyro and accel joined.
#[test]
#[ignore = "needs shared data"]
fn px4_ulog_imu_logs() {
    let (bytes, name) = read(ULOG);
    let r = imu_logs_from_ulog(&bytes, &name).unwrap();
    assert_eq!(r.format, AutopilotFormat::ULog);
    assert_eq!(r.truncated_at_byte, None);
    let inst: Vec<u8> = r.imus.iter().map(|i| i.instance).collect();
    assert_eq!(inst, [0, 1, 2]);
    let temps = [
        (40.02537, 40.36083),
        (28.246023, 28.368422),
        (29.434422, 29.721958),
    ];
    let norms = [9.758297, 9.921783, 9.836068]; // numpy medians, accel rows as logged
    for (imu, ((lo, hi), norm)) in r.imus.iter().zip(temps.into_iter().zip(norms)) {
        let log = &imu.log;
        assert_eq!(log.len(), 6, "instance {}", imu.instance);
        assert_eq!(
            log.channels.len(),
            7,
            "no separate acc_temperature: same chip"
        );
        let (tl, th) = range(&log.channel("temperature").unwrap().values);
        assert!(
            (tl - lo).abs() < 1e-5 && (th - hi).abs() < 1e-5,
            "{tl} {th}"
        );
        assert!((log.tau0_s - 1.0).abs() < 0.01, "{}", log.tau0_s);
        let [ax, ay, az] = log.triad_of(Quantity::SpecificForce).unwrap();
        let n = median(
            (0..6)
                .map(|i| (ax[i].powi(2) + ay[i].powi(2) + az[i].powi(2)).sqrt())
                .collect(),
        );
        assert!((n - norm).abs() < 1e-5, "accel norm {n}");
        let [gx, gy, gz] = log.triad_of(Quantity::AngularRate).unwrap();
        assert!((0..6).all(|i| (gx[i].powi(2) + gy[i].powi(2) + gz[i].powi(2)).sqrt() < 0.1));
    }
    let l0 = &r.imus[0].log;
    assert_eq!(l0.time_s.as_ref().unwrap()[0], 21.312030);
    assert_eq!(
        l0.channel("acc_x").unwrap().values[0],
        f64::from(0.682_129_8_f32)
    );
    assert_eq!(
        l0.channel("acc_z").unwrap().values[0],
        f64::from(-9.696_953_f32)
    );
    assert!(
        r.found
            .iter()
            .any(|(n, c)| n == "sensor_gyro[2]" && *c == 6)
    );
}

/// MethodicConfigurator's truncated DataFlash log: clean stop, IMU values as pymavlink.
#[test]
#[ignore = "needs shared data"]
fn ardupilot_dataflash_truncated_log() {
    let (bytes, name) = read(DATAFLASH);
    assert_eq!(bytes.len(), 81_920);
    assert_eq!(detect_format(&bytes), Some(AutopilotFormat::DataFlash));
    let df = parse_dataflash(&bytes, &name).unwrap();
    assert_eq!(df.skipped_bytes, 0);
    // The last two bytes are the `0xA3 0x95` of a message whose type byte was cut off.
    let cut = df.truncated_at_byte.expect("the log is cut mid-message");
    assert_eq!(cut, 81_918);
    assert_eq!(bytes[81_918..], [0xA3, 0x95]);
    assert_eq!(df.count("FMT"), 184);
    assert_eq!(df.count("PARM"), 1077);
    assert_eq!(df.count("IMU"), 20);
    assert!(!df.parameters().is_empty());
    let r = imu_logs_from_dataflash(&bytes, &name).unwrap();
    assert_eq!(r.truncated_at_byte, Some(cut));
    assert!(r.notes.iter().any(|n| n.contains("truncated")));
    assert_eq!(r.imus.len(), 2);
    let l0 = &r.imus[0].log;
    assert_eq!(l0.len(), 10);
    assert_eq!(l0.time_s.as_ref().unwrap()[0], 140.209868);
    assert_eq!(*l0.time_s.as_ref().unwrap().last().unwrap(), 140.575610);
    assert_eq!(
        l0.channel("gyro_x").unwrap().values[0],
        0.005344705190509558
    );
    assert_eq!(l0.channel("acc_z").unwrap().values[0], -9.763680458068848);
    assert_eq!(
        l0.channel("temperature").unwrap().values[0],
        37.3057975769043
    );
    let (tl, th) = range(&l0.channel("temperature").unwrap().values);
    assert!((tl - 37.30466842651367).abs() < 1e-9 && (th - 37.313560485839844).abs() < 1e-9);
    let l1 = &r.imus[1].log;
    assert_eq!(l1.len(), 10);
    assert!(
        l1.channel("temperature")
            .unwrap()
            .values
            .iter()
            .all(|&t| t == 28.5)
    );
    for (imu, norm) in r.imus.iter().zip([9.817251951826298, 9.803149146330014]) {
        let [ax, ay, az] = imu.log.triad_of(Quantity::SpecificForce).unwrap();
        let n = median(
            (0..10)
                .map(|i| (ax[i].powi(2) + ay[i].powi(2) + az[i].powi(2)).sqrt())
                .collect(),
        );
        assert!((n - norm).abs() < 1e-12, "{n}");
    }
}

/// Cutting the real logs anywhere never panics; ULog cuts stop cleanly past the header,
/// DataFlash cuts always stop cleanly. (ULog: every byte of the first 4 KiB, the
/// definitions, then 200 cuts spread over the file; DataFlash: every 7th byte.)
#[test]
#[ignore = "needs shared data"]
fn real_logs_truncated_anywhere() {
    let (u, _) = read(ULOG);
    let cuts = (0..4096).chain((0..200).map(|k| k * u.len() / 200 + 13));
    for cut in cuts.filter(|&c| c <= u.len()) {
        match parse_ulog(&u[..cut], "u") {
            Ok(p) => assert!(cut >= 16 && p.truncated_at_byte.is_none_or(|t| t < cut as u64)),
            Err(e) => assert!(cut < 16, "cut {cut}: {e}"),
        }
        let _ = imu_logs_from_ulog(&u[..cut], "u");
    }
    let (d, _) = read(DATAFLASH);
    for cut in (0..d.len()).step_by(7) {
        let p = parse_dataflash(&d[..cut], "d").unwrap();
        assert_eq!(p.skipped_bytes, 0, "cut {cut}");
        let _ = imu_logs_from_dataflash(&d[..cut], "d");
    }
}
