//! Live weather for a frame loop: one feed that merges a [`WeatherWatch`] of a weather file and
//! the timed weather events of a scripted flight. Both go the same way: the file is read and
//! checked whole ([`load_whole`]) and the caller's `prepare` (typically building the
//! [`WeatherField`](super::WeatherField)) runs off the frame thread; [`LiveWeather::poll`] hands
//! over what is ready and never waits. A timed event whose file is not prepared yet when its time
//! comes is applied on the first frame after it is (later events wait behind it, in order).
//!
//! Times are seconds of the caller's clock (flight time).

use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::mpsc::{self, Receiver, TryRecvError};
use std::thread;
use std::time::Duration;

use super::error::WeatherError;
use super::input::WeatherInput;
use super::stations::StationTable;
use super::watch::{WatchUpdate, WeatherWatch, load_whole};

/// Turns a decoded weather input into what the caller keeps; runs off the frame thread.
pub type Prepare<T> = Arc<dyn Fn(WeatherInput) -> T + Send + Sync>;

/// One change handed over by [`LiveWeather::poll`].
#[derive(Debug)]
pub enum LiveChange<T> {
    /// A good new weather, prepared: apply it.
    Loaded {
        /// The file it came from.
        source: PathBuf,
        /// The prepared weather.
        weather: T,
    },
    /// A file that cannot be used (one line naming file and line): keep the last good weather.
    Rejected(String),
}

struct Scheduled<T> {
    time_s: f64,
    path: PathBuf,
    result: Receiver<Result<T, String>>,
}

/// A watched file and timed events, merged. See the module docs.
pub struct LiveWeather<T> {
    watch: Option<WeatherWatch<T>>,
    scheduled: VecDeque<Scheduled<T>>,
}

impl<T> Default for LiveWeather<T> {
    fn default() -> Self {
        Self {
            watch: None,
            scheduled: VecDeque::new(),
        }
    }
}

impl<T: Send + 'static> LiveWeather<T> {
    /// A feed with nothing to watch and nothing scheduled.
    pub fn new() -> Self {
        Self::default()
    }

    /// Watches `path` (see [`WeatherWatch::start`]); replaces an earlier watch.
    pub fn watch(
        &mut self,
        path: &Path,
        stations: Option<Arc<StationTable>>,
        settle: Duration,
        prepare: Prepare<T>,
    ) -> Result<(), WeatherError> {
        self.watch = Some(WeatherWatch::start(path, stations, settle, move |input| {
            prepare(input)
        })?);
        Ok(())
    }

    /// Schedules `path` for `time_s` (after the events already scheduled). It is read, checked
    /// and prepared now, on a thread of its own, so it is ready when its time comes.
    pub fn schedule(
        &mut self,
        time_s: f64,
        path: &Path,
        stations: Option<Arc<StationTable>>,
        prepare: Prepare<T>,
    ) -> Result<(), WeatherError> {
        let (tx, result) = mpsc::channel();
        let worker_path = path.to_path_buf();
        thread::Builder::new()
            .name("skycast.weather_event".to_string())
            .spawn(move || {
                let prepared = load_whole(&worker_path, stations.as_deref()).map(|i| prepare(i));
                let _ = tx.send(prepared);
            })
            .map_err(|source| WeatherError::Io {
                path: path.to_path_buf(),
                source,
            })?;
        self.scheduled.push_back(Scheduled {
            time_s,
            path: path.to_path_buf(),
            result,
        });
        Ok(())
    }

    /// Timed events not applied yet.
    pub fn scheduled(&self) -> usize {
        self.scheduled.len()
    }

    /// The changes due at `time_s` that are ready, oldest first. Never blocks.
    pub fn poll(&mut self, time_s: f64) -> Vec<LiveChange<T>> {
        let mut out = Vec::new();
        while let Some(next) = self.scheduled.front() {
            if next.time_s > time_s {
                break;
            }
            let change = match next.result.try_recv() {
                Err(TryRecvError::Empty) => break, // still preparing: apply on a later frame
                Ok(Ok(weather)) => LiveChange::Loaded {
                    source: next.path.clone(),
                    weather,
                },
                Ok(Err(message)) => rejected(message),
                Err(TryRecvError::Disconnected) => rejected(format!(
                    "{}: the thread preparing it stopped",
                    next.path.display()
                )),
            };
            out.push(change);
            self.scheduled.pop_front();
        }
        if let Some(watch) = &self.watch {
            for update in watch.poll() {
                out.push(match update {
                    WatchUpdate::Loaded(weather) => LiveChange::Loaded {
                        source: watch.path().to_path_buf(),
                        weather,
                    },
                    // The watch logged it already.
                    WatchUpdate::Rejected(message) => LiveChange::Rejected(message),
                });
            }
        }
        out
    }
}

fn rejected<T>(message: String) -> LiveChange<T> {
    log::warn!("{message}; keeping the last good weather");
    LiveChange::Rejected(message)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn events_come_in_order_when_due_and_broken_ones_are_rejected() {
        let dir = std::env::temp_dir().join(format!("skycast-live-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let good = dir.join("good.txt");
        std::fs::write(&good, "KSAT 271700Z 19014KT 10SM BKN060 23/15 A2998\n").unwrap();
        let cut = dir.join("cut.txt");
        std::fs::write(&cut, "KSAT 271700Z 19014KT 10SM BKN0").unwrap();
        let table = Arc::new(
            StationTable::load(Path::new(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/weather/nsd_cccc.txt"
            )))
            .unwrap(),
        );
        let count: Prepare<usize> =
            Arc::new(|input| input.reports().map_or(0, |f| f.reports.len()));
        let mut live = LiveWeather::new();
        live.schedule(10.0, &good, Some(Arc::clone(&table)), Arc::clone(&count))
            .unwrap();
        live.schedule(20.0, &cut, Some(table), count).unwrap();
        assert!(live.poll(5.0).is_empty(), "nothing before its time");
        // Wait (as a test may) until the first is prepared, then it comes alone at t = 10.
        let mut got = Vec::new();
        for _ in 0..500 {
            got = live.poll(10.0);
            if !got.is_empty() {
                break;
            }
            thread::sleep(Duration::from_millis(10));
        }
        assert!(
            matches!(&got[..], [LiveChange::Loaded { weather: 1, source }] if source == &good),
            "{got:?}"
        );
        let mut got = Vec::new();
        for _ in 0..500 {
            got = live.poll(25.0);
            if !got.is_empty() {
                break;
            }
            thread::sleep(Duration::from_millis(10));
        }
        assert!(
            matches!(&got[..], [LiveChange::Rejected(m)] if m.contains("cut.txt:1: ends in the middle of a line")),
            "{got:?}"
        );
        assert_eq!(live.scheduled(), 0);
    }
}
