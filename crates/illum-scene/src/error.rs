//! Errors from loading and checking a scene.
//!
//! Every message carries four things, so a user can fix the file without reading code: where
//! (the file, or "command line" for flags), which field (a dotted path such as
//! `objects[3] ("tall block").box.half_extent`), the value that was given, and what is allowed.

use std::ops::Range;

/// Why a scene could not be loaded or used.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("{file}: cannot read the scene file")]
    Io {
        file: String,
        #[source]
        source: std::io::Error,
    },

    /// The text is not valid TOML, or does not have the shape of a scene file (an unknown key,
    /// a missing key, a string where a number belongs, ...). `line` and `column` are 1-based and
    /// point at the offending text; `message` is the parser's description, which names the key
    /// for unknown and missing keys.
    #[error("{file}:{line}:{column}: {message}")]
    Syntax { file: String, line: usize, column: usize, message: String },

    /// A well-formed value that the renderer cannot accept.
    #[error("{file}: {field} = {value}: {allowed}")]
    Invalid {
        /// The file label, or the origin of the value (e.g. "command line").
        file: String,
        /// Dotted path of the field, e.g. `pathtrace.spp` or `--spp`.
        field: String,
        /// The value as given, in TOML-like notation.
        value: String,
        /// What would have been accepted.
        allowed: String,
    },

    /// A valid scene that asks for something a renderer does not implement.
    #[error("{file}: {place}: the {renderer} cannot render {feature}")]
    Unsupported {
        file: String,
        /// Where the scene uses it, e.g. `objects[11] ("light"), material "light"`.
        place: String,
        /// What it is, e.g. "an area light (a quad with an emitting material)".
        feature: String,
        /// The renderer, e.g. "rasterizer".
        renderer: String,
    },
}

impl SceneError {
    /// Builds a [`SceneError::Invalid`].
    pub fn invalid(
        file: &str,
        field: impl Into<String>,
        value: impl Into<String>,
        allowed: impl Into<String>,
    ) -> Self {
        SceneError::Invalid {
            file: file.to_owned(),
            field: field.into(),
            value: value.into(),
            allowed: allowed.into(),
        }
    }

    /// Converts a TOML/serde error into [`SceneError::Syntax`], turning its byte span into a
    /// 1-based line and column (counted in characters, so non-ASCII text does not shift it).
    /// The offending source line is quoted after the parser's message, because serde's type
    /// errors ("invalid type: string \"16\", expected an integer") do not name the key.
    /// An error without a span (rare: only errors about the document as a whole) is reported
    /// at line 1, column 1.
    pub(crate) fn from_toml(err: &toml::de::Error, text: &str, file: &str) -> Self {
        let (line, column) = match err.span() {
            Some(Range { start, .. }) => line_column(text, start),
            None => (1, 1),
        };
        let mut message = err.message().trim_end().to_owned();
        let source_line = text.lines().nth(line - 1).unwrap_or("").trim();
        if err.span().is_some() && !source_line.is_empty() {
            const MAX_CHARS: usize = 120;
            let shown: String = source_line.chars().take(MAX_CHARS).collect();
            let more = if source_line.chars().count() > MAX_CHARS { " ..." } else { "" };
            message.push_str(&format!(" (in `{shown}{more}`)"));
        }
        SceneError::Syntax { file: file.to_owned(), line, column, message }
    }
}

/// 1-based (line, column) of byte offset `offset` in `text`; the column counts characters.
fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let column = text[line_start..offset].chars().count() + 1;
    (line, column)
}

/// A value given as text (a command-line flag) that is not one of the allowed spellings.
/// Returned by the `FromStr` impls of the settings' enums ([`Bounces`](crate::Bounces),
/// [`Sampling`](crate::Sampling), [`Look`](crate::Look), ...).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{value:?}: {allowed}")]
pub struct ParseValueError {
    /// The text that was given.
    pub value: String,
    /// What would have been accepted.
    pub allowed: String,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_column_counts_from_one_in_characters() {
        let text = "ab\ncdé\nxyz";
        assert_eq!(line_column(text, 0), (1, 1));
        assert_eq!(line_column(text, 1), (1, 2));
        assert_eq!(line_column(text, 3), (2, 1));
        // 'é' is two bytes; the 'x' after the next newline is still column 1 of line 3 and the
        // newline itself is column 4 of line 2.
        assert_eq!(line_column(text, 7), (2, 4));
        assert_eq!(line_column(text, 8), (3, 1));
        assert_eq!(line_column(text, 100), (3, 4));
    }

    #[test]
    fn invalid_display_has_file_field_value_allowed() {
        let e = SceneError::invalid("scenes/x.toml", "pathtrace.spp", "0", "must be at least 1");
        assert_eq!(e.to_string(), "scenes/x.toml: pathtrace.spp = 0: must be at least 1");
    }
}
