//! Inputs that are not plain regular files, or not what they claim: standard input, pipes,
//! FIFOs, gzip streams, devices without end, executables, files without line ends, logs at
//! two sample rates, model files that are not model files.
#![cfg(unix)]

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

mod common;
use common::bin;

fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("driftless-inputs-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn text(o: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// Runs `cmd` with `input` on its standard input.
fn with_stdin(cmd: &mut Command, input: &[u8]) -> Output {
    let mut child = cmd
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let input = input.to_vec();
    // A reader that stops early closes the pipe: the broken pipe is not an error here.
    let writer = std::thread::spawn(move || {
        let _ = stdin.write_all(&input);
    });
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap();
    out
}

/// Runs `cmd`, killing it after `limit`: (output, elapsed, finished in time).
fn bounded(cmd: &mut Command, limit: Duration) -> (Output, Duration, bool) {
    let t0 = Instant::now();
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut in_time = true;
    while child.try_wait().unwrap().is_none() {
        if t0.elapsed() > limit {
            in_time = false;
            let _ = child.kill();
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    let out = child.wait_with_output().unwrap();
    (out, t0.elapsed(), in_time)
}

#[test]
fn standard_input_gives_the_same_analysis_as_the_file() {
    let d = scratch("stdin");
    let seq: String = (1..=1000).map(|k| format!("{k}\n")).collect();
    let file = d.join("seq.txt");
    std::fs::write(&file, &seq).unwrap();
    let gz = d.join("seq.txt.gz");
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(seq.as_bytes()).unwrap();
    std::fs::write(&gz, e.finish().unwrap()).unwrap();

    let from_file = bin()
        .arg("allan")
        .arg(&file)
        .args(["--rate", "1"])
        .output()
        .unwrap();
    let (want, err) = text(&from_file);
    assert!(from_file.status.success(), "{err}");
    assert!(want.contains("1000 samples"), "{want}");
    let want = want.replace(&file.display().to_string(), "INPUT");
    for input in [seq.as_bytes().to_vec(), std::fs::read(&gz).unwrap()] {
        let o = with_stdin(bin().args(["allan", "/dev/stdin", "--rate", "1"]), &input);
        let (got, err) = text(&o);
        assert!(o.status.success(), "{err}");
        assert_eq!(got.replace("/dev/stdin", "INPUT"), want);
    }

    // The first bytes of a piped log are data, not only a magic to sniff.
    let out = d.join("out.csv");
    let o = with_stdin(
        bin()
            .args(["convert", "/dev/stdin"])
            .arg(&out)
            .args(["--rate", "1"]),
        b"1000.123456789\n1001\n1002\n",
    );
    assert!(o.status.success(), "{}", text(&o).1);
    let csv = std::fs::read_to_string(&out).unwrap();
    assert!(csv.contains("\n1000.123456789\n1001\n1002\n"), "{csv}");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_binary_log_through_a_fifo_is_read_like_the_file() {
    let d = scratch("fifo");
    let csv = d.join("log.csv");
    let rows: String = (0..2000)
        .map(|k| format!("{},{}\n", k as f64 * 0.01, ((k * 7) % 13) as f64 * 0.01))
        .collect();
    std::fs::write(&csv, format!("time,gx\n{rows}")).unwrap();
    let dlog = d.join("log.dlog");
    let o = bin().arg("convert").arg(&csv).arg(&dlog).output().unwrap();
    assert!(o.status.success(), "{}", text(&o).1);
    let fifo = d.join("fifo");
    match Command::new("mkfifo").arg(&fifo).status() {
        Ok(s) if s.success() => {}
        _ => {
            println!("note: no `mkfifo` here; FIFO test skipped");
            return;
        }
    }
    let bytes = std::fs::read(&dlog).unwrap();
    let f2 = fifo.clone();
    let writer = std::thread::spawn(move || {
        if let Ok(mut f) = std::fs::OpenOptions::new().write(true).open(&f2) {
            let _ = f.write_all(&bytes);
        }
    });
    let (o, _, in_time) = bounded(bin().arg("allan").arg(&fifo), Duration::from_secs(30));
    if !in_time {
        // Unblock the writer before failing.
        let _ = std::fs::File::open(&fifo);
    }
    writer.join().unwrap();
    assert!(in_time, "reading a binary log through a FIFO hangs");
    let (got, err) = text(&o);
    assert!(o.status.success(), "{err}");
    let want = bin().arg("allan").arg(&dlog).output().unwrap();
    assert_eq!(
        got.replace(&fifo.display().to_string(), "INPUT"),
        text(&want).0.replace(&dlog.display().to_string(), "INPUT")
    );
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn endless_binary_and_newline_free_inputs_end_in_an_error_within_a_second() {
    let d = scratch("endless");
    let noline = d.join("noline.txt");
    let mut f = std::fs::File::create(&noline).unwrap();
    let chunk = "0.1,0.2,0.3,".repeat(1 << 16);
    for _ in 0..5 {
        f.write_all(chunk.as_bytes()).unwrap();
    }
    drop(f);
    let mut cases: Vec<(PathBuf, &str)> = vec![(noline.clone(), "line 1 is longer than 1 MiB")];
    for (dev, what) in [
        ("/dev/zero", "binary data, not a text log (byte offset 0"),
        ("/bin/ls", "binary data, not a text log"),
    ] {
        if Path::new(dev).exists() {
            cases.push((PathBuf::from(dev), what));
        }
    }
    for (path, what) in cases {
        let (o, took, in_time) = bounded(
            bin().arg("allan").arg(&path).args(["--rate", "100"]),
            Duration::from_secs(10),
        );
        let err = text(&o).1;
        assert!(in_time, "{}: still running after 10 s", path.display());
        assert_eq!(o.status.code(), Some(1), "{}: {err}", path.display());
        assert!(err.contains(what), "{}: {err}", path.display());
        assert!(
            took < Duration::from_secs(1),
            "{}: {took:?}",
            path.display()
        );
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_log_at_two_rates_is_refused() {
    let d = scratch("rates");
    let mut t = 0.0f64;
    let mut s = String::from("time,gx\n");
    for k in 0..10_000 {
        s.push_str(&format!("{t:.4},{}\n", ((k * 7) % 13) as f64 * 0.01));
        t += if k < 3000 { 0.01 } else { 0.02 };
    }
    let log = d.join("two.csv");
    std::fs::write(&log, s).unwrap();
    let o = bin().arg("allan").arg(&log).output().unwrap();
    let err = text(&o).1;
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("the sample rate changes: 50 Hz"), "{err}");
    assert!(err.contains("but 100 Hz"), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_model_file_over_the_size_cap_is_refused_naming_it() {
    let d = scratch("model");
    let log = d.join("log.csv");
    std::fs::write(&log, "time,gx\n0,1\n0.01,2\n0.02,3\n0.03,4\n").unwrap();
    let big = d.join("big.toml");
    std::fs::File::create(&big)
        .unwrap()
        .set_len(17 << 20)
        .unwrap();
    let mut models = vec![big.clone()];
    if Path::new("/dev/zero").exists() {
        models.push(PathBuf::from("/dev/zero"));
    }
    for model in models {
        let (o, took, in_time) = bounded(
            bin()
                .arg("compensate")
                .arg(&log)
                .arg("--model")
                .arg(&model)
                .arg("--out")
                .arg(d.join("out.csv")),
            Duration::from_secs(10),
        );
        let err = text(&o).1;
        assert!(in_time && took < Duration::from_secs(1), "{took:?}");
        assert_eq!(o.status.code(), Some(1), "{err}");
        assert!(
            err.contains(&model.display().to_string()) && err.contains("larger than 16 MiB"),
            "{err}"
        );
    }
    let _ = std::fs::remove_dir_all(&d);
}

fn simulate_drive(out: &Path) {
    let scenario =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenarios/city-drive.toml");
    let o = bin()
        .args(["simulate", "--json", "--out"])
        .arg(out)
        .arg(scenario)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o).1);
}

/// `nav` reads its IMU and GNSS files once, so standard input works for either when the IMU
/// format is stated; with `auto` a pipe is refused (detection would consume its first
/// line), naming the flag to set. `/dev/zero` as the GNSS file ends in an error at once.
#[test]
fn nav_reads_standard_input_once_or_says_what_to_set() {
    let d = scratch("navpipe");
    let sim = d.join("sim");
    simulate_drive(&sim);
    let imu = std::fs::read(sim.join("imu.txt")).unwrap();
    let gnss = std::fs::read(sim.join("gnss.txt")).unwrap();
    let run = |imu_arg: &Path, gnss_arg: &Path, extra: &[&str], input: &[u8]| {
        with_stdin(
            bin()
                .args(["nav", "--json", "--imu"])
                .arg(imu_arg)
                .arg("--gnss")
                .arg(gnss_arg)
                .args(extra),
            input,
        )
    };
    let (imu_file, gnss_file) = (sim.join("imu.txt"), sim.join("gnss.txt"));
    let stdin = Path::new("/dev/stdin");
    let file = run(&imu_file, &gnss_file, &[], b"");
    assert!(file.status.success(), "{}", text(&file).1);
    let piped_imu = run(stdin, &gnss_file, &["--imu-format", "kfgins"], &imu);
    assert!(piped_imu.status.success(), "{}", text(&piped_imu).1);
    assert_eq!(piped_imu.stdout, file.stdout);
    let piped_gnss = run(&imu_file, stdin, &[], &gnss);
    assert!(piped_gnss.status.success(), "{}", text(&piped_gnss).1);
    assert_eq!(piped_gnss.stdout, file.stdout);

    let auto = run(stdin, &gnss_file, &[], &imu);
    let (out, err) = text(&auto);
    assert_eq!(auto.status.code(), Some(1), "{out}");
    assert!(
        err.contains("/dev/stdin") && err.contains("--imu-format") && out.is_empty(),
        "{err}"
    );

    let (o, took, finished) = bounded(
        bin()
            .args(["nav", "--imu"])
            .arg(&imu_file)
            .args(["--gnss", "/dev/zero"]),
        Duration::from_secs(10),
    );
    assert!(finished && took < Duration::from_secs(5), "{took:?}");
    assert_eq!(o.status.code(), Some(1));
    assert!(
        text(&o).1.contains("/dev/zero: binary data"),
        "{}",
        text(&o).1
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// A KF-GINS configuration whose GNSS file belongs to another trajectory (a leftover of
/// another simulation) is refused, naming the file and the distance from `initpos`, not
/// run to a solution of neither trajectory with exit 0.
#[test]
fn a_kf_gins_gnss_file_of_another_trajectory_is_refused() {
    let d = scratch("foreign");
    let sim = d.join("sim");
    simulate_drive(&sim);
    // The same drive's fixes, moved 20 km north: another trajectory at the same times.
    let moved: String = std::fs::read_to_string(sim.join("gnss.txt"))
        .unwrap()
        .lines()
        .map(|l| {
            let mut f: Vec<String> = l.split_whitespace().map(str::to_owned).collect();
            let lat: f64 = f[1].parse().unwrap();
            f[1] = format!("{:.11}", lat + 0.18);
            f.join(" ") + "\n"
        })
        .collect();
    std::fs::write(sim.join("gnss.txt"), moved).unwrap();
    let o = bin()
        .current_dir(&sim)
        .args(["nav", "--kf-gins", "kf-gins.yaml"])
        .output()
        .unwrap();
    let (_, err) = text(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("gnss.txt") && err.contains("km from initpos") && err.contains("20.0 km"),
        "{err}"
    );
    assert!(
        !sim.join("kf-gins-out").exists(),
        "outputs written for a refused run"
    );
    let _ = std::fs::remove_dir_all(&d);
}
