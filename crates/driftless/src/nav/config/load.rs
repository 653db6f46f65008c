//! Loading a configuration: the file and the flag overrides merged into one TOML table,
//! located errors (`FILE:LINE:COL` or the flag), and the commented default file.

use super::*;

pub(super) fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

pub(super) fn flag_value(k: &Key, text: &str) -> Result<toml::Value, String> {
    let num = |s: &str| -> Result<f64, String> {
        let v: f64 = s
            .trim()
            .parse()
            .map_err(|_| format!("{s:?} is not a number"))?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(format!("{s:?} is not finite"))
        }
    };
    Ok(match k.kind {
        ValueKind::Float => toml::Value::Float(num(text)?),
        ValueKind::FloatOrAuto => match text.trim() {
            "auto" => toml::Value::String("auto".into()),
            t => toml::Value::Float(num(t).map_err(|e| format!("{e} (or `auto`)"))?),
        },
        ValueKind::Bool => match text.trim() {
            "true" | "yes" | "on" | "1" => toml::Value::Boolean(true),
            "false" | "no" | "off" | "0" => toml::Value::Boolean(false),
            other => return Err(format!("{other:?} is not true or false")),
        },
        ValueKind::Text => toml::Value::String(text.to_owned()),
        ValueKind::Vec3 => {
            let parts: Vec<&str> = text.split(',').collect();
            if parts.len() != 3 {
                return Err(format!(
                    "{text:?}: expected three comma-separated numbers ({})",
                    k.value_name
                ));
            }
            toml::Value::Array(
                parts
                    .iter()
                    .map(|p| num(p).map(toml::Value::Float))
                    .collect::<Result<_, _>>()?,
            )
        }
        ValueKind::List => toml::Value::Array(
            text.split(',')
                .map(|s| toml::Value::String(s.trim().to_owned()))
                .collect(),
        ),
        ValueKind::Table => {
            let mut t = toml::Table::new();
            for pair in text.split(',') {
                let (name, v) = pair
                    .split_once('=')
                    .ok_or_else(|| format!("{pair:?}: expected NAME=NUMBER"))?;
                t.insert(name.trim().to_owned(), toml::Value::Float(num(v)?));
            }
            toml::Value::Table(t)
        }
    })
}

pub(super) fn merge(into: &mut toml::Table, from: toml::Table) {
    for (k, v) in from {
        match (into.get_mut(&k), v) {
            (Some(toml::Value::Table(a)), toml::Value::Table(b)) => merge(a, b),
            (_, v) => {
                into.insert(k, v);
            }
        }
    }
}

impl LoadedConfig {
    /// Where key `path` was set, for messages.
    pub(crate) fn locate(&self, path: &str) -> String {
        if self.from_flags.contains(path) {
            let flag = key_by_path(path).map_or(path, |k| k.flag);
            return format!("flag --{flag}");
        }
        let Some(file) = &self.file else {
            return format!("key `{path}` (default)");
        };
        let name = file.display();
        if let Some(text) = &self.source_text
            && let Ok(doc) = text.parse::<toml_edit::ImDocument<String>>()
        {
            let mut item: Option<&toml_edit::Item> = None;
            for (i, part) in path.split('.').enumerate() {
                item = if i == 0 {
                    doc.get(part)
                } else {
                    item.and_then(|it| it.get(part))
                };
            }
            if let Some(span) = item.and_then(|it| it.span()) {
                let (l, c) = line_col(text, span.start);
                return format!("{name}:{l}:{c} (key `{path}`)");
            }
        }
        format!("{name} (key `{path}`, default)")
    }

    /// A [`KeyError`] located.
    pub fn error(&self, e: KeyError) -> ConfigError {
        ConfigError {
            location: self.locate(&e.key),
            message: e.message,
        }
    }

    /// A path value of key `path`: `${DRIFTLESS_DATA}` expanded, then resolved against the
    /// configuration's folder (file values) or the working directory (flags).
    pub fn path(&self, key_path: &str, p: &Path) -> PathBuf {
        let base = if self.from_flags.contains(key_path) {
            Path::new("")
        } else {
            self.base_dir.as_path()
        };
        crate::io::resolve_data_path(p, base)
    }
}

impl NavConfig {
    /// Reads `file` (if any), applies `overrides` on top, checks every value
    /// ([`NavConfig::validate`]). Errors name the file, line and column or the flag.
    pub fn load(file: Option<&Path>, overrides: &[Override]) -> Result<LoadedConfig, ConfigError> {
        let source = match file {
            Some(f) => {
                let text = crate::io::nav::read_text_capped(f, MAX_CONFIG_BYTES).map_err(|e| {
                    ConfigError {
                        location: f.display().to_string(),
                        message: e,
                    }
                })?;
                let base_dir = f.parent().map(Path::to_path_buf).unwrap_or_default();
                Some((text, f.to_path_buf(), base_dir))
            }
            None => None,
        };
        NavConfig::load_text(source, overrides)
    }

    /// [`NavConfig::load`] of a configuration text: (text, name for messages, folder its
    /// relative paths resolve against).
    pub fn load_text(
        source: Option<(String, PathBuf, PathBuf)>,
        overrides: &[Override],
    ) -> Result<LoadedConfig, ConfigError> {
        let mut table = toml::Table::new();
        let mut source_text = None;
        let mut base_dir = PathBuf::new();
        let mut file = None;
        if let Some((text, path, dir)) = source {
            let name = path.display().to_string();
            // Types and unknown keys, with the file's own positions.
            if let Err(e) = toml::from_str::<NavConfig>(&text) {
                let location = match e.span() {
                    Some(s) => {
                        let (l, c) = line_col(&text, s.start);
                        format!("{name}:{l}:{c}")
                    }
                    None => name.clone(),
                };
                return Err(ConfigError {
                    location,
                    message: format!(
                        "{} (`driftless nav --print-config` lists every key with its type)",
                        e.message().trim()
                    ),
                });
            }
            table = toml::from_str(&text).map_err(|e| ConfigError {
                location: name.clone(),
                message: e.message().to_owned(),
            })?;
            source_text = Some(text);
            base_dir = dir;
            file = Some(path);
        }
        let mut from_flags = BTreeSet::new();
        for o in overrides {
            let value = flag_value(o.key, &o.value).map_err(|m| ConfigError {
                location: format!("flag --{} {}", o.key.flag, o.value),
                message: m,
            })?;
            let (section, name) = o.key.path.split_once('.').unwrap_or(("", o.key.path));
            let mut inner = toml::Table::new();
            inner.insert(name.to_owned(), value);
            let mut outer = toml::Table::new();
            outer.insert(section.to_owned(), toml::Value::Table(inner));
            // Each flag's value must fit its key on its own.
            if let Err(e) = NavConfig::deserialize(toml::Value::Table(outer.clone())) {
                return Err(ConfigError {
                    location: format!("flag --{} {}", o.key.flag, o.value),
                    message: e.to_string(),
                });
            }
            merge(&mut table, outer);
            from_flags.insert(o.key.path);
        }
        let config =
            NavConfig::deserialize(toml::Value::Table(table)).map_err(|e| ConfigError {
                location: file
                    .as_ref()
                    .map_or("flags".into(), |f| f.display().to_string()),
                message: e.to_string(),
            })?;
        let loaded = LoadedConfig {
            config,
            base_dir,
            from_flags,
            file,
            source_text,
        };
        loaded.config.validate().map_err(|e| loaded.error(e))?;
        Ok(loaded)
    }

    /// The commented default configuration (`driftless nav --print-config`): every key
    /// with its help, defaults as values, optional keys commented out with an example.
    pub fn default_toml() -> String {
        let defaults = toml::Value::try_from(NavConfig::default())
            .unwrap_or(toml::Value::Table(toml::Table::new()));
        let mut out = String::from(
            "# driftless navigation configuration (`driftless nav --config FILE`).\n\
             # Every key is also a flag (shown after the help); flags override this file.\n\
             # Relative paths resolve against this file's folder; ${DRIFTLESS_DATA} expands.\n",
        );
        let mut section = "";
        for k in KEYS {
            let (sec, name) = k.path.split_once('.').unwrap_or(("", k.path));
            if sec != section {
                out.push_str(&format!("\n[{sec}]\n"));
                section = sec;
            }
            out.push_str(&format!("# {} (--{})\n", k.help, k.flag));
            match defaults.get(sec).and_then(|s| s.get(name)) {
                Some(v) => out.push_str(&format!("{name} = {}\n", render(v))),
                None => out.push_str(&format!("# {name} = {}\n", k.example)),
            }
        }
        out
    }
}

pub(super) fn render(v: &toml::Value) -> String {
    match v {
        toml::Value::Table(t) => {
            let inner: Vec<String> = t
                .iter()
                .map(|(k, v)| format!("{k} = {}", render(v)))
                .collect();
            format!("{{ {} }}", inner.join(", "))
        }
        toml::Value::Array(a) => {
            let inner: Vec<String> = a.iter().map(render).collect();
            format!("[{}]", inner.join(", "))
        }
        toml::Value::Float(f) => {
            let s = format!("{f:?}");
            if s.contains('.') || s.contains('e') || s.contains("inf") || s.contains("NaN") {
                s
            } else {
                format!("{s}.0")
            }
        }
        other => other.to_string(),
    }
}
