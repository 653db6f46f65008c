//! `driftless completions SHELL`: the shell completion script on standard output, made
//! from the command-line definition itself (so it never lists a flag that is gone).
//!
//! Install, e.g.: `driftless completions bash > ~/.local/share/bash-completion/completions/driftless`,
//! `driftless completions zsh > ~/.zfunc/_driftless`,
//! `driftless completions fish > ~/.config/fish/completions/driftless.fish`.

use anyhow::Result;
use clap::{Args, ValueEnum};
use clap_complete::Shell;

/// The shells a script is made for.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum ShellName {
    Bash,
    Zsh,
    Fish,
}

#[derive(Args, Debug)]
pub struct CompletionsArgs {
    /// The shell to complete in.
    #[arg(value_enum)]
    pub shell: ShellName,
}

pub fn run(a: CompletionsArgs, mut cmd: clap::Command) -> Result<()> {
    let shell = match a.shell {
        ShellName::Bash => Shell::Bash,
        ShellName::Zsh => Shell::Zsh,
        ShellName::Fish => Shell::Fish,
    };
    let name = cmd.get_name().to_owned();
    let mut script = Vec::new();
    clap_complete::generate(shell, &mut cmd, name, &mut script);
    out!("{}", String::from_utf8_lossy(&script));
    Ok(())
}
