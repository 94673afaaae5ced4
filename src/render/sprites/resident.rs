//! The clouds on the GPU. A block's sprites and clouds are written into storage buffers once,
//! when it arrives, into a range of slots ([`SlotRanges`]) that only the device moves them out
//! of (when the slots are packed); after that a frame writes only what changed: a cloud's
//! back-to-front order when Wang's cache says so, and the small draw list. The buffers grow
//! only when the blocks held at once need more slots than they have (to a sixteenth more, in
//! steps of their first size), up to the device's limits (or the host's budget); past that the
//! farthest blocks are left out and counted, never a validation error. So their size follows
//! the most sprites and clouds ever held at once: during a weather change, the old generation
//! dissipating while the new one forms (`docs/src/long-flights.md` gives the bound).
//!
//! Units: metres; sprite and cloud data relative to the cloud centre, cloud centres f64.

use std::ops::Range;

use glam::{DVec3, Vec3};

use super::cloud_light::{BlockLight, CloudLight};
use super::slots::SlotRanges;
use crate::render::gpu_types::{GpuCloud, GpuListCloud, GpuSprite};
use crate::render::id_hash::{IdMap, IdSet};
use crate::render::scene::{BlockMotion, SkyBlock, SkyCloud};
use crate::render::stats::Spent;

// Where a block's slots are found, packed and grown, and its records written: apart, as the
// set's bookkeeping above does not need to read it.
mod packing;
// The drift bands' offsets, which every block reads at use.
mod drift;

pub(in crate::render) use drift::SharedDrift;

/// Bytes of GPU memory each sprite slot costs: its record, its order entry and its Harris and
/// Lastra light (a cloud's record and list entry come on top, about a twentieth of it for
/// 30-sprite clouds; the quad indices are for the sprites drawn, not held).
pub const BYTES_PER_SPRITE: u64 = std::mem::size_of::<GpuSprite>() as u64 + 4 + 4;

/// A cloud's bounds (computed once when its block arrives) and its order cache.
#[derive(Debug, Clone)]
pub(in crate::render) struct CloudState {
    /// Its centre, metres (a copy of the cloud's: what a frame reads of every cloud, together).
    pub centre_m: DVec3,
    /// Its sprites.
    pub sprites: u32,
    /// Radius of a sphere around the centre holding every sprite, metres.
    pub radius_m: f32,
    /// Half extents and centre offset of the box of its sprite cores (in-cloud fog).
    pub core_half_m: Vec3,
    pub core_centre_m: Vec3,
    /// Half extents and centre offset of the box of its sprites' centres, and its largest
    /// sprite's half side: a camera farther from that box than a lock's reach of that half side
    /// (or the half side, if more) is within no sprite's facing lock nor rain shaft.
    pub centres_half_m: Vec3,
    pub centres_centre_m: Vec3,
    pub largest_half_side_m: f32,
    /// First sprite slot (its order lives at the same slots of the order buffer).
    pub sprite_base: u32,
    /// Where its sprites' offsets start in the block's [`Resident::offsets`].
    pub first_offset: u32,
    /// Its slot in the cloud buffer.
    pub cloud_slot: u32,
    /// Camera relative to the cloud and sky time when its order was last computed.
    pub ordered_at: Option<(DVec3, f64)>,
}

/// A cloud as a view's draw list looks at it ([`Resident::seen`]): a copy of its centre, its
/// radius and its largest sprite's half side.
#[derive(Debug, Clone, Copy)]
pub(in crate::render) struct CloudSeen {
    pub centre_m: DVec3,
    pub radius_m: f32,
    pub largest_half_side_m: f32,
}

/// When a block's cloud list and orders must be looked at again: the camera relative to the
/// block then, how far it may move from there and until when, before any of its clouds passes
/// its cache thresholds or the draw distance.
#[derive(Debug, Clone, Copy)]
pub(in crate::render) struct BlockCheck {
    pub camera_rel_m: DVec3,
    pub move_budget_m: f64,
    pub checked_s: f64,
    pub deadline_s: f64,
}

/// A block the sky holds.
#[derive(Debug, Clone)]
pub(in crate::render) struct Resident {
    pub block: SkyBlock,
    /// Its fade and drift band, and its own offset: the one it moves by while `own_since` is
    /// the drift's count of settings (it was given after the bands were last set); else its
    /// band's offset ([`Self::offset_m`]).
    motion: BlockMotion,
    drift: SharedDrift,
    own_since: u64,
    /// Radius of a sphere around the block's centre holding all its clouds, metres.
    pub radius_m: f64,
    /// Its largest cloud's radius, metres: how far its sprites reach past the plane between
    /// it and a neighbour (the draw list interleaves the clouds of two deck blocks whose order
    /// the camera is that close to deciding).
    pub largest_cloud_m: f64,
    /// The lowest and highest corner of the box of its clouds' centres, from its centre,
    /// metres: with [`Self::largest_cloud_m`], where its clouds can be without reading them
    /// (the impostor ring's content band).
    pub centres_box_m: (DVec3, DVec3),
    /// The largest half side of its sprites, metres: how far a quad's corner reaches past the
    /// cloud radius that counts only the half side (`sqrt(2) - 1` of it).
    pub largest_half_side_m: f32,
    /// Whether it holds a deck (a layer's cells on the lattice, `sunlit_depth_m` set): clouds
    /// side by side up to its sides, which overlap a neighbouring deck's all along the boundary.
    pub deck: bool,
    /// Its drawn clouds, back to front, as last sorted (the GPU's copy is at its cloud slots of
    /// the list buffer), and their sprites.
    pub list: Vec<GpuListCloud>,
    /// Which writing of `list` it holds (0: none yet): what the draw list worked out from a
    /// list (the clouds of neighbouring blocks interleaved) holds while this stays.
    pub list_serial: u64,
    pub list_sprites: u32,
    pub check: Option<BlockCheck>,
    /// Its slots, while it is on the GPU.
    pub place: Option<(Range<u32>, Range<u32>)>,
    /// Which placing `place` is: a number no other placing of any block had, so that a copy
    /// of what was written at its slots (the impostor ring's orders) knows it still is.
    pub place_serial: u64,
    /// Written to its slots yet.
    pub uploaded: bool,
    /// Its Harris and Lastra light (empty under Wang's model).
    pub light: BlockLight,
    /// Drawn as sprites at any distance and never in the ring: a storm cell beyond the cloud
    /// field ([`crate::render::Sky::insert_distant_block`]).
    pub distant: bool,
    pub clouds: Vec<CloudState>,
    /// What a view's draw list reads of each cloud of [`Self::clouds`], in its order, 32 bytes
    /// a cloud: read in the order of the block's list, scattered, once a frame for every cloud
    /// of a block across the view's edge (reading it from the clouds' states cost two or three
    /// cache lines a cloud, most of the draw list's time over an overcast).
    pub seen: Vec<CloudSeen>,
    /// Every sprite's offset from its cloud's centre, metres, cloud after cloud
    /// ([`CloudState::first_offset`]): what a sort of a cloud's sprites reads, 12 bytes a sprite
    /// together, not the 40 of a whole sprite (the Cb circle's frames re-sort 4,000 sprites, and
    /// reading their offsets from the sprites cost more than the sort).
    pub offsets: Vec<Vec3>,
    /// Lowest and highest heights of its clouds' sprites (their core boxes), metres relative
    /// to the block's centre: a storm cell's part spans from its base to its anvil.
    pub z_span_m: (f64, f64),
}

impl Resident {
    pub(in crate::render) fn new(block: SkyBlock, motion: BlockMotion) -> Self {
        let mut first_offset = 0u32;
        let clouds: Vec<CloudState> = block
            .clouds
            .iter()
            .map(|c| {
                let (core_half_m, core_centre_m) = c.core_box_m();
                let (centres_half_m, centres_centre_m, largest_half_side_m) = centres_box_m(c);
                let state = CloudState {
                    centre_m: c.centre_m,
                    sprites: c.sprites.len() as u32,
                    radius_m: c.radius_m(),
                    core_half_m,
                    core_centre_m,
                    centres_half_m,
                    centres_centre_m,
                    largest_half_side_m,
                    sprite_base: 0,
                    first_offset,
                    cloud_slot: 0,
                    ordered_at: None,
                };
                first_offset += c.sprites.len() as u32;
                state
            })
            .collect();
        let seen = (clouds.iter())
            .map(|c| CloudSeen {
                centre_m: c.centre_m,
                radius_m: c.radius_m,
                largest_half_side_m: c.largest_half_side_m,
            })
            .collect();
        let offsets = block
            .clouds
            .iter()
            .flat_map(|c| c.sprites.iter().map(|s| s.offset_m))
            .collect();
        let radius_m = clouds
            .iter()
            .map(|c| (c.centre_m - block.centre_m).length() + c.radius_m as f64)
            .fold(0.0, f64::max);
        let largest_cloud_m = clouds.iter().map(|c| c.radius_m as f64).fold(0.0, f64::max);
        let centres_box_m = (clouds.iter())
            .map(|c| c.centre_m - block.centre_m)
            .fold(None, |b: Option<(DVec3, DVec3)>, c| {
                Some(b.map_or((c, c), |(lo, hi)| (lo.min(c), hi.max(c))))
            })
            .unwrap_or_default();
        let largest_half_side_m = clouds
            .iter()
            .map(|c| c.largest_half_side_m)
            .fold(0.0, f32::max);
        let deck = block.clouds.iter().any(|c| c.sunlit_depth_m > 0.0);
        let z_span_m = clouds
            .iter()
            .map(|c| {
                let z = c.centre_m.z - block.centre_m.z + c.core_centre_m.z as f64;
                (z - c.core_half_m.z as f64, z + c.core_half_m.z as f64)
            })
            .reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)))
            .unwrap_or((0.0, 0.0));
        Self {
            block,
            motion,
            drift: SharedDrift::default(),
            own_since: 0,
            radius_m,
            largest_cloud_m,
            centres_box_m,
            largest_half_side_m,
            deck,
            z_span_m,
            list: Vec::new(),
            list_serial: 0,
            list_sprites: 0,
            check: None,
            place: None,
            place_serial: 0,
            uploaded: false,
            light: BlockLight::default(),
            distant: false,
            clouds,
            seen,
            offsets,
        }
    }

    /// The offsets of cloud `ci`'s sprites ([`Self::offsets`]).
    pub fn offsets_of(&self, ci: usize) -> &[Vec3] {
        let c = &self.clouds[ci];
        &self.offsets[c.first_offset as usize..(c.first_offset + c.sprites) as usize]
    }

    /// Sprites of all its clouds.
    pub fn sprite_count(&self) -> u32 {
        self.block
            .clouds
            .iter()
            .map(|c| c.sprites.len() as u32)
            .sum()
    }

    /// Its centre now (with the drift), metres.
    pub fn centre_m(&self) -> DVec3 {
        self.block.centre_m + self.offset_m()
    }

    /// Its drift now, metres: its own offset if it was given since the drift bands were last
    /// set, else its band's.
    pub fn offset_m(&self) -> DVec3 {
        if self.own_since == self.drift.settings() {
            self.motion.offset_m
        } else {
            self.drift.offset_m(self.motion.drift_band)
        }
    }

    /// Where it is in its life.
    pub fn fade(&self) -> crate::render::Fade {
        self.motion.fade
    }

    /// Its motion now: its fade and band, and its drift ([`Self::offset_m`]).
    pub fn motion(&self) -> BlockMotion {
        BlockMotion {
            offset_m: self.offset_m(),
            ..self.motion
        }
    }

    /// Gives it `motion`, its offset its own until the drift bands are next set.
    pub fn set_motion(&mut self, motion: BlockMotion) {
        self.motion = motion;
        self.own_since = self.drift.settings();
    }

    /// Sets where it is in its life, keeping its drift.
    pub fn set_fade(&mut self, fade: crate::render::Fade) {
        self.motion.fade = fade;
    }

    /// Its centre moved up or down to the height within its clouds' span nearest `height_m`:
    /// how far above or below the camera the block is, for the impostor ring's height limit (a
    /// storm cell 30 km off spans the camera's height although its middle is 4 km above it).
    pub fn nearest_height_m(&self, height_m: f64) -> DVec3 {
        let c = self.centre_m();
        let (lo, hi) = self.z_span_m;
        DVec3::new(c.x, c.y, height_m.clamp(c.z + lo, c.z + hi.max(lo)))
    }

    /// A fixed order for blocks as far from the camera as each other (a camera on the corner
    /// of four blocks sees them at one distance): by place, west then south first, then by id
    /// (generations of one place, oldest first). Never by id alone: ids are handed out as the
    /// background generation finishes, in an order that differs from run to run, and the
    /// frame must not (equally far blocks' overlapping sprites blend differently in either
    /// order, and the upload and relight budgets would take either first).
    pub(in crate::render) fn tie_order(&self, other: &Resident) -> std::cmp::Ordering {
        let (a, b) = (self.block.centre_m, other.block.centre_m);
        a.x.total_cmp(&b.x)
            .then(a.y.total_cmp(&b.y))
            .then(self.block.id.cmp(&other.block.id))
    }
}

/// The half extents and centre of the box of a cloud's sprite centres, and the largest half
/// side of its sprites.
fn centres_box_m(cloud: &SkyCloud) -> (Vec3, Vec3, f32) {
    if cloud.sprites.is_empty() {
        return (Vec3::ZERO, Vec3::ZERO, 0.0);
    }
    let (mut lo, mut hi, mut half) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN), 0.0f32);
    for s in &cloud.sprites {
        lo = lo.min(s.offset_m);
        hi = hi.max(s.offset_m);
        half = half.max(0.5 * s.width_m.max(s.height_m));
    }
    ((hi - lo) * 0.5, (hi + lo) * 0.5, half)
}

/// The blocks the sky holds and their GPU buffers.
pub(in crate::render) struct ResidentSet {
    device: wgpu::Device,
    pub blocks: IdMap<Resident>,
    sprite_slots: SlotRanges,
    cloud_slots: SlotRanges,
    /// Most sprite slots the device (or the budget) allows.
    limit_sprites: u32,
    pub sprite_buffer: wgpu::Buffer,
    pub cloud_buffer: wgpu::Buffer,
    /// Per sprite slot its Harris and Lastra light (`cloud_light`; zeros under Wang's model).
    pub light_buffer: wgpu::Buffer,
    /// The Harris and Lastra light's state (off under Wang's model).
    pub light: CloudLight,
    /// Sprites lit this frame (written or relit), and the CPU time it took, microseconds.
    pub lit_sprites: u32,
    pub light_us: u64,
    /// The sky camera's per-cloud orders, at the clouds' sprite slots.
    pub order_buffer: wgpu::Buffer,
    /// The sky camera's per-block cloud lists, at the blocks' cloud slots.
    pub list_buffer: wgpu::Buffer,
    layout: wgpu::BindGroupLayout,
    /// Group 2 of the sprite passes: sprites and clouds.
    pub group: wgpu::BindGroup,
    /// A CPU copy of the order buffer; `dirty_orders` are the spans to write this frame.
    pub orders_cpu: Vec<u32>,
    pub dirty_orders: Vec<Range<u32>>,
    /// The same for the cloud lists.
    pub lists_cpu: Vec<GpuListCloud>,
    pub dirty_lists: Vec<Range<u32>>,
    /// Counts buffer rebuilds: bind groups made with the old buffers must be made again.
    pub generation: u64,
    /// The time this frame spent submitting the copies of grown buffers: a wait
    /// for the device (lavapipe runs a submission on the submitting thread), reported apart.
    pub grow_wait: Spent,
    /// Where this frame's packings moved the sprite slots of the blocks held, one list of runs
    /// a packing, in the order they came ([`Self::moved_slot`]).
    packs: Vec<Vec<SlotMove>>,
    /// Whether the order and list buffers are new this frame (they grew or packed): written
    /// whole from their CPU copies once the blocks are placed.
    whole_due: bool,
    /// The blocks not placed or not written yet: what placing and writing look at each frame,
    /// not the thousands held.
    waiting: IdSet,
    /// Counts changes to which blocks are on the GPU (one came, went, was written or lost its
    /// place): while it stays the same, so do they.
    pub changes: u64,
    /// Counts changes of a block's kind of fade (steady, forming, dissipating;
    /// [`crate::render::Sky::set_block_fade`] and its kin), not of its progress: what the
    /// shadow map's cover check watches, which a sky of forming clouds would otherwise trip
    /// every frame.
    pub fades: u64,
    /// The drift bands' offsets [`crate::render::Sky::set_band_drifts`] last moved every block
    /// to, as every block it holds reads them ([`Resident::offset_m`]).
    drift: SharedDrift,
    /// Placings of blocks so far ([`Resident::place_serial`]).
    placings: u64,
    /// Sprites and clouds of blocks the caller will insert in the next frames
    /// ([`crate::render::Sky::expect_blocks`]): a buffer that grows grows for them too, once.
    pub expected: (u64, u64),
}

/// A run of sprite slots a packing moved: `from` now lies at `to..to + from.len()`.
#[derive(Debug, Clone, PartialEq)]
struct SlotMove {
    from: Range<u32>,
    to: u32,
}

/// `slot` of a range that started at `from` and starts at `to` now.
fn rebase(slot: u32, from: u32, to: u32) -> u32 {
    slot.wrapping_sub(from).wrapping_add(to)
}

const FIRST_SPRITES: u32 = 4096;
const FIRST_CLOUDS: u32 = 256;

/// The most sprite and cloud slots the resident buffers grow to while at most `sprites` sprites
/// and `clouds` clouds are held at once (the blocks of every generation alive, forming,
/// dissipating or steady): a sixteenth more, rounded up to steps of 4,096 sprites and 256
/// clouds, and never less than those. Each sprite slot costs [`BYTES_PER_SPRITE`], each cloud
/// slot 144 bytes. How many a weather holds is in `docs/src/long-flights.md`.
pub fn resident_slots_bound(sprites: u32, clouds: u32) -> (u32, u32) {
    let up = |n: u32, step: u32| {
        let step = step as u64;
        ((n as u64 * 17 / 16).div_ceil(step) * step)
            .max(step)
            .min(u32::MAX as u64) as u32
    };
    (up(sprites, FIRST_SPRITES), up(clouds, FIRST_CLOUDS))
}

impl ResidentSet {
    /// Empty buffers on `device`; `budget_bytes` caps the sprite memory (0: the device's
    /// limits alone).
    pub fn new(device: &wgpu::Device, budget_bytes: u64) -> Self {
        let limits = device.limits();
        let storage_max = limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size);
        let by_device =
            (storage_max / std::mem::size_of::<GpuSprite>() as u64).min(u32::MAX as u64 / 6);
        let by_budget = if budget_bytes == 0 {
            u64::MAX
        } else {
            budget_bytes / BYTES_PER_SPRITE
        };
        let limit_sprites = by_device.min(by_budget) as u32;
        let storage = |b: u32| wgpu::BindGroupLayoutEntry {
            binding: b,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: true },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("sky.resident_layout"),
            entries: &[storage(0), storage(1), storage(2)],
        });
        let sprites = FIRST_SPRITES.min(limit_sprites.max(1));
        let b = buffers(device, &layout, sprites, FIRST_CLOUDS);
        Self {
            device: device.clone(),
            blocks: IdMap::default(),
            sprite_slots: SlotRanges::new(sprites),
            cloud_slots: SlotRanges::new(FIRST_CLOUDS),
            limit_sprites,
            sprite_buffer: b.sprites,
            cloud_buffer: b.clouds,
            light_buffer: b.lights,
            light: CloudLight::default(),
            lit_sprites: 0,
            light_us: 0,
            order_buffer: b.orders,
            list_buffer: b.lists,
            layout,
            group: b.group,
            orders_cpu: vec![0; sprites as usize],
            dirty_orders: Vec::new(),
            lists_cpu: vec![GpuListCloud::default(); FIRST_CLOUDS as usize],
            dirty_lists: Vec::new(),
            generation: 0,
            grow_wait: Spent::default(),
            packs: Vec::new(),
            whole_due: false,
            waiting: IdSet::default(),
            changes: 0,
            fades: 0,
            drift: SharedDrift::default(),
            placings: 0,
            expected: (0, 0),
        }
    }

    /// The layout of [`Self::group`].
    pub fn layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }

    /// Bytes of the sprite, cloud, order and index buffers.
    pub fn gpu_bytes(&self) -> u64 {
        self.sprite_buffer.size()
            + self.cloud_buffer.size()
            + self.light_buffer.size()
            + self.order_buffer.size()
            + self.list_buffer.size()
    }

    /// Blocks held, their sprites, and the sprite and cloud slots (in all, in use).
    pub fn occupancy(&self) -> (u32, u32, (u32, u32), (u32, u32)) {
        let sprites = self.blocks.values().map(Resident::sprite_count).sum();
        (
            self.blocks.len() as u32,
            sprites,
            (self.sprite_slots.capacity(), self.sprite_slots.used()),
            (self.cloud_slots.capacity(), self.cloud_slots.used()),
        )
    }

    /// Adds or replaces a block (uploaded by the next [`Self::place`]).
    pub fn insert(&mut self, block: SkyBlock, motion: BlockMotion) {
        self.remove(block.id);
        self.waiting.insert(block.id);
        self.changes += 1;
        let mut r = Resident::new(block, motion);
        r.drift = self.drift.clone();
        r.own_since = self.drift.settings();
        self.blocks.insert(r.block.id, r);
    }

    /// Moves every drift band to `offsets_m` (the blocks that follow their band with it): one
    /// write whatever the blocks held.
    pub fn set_drift(&mut self, offsets_m: &crate::render::scene::BandOffsets) {
        self.drift.set(offsets_m);
    }

    /// The drift bands' offsets the blocks were last moved to (none yet: zero).
    pub fn drift_m(&self) -> crate::render::scene::BandOffsets {
        self.drift.offsets_m()
    }

    /// Retires a block and frees its slots; returns the sprite slots it had, if it was held.
    pub fn remove(&mut self, id: u64) -> Option<Range<u32>> {
        let old = self.blocks.remove(&id)?;
        self.waiting.remove(&id);
        self.changes += 1;
        match old.place {
            Some((sprites, clouds)) => {
                self.sprite_slots.release(sprites.clone());
                self.cloud_slots.release(clouds);
                Some(sprites)
            }
            None => Some(0..0),
        }
    }

    /// Places every block not on the GPU yet in slots (growing or packing the buffers where
    /// the limits allow, which is the only device work of it; past them the farthest from
    /// `camera_m` are left out). Returns the blocks left out. Blocks a packing moved keep what
    /// was written ([`Self::moved_slot`]); [`Self::write_placed`] writes the new ones.
    pub fn place(&mut self, queue: &wgpu::Queue, camera_m: DVec3) -> u32 {
        self.packs.clear();
        self.grow_wait = Spent::default();
        let blocks = &self.blocks;
        let mut waiting: Vec<(f64, &Resident)> = self
            .waiting
            .iter()
            .filter_map(|id| blocks.get(id))
            .filter(|r| r.place.is_none())
            .map(|r| ((r.centre_m() - camera_m).length_squared(), r))
            .collect();
        if !waiting.is_empty() {
            waiting.sort_by(|a, b| a.0.total_cmp(&b.0).then_with(|| a.1.tie_order(b.1)));
            let waiting: Vec<(f64, u64)> =
                waiting.iter().map(|(d2, r)| (*d2, r.block.id)).collect();
            for &(d2, id) in &waiting {
                self.place_one(queue, id, d2, camera_m);
            }
        }
        // Blocks that did not fit, and any a nearer one took the place of.
        let blocks = &self.blocks;
        self.waiting
            .iter()
            .filter_map(|id| blocks.get(id))
            .filter(|r| r.place.is_none())
            .count() as u32
    }

    /// Writes the blocks [`Self::place`] placed, nearest first, up to `budget_sprites` sprites
    /// (and the order and list buffers whole when they are new). Returns the bytes written.
    pub fn write_placed(
        &mut self,
        queue: &wgpu::Queue,
        camera_m: DVec3,
        budget_sprites: u32,
    ) -> u64 {
        // Once, however many times the buffers grew or packed (the first frame of the FL350
        // cruise grows them 71 times: 52 MB written whole into buffers dropped at once).
        let mut written = 0;
        if std::mem::take(&mut self.whole_due) {
            written += self.write_whole(queue);
        }
        written + self.upload(queue, camera_m, budget_sprites)
    }

    /// Whether the last [`Self::place`] packed the buffers (moved blocks to other
    /// slots).
    pub fn packed(&self) -> bool {
        !self.packs.is_empty()
    }

    /// Where sprite slot `slot` of a block held before the last [`Self::place`] is
    /// now, after the packings it made (none: where it was); `None` if no block placed then
    /// holds that slot now. For what keeps sprite slots across frames (the facing locks).
    pub fn moved_slot(&self, slot: u32) -> Option<u32> {
        self.packs.iter().try_fold(slot, |slot, moves| {
            let i = moves.partition_point(|m| m.from.end <= slot);
            let m = moves.get(i).filter(|m| m.from.contains(&slot))?;
            Some(rebase(slot, m.from.start, m.to))
        })
    }
}

/// A storage buffer the queue writes into, of at least 16 bytes.
pub(in crate::render) fn storage_buffer(
    device: &wgpu::Device,
    label: &str,
    bytes: u64,
) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(16),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// The resident buffers and the group of the two the sprite passes bind.
struct Buffers {
    sprites: wgpu::Buffer,
    clouds: wgpu::Buffer,
    lights: wgpu::Buffer,
    orders: wgpu::Buffer,
    lists: wgpu::Buffer,
    group: wgpu::BindGroup,
}

/// Sprite, cloud, order and list buffers for `sprites` and `clouds` slots.
fn buffers(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    sprites: u32,
    clouds: u32,
) -> Buffers {
    // Copied from when they grow.
    let storage = |label, size: u64| {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: size.max(16),
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        })
    };
    let sprite_buffer = storage(
        "sky.sprites",
        sprites as u64 * std::mem::size_of::<GpuSprite>() as u64,
    );
    let cloud_buffer = storage(
        "sky.clouds",
        clouds as u64 * std::mem::size_of::<GpuCloud>() as u64,
    );
    let light_buffer = storage("sky.sprite_lights", sprites as u64 * 4);
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("sky.resident_group"),
        layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: sprite_buffer.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: cloud_buffer.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: light_buffer.as_entire_binding(),
            },
        ],
    });
    Buffers {
        sprites: sprite_buffer,
        clouds: cloud_buffer,
        lights: light_buffer,
        orders: storage("sky.orders", sprites as u64 * 4),
        lists: storage(
            "sky.lists",
            clouds as u64 * std::mem::size_of::<GpuListCloud>() as u64,
        ),
        group,
    }
}

/// Index list for `sprites` quads of four corners (two triangles each): the vertex shader
/// builds corner `v % 4` of the frame's sprite `v / 4`.
pub fn quad_index_buffer(device: &wgpu::Device, sprites: u32) -> wgpu::Buffer {
    use wgpu::util::DeviceExt;
    let indices: Vec<u32> = (0..sprites.max(1))
        .flat_map(|q| {
            let b = q * 4;
            [b, b + 2, b + 1, b + 1, b + 2, b + 3]
        })
        .collect();
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("sky.quad_indices"),
        contents: bytemuck::cast_slice(&indices),
        usage: wgpu::BufferUsages::INDEX,
    })
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::clouds::CloudTypes;
    use crate::clouds::storm::{cell_cloud, part_in_block};
    use crate::render::impostor::{ImpostorSettings, is_far};
    use crate::weather::storms::StormCell;
    use crate::weather::{BlockIndex, BlockWeather, CloudType};

    /// A storm cell's part stands from its base to its anvil: its middle is more than 10,000
    /// ft above a camera at its base's height, yet the cell 40 km off spans that height and
    /// goes in the impostor ring (judged by its middle, every block of a field of storms stayed
    /// a sprite out to the view radius: 295,000 sprites drawn in the storm bench). A camera far
    /// above its top still keeps it out.
    #[test]
    fn a_block_spanning_the_camera_height_goes_in_the_ring() {
        let types = CloudTypes::builtin();
        let cell = StormCell {
            key: 3,
            centre_m: [2_000.0, 2_000.0],
            base_width_m: 10_000.0,
            base_ft_agl: 3_000.0,
            top_ft_msl: 38_000.0,
            ground_m_msl: 0.0,
            anvil_width_m: 30_000.0,
            anvil_offset_m: [10_000.0, 0.0],
            anvil_thickness_m: 2_500.0,
            turrets: 4,
            wind_aloft_m_s: [20.0, 0.0],
            thunder: 0,
            precipitation: 0.0,
            cloud_type: CloudType::Cumulonimbus,
        };
        let whole = cell_cloud(
            &cell,
            types.get(CloudType::Cumulonimbus),
            &BlockWeather::default(),
        );
        let part = part_in_block(&whole, BlockIndex::new(0, 0), 0).expect("the cell's middle");
        let sky = SkyCloud::from(&part);
        let block = SkyBlock {
            id: 1,
            centre_m: sky.centre_m,
            clouds: vec![sky],
        };
        let r = Resident::new(block, BlockMotion::default());
        let s = ImpostorSettings::default();
        let camera = DVec3::new(2_000.0, -38_000.0, 1_000.0);
        assert!(r.centre_m().z - camera.z > s.max_height_difference_ft * 0.3048);
        assert!(!is_far(r.centre_m(), camera, camera, &s));
        assert!(is_far(r.nearest_height_m(camera.z), camera, camera, &s));
        let above = DVec3::new(camera.x, camera.y, 11_583.0 + 4_000.0);
        assert!(!is_far(r.nearest_height_m(above.z), above, above, &s));
    }
}
