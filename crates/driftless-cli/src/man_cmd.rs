//! `driftless man`: the man page (roff) made from the command-line definition — the
//! top-level page on standard output, or with `--out DIR` one page per command and
//! subcommand (`driftless.1`, `driftless-allan.1`, `driftless-thermal-ramp.1`, …).
//!
//! Read one without installing: `driftless man | man -l -`.

use anyhow::{Context, Result};
use clap::Args;
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct ManArgs {
    /// Write driftless.1 and one page per subcommand into this folder instead of printing
    /// the top-level page (existing pages of the same names are replaced).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
}

pub fn run(a: ManArgs, cmd: clap::Command) -> Result<()> {
    let mut cmd = cmd.disable_help_subcommand(true);
    cmd.build();
    let Some(dir) = &a.out else {
        out!("{}", render(&cmd)?.1);
        return Ok(());
    };
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let mut written = Vec::new();
    write_pages(&cmd, dir, &mut written)?;
    for p in &written {
        outln!("{}", p.display());
    }
    Ok(())
}

/// The page of `cmd`: its file name and roff text.
fn render(cmd: &clap::Command) -> Result<(String, String)> {
    let man = clap_mangen::Man::new(cmd.clone())
        .source(format!("driftless {}", env!("CARGO_PKG_VERSION")));
    let mut roff = Vec::new();
    man.render(&mut roff)
        .with_context(|| format!("rendering the man page of {}", cmd.get_name()))?;
    Ok((
        man.get_filename(),
        String::from_utf8_lossy(&roff).into_owned(),
    ))
}

/// Writes the page of `cmd` and of every visible subcommand, depth first.
fn write_pages(cmd: &clap::Command, dir: &Path, written: &mut Vec<PathBuf>) -> Result<()> {
    let (name, roff) = render(cmd)?;
    let p = dir.join(name);
    driftless::io::output::write(&p, roff).with_context(|| format!("writing {}", p.display()))?;
    written.push(p);
    for sub in cmd.get_subcommands().filter(|s| !s.is_hide_set()) {
        write_pages(sub, dir, written)?;
    }
    Ok(())
}
