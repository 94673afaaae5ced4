//! `--script FILE`: timed key presses for tests and recordings (TOML), by frame number so a run
//! does the same thing at any frame rate:
//!
//! ```toml
//! [[press]]
//! frame = 10        # the frame the key goes down on (0 = the first)
//! key = "Plus"      # a name from `skycast view --help` (W, Shift, PageUp, F12, ...)
//! frames = 1        # how many frames it stays down (held keys), default 1
//!
//! [[look]]
//! frame = 20        # a mouse drag on this frame
//! dx_px = 200       # pixels right (turns right)
//! dy_px = -50       # pixels down (negative: looks up)
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
    #[serde(default)]
    look: Vec<Look>,
}

/// A scripted mouse drag: on frame `frame`, the view turned as by a drag of `dx_px`, `dy_px`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Look {
    /// The frame it happens on.
    pub frame: u64,
    /// Pixels right.
    #[serde(default)]
    pub dx_px: f64,
    /// Pixels down.
    #[serde(default)]
    pub dy_px: f64,
}

/// A script: key presses and mouse drags.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Script {
    /// Key presses.
    pub presses: Vec<Press>,
    /// Mouse drags.
    pub looks: Vec<Look>,
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
pub fn load(path: &Path) -> anyhow::Result<Script> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    parse(&text, path)
}

/// Parses a script's text; `path` names it in errors.
pub fn parse(text: &str, path: &Path) -> anyhow::Result<Script> {
    let file: ScriptFile =
        toml::from_str(text).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let presses = file
        .press
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
        .collect::<anyhow::Result<_>>()?;
    if let Some((i, look)) = file
        .look
        .iter()
        .enumerate()
        .find(|(_, l)| !(l.dx_px.is_finite() && l.dy_px.is_finite()))
    {
        anyhow::bail!(
            "{}: look {} (frame {}): dx_px and dy_px must be numbers",
            path.display(),
            i + 1,
            look.frame
        );
    }
    Ok(Script {
        presses,
        looks: file.look,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presses_hold_for_their_frames_and_looks_turn_on_theirs() {
        let text = "[[press]]\nframe = 3\nkey = \"w\"\nframes = 5\n\
                    [[press]]\nframe = 9\nkey = \"Plus\"\n\
                    [[look]]\nframe = 4\ndx_px = 20.0\n";
        let script = parse(text, Path::new("s.toml")).unwrap();
        let look = Look {
            frame: 4,
            dx_px: 20.0,
            dy_px: 0.0,
        };
        assert_eq!(script.looks, [look]);
        assert_eq!(
            script.presses,
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
