//! `--script FILE`: timed key presses for tests and recordings (TOML), by frame number so a run
//! does the same thing at any frame rate:
//!
//! ```toml
//! [[press]]
//! frame = 10        # the frame the key goes down on (0 = the first)
//! key = "Plus"      # a name from `skycast view --help` (W, Shift, PageUp, F12, ...)
//! frames = 1        # how many frames it stays down (held keys), default 1
//! ```

use std::path::Path;

use anyhow::Context;
use serde::Deserialize;

use super::controls::Key;

/// One scripted press as the file has it.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PressEntry {
    frame: u64,
    key: String,
    #[serde(default = "one_frame")]
    frames: u64,
}

fn one_frame() -> u64 {
    1
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ScriptFile {
    #[serde(default)]
    press: Vec<PressEntry>,
}

/// A key down from frame `from` until before frame `until`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Press {
    /// The key.
    pub key: Key,
    /// First frame it is down.
    pub from: u64,
    /// First frame it is up again.
    pub until: u64,
}

/// Reads a script; an error names the file and the line (TOML) or the press and its field.
pub fn load(path: &Path) -> anyhow::Result<Vec<Press>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    parse(&text, path)
}

/// Parses a script's text; `path` names it in errors.
pub fn parse(text: &str, path: &Path) -> anyhow::Result<Vec<Press>> {
    let file: ScriptFile =
        toml::from_str(text).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    file.press
        .iter()
        .enumerate()
        .map(|(i, entry)| {
            let key = Key::from_name(&entry.key).ok_or_else(|| {
                anyhow::anyhow!(
                    "{}: press {} (frame {}): key `{}` is not one `skycast view --help` lists",
                    path.display(),
                    i + 1,
                    entry.frame,
                    entry.key
                )
            })?;
            if entry.frames == 0 {
                anyhow::bail!(
                    "{}: press {}: frames must be at least 1",
                    path.display(),
                    i + 1
                );
            }
            Ok(Press {
                key,
                from: entry.frame,
                until: entry.frame.saturating_add(entry.frames),
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presses_hold_for_their_frames() {
        let text =
            "[[press]]\nframe = 3\nkey = \"w\"\nframes = 5\n[[press]]\nframe = 9\nkey = \"Plus\"\n";
        let presses = parse(text, Path::new("s.toml")).unwrap();
        assert_eq!(
            presses,
            [
                Press {
                    key: Key::W,
                    from: 3,
                    until: 8
                },
                Press {
                    key: Key::Plus,
                    from: 9,
                    until: 10
                },
            ]
        );
    }

    #[test]
    fn errors_name_the_file_and_the_press() {
        let err = parse(
            "[[press]]\nframe = 1\nkey = \"Ctrl\"\n",
            Path::new("s.toml"),
        );
        let text = err.unwrap_err().to_string();
        assert!(
            text.contains("s.toml: press 1 (frame 1): key `Ctrl`"),
            "{text}"
        );
        let err = parse("[[press]]\nframe = \"x\"\n", Path::new("s.toml"));
        let text = err.unwrap_err().to_string();
        assert!(
            text.starts_with("s.toml: ") && text.contains("line 2"),
            "{text}"
        );
    }
}
