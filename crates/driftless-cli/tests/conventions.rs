//! What every `driftless` command does alike: completion scripts and man pages that
//! cover every subcommand, exit status 2 for a usage error and 1 for bad data, the
//! global `--quiet` / `--verbose` (stdout only the result: `--json` parses with
//! `--verbose`; a clean `--quiet` run prints nothing on stderr), and `simulate --write`.

use std::path::{Path, PathBuf};
use std::process::Output;

mod common;
use common::{bin, run_json};

fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("driftless-conv-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn stdout_of(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr_of(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The subcommands `driftless --help` lists (so a new one is covered without editing
/// this test).
fn subcommands() -> Vec<String> {
    let o = bin().arg("--help").output().unwrap();
    assert!(o.status.success());
    let help = stdout_of(&o);
    let list: Vec<String> = help
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| !l.trim().is_empty())
        .filter_map(|l| l.split_whitespace().next().map(str::to_owned))
        .filter(|n| n != "help")
        .collect();
    for expected in ["allan", "nav", "simulate", "thermal", "completions", "man"] {
        assert!(list.iter().any(|n| n == expected), "{expected} in {list:?}");
    }
    list
}

#[test]
fn completion_scripts_cover_every_subcommand() {
    let subs = subcommands();
    for shell in ["bash", "zsh", "fish"] {
        let o = bin().args(["completions", shell]).output().unwrap();
        assert_eq!(o.status.code(), Some(0), "{shell}: {}", stderr_of(&o));
        let script = stdout_of(&o);
        for s in &subs {
            assert!(script.contains(s.as_str()), "{shell} script lacks {s}");
        }
        // The global flags complete everywhere.
        assert!(
            script.contains("quiet") && script.contains("verbose"),
            "{shell}"
        );
    }
    let bash = stdout_of(&bin().args(["completions", "bash"]).output().unwrap());
    assert!(
        bash.contains("complete -F _driftless"),
        "bash registers the function"
    );
    // An unknown shell is a usage error naming the valid ones.
    let o = bin().args(["completions", "tcsh"]).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr_of(&o).contains("bash, zsh, fish"),
        "{}",
        stderr_of(&o)
    );
}

#[test]
fn man_page_covers_every_subcommand_and_the_exit_status() {
    let subs = subcommands();
    let o = bin().arg("man").output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr_of(&o));
    let roff = stdout_of(&o);
    assert!(
        roff.contains(".TH driftless 1"),
        "{}",
        &roff[..200.min(roff.len())]
    );
    for s in &subs {
        // roff escapes the hyphen: driftless\-allan(1)
        assert!(
            roff.contains(&format!("driftless\\-{s}(1)")),
            "man page lacks {s}"
        );
    }
    assert!(roff.contains("Exit status"));

    let dir = scratch("man");
    let o = bin().args(["man", "--out"]).arg(&dir).output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr_of(&o));
    for page in std::iter::once("driftless.1".to_owned())
        .chain(subs.iter().map(|s| format!("driftless-{s}.1")))
    {
        let text =
            std::fs::read_to_string(dir.join(&page)).unwrap_or_else(|e| panic!("{page}: {e}"));
        let title = page.trim_end_matches(".1");
        assert!(text.contains(&format!(".TH {title} 1")), "{page}");
        assert!(stdout_of(&o).contains(&page), "{page} not listed");
    }
    // Nested subcommands get their own page too.
    assert!(dir.join("driftless-thermal-soak.1").is_file());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn exit_status_is_documented_and_kept() {
    let o = bin().arg("--help").output().unwrap();
    let help = stdout_of(&o);
    for line in ["Exit status:", "0  success", "1  error", "2  usage error"] {
        assert!(help.contains(line), "--help lacks {line:?}");
    }
    // Usage errors: an unknown flag, a missing argument, an unknown subcommand.
    for args in [
        &["allan", "--no-such-flag", "x.csv"][..],
        &["allan"][..],
        &["frobnicate"][..],
    ] {
        let o = bin().args(args).output().unwrap();
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr_of(&o));
    }
    // A data error: the file exists, its contents cannot be read as a log.
    let dir = scratch("exit");
    let p = dir.join("bad.csv");
    std::fs::write(&p, "time,gx\n0,1\n0.01,abc\n0.02,3\n").unwrap();
    let o = bin().arg("allan").arg(&p).output().unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stderr_of(&o));
    assert!(stderr_of(&o).contains("bad.csv:3"), "{}", stderr_of(&o));
    assert!(o.stdout.is_empty(), "no result on stdout after an error");
    // --quiet never hides an error.
    let o = bin().arg("allan").arg(&p).arg("--quiet").output().unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr_of(&o).starts_with("error: "), "{}", stderr_of(&o));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn negative_numbers_are_values_with_a_clear_message() {
    let dir = scratch("neg");
    let p = dir.join("log.csv");
    std::fs::write(&p, "1\n2\n3\n4\n5\n6\n7\n8\n9\n10\n").unwrap();
    let file = p.display().to_string();
    for (args, flag, needs) in [
        (vec!["allan", &file, "--rate", "-100"], "--rate", "positive"),
        (vec!["allan", &file, "--rate", "0"], "--rate", "positive"),
        (
            vec!["allan", &file, "--rate", "100", "--gap-factor", "-2"],
            "--gap-factor",
            "greater than 1",
        ),
        (
            vec!["allan", &file, "--instance", "-1"],
            "--instance",
            "zero or a positive",
        ),
        (
            vec!["convert", &file, "out.dlog", "--rate", "-5"],
            "--rate",
            "positive",
        ),
        (vec!["bench", "--hours", "-1"], "--hours", "positive"),
        (
            vec!["allan", &file, "--rate", "100", "--confidence", "-0.5"],
            "--confidence",
            "between 0 and 1",
        ),
        (
            vec!["allan", &file, "--rate", "100", "--scale", "0"],
            "--scale",
            "other than 0",
        ),
        (
            vec!["demo", "--noise", "--hours", "-1"],
            "--hours",
            "positive",
        ),
        (
            vec!["demo", "--noise", "--rate", "-50"],
            "--rate",
            "positive",
        ),
        (
            vec!["demo", "--runs", "-2"],
            "--runs",
            "positive whole number",
        ),
        (
            vec!["experiment", "x.toml", "--runs", "0"],
            "--runs",
            "positive whole number",
        ),
        (
            vec!["bench", "--runs", "-3"],
            "--runs",
            "positive whole number",
        ),
        (
            vec!["simulate", "x.toml", "--seed", "-7"],
            "--seed",
            "zero or a positive",
        ),
        (
            vec!["thermal", "check", &file, "--order", "-2"],
            "--order",
            "zero or a positive",
        ),
        (
            vec!["thermal", "check", &file, "--min-rise", "-10"],
            "--min-rise",
            "zero or a positive",
        ),
        (
            vec!["thermal", "ramp", &file, "--bin", "-1"],
            "--bin",
            "positive",
        ),
        (
            vec!["thermal", "soak", &file, "--gravity", "-9.8"],
            "--gravity",
            "positive",
        ),
        (
            vec!["thermal", "soak", &file, "--settled-band-c", "-0.2"],
            "--settled-band-c",
            "positive",
        ),
        (
            vec![
                "calibrate",
                "six-position",
                &file,
                "--orientation-tolerance-deg",
                "-15",
            ],
            "--orientation-tolerance-deg",
            "positive",
        ),
        (
            vec![
                "calibrate",
                "six-position",
                &file,
                "--table-rate-deg-s",
                "-50",
            ],
            "--table-rate-deg-s",
            "positive",
        ),
        (
            vec![
                "calibrate",
                "multi-position",
                &file,
                "--gyro-scale-guess",
                "-1e-4",
            ],
            "--gyro-scale-guess",
            "positive",
        ),
    ] {
        let o = bin().args(&args).current_dir(&dir).output().unwrap();
        let err = stderr_of(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(!err.contains("unexpected argument"), "{args:?}: {err}");
        assert!(err.contains(flag) && err.contains(needs), "{args:?}: {err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A static log with white noise on two gyro axes (deterministic, a few thousand rows).
fn static_log(dir: &Path) -> PathBuf {
    let p = dir.join("static.csv");
    let mut text = String::from("time [s],gyro_x [rad/s],gyro_y [rad/s]\n");
    let mut state = 12345u64;
    let mut noise = || {
        // xorshift: uniform in (-0.5, 0.5), enough for a white-noise curve
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    for i in 0..4000 {
        text.push_str(&format!(
            "{:.3},{:.6e},{:.6e}\n",
            i as f64 * 0.01,
            1e-3 * noise(),
            1e-3 * noise()
        ));
    }
    std::fs::write(&p, text).unwrap();
    p
}

/// Runs `args` with `--json --verbose` (stdout must be one JSON document) and with
/// `--quiet` (stderr must be empty), both successfully. An argument `{out}` becomes a
/// folder of its own for each run.
fn check_streams(what: &str, args: &[&std::ffi::OsStr], cwd: &Path) -> serde_json::Value {
    let with_out = |tag: &str| -> Vec<std::ffi::OsString> {
        args.iter()
            .map(|a| {
                if *a == "{out}" {
                    format!("out-{tag}").into()
                } else {
                    a.to_os_string()
                }
            })
            .collect()
    };
    let o = bin()
        .args(with_out("json"))
        .args(["--json", "--verbose"])
        .current_dir(cwd)
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{what} --json -v: {}",
        stderr_of(&o)
    );
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap_or_else(|e| {
        panic!(
            "{what} --json --verbose stdout is not JSON ({e}):\n{}",
            stdout_of(&o)
        )
    });
    let o = bin()
        .args(with_out("quiet"))
        .arg("--quiet")
        .current_dir(cwd)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{what} -q: {}", stderr_of(&o));
    assert!(
        o.stderr.is_empty(),
        "{what} --quiet wrote on stderr:\n{}",
        stderr_of(&o)
    );
    assert!(
        !o.stdout.is_empty(),
        "{what} --quiet still prints the result"
    );
    v
}

fn os<'a>(v: &'a [&'a str]) -> Vec<&'a std::ffi::OsStr> {
    v.iter().map(std::ffi::OsStr::new).collect()
}

#[test]
fn quiet_and_verbose_keep_stdout_for_the_result_allan_and_convert() {
    let dir = scratch("allan");
    let log = static_log(&dir);
    let log_s = log.display().to_string();
    let v = check_streams("allan", &os(&["allan", &log_s, "--no-fit"]), &dir);
    assert_eq!(v["channels"].as_array().unwrap().len(), 2);
    // The flags are global: also accepted before the subcommand, short forms too.
    let o = bin()
        .args(["-q", "allan", &log_s, "--no-fit"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr_of(&o));
    assert!(o.stderr.is_empty(), "{}", stderr_of(&o));
    // --quiet and --verbose together are a usage error.
    let o = bin().args(["allan", &log_s, "-q", "-v"]).output().unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr_of(&o));

    // convert prints its summary as a note: on stderr, silenced by --quiet.
    let out = dir.join("static.dlog");
    let o = bin().args(["convert", &log_s]).arg(&out).output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr_of(&o));
    assert!(o.stdout.is_empty() && stderr_of(&o).contains("4000 samples"));
    let out2 = dir.join("static2.dlog");
    let o = bin()
        .args(["convert", "-q", &log_s])
        .arg(&out2)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr_of(&o));
    assert!(o.stderr.is_empty(), "{}", stderr_of(&o));
    assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&out2).unwrap());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn quiet_and_verbose_keep_stdout_for_the_result_simulate_nav_calibrate_thermal() {
    let dir = scratch("sim");
    // Chamber run at one temperature: imu.csv + manifest.toml for calibrate and thermal.
    let chamber = dir.join("chamber.toml");
    std::fs::write(
        &chamber,
        "seed = 4\n[imu]\nrate_hz = 100.0\npreset = \"consumer\"\noutput = \"rates\"\n\
         errors = \"deterministic\"\n[trajectory]\ntype = \"chamber\"\n\
         temperatures_c = [25.0]\nsoak_s = 20.0\nposition_dwell_s = 10.0\n",
    )
    .unwrap();
    let v = check_streams(
        "simulate",
        &os(&[
            "simulate",
            "chamber.toml",
            "--out",
            "{out}",
            "--write",
            "csv",
        ]),
        &dir,
    );
    assert!(v["files"].as_array().unwrap().len() >= 2);
    let v = check_streams(
        "calibrate six-position",
        &os(&[
            "calibrate",
            "six-position",
            "out-json/imu.csv",
            "--manifest",
            "out-json/manifest.toml",
            "--g-sensitivity",
        ]),
        &dir,
    );
    assert!(v.is_object());
    let v = check_streams(
        "thermal check",
        &os(&["thermal", "check", "out-json/imu.csv"]),
        &dir,
    );
    assert!(v.is_array() || v.is_object());

    // A drive with GNSS: the KF-GINS files, run unchanged by nav --kf-gins.
    let city =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenarios/city-drive.toml");
    let o = bin()
        .args(["simulate", "--quiet", "--write", "kfgins,rtklib", "--out"])
        .arg(dir.join("city"))
        .arg(&city)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr_of(&o));
    assert!(o.stderr.is_empty(), "{}", stderr_of(&o));
    let city_dir = dir.join("city");
    let v = check_streams(
        "nav --kf-gins",
        &os(&["nav", "--kf-gins", "kf-gins.yaml"]),
        &city_dir,
    );
    assert!(v["gnss_accepted"].as_u64().unwrap() > 100);
    // What --quiet silenced: the note that the simulated starttime precedes the first
    // IMU epoch (printed on stderr without the flag, never on stdout).
    let o = bin()
        .args(["nav", "--kf-gins", "kf-gins.yaml", "--json"])
        .current_dir(&city_dir)
        .output()
        .unwrap();
    assert!(stderr_of(&o).contains("note: "), "{}", stderr_of(&o));
    assert!(!stdout_of(&o).contains("note: "));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn quiet_and_verbose_keep_stdout_for_the_result_demo() {
    let dir = scratch("demo");
    let v = check_streams(
        "demo --noise",
        &os(&["demo", "--noise", "--hours", "0.2", "--out", "{out}"]),
        &dir,
    );
    assert!(v["channels"].as_array().is_some_and(|c| !c.is_empty()));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Names of the regular files in `dir`.
fn files_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn simulate_write_chooses_the_output_families() {
    let dir = scratch("write");
    let city =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenarios/city-drive.toml");
    let kfgins = ["imu.txt", "truth.nav", "gnss.txt", "kf-gins.yaml"];

    // csv: the rate log (and the sensor truth), no KF-GINS or RTKLIB file.
    let csv = dir.join("csv");
    let v = run_json(
        bin()
            .args(["simulate", "--json", "--write", "csv", "--out"])
            .arg(&csv)
            .arg(&city),
    );
    assert_eq!(files_in(&csv), ["imu.csv", "sensor.toml"]);
    assert_eq!(v["files"].as_array().unwrap().len(), 2);

    // kfgins: a folder nav --kf-gins runs as it is.
    let kf = dir.join("kf");
    run_json(
        bin()
            .args(["simulate", "--json", "--write", "kfgins", "--out"])
            .arg(&kf)
            .arg(&city),
    );
    let mut expect: Vec<&str> = kfgins.iter().copied().chain(["sensor.toml"]).collect();
    expect.sort();
    assert_eq!(files_in(&kf), expect);
    let k = run_json(
        bin()
            .current_dir(&kf)
            .args(["nav", "--kf-gins", "kf-gins.yaml", "--json"]),
    );
    assert!(k["epochs"].as_u64().unwrap() > 20_000);
    assert!(k["gnss_accepted"].as_u64().unwrap() > 100);

    // rtklib: the fixes only; and a later run with --force removes what it did not write.
    let o = bin()
        .args([
            "simulate", "--json", "--force", "--write", "rtklib", "--out",
        ])
        .arg(&kf)
        .arg(&city)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr_of(&o));
    let left = files_in(&kf);
    assert!(left.contains(&"gnss.pos".to_owned()), "{left:?}");
    for f in kfgins {
        assert!(
            !left.contains(&f.to_owned()),
            "{f} of the earlier run left: {left:?}"
        );
    }

    // Unknown family: usage error listing the valid ones, nothing written.
    let o = bin()
        .args(["simulate", "--write", "csv,matlab", "--out"])
        .arg(dir.join("bad"))
        .arg(&city)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = stderr_of(&o);
    assert!(
        err.contains("matlab") && err.contains("csv, kfgins, rtklib"),
        "{err}"
    );
    assert!(!dir.join("bad").exists());

    // rtklib alone on a scenario without GNSS would write no data: refused up front.
    let st = dir.join("static.toml");
    std::fs::write(
        &st,
        "[imu]\nrate_hz = 100.0\npreset = \"consumer\"\n[trajectory]\ntype = \"static\"\n\
         lat_deg = 30.0\nduration_s = 5.0\n",
    )
    .unwrap();
    let o = bin()
        .args(["simulate", "--write", "rtklib", "--out"])
        .arg(dir.join("st"))
        .arg(&st)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr_of(&o).contains("no [gnss]"), "{}", stderr_of(&o));
    let _ = std::fs::remove_dir_all(&dir);
}

/// The `*_cmd` modules of the binary's sources (`foo_cmd.rs` and `foo_cmd/…`), each
/// with its files' text.
fn command_modules() -> Vec<(String, Vec<(PathBuf, String)>)> {
    fn files_under(p: &Path, out: &mut Vec<(PathBuf, String)>) {
        if p.is_dir() {
            let mut entries: Vec<PathBuf> = std::fs::read_dir(p)
                .unwrap()
                .map(|e| e.unwrap().path())
                .collect();
            entries.sort();
            for e in entries {
                files_under(&e, out);
            }
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push((p.to_path_buf(), std::fs::read_to_string(p).unwrap()));
        }
    }
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut modules: Vec<(String, Vec<(PathBuf, String)>)> = Vec::new();
    for e in std::fs::read_dir(&src).unwrap() {
        let p = e.unwrap().path();
        let stem = p.file_stem().unwrap().to_string_lossy().into_owned();
        if !stem.ends_with("_cmd") {
            continue;
        }
        let i = match modules.iter().position(|(m, _)| *m == stem) {
            Some(i) => i,
            None => {
                modules.push((stem, Vec::new()));
                modules.len() - 1
            }
        };
        files_under(&p, &mut modules[i].1);
    }
    modules.sort_by(|a, b| a.0.cmp(&b.0));
    modules
}

/// The `*_cmd` modules a source text names through `crate::` (`crate::foo_cmd`, or
/// `foo_cmd` inside a `crate::{…}` group).
fn cmd_modules_named(text: &str) -> Vec<String> {
    let mut named = Vec::new();
    let mut rest = text;
    while let Some(at) = rest.find("crate::") {
        rest = &rest[at + "crate::".len()..];
        let path: String = if let Some(group) = rest.strip_prefix('{') {
            group.chars().take_while(|&c| c != '}').collect()
        } else {
            rest.chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect()
        };
        for word in path.split(|c: char| !(c.is_alphanumeric() || c == '_')) {
            if word.ends_with("_cmd") && !named.iter().any(|n| n == word) {
                named.push(word.to_owned());
            }
        }
    }
    named
}

#[test]
fn command_modules_do_not_import_each_other() {
    // The scanner itself: it finds both spellings and nothing else.
    assert_eq!(
        cmd_modules_named("use crate::demo_cmd::spinner; crate::output::sci(1.0)"),
        ["demo_cmd"]
    );
    assert_eq!(
        cmd_modules_named("use crate::{input::InputArgs, allan_cmd::run};"),
        ["allan_cmd"]
    );
    let modules = command_modules();
    assert!(
        modules.len() >= 10 && modules.iter().any(|(m, _)| m == "allan_cmd"),
        "found only {:?}",
        modules.iter().map(|(m, _)| m).collect::<Vec<_>>()
    );
    let mut offences = Vec::new();
    for (module, files) in &modules {
        for (path, text) in files {
            for other in cmd_modules_named(text) {
                if other != *module {
                    offences.push(format!("{} uses crate::{other}", path.display()));
                }
            }
        }
    }
    assert!(
        offences.is_empty(),
        "command modules share work through the library or a neutral CLI module, never \
         through another command:\n{}",
        offences.join("\n")
    );
}
