//! The field of cloud blocks around a point: what exists now, generated in the background,
//! changing with the weather and drifting with the wind.
//!
//! - [`BlockGenerator`] runs [`generate_block`] on a rayon pool of its own and hands results back
//!   through a channel: [`BlockGenerator::poll`] never blocks, so a caller drawing frames keeps
//!   drawing while blocks are made. [`generate_blocks`] is the blocking, data-parallel batch form.
//! - [`CloudField`] keeps the blocks within `radius_m` of a centre. Blocks live in the frame of the
//!   moving air: block (i, j) of the field sits at its ground position plus the drift (layer wind
//!   = surface wind x `wind_factor`, integrated over time), so clouds glide across block borders
//!   and a block keeps its identity and content while it drifts (no jumps). When a block's weather
//!   changes noticeably, its old clouds dissipate while the new ones form (Wang 2003 §4); a block
//!   is never swapped at once. Blocks entering the field at its rim appear fully formed, unless
//!   the blocks beside them are still forming after a weather change: then they form with them.
//!
//! Units: metres east/north in the local frame, seconds of field time.

use std::collections::{BTreeMap, BTreeSet};
use std::sync::Arc;
use std::sync::mpsc::{Receiver, Sender, channel};

use glam::DVec2;
use rayon::prelude::*;

use super::CloudsError;
use super::bands::DriftBand;
use super::block::CloudBlock;
use super::boxes::GenerationBoxes;
use super::config::{CloudTypes, CloudsConfig};
use super::generate::{generate_block, generate_block_in_field};
use super::lifecycle::{Phase, ends_at, phase_at};
use super::storm::CellCache;
use crate::weather::storms::{StormCell, StormContext, cells_over};
use crate::weather::{BLOCK_SIZE_M, BlockCover, BlockIndex, BlockLayer, BlockWeather, CloudType};

/// A finished generation job.
#[derive(Debug, Clone, PartialEq)]
pub struct Generated {
    /// The block asked for.
    pub index: BlockIndex,
    /// The weather it was generated from.
    pub weather: BlockWeather,
    /// The clouds.
    pub block: CloudBlock,
    /// Their core boxes for the probe's queries, worked out here on the worker (not on the
    /// frame thread that takes the block in).
    pub boxes: Arc<GenerationBoxes>,
}

/// Generates blocks on a thread pool without blocking the caller.
pub struct BlockGenerator {
    pool: Arc<rayon::ThreadPool>,
    types: Arc<CloudTypes>,
    tx: Sender<Generated>,
    rx: Receiver<Generated>,
    pending: usize,
    cells: Arc<CellCache>,
}

impl std::fmt::Debug for BlockGenerator {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BlockGenerator")
            .field("threads", &self.pool.current_num_threads())
            .field("pending", &self.pending)
            .finish()
    }
}

impl BlockGenerator {
    /// A generator with a pool of `threads` worker threads (0: one per core).
    pub fn new(types: Arc<CloudTypes>, threads: usize) -> Result<Self, CloudsError> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|k| format!("skycast-clouds-{k}"))
            .build()
            .map_err(|e| CloudsError::ThreadPool(e.to_string()))?;
        Ok(Self::with_pool(types, Arc::new(pool)))
    }

    /// A generator running on an existing pool (shared with the host, or a test's).
    pub fn with_pool(types: Arc<CloudTypes>, pool: Arc<rayon::ThreadPool>) -> Self {
        let (tx, rx) = channel();
        Self {
            pool,
            types,
            tx,
            rx,
            pending: 0,
            cells: Arc::new(CellCache::default()),
        }
    }

    /// The pool it runs on (for another generator beside it: [`Self::with_pool`]).
    pub fn pool(&self) -> Arc<rayon::ThreadPool> {
        Arc::clone(&self.pool)
    }

    /// Queues one block; returns at once.
    pub fn submit(&mut self, index: BlockIndex, weather: BlockWeather, seed: u64) {
        let tx = self.tx.clone();
        let types = Arc::clone(&self.types);
        self.pending += 1;
        self.pool.spawn(move || {
            let block = generate_block(index, &weather, seed, &types);
            let boxes = Arc::new(GenerationBoxes::of(&block.clouds));
            // The receiver is gone only when the generator was dropped: nobody wants the block.
            let _ = tx.send(Generated {
                index,
                weather,
                block,
                boxes,
            });
        });
    }

    /// Queues one block of the cloud field (the layers of drift `band`), whose cumulonimbus are
    /// the storm `cells` that reach over it ([`super::generate::generate_block_in_field`]); returns at once.
    pub fn submit_in_field(
        &mut self,
        index: BlockIndex,
        weather: BlockWeather,
        (cells, band): (Vec<StormCell>, DriftBand),
        seed: u64,
    ) {
        let tx = self.tx.clone();
        let types = Arc::clone(&self.types);
        let cache = Arc::clone(&self.cells);
        self.pending += 1;
        self.pool.spawn(move || {
            let block =
                generate_block_in_field(index, &weather, (&cells, band), &cache, seed, &types);
            let boxes = Arc::new(GenerationBoxes::of(&block.clouds));
            let _ = tx.send(Generated {
                index,
                weather,
                block,
                boxes,
            });
        });
    }

    /// Runs `job` on the generator's pool (work that belongs beside the blocks' own, off the
    /// caller's thread).
    pub fn spawn(&self, job: impl FnOnce() + Send + 'static) {
        self.pool.spawn(job);
    }

    /// The blocks finished since the last call, without waiting for any.
    pub fn poll(&mut self) -> Vec<Generated> {
        let done: Vec<Generated> = self.rx.try_iter().collect();
        self.pending -= done.len();
        done
    }

    /// Frees `generations` on the pool, not on the caller's thread: the clouds of the 30-odd
    /// blocks a field drops as the camera crosses a block are hundreds of thousands of sprites,
    /// 1 to 5 ms of frees on the frame that crossed (the cruise).
    pub fn free_later(&self, generations: Vec<FieldBlock>) {
        if !generations.is_empty() {
            self.pool.spawn(move || drop(generations));
        }
    }

    /// Waits for every queued block (for tools and tests; a frame loop uses [`Self::poll`]).
    pub fn wait_all(&mut self) -> Vec<Generated> {
        let mut done = Vec::with_capacity(self.pending);
        while self.pending > 0 {
            match self.rx.recv() {
                Ok(g) => {
                    self.pending -= 1;
                    done.push(g);
                }
                Err(_) => break,
            }
        }
        done
    }

    /// Blocks queued and not yet handed back.
    pub fn pending(&self) -> usize {
        self.pending
    }
}

/// Generates many blocks in parallel on the current rayon pool, in input order (blocking).
pub fn generate_blocks(
    jobs: &[(BlockIndex, BlockWeather)],
    seed: u64,
    types: &CloudTypes,
) -> Vec<CloudBlock> {
    jobs.par_iter()
        .map(|(index, weather)| generate_block(*index, weather, seed, types))
        .collect()
}

/// The blocks whose centre lies within `radius_m` of `centre_m`, in index order.
pub fn blocks_within(centre_m: DVec2, radius_m: f64) -> Vec<BlockIndex> {
    let lo = BlockIndex::containing(centre_m - DVec2::splat(radius_m));
    let hi = BlockIndex::containing(centre_m + DVec2::splat(radius_m));
    let mut out = Vec::new();
    for j in lo.j..=hi.j {
        for i in lo.i..=hi.i {
            let b = BlockIndex::new(i, j);
            if b.centre_m().distance_squared(centre_m) <= radius_m * radius_m {
                out.push(b);
            }
        }
    }
    out
}

/// Whether two block weathers differ enough to re-form the clouds: a layer added or removed, a
/// type changed, coverage by an okta or more (at the sample point or on the rim, see
/// [`BlockCover::differs`]), base or thickness by 300 ft or more.
pub fn weather_changed(a: &BlockWeather, b: &BlockWeather) -> bool {
    weather_changed_in(DriftBand::WHOLE, a, b)
}

/// [`weather_changed`] for the layers of drift `band` alone (a cover change at the rim counts
/// for every band).
pub fn weather_changed_in(band: DriftBand, a: &BlockWeather, b: &BlockWeather) -> bool {
    // Without a copy: a weather change compares the thousands of blocks of every band.
    fn of_band(band: DriftBand, w: &BlockWeather) -> impl Iterator<Item = &BlockLayer> {
        let layers = &w.layers;
        layers
            .iter()
            .filter(move |l| band.holds(layers, l.base_ft_agl))
    }
    let of_band = |w| of_band(band, w);
    BlockCover::differs(a.cover.as_ref(), b.cover.as_ref(), 1.0)
        || of_band(a).count() != of_band(b).count()
        || of_band(a).zip(of_band(b)).any(|(x, y)| {
            x.cloud_type != y.cloud_type
                || (x.coverage_oktas - y.coverage_oktas).abs() >= 1.0
                || (x.base_ft_agl - y.base_ft_agl).abs() >= 300.0
                || (x.thickness_ft - y.thickness_ft).abs() >= 300.0
        })
}

/// Whether a generation holds clouds.
fn has_clouds(g: &FieldBlock) -> bool {
    !g.block.clouds.is_empty()
}

/// A field time as a key of the queue of phase ends (times are finite).
#[derive(Debug, Clone, Copy, PartialEq)]
struct FieldTime(f64);

impl Eq for FieldTime {}

impl PartialOrd for FieldTime {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for FieldTime {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

/// When each block's next generation stops forming or dissipating by itself, soonest first.
type PhaseEnds = BTreeSet<(FieldTime, BlockIndex)>;

impl Slot {
    /// Puts the slot at `index` into `ends` at its generations' first phase end (out of it while
    /// every generation is steady), in place of where it was.
    fn schedule(&mut self, index: BlockIndex, ends: &mut PhaseEnds) {
        if let Some(t) = self.ends_s.take() {
            ends.remove(&(FieldTime(t), index));
        }
        self.ends_s = self
            .generations
            .iter()
            .filter_map(|g| ends_at(g.phase))
            .reduce(f64::min);
        if let Some(t) = self.ends_s {
            ends.insert((FieldTime(t), index));
        }
    }
}

/// One generation of clouds in a block, with where it is in its life.
#[derive(Debug, Clone, PartialEq)]
pub struct FieldBlock {
    /// The clouds as generated (the sprites' fades follow from `phase`:
    /// [`super::lifecycle::alpha_at`]; nothing is rewritten per frame).
    pub block: CloudBlock,
    /// Its clouds' core boxes ([`Generated::boxes`]).
    pub boxes: Arc<GenerationBoxes>,
    /// Forming, steady or dissipating.
    pub phase: Phase,
    /// Unique to this generation in its field (a weather change never reuses one).
    pub serial: u64,
}

#[derive(Debug)]
struct Slot {
    /// The weather of the newest generation asked for.
    weather: BlockWeather,
    /// The ground block and the weather's version it was last asked for with
    /// ([`CloudField::update_for`]; `None`: asked without a version).
    asked: Option<AskedFor>,
    /// Oldest first; during a weather change the old one dissipates while the new one forms.
    generations: Vec<FieldBlock>,
    /// The phase its first generation starts in (`CloudField::joining_phase` when it joined).
    joins: Phase,
    /// Where it is in the field's queue of phase ends (`CloudField::phase_ends`).
    ends_s: Option<f64>,
    /// An upper drift band's block over ground without a layer of its rank: held, without
    /// clouds or a generation asked for, so that it is not asked again while its weather stays,
    /// and a layer that the weather brings later forms instead of appearing at once.
    held_empty: bool,
    /// How long the change asked for last forms and how long the generations it supersedes
    /// take to go, seconds: the lifecycle's for a change of the weather, quicker for one the
    /// drift brings ([`LifecycleConfig::spans_for_drift`]).
    spans_s: (f32, f32),
}

/// A ground block and the version of the weather a field block over it was asked for with.
type AskedFor = (BlockIndex, u64);

/// The blocks around a point, advancing in time. See the module docs.
#[derive(Debug)]
pub struct CloudField {
    config: CloudsConfig,
    generator: BlockGenerator,
    /// The layers it holds ([`super::bands`]): its own drift is theirs.
    band: DriftBand,
    time_s: f64,
    drift_m: DVec2,
    /// The velocity the clouds drift with when the flight stage sets it (the air data's wind at
    /// their height, [`Self::set_drift_velocity`]); else the surface wind times `wind_factor`.
    drift_velocity_m_s: Option<DVec2>,
    wind_m_s: DVec2,
    slots: BTreeMap<BlockIndex, Slot>,
    next_serial: u64,
    /// Counts changes to which generations exist (added, gone).
    membership: u64,
    /// Generations that hold clouds (an upper band's field may hold none: the probes pass it).
    clouded: usize,
    /// The lowest and highest heights any generation taken in reached (its boxes and rain),
    /// metres: a line of sight that passes under or over them meets none of this field's clouds.
    heights_m: (f64, f64),
    /// The blocks with generations forming or dissipating, by when the first of them ends:
    /// advancing time touches only the blocks whose phases end then, not the thousands that
    /// fade at once across a weather change (building cumulus fade for ten minutes).
    phase_ends: PhaseEnds,
    /// The blocks taken off `phase_ends` in a frame (kept for its allocation).
    ending: Vec<BlockIndex>,
    /// What the weather field's storm cells are decided with.
    storms: StormContext,
    /// The storm cells over the field, as last decided (in the moving air's frame).
    cells: Vec<StormCell>,
}

impl CloudField {
    /// An empty field generating on its own pool (`threads`, 0: one per core).
    pub fn new(
        config: CloudsConfig,
        types: Arc<CloudTypes>,
        threads: usize,
    ) -> Result<Self, CloudsError> {
        Ok(Self::with_generator(
            config,
            BlockGenerator::new(types, threads)?,
        ))
    }

    /// An empty field using `generator`.
    pub fn with_generator(config: CloudsConfig, generator: BlockGenerator) -> Self {
        Self {
            config,
            generator,
            band: DriftBand::WHOLE,
            time_s: 0.0,
            drift_m: DVec2::ZERO,
            drift_velocity_m_s: None,
            wind_m_s: DVec2::ZERO,
            slots: BTreeMap::new(),
            next_serial: 0,
            membership: 0,
            clouded: 0,
            heights_m: (f64::INFINITY, f64::NEG_INFINITY),
            phase_ends: PhaseEnds::new(),
            ending: Vec::new(),
            storms: StormContext::default(),
            cells: Vec::new(),
        }
    }

    /// The field holding only the layers of drift `band` (one field per band, each drifting
    /// with its own wind: [`super::bands`]); its generations' serials are unique among the
    /// bands' fields (`serial % band.count == band.index`). Band 0 decides the storm cells.
    pub fn in_band(mut self, band: DriftBand) -> Self {
        self.band = band;
        self
    }

    /// The layers it holds.
    pub fn band(&self) -> DriftBand {
        self.band
    }

    /// What the storm cells are decided with.
    pub fn storms(&self) -> &StormContext {
        &self.storms
    }

    /// The storm cells over the field as last decided, in the moving air's frame (add
    /// [`Self::drift_m`] for the ground's).
    pub fn cells(&self) -> &[StormCell] {
        &self.cells
    }

    /// The field's seed (the cells' and the flashes').
    pub fn seed(&self) -> u64 {
        self.config.field.seed
    }

    /// Decides the storm cells with `storms` (the settings, the air data's wind profile and
    /// the frame's latitude) from now on.
    pub fn set_storms(&mut self, storms: StormContext) {
        self.storms = storms;
    }

    /// The storm cells that reach over the rectangle `min_m`..`max_m` of the moving air, with
    /// `weather` giving the weather of a ground block (as [`Self::update`] takes it).
    pub fn storm_cells(
        &self,
        min_m: DVec2,
        max_m: DVec2,
        weather: &dyn Fn(BlockIndex) -> BlockWeather,
    ) -> Vec<StormCell> {
        let drift = self.drift_m;
        cells_over(
            min_m,
            max_m,
            &mut |p| weather(BlockIndex::containing(p + drift)),
            &self.storms,
            self.config.field.seed,
        )
    }

    /// Asks for the blocks around `centre_m` (ground metres), with `weather` giving the weather
    /// of a ground block; queues what is missing or changed and takes in what has finished.
    /// Never waits for generation.
    pub fn update(&mut self, centre_m: DVec2, weather: &dyn Fn(BlockIndex) -> BlockWeather) {
        self.update_with(centre_m, weather, None);
    }

    /// [`Self::update`] with a weather that is one function of the ground block for each
    /// `version`: a block over the same ground block as when it was last asked, at the same
    /// version, keeps its weather without asking (a camera crossing into another block asked
    /// again for the weather of every one of the field's ~700 blocks, most of them unchanged).
    pub fn update_for(
        &mut self,
        centre_m: DVec2,
        weather: &dyn Fn(BlockIndex) -> BlockWeather,
        version: u64,
    ) {
        self.update_with(centre_m, weather, Some(version));
    }

    fn update_with(
        &mut self,
        centre_m: DVec2,
        weather: &dyn Fn(BlockIndex) -> BlockWeather,
        version: Option<u64>,
    ) {
        self.wind_m_s = match self.drift_velocity_m_s {
            Some(v) => v,
            None => {
                let here = weather(BlockIndex::containing(centre_m));
                here.wind.drift_m_s() * self.config.field.wind_factor
            }
        };
        let air_centre = centre_m - self.drift_m;
        let lifecycle = &self.config.lifecycle;
        let lifecycle_spans = (lifecycle.formation_s, lifecycle.dissipation_s);
        let drift_spans = lifecycle.spans_for_drift(self.wind_m_s.length());
        let radius = self.config.field.radius_m;
        let seed = self.config.field.seed;
        let wanted = blocks_within(air_centre, radius);
        // The storm cells over the field, decided once for the blocks this call queues: only
        // where the field's weather holds a cumulonimbus.
        let has_cb = |w: &BlockWeather| {
            w.layers
                .iter()
                .any(|l| l.cloud_type == CloudType::Cumulonimbus)
        };
        let asked: Vec<(BlockIndex, BlockWeather, Option<AskedFor>)> = wanted
            .iter()
            .filter_map(|&index| {
                let ground = BlockIndex::containing(index.centre_m() + self.drift_m);
                let key = version.map(|v| (ground, v));
                let kept = key.is_some() && self.slots.get(&index).is_some_and(|s| s.asked == key);
                (!kept).then(|| (index, weather(ground), key))
            })
            .collect();
        // Only band 0 draws the cells.
        let cb_seen = self.band.index == 0
            && (self.slots.values().any(|s| has_cb(&s.weather))
                || asked.iter().any(|(_, w, _)| has_cb(w)));
        let mut cells: Option<Vec<StormCell>> = None;
        let mut cells_for = |field: &Self, index: BlockIndex| {
            if cells.is_none() && cb_seen {
                let reach = DVec2::splat(radius + BLOCK_SIZE_M);
                cells = Some(field.storm_cells(air_centre - reach, air_centre + reach, weather));
            }
            let lo = index.min_corner_m();
            let hi = lo + DVec2::splat(BLOCK_SIZE_M);
            cells
                .iter()
                .flatten()
                .filter(|c| c.reaches(lo, hi))
                .copied()
                .collect::<Vec<_>>()
        };
        for (index, w, key) in asked {
            match self.slots.get(&index) {
                // An upper band holds no block over ground without a layer of its rank.
                None if !self.band.holds_any(&w) => {
                    let slot = Slot {
                        weather: w,
                        asked: key,
                        generations: Vec::new(),
                        joins: Phase::Steady,
                        ends_s: None,
                        held_empty: true,
                        spans_s: lifecycle_spans,
                    };
                    self.slots.insert(index, slot);
                }
                None => {
                    let mine = cells_for(self, index);
                    let band = self.band;
                    self.generator
                        .submit_in_field(index, w.clone(), (mine, band), seed);
                    // From the blocks with clouds beside it: not from those joining with it,
                    // which have none yet, so the same in any order.
                    let joins = self.joining_phase(index);
                    self.slots.insert(
                        index,
                        Slot {
                            weather: w,
                            asked: key,
                            generations: Vec::new(),
                            joins,
                            ends_s: None,
                            held_empty: false,
                            spans_s: lifecycle_spans,
                        },
                    );
                }
                Some(slot) if weather_changed_in(self.band, &slot.weather, &w) => {
                    // Asked again for the same field version: the air drifted onto ground of
                    // other weather.
                    let drifted = matches!((slot.asked, key), (Some(a), Some(k)) if a.1 == k.1);
                    let spans_s = match drifted {
                        true => drift_spans,
                        false => lifecycle_spans,
                    };
                    let mine = cells_for(self, index);
                    let band = self.band;
                    self.generator
                        .submit_in_field(index, w.clone(), (mine, band), seed);
                    let now = self.time_s;
                    if let Some(slot) = self.slots.get_mut(&index) {
                        (slot.weather, slot.asked, slot.spans_s) = (w, key, spans_s);
                        // A layer came where the band had none: it forms, as a weather change's
                        // new clouds do.
                        if std::mem::take(&mut slot.held_empty) {
                            slot.joins = Phase::Forming {
                                since_s: now,
                                over_s: spans_s.0,
                            };
                        }
                    }
                }
                Some(_) => {
                    if let Some(slot) = self.slots.get_mut(&index) {
                        slot.asked = key;
                    }
                }
            }
        }
        if !cb_seen {
            self.cells.clear();
        } else if let Some(decided) = cells {
            self.cells = decided;
        }
        // Blocks a block beyond the rim leave the field.
        let keep = radius + BLOCK_SIZE_M;
        let before = self.slots.len();
        let (phase_ends, clouded) = (&mut self.phase_ends, &mut self.clouded);
        let mut gone = Vec::new();
        self.slots.retain(|index, slot| {
            let kept = index.centre_m().distance_squared(air_centre) <= keep * keep;
            if !kept {
                if let Some(t) = slot.ends_s {
                    phase_ends.remove(&(FieldTime(t), *index));
                }
                *clouded -= slot.generations.iter().filter(|g| has_clouds(g)).count();
                gone.append(&mut slot.generations);
            }
            kept
        });
        if self.slots.len() != before {
            self.membership += 1;
        }
        self.generator.free_later(gone);
        self.take_finished();
    }

    fn take_finished(&mut self) {
        let done = self.generator.poll();
        self.take_in(done);
    }

    /// The phase a block's first generation starts in. Entering the field at its rim it
    /// appears formed (it was there all along, only out of reach), unless a block beside it is
    /// still forming after a weather change: then it forms with it, from the latest of their
    /// changes, so a block that joins mid-change does not stand whole among half-formed ones.
    fn joining_phase(&self, index: BlockIndex) -> Phase {
        (-1..=1)
            .flat_map(|dj| (-1..=1).map(move |di| BlockIndex::new(index.i + di, index.j + dj)))
            .filter_map(|beside| self.slots.get(&beside)?.generations.last())
            .filter_map(|g| match g.phase {
                Phase::Forming { since_s, .. } => Some((since_s, g.phase)),
                _ => None,
            })
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .map_or(Phase::Steady, |latest| latest.1)
    }

    fn take_in(&mut self, finished: Vec<Generated>) {
        let now = self.time_s;
        for done in finished {
            let Some(slot) = self.slots.get_mut(&done.index) else {
                continue;
            };
            if done.weather != slot.weather {
                continue; // superseded by a newer request
            }
            let (form_s, go_s) = slot.spans_s;
            let phase = if slot.generations.is_empty() {
                slot.joins
            } else {
                Phase::Forming {
                    since_s: now,
                    over_s: form_s,
                }
            };
            for g in &mut slot.generations {
                g.phase = match g.phase {
                    Phase::Steady => Phase::Dissipating {
                        since_s: now,
                        over_s: go_s,
                    },
                    // Still forming: back the way it came, from as far as it had formed.
                    Phase::Forming { .. } => Phase::Unforming {
                        since_s: now,
                        from: super::lifecycle::progress(g.phase, now),
                        over_s: form_s,
                    },
                    going => going,
                };
            }
            self.next_serial += 1;
            self.membership += 1;
            let band = self.band;
            self.clouded += usize::from(!done.block.clouds.is_empty());
            if !done.boxes.boxes.is_empty() {
                let (lo, hi) = &mut self.heights_m;
                (*lo, *hi) = (lo.min(done.boxes.lo_m.z), hi.max(done.boxes.hi_m.z));
            }
            slot.generations.push(FieldBlock {
                block: done.block,
                boxes: done.boxes,
                phase,
                serial: self.next_serial * u64::from(band.count) + u64::from(band.index),
            });
            slot.schedule(done.index, &mut self.phase_ends);
        }
    }

    /// Advances field time by `dt_s`: clouds drift, forming ones settle once formed,
    /// dissipated ones go. Per generation, not per sprite: the fades themselves are worked out
    /// where they are drawn ([`super::lifecycle::alpha_at`]).
    pub fn advance(&mut self, dt_s: f64) {
        self.time_s += dt_s;
        self.drift_m += self.wind_m_s * dt_s;
        let now = self.time_s;
        // Only the blocks a phase of which ends by now; each goes back in at its next end.
        self.ending.clear();
        let mut freed = Vec::new();
        while let Some(&(FieldTime(t), index)) = self.phase_ends.first() {
            if t > now {
                break;
            }
            self.phase_ends.pop_first();
            self.ending.push(index);
        }
        for &index in &self.ending {
            let Some(slot) = self.slots.get_mut(&index) else {
                continue;
            };
            slot.ends_s = None;
            for g in &mut slot.generations {
                g.phase = phase_at(g.phase, now);
            }
            let before = freed.len();
            freed.extend(slot.generations.extract_if(.., |g| g.phase == Phase::Gone));
            self.clouded -= freed[before..].iter().filter(|g| has_clouds(g)).count();
            if freed.len() != before {
                self.membership += 1;
            }
            // A phase that ends a rounding after `now` is back in the queue for the next call.
            slot.schedule(index, &mut self.phase_ends);
        }
        self.generator.free_later(freed);
        self.take_finished();
    }

    /// Takes in the blocks generated since the last call, without asking for any (what
    /// [`Self::update`] does after asking).
    pub fn poll(&mut self) {
        self.take_finished();
    }

    /// Counts changes to which generations exist (one added, one gone): while it stays the same,
    /// [`Self::blocks`] holds the same generations.
    pub fn membership(&self) -> u64 {
        self.membership
    }

    /// The lifecycle settings the field fades with.
    pub fn lifecycle(&self) -> &super::config::LifecycleConfig {
        &self.config.lifecycle
    }

    /// Waits until every queued block is generated and taken in (tools and tests).
    pub fn wait_for_pending(&mut self) {
        let done = self.generator.wait_all();
        self.take_in(done);
    }

    /// Everything to draw now: each block generation with the offset to add to its cloud centres
    /// (the drift), field-frame index first.
    pub fn blocks(&self) -> impl Iterator<Item = (BlockIndex, &FieldBlock)> {
        self.slots
            .iter()
            .flat_map(|(i, s)| s.generations.iter().map(move |g| (*i, g)))
    }

    /// The generations of one block, oldest first.
    pub fn generations(&self, index: BlockIndex) -> &[FieldBlock] {
        self.slots
            .get(&index)
            .map_or(&[][..], |s| s.generations.as_slice())
    }

    /// Runs `job` on the pool the blocks are generated on (work that belongs off the frame
    /// thread beside theirs: the weather of the blocks ahead).
    pub fn spawn(&self, job: impl FnOnce() + Send + 'static) {
        self.generator.spawn(job);
    }

    /// The radius of the field: blocks within it of its centre exist, metres.
    pub fn radius_m(&self) -> f64 {
        self.config.field.radius_m
    }

    /// How far the air (and every cloud) has moved since time 0, metres east/north: add it to a
    /// cloud's `centre_m` for its ground position now.
    pub fn drift_m(&self) -> DVec2 {
        self.drift_m
    }

    /// Drifts the clouds with `velocity_m_s` (east, north) from the next update on, where the
    /// flight stage knows the wind at their height; `None`: the surface wind times
    /// `[field] wind_factor`, the clouds stage's own guess.
    pub fn set_drift_velocity(&mut self, velocity_m_s: Option<DVec2>) {
        self.drift_velocity_m_s = velocity_m_s;
    }

    /// The velocity the clouds drift with now, metres a second east and north.
    pub fn drift_velocity_m_s(&self) -> DVec2 {
        self.wind_m_s
    }

    /// Field time, seconds.
    pub fn time_s(&self) -> f64 {
        self.time_s
    }

    /// Blocks in the field (with or without clouds generated yet).
    pub fn block_count(&self) -> usize {
        self.slots.len()
    }

    /// Whether any generation holds clouds (an upper drift band's field over a sky of one layer
    /// holds none).
    pub fn has_clouds(&self) -> bool {
        self.clouded > 0
    }

    /// The lowest and highest heights its clouds have reached since it began (never less: a
    /// bound, not the clouds now), metres above mean sea level.
    pub fn heights_m(&self) -> (f64, f64) {
        self.heights_m
    }

    /// Blocks queued for generation and not yet taken in.
    pub fn pending(&self) -> usize {
        self.generator.pending()
    }
}

#[cfg(test)]
#[path = "field_tests.rs"]
mod tests;
