//! Loading TOML files (config, themes, flight paths) with errors a user can act on: every error
//! names the file, the line and the field. Each stage deserialises its own types with serde; this
//! module only turns text into them and turns failures into [`ConfigError`]. Every settings file
//! type (`config/*.toml`) implements [`TomlSettings`], which reads, parses, checks and defaults
//! it in one way.

use std::ops::Range;
use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;

/// A TOML file that could not be read, parsed or validated.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{}{}: {}{message}", path.display(), line.map(|l| format!(":{l}")).unwrap_or_default(),
        field.as_ref().map(|f| format!("field `{f}`: ")).unwrap_or_default())]
pub struct ConfigError {
    /// The file.
    pub path: PathBuf,
    /// 1-based line of the offending text, when known.
    pub line: Option<usize>,
    /// The key at fault, when known.
    pub field: Option<String>,
    /// What is wrong.
    pub message: String,
}

impl ConfigError {
    /// An error about the text at `span` of `text` (a field's `toml::Spanned` span, say).
    pub fn at(
        path: &Path,
        text: &str,
        span: Range<usize>,
        field: &str,
        message: impl Into<String>,
    ) -> Self {
        Self {
            path: path.to_path_buf(),
            line: Some(line_of(text, span.start)),
            field: Some(field.to_string()),
            message: message.into(),
        }
    }

    /// An error about the field `section.key` (or a top-level `key`) of the TOML `text`: its
    /// line is where the key is set in that table, none when the file leaves it to its default.
    pub fn at_key(path: &Path, text: &str, field: &str, message: impl Into<String>) -> Self {
        Self {
            path: path.to_path_buf(),
            line: line_of_key(text, field),
            field: Some(field.to_string()),
            message: message.into(),
        }
    }

    /// An error about the whole file (it cannot be read, or a rule spans several fields).
    pub fn whole_file(path: &Path, message: impl Into<String>) -> Self {
        Self {
            path: path.to_path_buf(),
            line: None,
            field: None,
            message: message.into(),
        }
    }
}

/// Reads and parses a TOML file.
pub fn load_toml<T: DeserializeOwned>(path: &Path) -> Result<T, ConfigError> {
    let text = read_text(path)?;
    parse_toml(&text, path)
}

/// Reads a text file; the error names the file.
pub fn read_text(path: &Path) -> Result<String, ConfigError> {
    std::fs::read_to_string(path)
        .map_err(|err| ConfigError::whole_file(path, format!("cannot read: {err}")))
}

/// A settings file that skycast ships in `config/` and compiles in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShippedFile {
    /// Where it lives in the repository (`config/fog.toml`): the path its errors name.
    pub path: &'static str,
    /// Its text (`include_str!` of that file).
    pub text: &'static str,
}

impl ShippedFile {
    /// The shipped file at `path` (in the repository) whose text is `text`, in the `Some` that
    /// [`TomlSettings::SHIPPED`] takes.
    pub const fn at(path: &'static str, text: &'static str) -> Option<Self> {
        Some(Self { path, text })
    }
}

/// A TOML settings file type: how it is read, parsed, checked and defaulted, the same for every
/// settings type of every stage.
///
/// A type says only what is its own: its range checks ([`check`](Self::check), which accepts
/// everything unless overridden) and its shipped file ([`SHIPPED`](Self::SHIPPED)), when there
/// is one. [`parse`](Self::parse) and [`load`](Self::load) then give errors that name the file,
/// the line and the field ([`ConfigError`]), whether serde or a range check refused the text.
/// A type with a shipped file implements [`Default`] as [`shipped`](Self::shipped).
///
/// ```
/// use std::path::Path;
///
/// use serde::Deserialize;
/// use skycast::config::{ConfigError, ShippedFile, TomlSettings};
///
/// /// `config/haze.toml`.
/// #[derive(Debug, Deserialize)]
/// #[serde(deny_unknown_fields)]
/// struct HazeSettings {
///     /// Visibility in clear air, metres.
///     clear_visibility_m: f32,
/// }
///
/// impl Default for HazeSettings {
///     fn default() -> Self {
///         Self::shipped()
///     }
/// }
///
/// impl TomlSettings for HazeSettings {
///     // The text is `include_str!("../config/haze.toml")`, say.
///     const SHIPPED: Option<ShippedFile> =
///         ShippedFile::at("config/haze.toml", "clear_visibility_m = 40000.0\n");
///
///     fn check(&self, path: &Path, text: &str) -> Result<(), ConfigError> {
///         if !(self.clear_visibility_m >= 1.0) {
///             let message = "must be at least 1 metre";
///             return Err(ConfigError::at_key(path, text, "clear_visibility_m", message));
///         }
///         Ok(())
///     }
/// }
///
/// assert_eq!(HazeSettings::default().clear_visibility_m, 40000.0);
/// let err = HazeSettings::parse("clear_visibility_m = 0.5\n", Path::new("my_haze.toml"));
/// assert_eq!(
///     err.unwrap_err().to_string(),
///     "my_haze.toml:1: field `clear_visibility_m`: must be at least 1 metre"
/// );
/// // No file given: the shipped defaults.
/// assert_eq!(HazeSettings::load_or_default(None)?.clear_visibility_m, 40000.0);
/// # Ok::<(), ConfigError>(())
/// ```
pub trait TomlSettings: DeserializeOwned + Default {
    /// The shipped file of these settings, when there is one: what [`shipped`](Self::shipped)
    /// parses.
    const SHIPPED: Option<ShippedFile> = None;

    /// Checks the ranges and the rules between fields that serde cannot, once the `text` from
    /// `path` has parsed; an error names the field and its line ([`ConfigError::at_key`]). The
    /// default accepts everything.
    fn check(&self, path: &Path, text: &str) -> Result<(), ConfigError> {
        let _ = (path, text);
        Ok(())
    }

    /// Parses and checks settings text that came from `path` (used in messages only).
    fn parse(text: &str, path: &Path) -> Result<Self, ConfigError> {
        let settings: Self = parse_toml(text, path)?;
        settings.check(path, text)?;
        Ok(settings)
    }

    /// Reads, parses and checks a settings file.
    fn load(path: &Path) -> Result<Self, ConfigError> {
        let text = read_text(path)?;
        Self::parse(&text, path)
    }

    /// The settings file at `path`, or the defaults when there is none.
    fn load_or_default(path: Option<&Path>) -> Result<Self, ConfigError> {
        path.map_or_else(|| Ok(Self::default()), Self::load)
    }

    /// The shipped settings: [`SHIPPED`](Self::SHIPPED) parsed and checked. A type with a
    /// shipped file implements [`Default`] as this; for one without, it is `Default::default()`
    /// (so that type's `Default` must not call it).
    ///
    /// # Panics
    ///
    /// When the shipped file does not parse or check: a bug of the build, which
    /// `config::tests::shipped_settings_parse_and_match_their_files` catches.
    fn shipped() -> Self {
        let Some(file) = Self::SHIPPED else {
            return Self::default();
        };
        match Self::parse(file.text, Path::new(file.path)) {
            Ok(settings) => settings,
            Err(err) => panic!("the shipped {}: {err}", file.path),
        }
    }
}

/// Parses TOML text that came from `path` (used in messages only).
pub fn parse_toml<T: DeserializeOwned>(text: &str, path: &Path) -> Result<T, ConfigError> {
    toml::from_str(text).map_err(|err| ConfigError::from_toml(path, text, &err))
}

impl ConfigError {
    /// The error of a failed TOML parse of `text` (from `path`): its line, the field at fault
    /// and toml's message.
    pub fn from_toml(path: &Path, text: &str, err: &toml::de::Error) -> Self {
        let line = err.span().map(|span| line_of(text, span.start));
        let message = err.message().trim_end().to_string();
        // serde names the field in "missing field `x`" and "unknown field `x`"; otherwise the
        // span points at a value, and the key on that line is the field.
        let names_field =
            message.starts_with("missing field") || message.starts_with("unknown field");
        let field = names_field
            .then(|| backticked(&message))
            .flatten()
            .or_else(|| key_on_line(text, err.span()?.start));
        ConfigError {
            path: path.to_path_buf(),
            line,
            field,
            message,
        }
    }
}

/// 1-based line where `field` (`section.key`, or a top-level `key`) is set in the TOML `text`,
/// read as lines: the `key = ...` line after the `[section]` header and before the next header.
pub fn line_of_key(text: &str, field: &str) -> Option<usize> {
    let (section, key) = field.rsplit_once('.').unwrap_or(("", field));
    let mut in_section = section.is_empty();
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.starts_with('[') {
            in_section = line.trim_start_matches('[').trim_end_matches(']').trim() == section;
            continue;
        }
        let sets_key = line
            .strip_prefix(key)
            .is_some_and(|rest| rest.trim_start().starts_with('='));
        if in_section && sets_key {
            return Some(n + 1);
        }
    }
    None
}

/// 1-based line number of a byte offset.
pub fn line_of(text: &str, offset: usize) -> usize {
    let offset = offset.min(text.len());
    text.as_bytes()[..offset]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

fn backticked(message: &str) -> Option<String> {
    let start = message.find('`')? + 1;
    let len = message[start..].find('`')?;
    Some(message[start..start + len].to_string())
}

fn key_on_line(text: &str, offset: usize) -> Option<String> {
    let offset = offset.min(text.len());
    let line_start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    let line = text[line_start..].lines().next()?;
    let (key, _) = line.split_once('=')?;
    let key = key.trim().trim_start_matches('{').trim();
    (!key.is_empty()).then(|| key.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Deserialize;

    #[test]
    fn the_line_of_a_key_is_found_in_its_own_table() {
        let text = "top = 1\n[a]\nx = 1\n\n[b]\n  x  = 2 # the one\ny=3\n[[c]]\nz = 4\n";
        assert_eq!(line_of_key(text, "top"), Some(1));
        assert_eq!(line_of_key(text, "a.x"), Some(3));
        assert_eq!(line_of_key(text, "b.x"), Some(6));
        assert_eq!(line_of_key(text, "b.y"), Some(7));
        assert_eq!(line_of_key(text, "c.z"), Some(9));
        // Left to its default, or a key that only starts the same: no line.
        assert_eq!(line_of_key(text, "a.y"), None);
        assert_eq!(line_of_key("[a]\nxx = 1\n", "a.x"), None);
        let err = ConfigError::at_key(Path::new("f.toml"), text, "b.x", "too big");
        assert_eq!(err.to_string(), "f.toml:6: field `b.x`: too big");
    }

    #[derive(Debug, Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Sample {
        name: String,
        size_m: f32,
    }

    fn error_of(text: &str) -> ConfigError {
        parse_toml::<Sample>(text, Path::new("config/sample.toml")).unwrap_err()
    }

    #[test]
    fn wrong_type_names_line_and_field() {
        let err = error_of("name = \"a\"\nsize_m = \"big\"\n");
        assert_eq!((err.line, err.field.as_deref()), (Some(2), Some("size_m")));
        assert!(
            err.to_string()
                .starts_with("config/sample.toml:2: field `size_m`: "),
            "{err}"
        );
    }

    #[test]
    fn missing_and_unknown_fields_are_named() {
        assert_eq!(error_of("name = \"a\"\n").field.as_deref(), Some("size_m"));
        let err = error_of("name = \"a\"\nsize_m = 1.0\ncolour = 3\n");
        assert_eq!((err.line, err.field.as_deref()), (Some(3), Some("colour")));
    }

    #[test]
    fn syntax_error_has_a_line() {
        assert_eq!(error_of("name = \"a\"\nsize_m = \n").line, Some(2));
    }

    /// Every settings type's shipped file parses and checks, and is the file it says it is.
    #[test]
    fn shipped_settings_parse_and_match_their_files() {
        fn shipped<T: TomlSettings>() {
            let file = T::SHIPPED.expect("a shipped file");
            let on_disk = Path::new(env!("CARGO_MANIFEST_DIR")).join(file.path);
            let text = std::fs::read_to_string(&on_disk).unwrap_or_else(|err| panic!("{err}"));
            assert_eq!(text, file.text, "{} is not the file built in", file.path);
            if let Err(err) = T::parse(file.text, Path::new(file.path)) {
                panic!("{err}");
            }
            if let Err(err) = T::load(&on_disk) {
                panic!("{err}");
            }
        }
        shipped::<crate::shading::FogSettings>();
        shipped::<crate::shading::TimeOfDayTable>();
        shipped::<crate::weather::air::AirSettings>();
        shipped::<crate::weather::storms::StormSettings>();
        shipped::<crate::weather::field::CloudTypeRule>();
        shipped::<crate::weather::field::FieldSettings>();
        shipped::<crate::weather::model::ModelSettings>();
        shipped::<crate::render::RenderSettings>();
    }

    #[test]
    fn unreadable_file_names_the_file() {
        let err = load_toml::<Sample>(Path::new("/nonexistent/skycast.toml")).unwrap_err();
        assert!(
            err.to_string()
                .starts_with("/nonexistent/skycast.toml: cannot read"),
            "{err}"
        );
    }
}
