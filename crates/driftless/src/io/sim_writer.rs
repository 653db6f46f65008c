//! The files of a simulation ([`crate::sim::scenario::Simulation`]) with known truth, in
//! the families [`SimFamilies`] chooses:
//!
//! * `imu.csv` — rates with the reported temperature (`time [s]`, `gyro_x [rad/s]` …,
//!   `temp [degC]`);
//! * `imu.txt`, `truth.nav`, `gnss.txt`, `kf-gins.yaml` — KF-GINS formats: increments,
//!   the truth as a `.nav` file, 7-column GNSS, and a configuration that starts from the
//!   true state with noise from the sensor model ([`kfgins_config`]);
//! * `gnss.pos` — the fixes as RTKLIB `.pos`;
//! * `manifest.toml` — chamber segments (chamber scenarios), and `sensor.toml` — the
//!   resolved sensor-error configuration, with any choice.
//!
//! Every file goes through [`crate::io::output`] (temporary file, then rename).

use crate::io::LogError;
use crate::io::nav::{
    KfGinsConfigRaw, write_kfgins_gnss, write_kfgins_imu, write_kfgins_nav, write_rtklib_pos,
};
use crate::io::output::AtomicFile;
use crate::sim::scenario::{Scenario, Simulation, euler_of};
use driftless_model::units::{DEG_PER_H, DEG_PER_SQRT_H, M_PER_S_PER_SQRT_H};
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// Which families of files [`write_simulation`] writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SimFamilies {
    /// `imu.csv`.
    pub csv: bool,
    /// `imu.txt`, `truth.nav`, `gnss.txt`, `kf-gins.yaml`.
    pub kfgins: bool,
    /// `gnss.pos`.
    pub rtklib: bool,
}

impl SimFamilies {
    /// Every family.
    pub const ALL: SimFamilies = SimFamilies {
        csv: true,
        kfgins: true,
        rtklib: true,
    };
}

/// Every file [`write_simulation`] may write.
pub(crate) const SIM_OUTPUT_FILES: [&str; 8] = [
    "imu.csv",
    "imu.txt",
    "truth.nav",
    "gnss.txt",
    "gnss.pos",
    "kf-gins.yaml",
    "manifest.toml",
    "sensor.toml",
];

/// Why writing a simulation's files failed.
#[derive(Debug, thiserror::Error)]
pub enum SimWriteError {
    /// A folder or file could not be created.
    #[error("creating {}", path.display())]
    Create {
        /// The folder or file.
        path: PathBuf,
        /// Cause.
        source: std::io::Error,
    },
    /// A file could not be written.
    #[error("writing {}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// Cause.
        source: std::io::Error,
    },
    /// A file of an earlier run could not be removed.
    #[error("removing {} of an earlier run", path.display())]
    Remove {
        /// The file.
        path: PathBuf,
        /// Cause.
        source: std::io::Error,
    },
    /// The sensor configuration could not be serialised.
    #[error("serialising the sensor configuration")]
    Sensor(#[source] toml::ser::Error),
    /// A data file could not be written.
    #[error(transparent)]
    Log(Box<LogError>),
    /// The chamber manifest could not be serialised.
    #[error(transparent)]
    Manifest(#[from] crate::calib::protocol::ManifestError),
}

impl From<LogError> for SimWriteError {
    fn from(e: LogError) -> Self {
        SimWriteError::Log(Box::new(e))
    }
}

/// Writes the files of `sim` (run from `sc`) chosen by `families` into `dir` (created if
/// missing), then removes the files of an earlier simulation there that this run did not
/// replace — a GNSS file of another trajectory must not sit beside this run's IMU file.
/// Returns the files written, in order.
pub fn write_simulation(
    sim: &Simulation,
    sc: &Scenario,
    dir: &Path,
    families: SimFamilies,
) -> Result<Vec<PathBuf>, SimWriteError> {
    std::fs::create_dir_all(dir).map_err(|source| SimWriteError::Create {
        path: dir.to_path_buf(),
        source,
    })?;
    let files = write_files(sim, sc, dir, families)?;
    remove_stale_outputs(dir, &files)?;
    Ok(files)
}

fn create(dir: &Path, name: &str) -> Result<(AtomicFile, PathBuf), SimWriteError> {
    let path = dir.join(name);
    let f = AtomicFile::create(&path).map_err(|source| SimWriteError::Create {
        path: path.clone(),
        source,
    })?;
    Ok((f, path))
}

fn commit(f: AtomicFile, path: &Path) -> Result<(), SimWriteError> {
    f.commit().map_err(|source| SimWriteError::Write {
        path: path.to_path_buf(),
        source,
    })
}

fn write_small(path: PathBuf, bytes: impl AsRef<[u8]>) -> Result<PathBuf, SimWriteError> {
    crate::io::output::write(&path, bytes).map_err(|source| SimWriteError::Write {
        path: path.clone(),
        source,
    })?;
    Ok(path)
}

fn write_files(
    sim: &Simulation,
    sc: &Scenario,
    dir: &Path,
    families: SimFamilies,
) -> Result<Vec<PathBuf>, SimWriteError> {
    let mut files = Vec::new();
    let source = format!("driftless simulate {}", sc.name);
    // The big files are independent: write them concurrently.
    let (csv, kf) = rayon::join(
        || -> Result<Option<PathBuf>, SimWriteError> {
            if !families.csv {
                return Ok(None);
            }
            let p = dir.join("imu.csv");
            crate::io::write_csv_file(&sim.rates_log(&source), &p)?;
            Ok(Some(p))
        },
        || -> Result<Vec<PathBuf>, SimWriteError> {
            let mut out = Vec::new();
            if !families.kfgins {
                return Ok(out);
            }
            let (mut f, p) = create(dir, "imu.txt")?;
            write_kfgins_imu(buf(&mut f), &p.display().to_string(), &sim.increments())?;
            commit(f, &p)?;
            out.push(p);
            let (mut f, p) = create(dir, "truth.nav")?;
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
            let (mut f, p) = create(dir, "gnss.txt")?;
            write_kfgins_gnss(buf(&mut f), &p.display().to_string(), g)?;
            commit(f, &p)?;
            files.push(p);
        }
        if families.rtklib {
            let (mut f, p) = create(dir, "gnss.pos")?;
            write_rtklib_pos(buf(&mut f), &p.display().to_string(), g, &source)?;
            commit(f, &p)?;
            files.push(p);
        }
        if families.kfgins {
            files.push(write_small(
                dir.join("kf-gins.yaml"),
                kfgins_config(sim).to_yaml(),
            )?);
        }
    }
    if let Some(m) = &sim.manifest {
        files.push(write_small(dir.join("manifest.toml"), m.to_toml_string()?)?);
    }
    let text = format!(
        "# The sensor-error configuration simulated (seed {}); turn-on biases drawn:\n\
         # gyro {:?} rad/s, accel {:?} m/s^2\n{}",
        sc.seed,
        sim.imu.gyro_turn_on_bias_rad_s,
        sim.imu.accel_turn_on_bias_m_s2,
        toml::to_string(&sim.sensor).map_err(SimWriteError::Sensor)?
    );
    files.push(write_small(dir.join("sensor.toml"), text)?);
    Ok(files)
}

/// Removes the files of [`SIM_OUTPUT_FILES`] in `dir` that `written` does not hold.
fn remove_stale_outputs(dir: &Path, written: &[PathBuf]) -> Result<(), SimWriteError> {
    for name in SIM_OUTPUT_FILES {
        let p = dir.join(name);
        if written.iter().all(|w| w.file_name() != p.file_name()) && p.is_file() {
            std::fs::remove_file(&p).map_err(|source| SimWriteError::Remove {
                path: p.clone(),
                source,
            })?;
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
pub fn kfgins_config(sim: &Simulation) -> KfGinsConfigRaw {
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
        imunoise: crate::io::nav::kfgins_config::ImuNoiseRaw {
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
