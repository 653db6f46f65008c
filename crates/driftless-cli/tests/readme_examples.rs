//! Every ```` ```sh ```` block of `README.md` runs as written, in order, and exits 0.
//!
//! How the blocks run:
//! - Each block is one `sh -e -x` script (a failing line ends it; `-x` puts the line in
//!   the failure message). Shell variables do not carry from one block to the next; files
//!   do: the blocks share one working directory, so a later block reads what an earlier one
//!   wrote (the simulated chamber of the calibration section is the thermal section's input).
//! - The working directory behaves like the repository root without being it: a scratch
//!   folder holding a symbolic link to every top-level entry of the repository, beside a
//!   `shared` link to the repository's `../shared` (or, with `DRIFTLESS_DATA` set, a `shared`
//!   folder whose `data` links there). Relative paths such as `examples/…` and
//!   `../shared/data/…` resolve as from the root, and every output lands in the scratch
//!   folder, which the test removes. The test also checks that the repository's
//!   `git status` is the same before and after (an example writing *through* a link, such
//!   as `--out examples/x`, would dirty it).
//! - `driftless` is the binary under test: its folder is first on `PATH`.
//! - Lines that would build or test this workspace again from inside its own test run are
//!   not run: `cargo install …` (CI runs the README's install line itself, into a scratch
//!   root, `.ci/run`) and `cargo test …` (the suite this test belongs to).
//!   `cargo run --release -p driftless-cli -- ARGS` — which the README says runs the same as
//!   `driftless ARGS` — runs as `driftless ARGS` (cargo would wait for the build lock this
//!   test run holds).
//! - A command expected to fail says so at the end of its line: `# exit N` (single-line
//!   commands only); the block then requires exactly that status.
//! - Synopses (`driftless allan FILE [FILE …] [--rate HZ]`) belong in ```` ```text ````
//!   blocks, which are not run.
//!
//! Runtime: about 1 min on an idle 2-core machine (the demo's 20 Monte Carlo runs take
//! most of it; the 0.7 GB simulated chamber and the soak fit on it about 30 s); each
//! block's time is printed.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// One fenced `sh` block: its first line number in README.md and its lines (fence
/// indentation removed).
struct Block {
    line: usize,
    lines: Vec<String>,
}

/// The ```` ```sh ```` blocks of `readme`, in order. Fences may be indented (blocks
/// inside list items); the fence's indentation is removed from the block's lines.
fn sh_blocks(readme: &str) -> Vec<Block> {
    let mut out = Vec::new();
    let mut current: Option<(usize, usize, Vec<String>)> = None;
    for (i, raw) in readme.lines().enumerate() {
        let trimmed = raw.trim_start();
        let indent = raw.len() - trimmed.len();
        match current.take() {
            None => {
                if trimmed.trim_end() == "```sh" {
                    current = Some((i + 1, indent, Vec::new()));
                }
            }
            Some((line, ind, mut lines)) => {
                if trimmed.trim_end() == "```" {
                    out.push(Block { line, lines });
                } else {
                    let cut = raw.len() - raw.trim_start().len();
                    lines.push(raw[cut.min(ind)..].to_owned());
                    current = Some((line, ind, lines));
                }
            }
        }
    }
    assert!(current.is_none(), "README.md: an ```sh block is not closed");
    out
}

/// What the test does with one line of a block.
#[derive(Debug, PartialEq)]
enum Action {
    Run(String),
    /// Not run; the reason is printed.
    Skip(&'static str),
}

/// The shell line to run for a README line (see the module docs).
fn action(line: &str) -> Action {
    let t = line.trim_start();
    if t.starts_with("cargo install ") {
        return Action::Skip("the install step is .ci/run's, into a scratch root");
    }
    if t.starts_with("cargo test ") {
        return Action::Skip("the test suite this test belongs to");
    }
    if let Some(rest) = t.strip_prefix("cargo run --release -p driftless-cli -- ") {
        return Action::Run(format!("driftless {rest}"));
    }
    let Some((cmd, comment)) = t.split_once("# exit ") else {
        return Action::Run(line.to_owned());
    };
    let Ok(code) = comment.trim().parse::<u8>() else {
        return Action::Run(line.to_owned());
    };
    assert!(
        !cmd.trim_end().ends_with('\\'),
        "`# exit N` is for single-line commands: {line}"
    );
    Action::Run(format!(
        "if {cmd}; then rc=0; else rc=$?; fi; \
         [ \"$rc\" -eq {code} ] || {{ echo \"expected exit {code}, got $rc\" >&2; exit 1; }}"
    ))
}

/// The script of a block: its lines mapped by [`action`]; continuation lines of a skipped
/// line are skipped with it.
fn script(block: &Block) -> (String, Vec<String>) {
    let mut s = String::new();
    let mut skipped = Vec::new();
    let mut skipping = false;
    for l in &block.lines {
        let continued = l.trim_end().ends_with('\\');
        if skipping {
            skipping = continued;
            continue;
        }
        match action(l) {
            Action::Run(r) => {
                s.push_str(&r);
                s.push('\n');
            }
            Action::Skip(why) => {
                skipped.push(format!("{} ({why})", l.trim()));
                skipping = continued;
            }
        }
    }
    (s, skipped)
}

fn repo_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .expect("repository root")
}

/// `git status --porcelain` of the repository, or `None` without git.
fn git_status(root: &Path) -> Option<String> {
    let o = Command::new("git")
        .args(["status", "--porcelain", "--untracked-files=all"])
        .current_dir(root)
        .output()
        .ok()?;
    o.status
        .success()
        .then(|| String::from_utf8_lossy(&o.stdout).into_owned())
}

/// The scratch folder `base/root` that stands in for the repository root (links to its
/// entries) with `base/shared` beside it. Returns `base/root`.
fn scratch_root(base: &Path, repo: &Path) -> PathBuf {
    use std::os::unix::fs::symlink;
    let root = base.join("root");
    std::fs::create_dir_all(&root).expect("scratch root");
    for e in std::fs::read_dir(repo).expect("repository") {
        let e = e.expect("entry");
        let name = e.file_name();
        if name == ".git" {
            continue;
        }
        symlink(e.path(), root.join(&name)).expect("link");
    }
    match std::env::var_os("DRIFTLESS_DATA") {
        Some(data) => {
            let shared = base.join("shared");
            std::fs::create_dir_all(&shared).expect("shared");
            let data = PathBuf::from(data).canonicalize().expect("DRIFTLESS_DATA");
            symlink(&data, shared.join("data")).expect("link data");
            if let Some(docs) = data.parent().map(|p| p.join("docs")).filter(|d| d.is_dir()) {
                symlink(docs, shared.join("docs")).expect("link docs");
            }
        }
        None => symlink(repo.join("../shared"), base.join("shared")).expect("link shared"),
    }
    root
}

#[test]
fn sh_blocks_are_found_and_lines_mapped() {
    let md = "intro\n```sh\na --x \\\n  --y\n```\n\n  ```sh\n  b\n  ```\n```text\nc FILE\n```\n";
    let blocks = sh_blocks(md);
    assert_eq!(blocks.len(), 2);
    assert_eq!(blocks[0].line, 2);
    assert_eq!(blocks[0].lines, ["a --x \\", "  --y"]);
    assert_eq!(blocks[1].lines, ["b"]);
    assert_eq!(
        action("cargo run --release -p driftless-cli -- demo   # 1."),
        Action::Run("driftless demo   # 1.".into())
    );
    assert!(matches!(
        action("cargo test --release --workspace"),
        Action::Skip(_)
    ));
    let b = Block {
        line: 1,
        lines: vec![
            "cargo install --locked \\".into(),
            "  --path x".into(),
            "driftless --help".into(),
        ],
    };
    let (s, skipped) = script(&b);
    assert_eq!(s, "driftless --help\n");
    assert_eq!(skipped.len(), 1);
    // An expected failure passes only with that exit status.
    let Action::Run(ok) = action("false   # exit 1") else {
        panic!("not run")
    };
    let Action::Run(wrong) = action("true   # exit 1") else {
        panic!("not run")
    };
    let status = |s: &str| Command::new("sh").args(["-e", "-c", s]).status().unwrap();
    assert!(status(&ok).success());
    assert!(!status(&wrong).success());
}

#[test]
#[ignore = "needs shared data"]
fn every_readme_sh_block_runs_from_the_repository_root() {
    let repo = repo_root();
    let readme = std::fs::read_to_string(repo.join("README.md")).expect("README.md");
    let blocks = sh_blocks(&readme);
    assert!(blocks.len() >= 8, "only {} ```sh blocks", blocks.len());
    let base = std::env::temp_dir().join(format!("driftless-readme-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&base);
    let root = scratch_root(&base, &repo);
    let before = git_status(&repo);
    let bin_dir = Path::new(env!("CARGO_BIN_EXE_driftless"))
        .parent()
        .expect("binary folder")
        .to_path_buf();
    let path = std::env::join_paths(std::iter::once(bin_dir).chain(std::env::split_paths(
        &std::env::var_os("PATH").unwrap_or_default(),
    )))
    .expect("PATH");
    let total = Instant::now();
    for b in &blocks {
        let (s, skipped) = script(b);
        for k in skipped {
            eprintln!("README.md:{}: not run: {k}", b.line);
        }
        let t = Instant::now();
        let o = Command::new("sh")
            .args(["-e", "-x", "-c", &s])
            .current_dir(&root)
            .env("PATH", &path)
            .output()
            .expect("sh");
        let err = String::from_utf8_lossy(&o.stderr);
        let tail: Vec<&str> = err.lines().rev().take(25).collect();
        assert!(
            o.status.success(),
            "README.md:{}: the ```sh block exited with {:?} (a synopsis belongs in a ```text \
             block)\n{s}\n--- stderr (last lines) ---\n{}",
            b.line,
            o.status.code(),
            tail.into_iter().rev().collect::<Vec<_>>().join("\n")
        );
        eprintln!(
            "README.md:{}: ok in {:.1} s",
            b.line,
            t.elapsed().as_secs_f64()
        );
    }
    eprintln!(
        "{} README blocks in {:.1} s",
        blocks.len(),
        total.elapsed().as_secs_f64()
    );
    assert_eq!(
        git_status(&repo),
        before,
        "a README example wrote into the repository"
    );
    let _ = std::fs::remove_dir_all(&base);
}
