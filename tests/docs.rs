//! The README and the book (`docs/`) checked without mdBook, against the tree and the built
//! `skycast` binary:
//! - every relative link and picture resolves (a `#fragment` on a link to a Markdown file names
//!   one of its headings);
//! - every command quoted for a figure still parses: its subcommand is in `skycast --help` and
//!   each of its `--flags` in `skycast <subcommand> --help`; `cargo test --test NAME` and
//!   `cargo bench --bench NAME` name a file of `tests/` or `benches/`;
//! - every subcommand has its line in the README and in `docs/src/command-line.md`;
//! - every picture the README shows is one `make pictures` writes;
//! - every long flag of `skycast --help` and `skycast <subcommand> --help` is in
//!   `docs/src/command-line.md`;
//! - no link of the book leaves `docs/src/` (mdBook publishes only that folder);
//! - the book is no lab notebook: no commit hash, no dated note (a day and month without a year
//!   other than 2026, or an ISO date of 2026, in prose), no issue reference (`issue 31`,
//!   `Done means`, the shared design folder). The exact rules are the doc comments of
//!   `commit_hashes_in`, `dated_notes_in` and `outside_references_in`.
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
/// unknown flag, an unknown subcommand and a missing test binary, a commit hash, a dated note, an
/// issue reference, a flag the command-line chapter leaves out and a link out of the book, each
/// in a made-up page, beside look-alikes they must let through.
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

    // Notebook leftovers: commit hashes, dated notes, issue references.
    let text = "Since `5fde611` the ring is faster (main at e01c289).\n\
        Not hashes: #ffcc00, 1234567, deadbeef, 0x1000, 128x128, `cargo test` and 2025.\n\
        ```sh\ngit show 5fde611   # commands in fenced blocks are not prose\n```\n";
    let hashes: Vec<String> = commit_hashes_in(text).into_iter().map(|(_, w)| w).collect();
    assert_eq!(hashes, ["5fde611", "e01c289"], "{hashes:?}");

    let text = "## Figures (3 December, afternoon)\n\
        Measured on December 4 and on 4 December 2026, recorded 2026-12-02.\n\
        Data, not notes: the weather of 27 January 2025, `--time 2025-01-27T19:00:00Z`,\n\
        weather/awc-metars-2025-01-27T22Z.cache.csv, fd1us1-2026-01-31T06Z.txt, 3 km, May.\n";
    let dates: Vec<String> = dated_notes_in(text).into_iter().map(|(_, d)| d).collect();
    assert_eq!(
        dates,
        ["3 December", "December 4", "4 December", "2026-12-02"],
        "{dates:?}"
    );

    let text = "As issue 31 asked (issue #32, issues 28 and 33, branch `issue-31`), Done means 1\n\
        holds; see `../shared/DESIGN.md`. Not references: an issue with tissue 3, the issue's.\n";
    let refs: Vec<String> = outside_references_in(text)
        .into_iter()
        .map(|(_, r)| r)
        .collect();
    assert_eq!(refs.len(), 6, "{refs:?}");
    assert!(refs[0].starts_with("issue 31") && refs[5].starts_with("shared/DESIGN"));

    // A command-line chapter that names only some of `skycast render`'s flags.
    let text = "`skycast render --weather FILE --at LAT,LON --out frame.png`\n";
    let missing = flags_missing_from(&mut help, text);
    assert!(
        missing.iter().any(|m| m == "skycast render --alt-ft"),
        "{missing:?}"
    );
    assert!(
        missing.iter().any(|m| m == "skycast bench --far-field"),
        "{missing:?}"
    );
    assert!(
        !missing.iter().any(|m| m == "skycast render --weather"),
        "{missing:?}"
    );
    assert!(
        !missing.iter().any(|m| m.ends_with("--help")),
        "{missing:?}"
    );

    // Links out of the book, which mdBook does not publish.
    let text = "[in](clouds.md), ![pic](pictures/sheet_over_sky.png), [web](https://mutants.rs),\n\
        [here](#a-page), [code](../../src/flight/air.rs), [readme](../../README.md#skycast),\n\
        [sneaky](pictures/../../book.toml), and the path `src/flight/air.rs` as a code span.\n";
    let leaving = links_leaving_the_book(&page, text);
    assert_eq!(leaving.len(), 3, "{leaving:#?}");
    assert!(leaving[0].contains("src/flight/air.rs") && leaving[2].contains("book.toml"));
}

/// The book's own pages: every Markdown file under `docs/src/` (what mdBook publishes).
fn book_pages() -> Vec<PathBuf> {
    let src = root().join("docs/src");
    markdown_files()
        .into_iter()
        .filter(|f| f.starts_with(&src))
        .collect()
}

/// The words of a text (runs of ASCII letters and digits) with the byte each starts at.
fn words(text: &str) -> Vec<(usize, &str)> {
    let mut out = Vec::new();
    let mut start = None;
    for (i, c) in text.char_indices() {
        if c.is_ascii_alphanumeric() {
            start.get_or_insert(i);
        } else if let Some(s) = start.take() {
            out.push((s, &text[s..i]));
        }
    }
    if let Some(s) = start {
        out.push((s, &text[s..]));
    }
    out
}

/// Commit hashes in a page's prose (fenced blocks left out, code spans kept): a word of 7 to 40
/// lower-case hex digits holding at least one digit and one of the letters a-f. Numbers (no
/// letter), words like `deadbeef` (no digit), colours like `#ffcc00` (6 digits) and hex
/// constants like `0x1000` (an `x`) are not hashes.
fn commit_hashes_in(text: &str) -> Vec<(usize, String)> {
    let prose = parse(text).prose;
    words(&prose)
        .into_iter()
        .filter(|(_, w)| {
            (7..=40).contains(&w.len())
                && w.bytes()
                    .all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b))
                && w.bytes().any(|b| b.is_ascii_digit())
                && w.bytes().any(|b| b.is_ascii_lowercase())
        })
        .map(|(at, w)| (line_of(&prose, at), w.to_string()))
        .collect()
}

const MONTHS: [&str; 12] = [
    "January",
    "February",
    "March",
    "April",
    "May",
    "June",
    "July",
    "August",
    "September",
    "October",
    "November",
    "December",
];

/// The year skycast was written in: a date in it is a note of when something was done.
const DEVELOPMENT_YEAR: &str = "2026";

/// Dated notes in a page's prose (fenced blocks and code spans left out): a day and a month
/// (`3 December`, `December 3`) not followed by a year other than 2026, and an ISO date
/// (`2026-12-03`) of 2026 standing as a word of its own. Dates that are data carry their year:
/// the shipped weather of `27 January 2025`, `--time 2025-01-27T19:00:00Z`; an ISO date inside a
/// file name (`fd1us1-2026-01-31T06Z.txt`) is the file's name, not a note.
fn dated_notes_in(text: &str) -> Vec<(usize, String)> {
    let (_, prose) = code_spans(&parse(text).prose);
    let mut notes = Vec::new();
    let words = words(&prose);
    let day = |w: &str| {
        let digits = w.trim_end_matches(['s', 't', 'n', 'd', 'r', 'h']);
        !digits.is_empty()
            && digits.len() <= 2
            && digits.bytes().all(|b| b.is_ascii_digit())
            && (1..=31).contains(&digits.parse::<u32>().unwrap_or(0))
    };
    let year = |w: Option<&str>| {
        w.filter(|w| w.len() == 4 && w.bytes().all(|b| b.is_ascii_digit()))
            .map(str::to_string)
    };
    for (i, (at, word)) in words.iter().enumerate() {
        if !MONTHS.contains(word) {
            continue;
        }
        let before = i.checked_sub(1).map(|j| words[j].1);
        let after = words.get(i + 1).map(|(_, w)| *w);
        let (date, year) = if before.is_some_and(day) {
            (
                format!("{} {word}", before.unwrap_or("")),
                year(words.get(i + 1).map(|(_, w)| *w)),
            )
        } else if after.is_some_and(day) {
            (
                format!("{word} {}", after.unwrap_or("")),
                year(words.get(i + 2).map(|(_, w)| *w)),
            )
        } else {
            continue;
        };
        if year.is_none_or(|y| y == DEVELOPMENT_YEAR) {
            notes.push((*at, date));
        }
    }
    let bytes = prose.as_bytes();
    for (at, _) in prose.match_indices(DEVELOPMENT_YEAR) {
        let iso = prose.get(at..at + 10).unwrap_or("");
        let shape = iso.bytes().enumerate().all(|(i, b)| match i {
            4 | 7 => b == b'-',
            _ => b.is_ascii_digit(),
        });
        let alone =
            at == 0 || !(bytes[at - 1].is_ascii_alphanumeric() || b"-_./".contains(&bytes[at - 1]));
        if iso.len() == 10 && shape && alone {
            notes.push((at, iso.to_string()));
        }
    }
    notes.sort();
    notes
        .into_iter()
        .map(|(at, date)| (line_of(&prose, at), date))
        .collect()
}

/// References to what a reader of the book does not have, in a page's prose (fenced blocks left
/// out, code spans kept): issue numbers (`issue 31`, `issue #31`, `issues 28 and 33`, a branch
/// `issue-31`), an issue's acceptance criteria (`Done means`) and the team's shared design
/// folder (`shared/DESIGN.md`), which is not part of the repository.
fn outside_references_in(text: &str) -> Vec<(usize, String)> {
    let prose = parse(text).prose;
    let lower = prose.to_ascii_lowercase();
    let bytes = lower.as_bytes();
    let quote = |at: usize, len: usize| {
        let end = (at + len).min(prose.len());
        let end = (end..=prose.len())
            .find(|&e| prose.is_char_boundary(e))
            .unwrap_or(prose.len());
        (at, prose[at..end].trim_end().to_string())
    };
    let mut found = Vec::new();
    for (at, _) in lower.match_indices("issue") {
        if at > 0 && bytes[at - 1].is_ascii_alphabetic() {
            continue; // "tissue"
        }
        let rest = &lower[at + 5..];
        let rest = rest.strip_prefix('s').unwrap_or(rest);
        if rest
            .trim_start_matches([' ', '-', '#'])
            .starts_with(|c: char| c.is_ascii_digit())
        {
            found.push(quote(at, 10));
        }
    }
    for phrase in ["done means", "shared/design.md"] {
        for (at, _) in lower.match_indices(phrase) {
            found.push(quote(at, phrase.len()));
        }
    }
    found.sort();
    found
        .into_iter()
        .map(|(at, what)| (line_of(&prose, at), what))
        .collect()
}

/// Each finding of a notebook check over the book's pages, as `file:line: what`.
fn findings(check: fn(&str) -> Vec<(usize, String)>) -> Vec<String> {
    book_pages()
        .iter()
        .flat_map(|f| {
            check(&read(f))
                .into_iter()
                .map(move |(line, what)| format!("{}:{line}: {what}", f.display()))
        })
        .collect()
}

/// The book says what is, not when it was done: no commit hash in its prose.
#[test]
fn the_book_names_no_commit() {
    let found = findings(commit_hashes_in);
    assert!(
        found.is_empty(),
        "commit hashes in the book:\n{}",
        found.join("\n")
    );
}

/// The book says what is, not when it was done: no dated note in its prose (the rule is that of
/// `dated_notes_in`: dates that are data carry a year other than 2026).
#[test]
fn the_book_has_no_dated_notes() {
    let found = findings(dated_notes_in);
    assert!(
        found.is_empty(),
        "dated notes in the book:\n{}",
        found.join("\n")
    );
}

/// The book points at nothing its reader does not have: no issue numbers, no `Done means`, no
/// shared design folder.
#[test]
fn the_book_points_at_nothing_outside_the_repository() {
    let found = findings(outside_references_in);
    assert!(
        found.is_empty(),
        "references to what a reader does not have:\n{}",
        found.join("\n")
    );
}

/// Every long flag of `skycast --help` and of each `skycast <subcommand> --help` that `text`
/// (the command-line chapter) does not name, as `skycast SUB --flag`.
fn flags_missing_from(help: &mut Help, text: &str) -> Vec<String> {
    let named = long_flags(text);
    let mut subcommands = vec![String::new()];
    subcommands.extend(help.subcommands.iter().cloned());
    let mut missing = Vec::new();
    for sub in subcommands {
        for flag in help.flags_of(&sub).clone() {
            if flag != "--help" && flag != "--version" && !named.contains(&flag) {
                missing.push(format!("skycast {sub} {flag}").replace("  ", " "));
            }
        }
    }
    missing
}

/// Every flag the binary takes is in the book's chapter on the command line.
#[test]
fn every_flag_is_in_the_command_line_chapter() {
    let mut help = Help::new();
    let missing = flags_missing_from(&mut help, &read(&root().join("docs/src/command-line.md")));
    assert!(
        missing.is_empty(),
        "flags of `--help` that docs/src/command-line.md does not name:\n{}",
        missing.join("\n")
    );
}

/// A path with its `.` and `..` taken out, without asking the file system.
fn lexical(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for part in path.components() {
        match part {
            std::path::Component::ParentDir => {
                out.pop();
            }
            std::path::Component::CurDir => {}
            other => out.push(other),
        }
    }
    out
}

/// Every link or picture of a book page (`file`, under `docs/src/`) whose target lies outside
/// `docs/src/`: mdBook publishes only that folder, so such a link breaks in the built book.
fn links_leaving_the_book(file: &Path, text: &str) -> Vec<String> {
    let src = lexical(&root().join("docs/src"));
    let doc = parse(text);
    let (_, prose) = code_spans(&doc.prose);
    link_targets(&prose)
        .into_iter()
        .filter(|(_, t)| {
            let external = ["http://", "https://", "mailto:", "#"];
            !t.is_empty() && !external.iter().any(|p| t.starts_with(p))
        })
        .filter(|(_, t)| {
            let path = t.split('#').next().unwrap_or("");
            !lexical(&file.parent().unwrap_or(Path::new(".")).join(path)).starts_with(&src)
        })
        .map(|(line, t)| format!("{}:{line}: `{t}` leaves docs/src", file.display()))
        .collect()
}

/// No link of the book leaves `docs/src/`: a file of the repository is named as a path in a
/// code span (`src/flight/air.rs`), not linked.
#[test]
fn no_link_leaves_the_book() {
    let found: Vec<String> = book_pages()
        .iter()
        .flat_map(|f| links_leaving_the_book(f, &read(f)))
        .collect();
    assert!(
        found.is_empty(),
        "links out of the book:\n{}",
        found.join("\n")
    );
}
