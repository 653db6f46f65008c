//! Invariant checks shared by the harnesses.

use std::fmt::{Debug, Display};

/// Panics when the `Debug` text of `value` shows a non-finite float (`NaN`, `inf`, `-inf`)
/// outside string literals: a generic "every number in this parsed value is finite" check
/// for types that promise it.
pub fn finite_debug<T: Debug>(what: &str, value: &T) {
    let text = format!("{value:?}");
    if let Some(token) = non_finite_token(&text) {
        panic!("{what}: parsed value holds `{token}`: {text}");
    }
}

/// The first `NaN` or `inf` token of a `Debug` text outside `"…"` literals.
fn non_finite_token(text: &str) -> Option<&str> {
    let (mut in_string, mut escaped, mut start) = (false, false, None::<usize>);
    let bad = |t: &str| matches!(t, "NaN" | "inf");
    for (i, c) in text.char_indices() {
        if in_string {
            match (escaped, c) {
                (true, _) => escaped = false,
                (false, '\\') => escaped = true,
                (false, '"') => in_string = false,
                _ => {}
            }
            continue;
        }
        if c.is_alphanumeric() || c == '_' {
            start.get_or_insert(i);
            continue;
        }
        if let Some(s) = start.take()
            && bad(&text[s..i])
        {
            return Some(&text[s..i]);
        }
        in_string = c == '"';
    }
    start.map(|s| &text[s..]).filter(|t| bad(t))
}

/// Panics when an error's message is empty (or only white space).
pub fn message<E: Display>(what: &str, e: &E) -> String {
    let m = e.to_string();
    assert!(!m.trim().is_empty(), "{what}: empty error message");
    m
}

/// Panics when an error's message does not start with the input's name.
pub fn names_input<E: Display>(name: &str, e: &E) {
    let m = message(name, e);
    assert!(
        m.starts_with(name),
        "error does not name the input {name:?}: {m}"
    );
}

#[cfg(test)]
mod tests {
    use super::non_finite_token;

    #[test]
    fn finds_non_finite_outside_strings() {
        assert_eq!(non_finite_token("A { x: NaN }"), Some("NaN"));
        assert_eq!(non_finite_token("[1.0, -inf]"), Some("inf"));
        assert_eq!(non_finite_token("Some(inf)"), Some("inf"));
        assert_eq!(
            non_finite_token(r#"A { name: "NaN \" inf", info: 1.0 }"#),
            None
        );
        assert_eq!(non_finite_token("infinite_ok: 2.5e-3"), None);
    }
}
