//! `allan --export FORMAT=PATH,…`: the noise model in the units of other estimators, from
//! a fresh fit or from a saved model (`--model`).

use anyhow::{Context, Result, bail};
use driftless::allan::export::{self, ExportFormat, ExportOptions, GivenValues};
use driftless::allan::noise_model::NoiseModel;
use std::path::{Path, PathBuf};

use super::AllanArgs;

/// The `--export` targets and `--export-set` values, checked before any work.
pub(super) struct Exports {
    targets: Vec<(ExportFormat, PathBuf)>,
    given: GivenValues,
}

impl Exports {
    /// Parses `--export` and `--export-set`.
    pub(super) fn from_args(a: &AllanArgs) -> Result<Exports> {
        let mut targets: Vec<(ExportFormat, PathBuf)> = Vec::new();
        for item in a
            .export
            .iter()
            .flat_map(|s| s.split(','))
            .map(str::trim)
            .filter(|s| !s.is_empty())
        {
            let Some((format, path)) = item.split_once('=') else {
                bail!(
                    "--export {item:?}: expected FORMAT=PATH with FORMAT one of {}",
                    format_names()
                );
            };
            let format: ExportFormat = format.parse().context("--export")?;
            let path = PathBuf::from(path.trim());
            if path.as_os_str().is_empty() {
                bail!("--export {item:?}: the path is empty");
            }
            if let Some((f, _)) = targets.iter().find(|(_, p)| *p == path) {
                bail!(
                    "--export writes {} twice ({f} and {format}); give each format its own file",
                    path.display()
                );
            }
            targets.push((format, path));
        }
        for p in [a.save_model.as_deref(), a.plot.as_deref()]
            .into_iter()
            .flatten()
        {
            if targets.iter().any(|(_, t)| t == p) {
                bail!(
                    "--export writes {} that another output (--save-model or --plot) writes too",
                    p.display()
                );
            }
        }
        let given = match &a.export_set {
            Some(s) => s.parse::<GivenValues>().context("--export-set")?,
            None => GivenValues::default(),
        };
        if a.export_set.is_some() && targets.is_empty() {
            bail!("--export-set gives values for --export; add --export FORMAT=PATH");
        }
        Ok(Exports { targets, given })
    }

    /// Whether anything is to be exported.
    pub(super) fn is_empty(&self) -> bool {
        self.targets.is_empty()
    }

    /// The output paths, for the check against the inputs.
    pub(super) fn paths(&self) -> impl Iterator<Item = &Path> {
        self.targets.iter().map(|(_, p)| p.as_path())
    }

    /// Builds every file's text first (so a missing value writes nothing), then writes
    /// them; returns one line per file written.
    pub(super) fn write(&self, model: &NoiseModel) -> Result<Vec<String>> {
        let imu = export::imu_noise(model, &self.given);
        let opts = ExportOptions::default();
        let texts = self
            .targets
            .iter()
            .map(|(f, p)| {
                export::export(*f, &imu, &opts)
                    .with_context(|| format!("--export {f}={}", p.display()))
            })
            .collect::<Result<Vec<String>>>()?;
        let mut done = Vec::new();
        for ((f, p), text) in self.targets.iter().zip(texts) {
            let bounds = text.contains("CHECK:");
            driftless::io::output::write(p, text)
                .with_context(|| format!("writing {f} noise parameters {}", p.display()))?;
            let flagged = if bounds {
                " (lines marked CHECK hold a bound, see the file)"
            } else {
                ""
            };
            done.push(format!(
                "{f} noise parameters written to {}{flagged}",
                p.display()
            ));
        }
        Ok(done)
    }
}

fn format_names() -> String {
    let names: Vec<&str> = ExportFormat::ALL.iter().map(|f| f.name()).collect();
    names.join(", ")
}

/// `allan --model FILE --export …`: export a saved model without analysing a log.
pub(super) fn run_saved_model(a: &AllanArgs, model_path: &Path) -> Result<()> {
    if a.plot.is_some() || a.save_model.is_some() {
        bail!(
            "--model exports a saved noise model; --plot and --save-model need a log to \
             analyse"
        );
    }
    let exports = Exports::from_args(a)?;
    if exports.is_empty() {
        bail!(
            "--model {} needs --export FORMAT=PATH (formats: {})",
            model_path.display(),
            format_names()
        );
    }
    let outputs: Vec<Option<&Path>> = exports.paths().map(Some).collect();
    crate::paths::refuse_outputs_over_inputs(&outputs, &[Some(model_path)])?;
    let model = NoiseModel::load(model_path)
        .with_context(|| format!("reading noise model {}", model_path.display()))?;
    for line in exports.write(&model)? {
        outln!("{line}");
    }
    Ok(())
}
