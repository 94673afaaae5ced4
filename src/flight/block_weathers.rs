//! The block weathers the living cloud field asks for, kept while the camera is near them and
//! worked out ahead of it on a worker thread.
//!
//! The field asks for the weather of every block within its radius when the camera enters
//! another block, on the frame thread. A block's weather is a query of the weather field
//! (natural-neighbour weights, a blend of the stations' layers: microseconds a block), and a row
//! of new blocks is some thirty of them at once: a spike in that one frame. So after each such
//! frame the blocks just beyond the radius that are not kept yet are worked out on the field's
//! pool, and taken in by a later frame; the next row the camera brings in is then kept already.
//! A new weather field (a live update) is filled the same way: its blocks' weathers are
//! worked out on the pool before the field asks for them ([`BlockWeathers::fill`]).
//! The weather is a pure function of the field and the block, so a block's weather is the same
//! whether it came from the worker or the frame thread.

use std::collections::HashMap;
use std::sync::Arc;
use std::sync::mpsc::{Receiver, TryRecvError, channel};

use glam::DVec2;

use crate::clouds::field::blocks_within;
use crate::weather::field::WeatherField;
use crate::weather::{BLOCK_SIZE_M, BlockIndex, BlockWeather};

/// Blocks beyond the field's radius whose weather is worked out ahead, in blocks: the next row
/// in any direction, and one more for the drift.
const AHEAD_BLOCKS: f64 = 2.0;

/// Blocks beyond the field's radius whose weather is kept, in blocks (past those worked out
/// ahead, so that a camera turning back finds them).
const KEPT_BLOCKS: f64 = 4.0;

/// Weathers worked out on the worker, with the version of the field they are of.
type Batch = (u64, Vec<(BlockIndex, BlockWeather)>);

/// The kept block weathers (by ground block) and the batch being worked out ahead.
#[derive(Default)]
pub(super) struct BlockWeathers {
    kept: HashMap<BlockIndex, BlockWeather>,
    ahead: Option<Receiver<Batch>>,
    /// The field version of the kept weathers.
    version: u64,
    /// Whether the batch under way is a new field version's first ([`Self::fill`]).
    filling: bool,
}

impl BlockWeathers {
    /// The weather of ground block `index` of `field` (version `version`): kept, else worked
    /// out now and kept.
    pub fn get(&mut self, field: &WeatherField, version: u64, index: BlockIndex) -> BlockWeather {
        self.follow(version);
        self.kept
            .entry(index)
            .or_insert_with(|| field.block_weather(index))
            .clone()
    }

    /// Takes in a batch worked out ahead, if one is ready and of field version `version`.
    pub fn take_ready(&mut self, version: u64) {
        self.follow(version);
        let Some(rx) = &self.ahead else {
            return;
        };
        match rx.try_recv() {
            Ok((of, batch)) => {
                self.ahead = None;
                self.filling = false;
                if of == version {
                    for (index, weather) in batch {
                        self.kept.entry(index).or_insert(weather);
                    }
                }
            }
            Err(TryRecvError::Empty) => {}
            Err(TryRecvError::Disconnected) => (self.ahead, self.filling) = (None, false),
        }
    }

    /// For a new weather field (version `version`) taking over from another: starts working
    /// out the weathers of the blocks around `at` (as [`Self::ask_ahead`] takes it) on `spawn`
    /// when none of that version is kept or under way, and takes them in once ready. Returns
    /// whether they are still under way: the field keeps the last weather's blocks meanwhile,
    /// a frame or two (asking for every block of the field at once was some 700 weathers at
    /// 21 us on the frame thread, 15 ms in the frame of a live update).
    pub fn fill(
        &mut self,
        field: &Arc<WeatherField>,
        version: u64,
        at: (DVec2, DVec2, f64),
        spawn: impl FnOnce(Box<dyn FnOnce() + Send>),
    ) -> bool {
        self.take_ready(version);
        if self.kept.is_empty() && self.ahead.is_none() {
            self.filling = self.ask_ahead(field, version, at, spawn) > 0;
        }
        self.filling
    }

    /// After the field asked for the blocks within `radius_m` of `air_centre_m` (ground blocks
    /// lie `drift_m` on from the air's): forgets the weathers far behind, and hands the blocks
    /// just beyond the radius not kept yet to `spawn` (the field's pool) to be worked out, unless
    /// a batch is under way. Returns how many were handed over.
    pub fn ask_ahead(
        &mut self,
        field: &Arc<WeatherField>,
        version: u64,
        (air_centre_m, drift_m, radius_m): (DVec2, DVec2, f64),
        spawn: impl FnOnce(Box<dyn FnOnce() + Send>),
    ) -> usize {
        self.follow(version);
        let ground_centre = air_centre_m + drift_m;
        let keep_m = radius_m + KEPT_BLOCKS * BLOCK_SIZE_M;
        self.kept
            .retain(|index, _| (index.centre_m() - ground_centre).length() <= keep_m);
        if self.ahead.is_some() {
            return 0;
        }
        let mut todo: Vec<BlockIndex> =
            blocks_within(air_centre_m, radius_m + AHEAD_BLOCKS * BLOCK_SIZE_M)
                .into_iter()
                .map(|index| BlockIndex::containing(index.centre_m() + drift_m))
                .filter(|index| !self.kept.contains_key(index))
                .collect();
        todo.sort_unstable();
        todo.dedup();
        if todo.is_empty() {
            return 0;
        }
        let n = todo.len();
        let (tx, rx) = channel();
        let field = Arc::clone(field);
        spawn(Box::new(move || {
            let batch = todo
                .into_iter()
                .map(|index| (index, field.block_weather(index)))
                .collect();
            // The world may be gone (or have a new field) by now: then nobody listens.
            let _ = tx.send((version, batch));
        }));
        self.ahead = Some(rx);
        n
    }

    /// Weathers kept.
    #[cfg(test)]
    pub fn kept(&self) -> usize {
        self.kept.len()
    }

    /// Forgets everything of another field version.
    fn follow(&mut self, version: u64) {
        if version != self.version {
            self.kept.clear();
            self.ahead = None;
            self.filling = false;
            self.version = version;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    /// The 2025 bulk file around Los Angeles: the blocks' weathers differ.
    fn field() -> Arc<WeatherField> {
        Arc::new(crate::weather::storms::tests::real_field(33.90, -118.36))
    }

    #[test]
    fn weathers_worked_out_ahead_are_those_of_the_frame_thread_and_far_ones_are_forgotten() {
        let field = field();
        let mut weathers = BlockWeathers::default();
        let radius = 20_000.0;
        let spawned = std::cell::RefCell::new(None);
        let n = weathers.ask_ahead(
            &field,
            1,
            (DVec2::ZERO, DVec2::new(500.0, 0.0), radius),
            |job| *spawned.borrow_mut() = Some(job),
        );
        // Every block within the radius and two blocks more, none kept yet.
        assert!(n > 100, "{n} blocks");
        // A second ask while one is under way hands nothing over.
        assert_eq!(
            weathers.ask_ahead(&field, 1, (DVec2::ZERO, DVec2::ZERO, radius), |_| {}),
            0
        );
        let job = spawned.borrow_mut().take();
        job.expect("a job was handed over")();
        weathers.take_ready(1);
        assert_eq!(weathers.kept(), n);
        let index = BlockIndex::new(5, -3);
        assert_eq!(weathers.kept.get(&index), Some(&field.block_weather(index)));
        // The camera 100 km on: what lies behind is forgotten.
        weathers.ask_ahead(
            &field,
            1,
            (DVec2::new(100_000.0, 0.0), DVec2::ZERO, radius),
            |_| {},
        );
        assert!(!weathers.kept.contains_key(&index));
        // A batch of another field version is not taken in.
        let mut other = BlockWeathers::default();
        other.ask_ahead(&field, 2, (DVec2::ZERO, DVec2::ZERO, radius), |job| job());
        other.take_ready(3);
        assert_eq!(other.kept(), 0);
    }

    /// A new field's weathers are worked out on the worker: under way until its batch is
    /// taken in, then kept, the same as the frame thread's; a batch ahead of the camera at the
    /// same version is not a fill.
    #[test]
    fn a_new_fields_weathers_are_filled_on_the_worker_before_the_field_asks() {
        let field = field();
        let mut weathers = BlockWeathers::default();
        let at = (DVec2::ZERO, DVec2::ZERO, 20_000.0);
        weathers.get(&field, 1, BlockIndex::new(0, 0));
        let spawned = std::cell::RefCell::new(None);
        assert!(weathers.fill(&field, 2, at, |job| *spawned.borrow_mut() = Some(job)));
        assert_eq!(weathers.kept(), 0, "the last version's weathers are kept");
        // Not ready: still under way, nothing handed over twice.
        assert!(weathers.fill(&field, 2, at, |_| panic!("a second batch")));
        let job = spawned.borrow_mut().take();
        job.expect("a job was handed over")();
        assert!(!weathers.fill(&field, 2, at, |_| panic!("a second batch")));
        assert!(weathers.kept() > 100, "{} kept", weathers.kept());
        let index = BlockIndex::new(-2, 3);
        assert_eq!(weathers.kept.get(&index), Some(&field.block_weather(index)));
        // The camera moves on: the batch ahead of it is no fill.
        let on = (DVec2::new(8_000.0, 0.0), DVec2::ZERO, 20_000.0);
        assert!(weathers.ask_ahead(&field, 2, on, |_| {}) > 0);
        assert!(!weathers.fill(&field, 2, on, |_| panic!("a second batch")));
    }
}
