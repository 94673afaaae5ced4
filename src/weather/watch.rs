//! Live weather: watch a weather file and hand over each good new version, prepared off the
//! caller's thread, so a simulator's frames never wait for decoding or triangulation.
//!
//! The watcher listens to the file's folder (editors and download tools replace a file by
//! renaming a new one over it) with the `notify` crate. After a change it waits until the folder
//! has been quiet for a settle time, reads the file once, checks that it is whole (not empty, not
//! still growing, a bulk CSV with as many rows as its preamble announces, a report file ending
//! with a complete line), decodes it, and runs the caller's `prepare` (typically building the
//! [`WeatherField`](super::WeatherField) in the sky's frame) on its own thread. A file that is not
//! usable is a [`WatchUpdate::Rejected`] with one clear message: the caller keeps its last good
//! weather and the next change is tried again.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::thread;
use std::time::Duration;

use notify::{RecommendedWatcher, RecursiveMode, Watcher};

use super::error::WeatherError;
use super::files::{self, FileFormat};
use super::input::WeatherInput;
use super::stations::StationTable;

/// What the watcher hands over after a change of the file.
#[derive(Debug)]
pub enum WatchUpdate<T> {
    /// The file changed and is good: the caller's prepared weather.
    Loaded(T),
    /// The file changed but cannot be used (half-written, empty, garbage): why, naming the file.
    /// Keep the last good weather.
    Rejected(String),
}

/// A running watch of one weather file. Dropping it stops the watch and its thread.
pub struct WeatherWatch<T> {
    path: PathBuf,
    updates: Receiver<WatchUpdate<T>>,
    _watcher: RecommendedWatcher,
}

impl<T: Send + 'static> WeatherWatch<T> {
    /// Watches `path`. After each change that settles for `settle`, the file is read, checked
    /// and decoded (placed with `stations`), and `prepare` turns it into what the caller keeps;
    /// all of this on the watch's own thread.
    pub fn start(
        path: &Path,
        stations: Option<Arc<StationTable>>,
        settle: Duration,
        prepare: impl Fn(WeatherInput) -> T + Send + 'static,
    ) -> Result<Self, WeatherError> {
        Self::start_loading(path, settle, move |path| {
            load_whole(path, stations.as_deref()).map(&prepare)
        })
    }

    /// Watches `path` for a file of any kind: after each change that settles for `settle`,
    /// `load` reads it on the watch's own thread and says what the caller keeps, or why the file
    /// cannot be used (one line naming the file). [`Self::start`] loads weather this way; the
    /// winds aloft ([`super::winds_aloft::WindsAloft::load_whole`]) go the same way.
    pub fn start_loading(
        path: &Path,
        settle: Duration,
        load: impl Fn(&Path) -> Result<T, String> + Send + 'static,
    ) -> Result<Self, WeatherError> {
        let path = path.to_path_buf();
        let folder = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let name = path.file_name().map(|n| n.to_os_string());
        let (changes, changed) = mpsc::channel::<()>();
        let mut watcher =
            notify::recommended_watcher(move |event: notify::Result<notify::Event>| {
                let ours = match &event {
                    // Reading the file (ours included) raises access events: not a change.
                    Ok(e) if e.kind.is_access() => false,
                    Ok(e) => e
                        .paths
                        .iter()
                        .any(|p| p.file_name().map(|n| n.to_os_string()) == name),
                    // An error of the watch itself: look at the file again rather than miss a change.
                    Err(_) => true,
                };
                if ours {
                    let _ = changes.send(());
                }
            })
            .map_err(|err| watch_error(&path, &err))?;
        watcher
            .watch(&folder, RecursiveMode::NonRecursive)
            .map_err(|err| watch_error(&path, &err))?;
        let (updates_tx, updates) = mpsc::channel();
        let worker_path = path.clone();
        thread::Builder::new()
            .name("skycast.weather_watch".to_string())
            .spawn(move || worker(&worker_path, settle, changed, updates_tx, load))
            .map_err(|source| WeatherError::Io {
                path: path.clone(),
                source,
            })?;
        Ok(Self {
            path,
            updates,
            _watcher: watcher,
        })
    }

    /// The file watched.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Every update since the last call, oldest first; never blocks.
    pub fn poll(&self) -> Vec<WatchUpdate<T>> {
        self.updates.try_iter().collect()
    }

    /// Waits up to `timeout` for the next update (for tests and tools, not for frame loops).
    pub fn wait(&self, timeout: Duration) -> Option<WatchUpdate<T>> {
        self.updates.recv_timeout(timeout).ok()
    }
}

fn watch_error(path: &Path, err: &notify::Error) -> WeatherError {
    WeatherError::NotWeather {
        path: path.to_path_buf(),
        reason: format!("cannot watch it: {err}"),
    }
}

/// The watch thread: debounce, load (check and prepare), hand over; ends when either side is
/// gone.
fn worker<T>(
    path: &Path,
    settle: Duration,
    changed: Receiver<()>,
    updates: Sender<WatchUpdate<T>>,
    load: impl Fn(&Path) -> Result<T, String>,
) {
    while changed.recv().is_ok() {
        // Wait for the writer to finish: until no change has come for `settle`.
        loop {
            match changed.recv_timeout(settle) {
                Ok(()) => continue,
                Err(RecvTimeoutError::Timeout) => break,
                Err(RecvTimeoutError::Disconnected) => return,
            }
        }
        let update = match load(path) {
            Ok(loaded) => WatchUpdate::Loaded(loaded),
            Err(message) => {
                log::warn!("{message}; keeping the last good weather");
                WatchUpdate::Rejected(message)
            }
        };
        if updates.send(update).is_err() {
            return;
        }
    }
}

/// Reads the file once and decodes it if it is whole; else why not, naming the file.
pub fn load_whole(path: &Path, stations: Option<&StationTable>) -> Result<WeatherInput, String> {
    let shown = path.display();
    let before = std::fs::metadata(path).map_err(|err| format!("{shown}: cannot read: {err}"))?;
    let bytes = std::fs::read(path).map_err(|err| format!("{shown}: cannot read: {err}"))?;
    let after = std::fs::metadata(path).map_err(|err| format!("{shown}: cannot read: {err}"))?;
    if before.len() != after.len() || after.len() != bytes.len() as u64 {
        return Err(format!(
            "{shown}: still being written (its size changed while reading)"
        ));
    }
    if bytes.iter().all(u8::is_ascii_whitespace) {
        return Err(format!("{shown}: the file is empty"));
    }
    let input = WeatherInput::parse(path, &bytes, stations).map_err(|err| err.to_string())?;
    if let WeatherInput::Reports(file) = &input {
        let text = String::from_utf8_lossy(&bytes);
        if file.format == FileFormat::AwcCsv {
            if let Some((line, announced)) = announced_results(&text)
                && announced != file.reports_found
            {
                return Err(format!(
                    "{shown}:{line}: announces {announced} results but holds {}: cut short",
                    file.reports_found
                ));
            }
        } else if !text.ends_with('\n') {
            let line = text.lines().count();
            return Err(format!(
                "{shown}:{line}: ends in the middle of a line: cut short"
            ));
        }
    }
    input.usable().map_err(|err| err.to_string())
}

/// The `<n> results` line of a bulk CSV's preamble: its 1-based line and `n`.
fn announced_results(text: &str) -> Option<(usize, usize)> {
    text.lines()
        .take(files::CSV_HEADER_SEARCH_LINES)
        .enumerate()
        .find_map(|(i, line)| {
            let n = line.trim().strip_suffix(" results")?.parse().ok()?;
            Some((i + 1, n))
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    const BULK: &str = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/weather/awc-metars-2025-01-27T22Z.cache.csv"
    );

    fn temp_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("skycast-watch-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn reports_in(input: &WeatherInput) -> usize {
        input.reports().map_or(0, |f| f.reports.len())
    }

    /// The first `rows` rows of the real bulk file, preamble and header untouched.
    fn bulk_head(rows: usize) -> String {
        let text = std::fs::read_to_string(BULK).unwrap();
        text.lines()
            .take(6 + rows)
            .map(|l| format!("{l}\n"))
            .collect()
    }

    #[test]
    fn whole_files_load_and_broken_ones_say_why() {
        let dir = temp_dir("whole");
        let path = dir.join("metars.cache.csv");
        let good = std::fs::read_to_string(BULK).unwrap();
        std::fs::write(&path, &good).unwrap();
        assert_eq!(reports_in(&load_whole(&path, None).unwrap()), 4876);

        std::fs::write(&path, bulk_head(100)).unwrap();
        let err = load_whole(&path, None).unwrap_err();
        assert!(
            err.ends_with("metars.cache.csv:5: announces 4909 results but holds 100: cut short"),
            "{err}"
        );

        std::fs::write(&path, "\n\n").unwrap();
        assert!(
            load_whole(&path, None)
                .unwrap_err()
                .ends_with("the file is empty")
        );
        std::fs::write(&path, "<html>503 Service Unavailable</html>\n").unwrap();
        assert!(
            load_whole(&path, None)
                .unwrap_err()
                .contains("not a weather file")
        );

        let plain = dir.join("metar.txt");
        std::fs::write(
            &plain,
            "KLAX 272153Z 26008KT 10SM FEW025 14/07 A3008\nKSAN 272151Z 23008KT 10S",
        )
        .unwrap();
        let err = load_whole(&plain, None).unwrap_err();
        assert!(
            err.ends_with("metar.txt:2: ends in the middle of a line: cut short"),
            "{err}"
        );
    }

    #[test]
    fn a_watch_hands_over_good_versions_and_rejects_broken_ones() {
        let dir = temp_dir("live");
        let path = dir.join("metars.cache.csv");
        std::fs::write(&path, bulk_head(4909)).unwrap();
        let watch = WeatherWatch::start(&path, None, Duration::from_millis(300), |input| {
            reports_in(&input)
        })
        .unwrap();
        assert!(watch.poll().is_empty(), "nothing before a change");
        let next = || {
            watch
                .wait(Duration::from_secs(10))
                .expect("an update within 10 s")
        };

        // A writer caught half-way, then garbage: rejected, each once.
        std::fs::write(&path, bulk_head(2000)).unwrap();
        assert!(matches!(next(), WatchUpdate::Rejected(m) if m.contains("cut short")));
        std::fs::write(&path, "garbage\n").unwrap();
        assert!(matches!(next(), WatchUpdate::Rejected(m) if m.contains("not a weather file")));

        // A new version replaced by rename, as download tools do: handed over, decoded.
        let mut smaller = bulk_head(4909).replacen("4909 results", "300 results", 1);
        smaller = smaller
            .lines()
            .take(306)
            .map(|l| format!("{l}\n"))
            .collect();
        let staging = dir.join("download.tmp");
        std::fs::write(&staging, &smaller).unwrap();
        std::fs::rename(&staging, &path).unwrap();
        match next() {
            WatchUpdate::Loaded(reports) => assert!((280..=300).contains(&reports), "{reports}"),
            WatchUpdate::Rejected(m) => panic!("{m}"),
        }
        // Changes to other files in the folder are not ours.
        std::fs::write(dir.join("other.txt"), "x\n").unwrap();
        assert!(watch.wait(Duration::from_millis(500)).is_none());
    }
}
