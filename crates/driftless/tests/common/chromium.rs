//! Headless-Chromium checks of a self-contained HTML page: did every `<img>` decode (the
//! page's `<p id="image-check">images loaded: K/N</p>`, written by its own script after
//! `load`), and does a screenshot show something other than a blank page. Included with
//! `#[path]` by `tests/report_html.rs`; reusable by any test that writes HTML.
//!
//! The browser is `$DRIFTLESS_CHROMIUM`, else the first of `/usr/bin/chromium`,
//! `chromium`, `chromium-browser`, `google-chrome` found. A missing browser is an
//! error, not a skip: the callers are `#[ignore = "needs chromium"]` tests that CI runs
//! explicitly, and a silent pass there would hide a broken report.
#![allow(dead_code)] // each test file uses a different subset

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// Longest a single Chromium run may take before it is killed.
const RUN_TIMEOUT: Duration = Duration::from_secs(120);

/// The Chromium executable, or why there is none.
pub fn chromium_binary() -> Result<PathBuf, String> {
    if let Some(p) = std::env::var_os("DRIFTLESS_CHROMIUM") {
        let p = PathBuf::from(p);
        return if p.is_file() {
            Ok(p)
        } else {
            Err(format!("DRIFTLESS_CHROMIUM={} is not a file", p.display()))
        };
    }
    let fixed = Path::new("/usr/bin/chromium");
    if fixed.is_file() {
        return Ok(fixed.to_path_buf());
    }
    let path = std::env::var_os("PATH").unwrap_or_default();
    for name in ["chromium", "chromium-browser", "google-chrome"] {
        for dir in std::env::split_paths(&path) {
            let p = dir.join(name);
            if p.is_file() {
                return Ok(p);
            }
        }
    }
    Err(
        "chromium not found (install it, e.g. `apt-get install -y chromium`, or set \
         DRIFTLESS_CHROMIUM)"
            .into(),
    )
}

/// A fresh, empty directory under the temp dir, removed on drop (a new Chromium
/// profile per run: no state leaks between runs or from a user's browser).
pub struct TempDir(pub PathBuf);

impl TempDir {
    pub fn new(tag: &str) -> Result<TempDir, String> {
        static N: AtomicUsize = AtomicUsize::new(0);
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.subsec_nanos())
            .unwrap_or(0);
        let dir = std::env::temp_dir().join(format!(
            "driftless-{tag}-{}-{}-{nanos}",
            std::process::id(),
            N.fetch_add(1, Ordering::Relaxed)
        ));
        std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        Ok(TempDir(dir))
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// `file://` URL of an absolute or relative path.
fn file_url(html: &Path) -> Result<String, String> {
    let abs = std::fs::canonicalize(html).map_err(|e| format!("{}: {e}", html.display()))?;
    let s = abs
        .to_str()
        .ok_or_else(|| format!("{} is not UTF-8", abs.display()))?;
    // Percent-encode what a URL path cannot hold literally.
    let mut url = String::from("file://");
    for b in s.bytes() {
        match b {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'/' | b'-' | b'_' | b'.' | b'~' => {
                url.push(char::from(b))
            }
            _ => url.push_str(&format!("%{b:02X}")),
        }
    }
    Ok(url)
}

/// Runs headless Chromium on `html` with `extra` arguments, in a fresh profile;
/// returns its stdout. Fails on a non-zero exit or after [`RUN_TIMEOUT`].
pub fn run_chromium(html: &Path, extra: &[String]) -> Result<String, String> {
    let bin = chromium_binary()?;
    let profile = TempDir::new("chromium-profile")?;
    let out_dir = TempDir::new("chromium-out")?;
    let (stdout_path, stderr_path) = (out_dir.0.join("stdout"), out_dir.0.join("stderr"));
    let file = |p: &Path| std::fs::File::create(p).map_err(|e| format!("{}: {e}", p.display()));
    let mut cmd = Command::new(&bin);
    cmd.args([
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--hide-scrollbars",
        "--virtual-time-budget=5000",
    ])
    .arg(format!("--user-data-dir={}", profile.0.display()))
    .args(extra)
    .arg(file_url(html)?)
    .stdin(Stdio::null())
    .stdout(file(&stdout_path)?)
    .stderr(file(&stderr_path)?);
    let mut child = cmd
        .spawn()
        .map_err(|e| format!("cannot start {}: {e}", bin.display()))?;
    let start = Instant::now();
    let status = loop {
        match child.try_wait() {
            Ok(Some(s)) => break s,
            Ok(None) if start.elapsed() > RUN_TIMEOUT => {
                let _ = child.kill();
                let _ = child.wait();
                return Err(format!("chromium did not finish within {RUN_TIMEOUT:?}"));
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(50)),
            Err(e) => return Err(format!("waiting for chromium: {e}")),
        }
    };
    let stdout = std::fs::read_to_string(&stdout_path).unwrap_or_default();
    if !status.success() {
        let stderr = std::fs::read_to_string(&stderr_path).unwrap_or_default();
        let tail: String = stderr
            .lines()
            .rev()
            .take(15)
            .collect::<Vec<_>>()
            .into_iter()
            .rev()
            .collect::<Vec<_>>()
            .join("\n");
        return Err(format!("chromium exited with {status}:\n{tail}"));
    }
    Ok(stdout)
}

/// The DOM of `html` after its scripts ran (`--dump-dom`).
pub fn dump_dom(html: &Path) -> Result<String, String> {
    run_chromium(html, &["--dump-dom".to_owned()])
}

/// `(K, N)` from the first `images loaded: K/N` in `dom`.
pub fn parse_image_check(dom: &str) -> Result<(usize, usize), String> {
    let key = "images loaded: ";
    let i = dom.find(key).ok_or_else(|| {
        "no `images loaded: K/N` in the DOM (did the page script run?)".to_owned()
    })?;
    let rest = &dom[i + key.len()..];
    let end = rest
        .find(|c: char| !(c.is_ascii_digit() || c == '/'))
        .unwrap_or(rest.len());
    let (k, n) = rest[..end]
        .split_once('/')
        .ok_or_else(|| format!("malformed image check {:?}", &rest[..end]))?;
    let parse = |s: &str| {
        s.parse::<usize>()
            .map_err(|e| format!("image check {:?}: {e}", &rest[..end]))
    };
    Ok((parse(k)?, parse(n)?))
}

/// Images that decoded and images in total, as the page itself counted them.
pub fn image_check(html: &Path) -> Result<(usize, usize), String> {
    parse_image_check(&dump_dom(html)?)
}

/// What a screenshot showed.
#[derive(Debug, Clone)]
pub struct Screenshot {
    pub width: u32,
    pub height: u32,
    pub file_bytes: usize,
    /// Fraction of pixels that are not (near) white; `None` when the PNG could not be
    /// decoded in this build (no `png` feature), see [`check_not_blank`].
    pub non_white_fraction: Option<f64>,
    /// Number of distinct colours (quantised to 4 bits per channel), if decoded.
    pub colours: Option<usize>,
}

/// Screenshot of `html` at `width` × `height` CSS px into `png`, then measured.
pub fn screenshot(html: &Path, png: &Path, width: u32, height: u32) -> Result<Screenshot, String> {
    let _ = std::fs::remove_file(png);
    run_chromium(
        html,
        &[
            format!("--screenshot={}", png.display()),
            format!("--window-size={width},{height}"),
        ],
    )?;
    let bytes = std::fs::read(png).map_err(|e| format!("no screenshot {}: {e}", png.display()))?;
    let (w, h) = png_size(&bytes)?;
    let (non_white_fraction, colours) = pixel_stats(&bytes)?;
    Ok(Screenshot {
        width: w,
        height: h,
        file_bytes: bytes.len(),
        non_white_fraction,
        colours,
    })
}

/// Width and height from the PNG signature and IHDR chunk.
pub fn png_size(bytes: &[u8]) -> Result<(u32, u32), String> {
    if bytes.len() < 24 || &bytes[..8] != b"\x89PNG\r\n\x1a\n" || &bytes[12..16] != b"IHDR" {
        return Err("not a PNG file".into());
    }
    let be = |i: usize| u32::from_be_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
    Ok((be(16), be(20)))
}

#[cfg(feature = "png")]
fn pixel_stats(bytes: &[u8]) -> Result<(Option<f64>, Option<usize>), String> {
    let img = tiny_skia::Pixmap::decode_png(bytes).map_err(|e| format!("PNG decode: {e}"))?;
    let px = img.pixels();
    let non_white = px
        .iter()
        .filter(|p| p.red() < 245 || p.green() < 245 || p.blue() < 245)
        .count();
    let mut seen = std::collections::HashSet::new();
    for p in px {
        seen.insert((p.red() >> 4, p.green() >> 4, p.blue() >> 4));
    }
    Ok((
        Some(non_white as f64 / px.len().max(1) as f64),
        Some(seen.len()),
    ))
}

#[cfg(not(feature = "png"))]
fn pixel_stats(_bytes: &[u8]) -> Result<(Option<f64>, Option<usize>), String> {
    Ok((None, None))
}

/// Fails if the screenshot looks blank. With pixels (the `png` feature, as in CI's
/// workspace run): at least `min_non_white` of them not white and ≥ 16 colours. Without:
/// a compressed-size floor — a uniform page deflates to well under 0.01 byte per pixel,
/// a page of anti-aliased plots and text to far more.
pub fn check_not_blank(s: &Screenshot, min_non_white: f64) -> Result<(), String> {
    match (s.non_white_fraction, s.colours) {
        (Some(f), Some(c)) => {
            if f < min_non_white || c < 16 {
                return Err(format!(
                    "screenshot looks blank: {:.2} % non-white pixels, {c} colours",
                    100.0 * f
                ));
            }
        }
        _ => {
            let per_px = s.file_bytes as f64 / (f64::from(s.width) * f64::from(s.height));
            if per_px < 0.02 {
                return Err(format!(
                    "screenshot looks blank: {} bytes for {}×{} px",
                    s.file_bytes, s.width, s.height
                ));
            }
        }
    }
    Ok(())
}
