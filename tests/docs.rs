//! The README and the book (`docs/`) checked without mdBook, against the tree and the built
//! `skycast` binary:
//! - every relative link and picture resolves (a `#fragment` on a link to a Markdown file names
//!   one of its headings);
//! - every command quoted for a figure still parses: its subcommand is in `skycast --help` and
//!   each of its `--flags` in `skycast <subcommand> --help`; `cargo test --test NAME` and
//!   `cargo bench --bench NAME` name a file of `tests/` or `benches/`;
//! - every subcommand has its line in the README and in `docs/src/command-line.md`;
//! - every picture the README shows is one `make pictures` writes.
//!
//! Which lines count as quoted commands is the convention written in `docs/src/testing.md` ("The
//! book's own check"): lines of a `sh` block starting with `skycast `, `cargo run ... -- ` or
//! `/usr/bin/time -v skycast `, continued over lines ending in `\`, and inline code spans that
//! start with `skycast ` and a subcommand.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// README.md and every Markdown file under docs/ (the built book, docs/book/, left out).
fn markdown_files() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            if path.is_dir() {
                if path.file_name().is_some_and(|n| n != "book") {
                    walk(&path, out);
                }
            } else if path.extension().is_some_and(|e| e == "md") {
                out.push(path);
            }
        }
    }
    let mut files = vec![root().join("README.md")];
    walk(&root().join("docs"), &mut files);
    files.sort();
    files
}

/// A fenced code block: its info string (`sh`, `rust,no_run`), first line number and lines.
struct Fence {
    info: String,
    lines: Vec<(usize, String)>,
}

/// A Markdown file split into its fenced blocks and its prose (the text with every fenced line
/// blanked, so positions still give line numbers).
struct Doc {
    fences: Vec<Fence>,
    prose: String,
}

fn parse(text: &str) -> Doc {
    let mut fences = Vec::new();
    let mut prose = String::with_capacity(text.len());
    let mut open: Option<(String, Fence)> = None;
    for (i, line) in text.lines().enumerate() {
        let trimmed = line.trim_start();
        let fence_marker: String = trimmed
            .chars()
            .take_while(|&c| c == '`' || c == '~')
            .collect();
        match open.take() {
            None if fence_marker.len() >= 3 => {
                let info = trimmed[fence_marker.len()..].trim().to_string();
                open = Some((
                    fence_marker,
                    Fence {
                        info,
                        lines: Vec::new(),
                    },
                ));
                prose.push('\n');
            }
            None => {
                prose.push_str(line);
                prose.push('\n');
            }
            Some((marker, fence)) => {
                prose.push('\n');
                if trimmed.starts_with(&marker) && trimmed.trim_end() == fence_marker {
                    fences.push(fence);
                } else {
                    let mut fence = fence;
                    fence.lines.push((i + 1, line.to_string()));
                    open = Some((marker, fence));
                }
            }
        }
    }
    if let Some((_, fence)) = open {
        fences.push(fence);
    }
    Doc { fences, prose }
}

fn line_of(text: &str, at: usize) -> usize {
    text[..at].matches('\n').count() + 1
}

/// Inline code spans of the prose (backtick runs of any length, across line breaks), with the
/// line each starts on, and the prose with the spans blanked out.
fn code_spans(prose: &str) -> (Vec<(usize, String)>, String) {
    let bytes = prose.as_bytes();
    let mut spans = Vec::new();
    let mut rest = prose.to_string().into_bytes();
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] != b'`' {
            i += 1;
            continue;
        }
        let run = bytes[i..].iter().take_while(|&&b| b == b'`').count();
        let mut j = i + run;
        let mut close = None;
        while j < bytes.len() {
            if bytes[j] == b'`' {
                let n = bytes[j..].iter().take_while(|&&b| b == b'`').count();
                if n == run {
                    close = Some(j);
                    break;
                }
                j += n;
            } else {
                j += 1;
            }
        }
        match close {
            Some(end) => {
                let content = prose[i + run..end].replace('\n', " ");
                spans.push((line_of(prose, i), content.trim().to_string()));
                for b in &mut rest[i..end + run] {
                    if *b != b'\n' {
                        *b = b' ';
                    }
                }
                i = end + run;
            }
            None => i += run,
        }
    }
    (
        spans,
        String::from_utf8(rest).expect("blanking keeps UTF-8"),
    )
}

/// Link and picture targets of prose without code spans: `[text](target)`, `![alt](target)`,
/// `[label]: target` and `<img src="target">`.
fn link_targets(prose: &str) -> Vec<(usize, String)> {
    let mut targets = Vec::new();
    for (at, _) in prose.match_indices("](") {
        let start = at + 2;
        let target: String = prose[start..]
            .chars()
            .take_while(|&c| c != ')' && !c.is_whitespace())
            .collect();
        targets.push((line_of(prose, at), target));
    }
    for (at, _) in prose.match_indices("src=\"") {
        let target: String = prose[at + 5..].chars().take_while(|&c| c != '"').collect();
        targets.push((line_of(prose, at), target));
    }
    for (i, line) in prose.lines().enumerate() {
        let t = line.trim_start();
        if let (true, Some(close)) = (t.starts_with('['), t.find("]:"))
            && let Some(target) = t[close + 2..].split_whitespace().next()
        {
            targets.push((i + 1, target.to_string()));
        }
    }
    targets
}

/// The anchors mdBook (and GitHub) give a file's headings: the heading's text in lower case,
/// spaces to `-`, letters, digits, `-` and `_` kept, the rest dropped.
fn heading_ids(text: &str) -> BTreeSet<String> {
    // Headings keep the text of their code spans: read from the prose with only fences blanked.
    parse(text)
        .prose
        .lines()
        .filter(|l| l.starts_with('#'))
        .map(|l| {
            l.trim_start_matches('#')
                .trim()
                .chars()
                .filter_map(|c| {
                    if c.is_alphanumeric() || c == '_' || c == '-' {
                        Some(c.to_lowercase().next().unwrap_or(c))
                    } else if c.is_whitespace() {
                        Some('-')
                    } else {
                        None
                    }
                })
                .collect()
        })
        .collect()
}

/// Why `target`, written in `file` (whose text is `text`), does not resolve; `None` when it does.
fn broken_link(file: &Path, text: &str, target: &str) -> Option<String> {
    let external = ["http://", "https://", "mailto:"];
    if target.is_empty() || external.iter().any(|p| target.starts_with(p)) {
        return None;
    }
    let (path_part, fragment) = match target.split_once('#') {
        Some((p, f)) => (p, Some(f)),
        None => (target, None),
    };
    let (resolved, target_text) = if path_part.is_empty() {
        (file.to_path_buf(), text.to_string())
    } else {
        let resolved = file.parent().unwrap_or(Path::new(".")).join(path_part);
        if !resolved.exists() {
            return Some(format!("`{target}`: no file {}", resolved.display()));
        }
        let text = std::fs::read_to_string(&resolved).unwrap_or_default();
        (resolved, text)
    };
    if let (Some(fragment), true) = (fragment, resolved.extension().is_some_and(|e| e == "md"))
        && !heading_ids(&target_text).contains(fragment)
    {
        return Some(format!(
            "`{target}`: {} has no heading `#{fragment}`",
            resolved.display()
        ));
    }
    None
}

/// Every broken relative link or picture of one Markdown text, as `file:line: why`.
fn broken_links_in(file: &Path, text: &str) -> Vec<String> {
    let doc = parse(text);
    let (_, prose) = code_spans(&doc.prose);
    link_targets(&prose)
        .into_iter()
        .filter_map(|(line, target)| {
            broken_link(file, text, &target).map(|why| format!("{}:{line}: {why}", file.display()))
        })
        .collect()
}

/// The command lines a Markdown text quotes, by the convention above, with their line numbers:
/// each as the words from `skycast` on (`skycast render --at ...`), or a `cargo test`/`cargo
/// bench` line as written.
fn quoted_commands(text: &str) -> Vec<(usize, String)> {
    let doc = parse(text);
    let mut commands = Vec::new();
    for fence in doc.fences.iter().filter(|f| {
        let lang = f.info.split([',', ' ']).next().unwrap_or("");
        matches!(lang, "sh" | "bash" | "shell" | "console")
    }) {
        let mut pending: Option<(usize, String)> = None;
        for (line_no, line) in &fence.lines {
            let line = line.split(" # ").next().unwrap_or("").trim_end();
            let (start, mut joined) = match pending.take() {
                Some((start, so_far)) => (start, so_far + " " + line.trim()),
                None => (*line_no, line.trim().to_string()),
            };
            if joined.ends_with('\\') {
                joined.pop();
                pending = Some((start, joined));
            } else {
                commands.push((start, joined));
            }
        }
        if let Some(last) = pending {
            commands.push(last);
        }
    }
    let (spans, _) = code_spans(&doc.prose);
    commands.extend(spans);
    commands
        .into_iter()
        .filter_map(|(line, command)| {
            let command = command.trim().trim_start_matches("$ ");
            let command = command.strip_prefix("/usr/bin/time -v ").unwrap_or(command);
            let skycast = if command.starts_with("cargo run") {
                command
                    .split_once(" -- ")
                    .map(|(_, rest)| format!("skycast {rest}"))
            } else if command.starts_with("skycast ") {
                Some(command.to_string())
            } else if command.starts_with("cargo test") || command.starts_with("cargo bench") {
                return Some((line, command.to_string()));
            } else {
                None
            }?;
            // A span like `skycast = { ... }` or `skycast <command>` is not a command.
            let word = skycast.split_whitespace().nth(1).unwrap_or("");
            let is_command = word.starts_with("--")
                || (!word.is_empty() && word.chars().all(|c| c.is_ascii_lowercase() || c == '-'));
            is_command.then_some((line, skycast))
        })
        .collect()
}

/// The `--flags` of a command line or a help text: words starting with `--`, cut at `=`, `[`,
/// `]`, `|`, `,` and `.`.
fn long_flags(text: &str) -> BTreeSet<String> {
    text.split(|c: char| c.is_whitespace() || "[]|,=<>()`'\"".contains(c))
        .filter(|w| w.starts_with("--") && w.len() > 2)
        .map(|w| w.trim_end_matches(['.', ':', ';']).to_string())
        .filter(|w| w.len() > 2)
        .collect()
}

/// What `skycast --help` and `skycast <subcommand> --help` say, asked once per subcommand.
struct Help {
    subcommands: BTreeSet<String>,
    flags: BTreeMap<String, BTreeSet<String>>,
}

impl Help {
    fn run(args: &[&str]) -> String {
        let out = Command::new(env!("CARGO_BIN_EXE_skycast"))
            .args(args)
            .output()
            .expect("runs skycast");
        assert!(out.status.success(), "skycast {args:?} failed");
        String::from_utf8_lossy(&out.stdout).into_owned()
    }

    fn new() -> Self {
        let top = Self::run(&["--help"]);
        let mut subcommands = BTreeSet::new();
        let mut in_commands = false;
        for line in top.lines() {
            if line.starts_with("Commands:") {
                in_commands = true;
            } else if in_commands && line.starts_with("  ") {
                if let Some(name) = line.split_whitespace().next() {
                    subcommands.insert(name.to_string());
                }
            } else if !line.trim().is_empty() {
                in_commands = false;
            }
        }
        subcommands.remove("help");
        let mut flags = BTreeMap::new();
        flags.insert(String::new(), long_flags(&top));
        Help { subcommands, flags }
    }

    fn flags_of(&mut self, subcommand: &str) -> &BTreeSet<String> {
        self.flags
            .entry(subcommand.to_string())
            .or_insert_with(|| long_flags(&Self::run(&[subcommand, "--help"])))
    }

    /// Why a quoted command does not parse; `None` when it does.
    fn problem(&mut self, command: &str) -> Option<String> {
        let words: Vec<&str> = command.split_whitespace().collect();
        if words.first() == Some(&"cargo") {
            for (kind, folder) in [("--test", "tests"), ("--bench", "benches")] {
                let name = words
                    .iter()
                    .position(|w| *w == kind)
                    .and_then(|i| words.get(i + 1));
                if let Some(name) = name.filter(|n| n.chars().any(|c| c.is_ascii_lowercase())) {
                    let file = root().join(folder).join(format!("{name}.rs"));
                    if !file.exists() {
                        return Some(format!("`{kind} {name}`: no {folder}/{name}.rs"));
                    }
                }
            }
            return None;
        }
        let sub = words.get(1).copied().unwrap_or("");
        let sub = if sub.starts_with("--") { "" } else { sub };
        if !sub.is_empty() && !self.subcommands.contains(sub) {
            return Some(format!(
                "`skycast {sub}` is not a subcommand of `skycast --help`"
            ));
        }
        let known = self.flags_of(sub).clone();
        let unknown: Vec<String> = long_flags(command)
            .into_iter()
            .filter(|f| f != "--help" && !known.contains(f))
            .collect();
        (!unknown.is_empty()).then(|| {
            format!("{} not in `skycast {sub} --help`", unknown.join(", ")).replace("  ", " ")
        })
    }
}

/// Every quoted command of one Markdown text that does not parse, as `file:line: why`.
fn broken_commands_in(help: &mut Help, file: &Path, text: &str) -> Vec<String> {
    quoted_commands(text)
        .into_iter()
        .filter_map(|(line, command)| {
            help.problem(&command)
                .map(|why| format!("{}:{line}: {why}\n    {command}", file.display()))
        })
        .collect()
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn every_relative_link_and_picture_resolves() {
    let files = markdown_files();
    assert!(files.len() > 5, "found only {files:?}");
    let broken: Vec<String> = files
        .iter()
        .flat_map(|f| broken_links_in(f, &read(f)))
        .collect();
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

#[test]
fn every_quoted_command_parses() {
    let mut help = Help::new();
    assert!(
        help.subcommands.contains("render"),
        "{:?}",
        help.subcommands
    );
    let mut checked = 0;
    let mut broken = Vec::new();
    for file in markdown_files() {
        let text = read(&file);
        checked += quoted_commands(&text).len();
        broken.extend(broken_commands_in(&mut help, &file, &text));
    }
    assert!(checked > 50, "only {checked} quoted commands found");
    assert!(
        broken.is_empty(),
        "quoted commands that no longer parse:\n{}",
        broken.join("\n")
    );
}

/// Every subcommand of `skycast --help` has its line in the README and in the book's chapter on
/// the command line.
#[test]
fn every_subcommand_is_listed() {
    let help = Help::new();
    for page in ["README.md", "docs/src/command-line.md"] {
        let text = read(&root().join(page));
        let (spans, _) = code_spans(&parse(&text).prose);
        for sub in &help.subcommands {
            let listed = spans.iter().any(|(_, s)| *s == format!("skycast {sub}"));
            assert!(listed, "{page} does not list `skycast {sub}`");
        }
    }
}

/// The README shows pictures that `make pictures` writes (Makefile: `$(PICTURES)/...`; `$$m`
/// stands for each shading model).
#[test]
fn the_readme_shows_pictures_that_make_pictures_writes() {
    let makefile = read(&root().join("Makefile"));
    let written: Vec<&str> = makefile
        .split_whitespace()
        .filter_map(|w| w.strip_prefix("$(PICTURES)/"))
        .collect();
    let readme = read(&root().join("README.md"));
    let (_, prose) = code_spans(&parse(&readme).prose);
    let shown: Vec<String> = link_targets(&prose)
        .into_iter()
        .filter_map(|(_, t)| t.strip_prefix("docs/src/pictures/").map(str::to_string))
        .filter(|t| t.ends_with(".png"))
        .collect();
    assert!(shown.len() >= 3, "the README shows {shown:?}");
    for picture in &shown {
        let made = written.iter().any(|w| match w.split_once("$$m") {
            Some((before, after)) => picture.starts_with(before) && picture.ends_with(after),
            None => w == picture,
        });
        assert!(
            made,
            "README shows {picture}, which `make pictures` does not write"
        );
    }
}

/// The checks find what they are for: a broken link, a missing picture, a bad fragment, an
/// unknown flag, an unknown subcommand and a missing test binary, each in a made-up page.
#[test]
fn the_checks_catch_what_they_are_for() {
    let page = root().join("docs/src/made-up.md");
    let text = "# A page\n\n## Some heading: `x`\n\n\
        See [the clouds](clouds.md), [here](#some-heading-x) and ![a sheet](pictures/sheet_over_sky.png).\n\
        Broken: [gone](no-such-page.md), ![lost](pictures/no-such.png), [bad](clouds.md#no-such-heading).\n";
    let broken = broken_links_in(&page, text);
    assert_eq!(broken.len(), 3, "{broken:#?}");
    assert!(broken[0].contains("no-such-page.md") && broken[1].contains("no-such.png"));
    assert!(broken[2].contains("no-such-heading"));

    let text = "Run `skycast render --at 1,2 --no-such-flag` and `skycast frobnicate`.\n\n\
        ```sh\nskycast fly --weather FILE --path P \\\n    --out DIR --every 3   # fine\n\
        cargo run --release -- bench --frames 16 --warp 9\ncargo test --test no_such_binary\n\
        cargo bench --bench weather\n```\n";
    let mut help = Help::new();
    let broken = broken_commands_in(&mut help, &page, text);
    assert_eq!(broken.len(), 4, "{broken:#?}");
    let why: Vec<&str> = broken.iter().filter_map(|b| b.lines().next()).collect();
    assert!(
        why[0].contains("--warp") && !why[0].contains("--frames"),
        "{why:?}"
    );
    assert!(why[1].contains("no_such_binary"), "{why:?}");
    assert!(
        why[2].contains("--no-such-flag") && !why[2].contains("--at "),
        "{why:?}"
    );
    assert!(why[3].contains("frobnicate"), "{why:?}");
}
