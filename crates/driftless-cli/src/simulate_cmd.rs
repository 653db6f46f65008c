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

use anyhow::Result;
use clap::{Args, ValueEnum};
use driftless::io::sim_writer::{SimFamilies, write_simulation};
use driftless::sim::scenario::Scenario;
use std::path::PathBuf;
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
fn families(write: &[Family]) -> SimFamilies {
    let all = write.is_empty();
    SimFamilies {
        csv: all || write.contains(&Family::Csv),
        kfgins: all || write.contains(&Family::Kfgins),
        rtklib: all || write.contains(&Family::Rtklib),
    }
}

pub fn run(a: SimulateArgs) -> Result<()> {
    let mut sc = Scenario::from_file(&a.scenario)?;
    if let Some(s) = a.seed {
        sc.seed = s;
    }
    let families = families(&a.write);
    if !families.csv && !families.kfgins && sc.gnss.is_none() {
        anyhow::bail!(
            "{}: --write rtklib writes only gnss.pos, and the scenario has no [gnss]; \
             add csv or kfgins to --write, or a [gnss] section to the scenario",
            a.scenario.display()
        );
    }
    let dir = a.out.clone().unwrap_or_else(|| sc.output.dir.clone());
    let _lock = driftless::io::output::claim_folder(&dir, a.force)?;
    let pb = crate::progress::spinner(!a.json, format!("simulating {}", a.scenario.display()));
    let t = Instant::now();
    let sim = sc.run()?;
    let sim_s = t.elapsed().as_secs_f64();
    pb.set_message(format!("writing {}", dir.display()));
    let t = Instant::now();
    let files = write_simulation(&sim, &sc, &dir, families)?;
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
