//! `driftless simulate SCENARIO.toml`: run a simulation scenario
//! ([`driftless::sim::scenario`]) and write its data with known truth:
//!
//! * `imu.csv` — rates with the reported temperature (`time [s]`, `gyro_x [rad/s]` …,
//!   `temp [degC]`; `driftless nav --imu-format csv` and `driftless allan` read it);
//! * `imu.txt`, `gnss.txt`, `truth.nav`, `kf-gins.yaml` — KF-GINS formats: increments,
//!   7-column GNSS, the truth as a `.nav` file, and a configuration that starts from
//!   the true state with noise from the sensor model (`driftless nav --kf-gins
//!   OUT/kf-gins.yaml` runs it);
//! * `gnss.pos` — the fixes as RTKLIB `.pos`;
//! * `manifest.toml` — chamber segments (chamber scenarios);
//! * `sensor.toml` — the resolved sensor-error configuration (the truth of every term).
//!
//! `--write csv,kfgins,rtklib` chooses the families written (default all): `csv` is
//! `imu.csv`, `kfgins` the four KF-GINS files, `rtklib` `gnss.pos`; `manifest.toml` and
//! `sensor.toml` (small: the truth of the segments and of the sensor) come with any choice.
//! The chamber example (`examples/scenarios/chamber-adi.toml`: 14 h of 100 Hz rates, no
//! GNSS) writes 0.70 GB of `imu.csv` and 0.62 GB of `imu.txt` (and 9 MB of `truth.nav`);
//! `driftless thermal soak` and `calibrate six-position` read only `imu.csv` and
//! `manifest.toml`, which `--write csv` writes alone (0.70 of the 1.33 GB).

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use driftless::io::nav::{
    KfGinsConfigRaw, write_kfgins_gnss, write_kfgins_imu, write_kfgins_nav, write_rtklib_pos,
};
use driftless::io::output::AtomicFile;
use driftless::sim::scenario::{Scenario, Simulation, euler_of};
use driftless_model::units::{DEG_PER_H, DEG_PER_SQRT_H, M_PER_S_PER_SQRT_H};
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(Args, Debug)]
pub struct SimulateArgs {
    /// Scenario file (TOML; see `driftless::sim::scenario` or the README).
    pub scenario: PathBuf,
    /// Output folder (default: the scenario's `[output] dir`, else `sim-out`).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Write into an output folder that already holds files: this run's files replace
    /// theirs, and files an earlier simulation wrote that this run does not are removed.
    /// Without it such a folder is refused, so that runs never mix.
    #[arg(long)]
    pub force: bool,
    /// Output families to write, comma-separated (default: all). csv: imu.csv (rates and
    /// temperature; for allan, calibrate, thermal and nav --imu-format csv); kfgins:
    /// imu.txt, truth.nav, gnss.txt and kf-gins.yaml (what nav --kf-gins runs); rtklib:
    /// gnss.pos (the fixes, RTKLIB .pos). manifest.toml (chamber scenarios) and
    /// sensor.toml (the sensor truth) are written with any choice.
    #[arg(long, value_enum, value_delimiter = ',', value_name = "FAMILIES")]
    pub write: Vec<Family>,
    /// Override the scenario's seed.
    #[arg(long, value_parser = crate::numbers::whole::<u64>, allow_hyphen_values = true)]
    pub seed: Option<u64>,
    /// Machine-readable summary.
    #[arg(long)]
    pub json: bool,
}

/// A family of output files (`--write`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Family {
    /// imu.csv: rates with the reported temperature.
    Csv,
    /// imu.txt, truth.nav, gnss.txt, kf-gins.yaml: the KF-GINS formats and configuration.
    Kfgins,
    /// gnss.pos: the GNSS fixes as RTKLIB .pos.
    Rtklib,
}

/// The families `--write` asked for (all when the flag is not given).
#[derive(Clone, Copy, Debug)]
struct Families {
    csv: bool,
    kfgins: bool,
    rtklib: bool,
}

impl Families {
    fn of(write: &[Family]) -> Self {
        let all = write.is_empty();
        Families {
            csv: all || write.contains(&Family::Csv),
            kfgins: all || write.contains(&Family::Kfgins),
            rtklib: all || write.contains(&Family::Rtklib),
        }
    }
}

pub fn run(a: SimulateArgs) -> Result<()> {
    let mut sc = Scenario::from_file(&a.scenario)?;
    if let Some(s) = a.seed {
        sc.seed = s;
    }
    let families = Families::of(&a.write);
    if !families.csv && !families.kfgins && sc.gnss.is_none() {
        anyhow::bail!(
            "{}: --write rtklib writes only gnss.pos, and the scenario has no [gnss]; \
             add csv or kfgins to --write, or a [gnss] section to the scenario",
            a.scenario.display()
        );
    }
    let dir = a.out.clone().unwrap_or_else(|| sc.output.dir.clone());
    let _lock = driftless::io::output::claim_folder(&dir, a.force)?;
    let pb = crate::demo_cmd::spinner(!a.json, format!("simulating {}", a.scenario.display()));
    let t = Instant::now();
    let sim = sc.run()?;
    let sim_s = t.elapsed().as_secs_f64();
    pb.set_message(format!("writing {}", dir.display()));
    let t = Instant::now();
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let files = write_outputs(&sim, &sc, &dir, families)?;
    remove_stale_outputs(&dir, &files)?;
    let write_s = t.elapsed().as_secs_f64();
    pb.finish_and_clear();
    let n_fix = sim.gnss.as_ref().map_or(0, |g| g.len());
    if a.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({
                "imu_samples": sim.imu.len(),
                "imu_rate_hz": 1.0 / sim.imu.dt_s,
                "gnss_fixes": n_fix,
                "gnss_outages_s": sim.gnss_outages_s,
                "seed": sc.seed,
                "simulate_s": sim_s,
                "write_s": write_s,
                "files": files.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
            }))?
        );
    } else {
        outln!(
            "{}: {} IMU samples at {} Hz ({:.1} s), {} GNSS fixes, {} outage windows; seed {}",
            a.scenario.display(),
            sim.imu.len(),
            1.0 / sim.imu.dt_s,
            sim.imu.len() as f64 * sim.imu.dt_s,
            n_fix,
            sim.gnss_outages_s.len(),
            sc.seed
        );
        outln!("simulated in {sim_s:.2} s, written in {write_s:.2} s:");
        for f in &files {
            outln!("  {}", f.display());
        }
    }
    Ok(())
}

fn write_outputs(
    sim: &Simulation,
    sc: &Scenario,
    dir: &Path,
    families: Families,
) -> Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    let create = |name: &str| -> Result<(AtomicFile, PathBuf)> {
        let p = dir.join(name);
        let f = AtomicFile::create(&p).with_context(|| format!("creating {}", p.display()))?;
        Ok((f, p))
    };
    let commit = |f: AtomicFile, p: &Path| -> Result<()> {
        f.commit()
            .with_context(|| format!("writing {}", p.display()))
    };
    let source = format!("driftless simulate {}", sc.name);
    // The big files are independent: write them concurrently.
    let (csv, kf) = rayon::join(
        || -> Result<Option<PathBuf>> {
            if !families.csv {
                return Ok(None);
            }
            let p = dir.join("imu.csv");
            driftless::io::write_csv_file(&sim.rates_log(&source), &p)?;
            Ok(Some(p))
        },
        || -> Result<Vec<PathBuf>> {
            let mut out = Vec::new();
            if !families.kfgins {
                return Ok(out);
            }
            let (mut f, p) = create("imu.txt")?;
            write_kfgins_imu(buf(&mut f), &p.display().to_string(), &sim.increments())?;
            commit(f, &p)?;
            out.push(p);
            let (mut f, p) = create("truth.nav")?;
            write_kfgins_nav(buf(&mut f), &p.display().to_string(), &sim.truth, 0)?;
            commit(f, &p)?;
            out.push(p);
            Ok(out)
        },
    );
    files.extend(csv?);
    files.extend(kf?);
    if let Some(g) = &sim.gnss {
        if families.kfgins {
            let (mut f, p) = create("gnss.txt")?;
            write_kfgins_gnss(buf(&mut f), &p.display().to_string(), g)?;
            commit(f, &p)?;
            files.push(p);
        }
        if families.rtklib {
            let (mut f, p) = create("gnss.pos")?;
            write_rtklib_pos(buf(&mut f), &p.display().to_string(), g, &source)?;
            commit(f, &p)?;
            files.push(p);
        }
        if families.kfgins {
            let p = dir.join("kf-gins.yaml");
            driftless::io::output::write(&p, kfgins_config(sim).to_yaml())
                .with_context(|| format!("writing {}", p.display()))?;
            files.push(p);
        }
    }
    if let Some(m) = &sim.manifest {
        let p = dir.join("manifest.toml");
        driftless::io::output::write(&p, m.to_toml_string()?)
            .with_context(|| format!("writing {}", p.display()))?;
        files.push(p);
    }
    let p = dir.join("sensor.toml");
    let text = format!(
        "# The sensor-error configuration simulated (seed {}); turn-on biases drawn:\n\
         # gyro {:?} rad/s, accel {:?} m/s^2\n{}",
        sc.seed,
        sim.imu.gyro_turn_on_bias_rad_s,
        sim.imu.accel_turn_on_bias_m_s2,
        toml::to_string(&sim.sensor).context("serialising the sensor configuration")?
    );
    driftless::io::output::write(&p, text).with_context(|| format!("writing {}", p.display()))?;
    files.push(p);
    Ok(files)
}

/// Every file `simulate` may write.
const OUTPUT_FILES: [&str; 8] = [
    "imu.csv",
    "imu.txt",
    "truth.nav",
    "gnss.txt",
    "gnss.pos",
    "kf-gins.yaml",
    "manifest.toml",
    "sensor.toml",
];

/// Removes the files of an earlier simulation in `dir` that this run (`written`) did not
/// replace — a GNSS file of another trajectory must not sit beside this run's IMU file.
fn remove_stale_outputs(dir: &Path, written: &[PathBuf]) -> Result<()> {
    for name in OUTPUT_FILES {
        let p = dir.join(name);
        if written.iter().all(|w| w.file_name() != p.file_name()) && p.is_file() {
            std::fs::remove_file(&p)
                .with_context(|| format!("removing {} of an earlier run", p.display()))?;
        }
    }
    Ok(())
}

/// A 1 MiB buffer in front of an output file.
fn buf(f: &mut AtomicFile) -> BufWriter<&mut AtomicFile> {
    BufWriter::with_capacity(1 << 20, f)
}

/// A KF-GINS configuration for the simulated files: the true initial state with small
/// σ, noise from the sensor model (white noise → ARW/VRW; the larger of turn-on σ and
/// bias instability → bias σ; the scale-factor polynomial's constant term → scale σ,
/// at least 100 ppm; correlation time 1 h), the lever arm.
fn kfgins_config(sim: &Simulation) -> KfGinsConfigRaw {
    let s = &sim.sensor;
    let max3 = |f: &dyn Fn(usize) -> f64| (0..3).map(f).fold(0.0f64, f64::max);
    let arw = max3(&|k| s.gyro.noise[k].white) / DEG_PER_SQRT_H;
    let vrw = max3(&|k| s.accel.noise[k].white) / M_PER_S_PER_SQRT_H;
    let gb = max3(&|k| {
        s.gyro.turn_on_bias_sigma_rad_s[k].max(s.gyro.noise[k].bias_instability)
            + s.gyro.bias_poly_rad_s[k].first().map_or(0.0, |c| c.abs())
    }) / DEG_PER_H;
    let ab = max3(&|k| {
        s.accel.turn_on_bias_sigma_m_s2[k].max(s.accel.noise[k].bias_instability)
            + s.accel.bias_poly_m_s2[k].first().map_or(0.0, |c| c.abs())
    }) * 1e5;
    let sf = |p: &[Vec<f64>; 3]| {
        (0..3)
            .map(|k| p[k].first().map_or(0.0, |c| c.abs()))
            .fold(100e-6, f64::max)
            * 1e6
    };
    let floor = |v: f64, min: f64| if v > min { v } else { min };
    let n = &sim.initial;
    let e = euler_of(&n.q_bn);
    KfGinsConfigRaw {
        imupath: "imu.txt".into(),
        gnsspath: "gnss.txt".into(),
        outputpath: "kf-gins-out".into(),
        imudatalen: 7,
        imudatarate: (1.0 / sim.imu.dt_s).round() as i64,
        starttime: n.time_s,
        endtime: -1.0,
        initpos: [n.lat_rad.to_degrees(), n.lon_rad.to_degrees(), n.height_m],
        initvel: n.vel_ned_m_s,
        initatt: [
            e.roll_rad.to_degrees(),
            e.pitch_rad.to_degrees(),
            e.yaw_rad.to_degrees(),
        ],
        initgyrbias: [0.0; 3],
        initaccbias: [0.0; 3],
        initgyrscale: [0.0; 3],
        initaccscale: [0.0; 3],
        initposstd: [0.05; 3],
        initvelstd: [0.05; 3],
        initattstd: [0.1, 0.1, 0.5],
        initbgstd: None,
        initbastd: None,
        initsgstd: None,
        initsastd: None,
        imunoise: driftless::io::nav::kfgins_config::ImuNoiseRaw {
            arw: [floor(arw, 1e-3); 3],
            vrw: [floor(vrw, 1e-4); 3],
            gbstd: [floor(gb, 0.01); 3],
            abstd: [floor(ab, 1.0); 3],
            gsstd: [sf(&s.gyro.scale_factor_poly); 3],
            asstd: [sf(&s.accel.scale_factor_poly); 3],
            corrtime: 1.0,
        },
        antlever: sim.lever_arm_b_m,
    }
}
