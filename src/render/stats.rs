//! What a frame of the sky cost and drew ([`FrameStats`]), the two clocks its costs are read
//! on ([`Stopwatch`], [`Spent`]), and the light it is shaded with ([`Lighting`]). Plain data.

use std::time::Instant;

use glam::Vec3;

use crate::shading::{
    DirectionalMapping, ForwardScattering, HarrisLastra, ShadingModel, TimeOfDay,
};

/// What one frame's update did and cost, returned by [`crate::SkySystem::update`] and
/// [`crate::Sky::prepare`]: a host logs it or shows it in an overlay (`skycast fly` writes it to
/// `frames.csv`, one row a frame).
///
/// ```
/// use skycast::FrameStats;
///
/// let mut stats = FrameStats::default(); // a host reads what `update` returns
/// (stats.field_us, stats.cpu_update_us, stats.record_us) = (23, 338, 31);
/// assert_eq!(stats.sky_cpu_us(), 392); // what the sky cost the frame thread
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[non_exhaustive]
pub struct FrameStats {
    /// Sprites drawn as sprites this frame (the impostors' not counted).
    pub sprites_drawn: u32,
    /// Clouds within the draw distance.
    pub clouds_drawn: u32,
    /// Clouds whose back-to-front sprite order was recomputed this frame (Wang 6.1's cache).
    pub clouds_recomputed: u32,
    /// Sprites of those clouds (the sky camera's sorting work of the frame).
    pub sprites_recomputed: u32,
    /// Sprites of far clouds sorted this frame for the impostor ring's next impostor (from the
    /// ring centre). With `sprites_recomputed` within `[vertex_cache]
    /// max_sorted_sprites_per_frame`, except on the frame that builds a first ring (the sky's
    /// first, or the ring switched on), which sorts it whole.
    pub ring_sprites_sorted: u32,
    /// Far sprites whose orders an impostor's view wrote again this frame into the ring's order
    /// buffer without sorting them: clouds whose blocks were placed again since their sort (the
    /// resident buffers packed), or too large to sort (their own order). Mostly 0: a sorted
    /// order is written once, by its sort.
    pub ring_orders_rewritten: u32,
    /// Fraction of drawn clouds served from the cache, 0..=1 (1 when nothing was drawn).
    pub cache_hit_rate: f32,
    /// CPU time of [`crate::render::Sky::prepare`] (less `gpu_wait_us`) plus the block changes
    /// handed to the sky since the last one (inserts and removals, by hand or in a
    /// [`crate::render::Sky::apply`] that brings or takes blocks), microseconds.
    pub cpu_update_us: u64,
    /// Time [`crate::render::Sky::prepare`] spent waiting for the device, microseconds: the
    /// submit that flushes the writes of a frame that was prepared and never recorded, which a
    /// busy device can hold (lavapipe waits in it for the submission before to finish). Not part
    /// of `cpu_update_us` or [`Self::sky_cpu_us`]; 0 on frames after a recorded one.
    pub gpu_wait_us: u64,
    /// CPU time the host's cloud field spent on the frame thread for this frame (the weather
    /// step, the clouds advanced, drift, lifecycle, the blocks looked through for the sky; not
    /// the sky's applying them, which is `cpu_update_us`), microseconds: a
    /// [`crate::render::SkyUpdate`]'s `field_cpu` and the host's own, as
    /// [`crate::SkySystem::update`] adds them ([`Self::add_field`]), or as reported to the sky
    /// with [`crate::render::Sky::add_field_cpu`].
    pub field_us: u64,
    /// The host's weather step this frame (polling a watched file, switching in a new field;
    /// never reading one), microseconds; part of `field_us`.
    pub weather_us: u64,
    /// CPU time of the last [`crate::render::Sky::record`], microseconds. Through
    /// [`crate::SkySystem::update`] it is the previous frame's recording (this frame's has not
    /// happened when `update` returns); a host driving [`crate::render::Sky`] itself that
    /// records after it prepares fills in this frame's, as the demo host does.
    pub record_us: u64,
    /// Bytes written to the GPU by this frame's update (new blocks, changed sprite orders, the
    /// draw list, uniforms, impostor builds).
    pub upload_bytes: u64,
    /// Bytes of the GPU buffers holding the sprites, clouds, orders and draw list.
    pub sprite_gpu_bytes: u64,
    /// Blocks the sky holds but left out of the GPU buffers (the farthest first) because the
    /// device's buffer limit or the sky's budget is reached.
    pub blocks_left_out: u32,
    /// How far inside a cloud the camera is, 0..=1.
    pub in_cloud: f32,
    /// Impostors of the far-cloud ring rendered this frame (Wang 6.2), 0..=8.
    pub impostors_rebuilt: u32,
    /// Blocks drawn as sprites (inside the ring, or beyond the 10,000 ft rule).
    pub blocks_near: u32,
    /// Blocks drawn into the impostors of the displayed ring.
    pub blocks_far: u32,
    /// Weight of the new ring while crossfading from the old one, 0..=1 (0 when not fading).
    pub crossfade_weight: f32,
    /// Bytes of the ring's GPU textures and buffers.
    pub ring_gpu_bytes: u64,
    /// CPU time of the far field on the frame thread, microseconds on the wall clock: its map's
    /// rows sampled and uploaded ([`crate::render::Sky::add_far_field_us`], part of `field_us`)
    /// and its uniform and band of elevations written (part of `cpu_update_us`).
    pub far_field_us: u64,
    /// Bytes of the far field's map and uniform on the GPU (as
    /// [`SkyMemory::far_field_bytes`]).
    pub far_field_gpu_bytes: u64,
    /// Resolution of the clouds' off-screen target as a fraction of the host's (1: drawn
    /// straight into the host's colour; `[clouds] resolution_scale`).
    pub cloud_scale: f32,
    /// Bytes of the off-screen cloud target's textures (colour, distance, farthest distance) at
    /// the last recorded frame size; 0 at scale 1.
    pub cloud_target_bytes: u64,
    /// Sprites whose Harris and Lastra light was computed this frame (blocks written, or relit
    /// after the sun turned); 0 under Wang's model.
    pub sprites_lit: u32,
    /// CPU time of that light, microseconds (part of `cpu_update_us`).
    pub light_us: u64,
    /// Bytes of the cloud shadow map's texture and buffers (`[cloud_shadows]`; a texel while
    /// switched off).
    pub shadow_gpu_bytes: u64,
    /// Whether the cloud shadow map was drawn this frame (else its last drawing, moved with the
    /// clouds' drift, is looked up).
    pub shadow_redrawn: bool,
    /// Sprites drawn into the shadow map this frame (0 when it was not drawn): a whole drawing,
    /// or a scroll's strips, the rectangles drawn again and the blocks added.
    pub shadow_sprites: u32,
    /// Texels of the shadow map cleared and drawn again this frame: the whole map, or a
    /// scroll's strips and the rectangles of blocks gone or changing (blocks added to the map
    /// add over it and are not counted; a scroll's copy is not).
    pub shadow_texels: u64,
    /// CPU time of the cloud shadow map's prepare on the frame thread, microseconds on the wall
    /// clock (part of `cpu_update_us`): what to draw decided, and for a drawing its draw list,
    /// cloud lists and uniform written. The submission of a drawing is apart
    /// (`gpu_wait_us`).
    pub shadow_us: u64,
    /// CPU time of the host's air-data queries this frame (`SkySystem::air_at`, lines of
    /// sight), microseconds: set by the host that asks (`skycast fly` does), 0 otherwise.
    pub air_us: u64,
    /// The same four sections (`field_us`, `cpu_update_us`, `record_us`, `air_us`) on the frame
    /// thread's own CPU clock: what the sky computed, without the time the system gave the
    /// thread's core to another thread meanwhile (which the wall-clock figures hold).
    pub thread: ThreadCpu,
}

impl FrameStats {
    /// All the time the sky held the frame thread: the cloud field, the update, the recording
    /// and the host's air-data queries, microseconds on the wall clock (so with any time slice
    /// another thread took from it meanwhile; [`Self::sky_thread_us`] is without); waits for
    /// the device (`gpu_wait_us`) are not in it.
    pub fn sky_cpu_us(&self) -> u64 {
        self.field_us + self.cpu_update_us + self.record_us + self.air_us
    }

    /// The frame thread's own CPU time in the same sections as [`Self::sky_cpu_us`],
    /// microseconds: the sky's computing alone. Equal to it but for preemption (and clock
    /// rounding); 0 where the system has no per-thread clock.
    pub fn sky_thread_us(&self) -> u64 {
        self.thread.field_us + self.thread.update_us + self.thread.record_us + self.thread.air_us
    }

    /// Sets `record_us` and its thread figure from what a recording spent
    /// ([`crate::render::Sky::last_record`]).
    pub fn set_record(&mut self, spent: Spent) {
        self.record_us = spent.wall_us;
        self.thread.record_us = spent.thread_us;
    }

    /// Adds what the host's cloud field `spent` on this frame to `field_us` and its thread
    /// figure (a [`crate::render::SkyUpdate`]'s `field_cpu` and the host's weather step).
    pub fn add_field(&mut self, spent: Spent) {
        self.field_us += spent.wall_us;
        self.thread.field_us += spent.thread_us;
    }

    /// Sets `air_us` and its thread figure from what the host's air-data queries spent.
    pub fn set_air(&mut self, spent: Spent) {
        self.air_us = spent.wall_us;
        self.thread.air_us = spent.thread_us;
    }
}

/// [`FrameStats`]' CPU sections on the frame thread's own CPU clock
/// (`CLOCK_THREAD_CPUTIME_ID`), microseconds; all 0 where the system has none (only Linux and
/// Android are read). A section that is a span less a part counted elsewhere (the field less the
/// sky's own work inside it, which the update counts; the update less its GPU waits) can show
/// more here than on the wall clock when the core was taken during that part; the sum of the
/// field and the update cannot, but for the waits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ThreadCpu {
    /// Of [`FrameStats::field_us`].
    pub field_us: u64,
    /// Of [`FrameStats::cpu_update_us`].
    pub update_us: u64,
    /// Of [`FrameStats::record_us`].
    pub record_us: u64,
    /// Of [`FrameStats::air_us`].
    pub air_us: u64,
}

/// Time spent on a span of the frame thread, read on two clocks, microseconds.
///
/// ```
/// use skycast::render::Stopwatch;
///
/// let watch = Stopwatch::start();
/// let sum: u64 = (0..100_000u64).map(|k| k * k % 7).sum();
/// let spent = watch.spent();
/// assert!(sum > 0 && spent.thread_us <= spent.wall_us); // a thread computes only while it runs
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Spent {
    /// On the wall clock: what the frame waited, with any time slice another thread took.
    pub wall_us: u64,
    /// On the thread's own CPU clock: what the thread computed (0 where there is no such
    /// clock).
    pub thread_us: u64,
}

impl Spent {
    /// `self` less `other` on both clocks, 0 at least.
    pub fn saturating_sub(self, other: Spent) -> Spent {
        Spent {
            wall_us: self.wall_us.saturating_sub(other.wall_us),
            thread_us: self.thread_us.saturating_sub(other.thread_us),
        }
    }
}

impl std::ops::Add for Spent {
    type Output = Spent;
    fn add(self, other: Spent) -> Spent {
        Spent {
            wall_us: self.wall_us + other.wall_us,
            thread_us: self.thread_us + other.thread_us,
        }
    }
}

impl std::ops::AddAssign for Spent {
    fn add_assign(&mut self, other: Spent) {
        *self = *self + other;
    }
}

/// The start of a span of the calling thread's work on both clocks of [`Spent`]; read it with
/// [`Self::spent`] on the same thread.
#[derive(Debug, Clone, Copy)]
pub struct Stopwatch {
    wall: Instant,
    thread_ns: u64,
}

impl Stopwatch {
    /// Starts now (two clocks read).
    pub fn start() -> Self {
        Self {
            wall: Instant::now(),
            thread_ns: thread_cpu_ns(),
        }
    }

    /// The wall clock's part of [`Self::spent`] alone (without reading the thread's clock,
    /// which costs about a microsecond).
    pub fn wall_us(&self) -> u64 {
        self.wall.elapsed().as_micros() as u64
    }

    /// What was spent since [`Self::start`] (two clocks read).
    pub fn spent(&self) -> Spent {
        // The thread's span lies inside the wall clock's (read after it at the start, before
        // it here), so it is never the longer one.
        let thread_ns = thread_cpu_ns().saturating_sub(self.thread_ns);
        Spent {
            wall_us: self.wall.elapsed().as_micros() as u64,
            thread_us: thread_ns / 1_000,
        }
    }
}

/// The calling thread's CPU time so far, nanoseconds (a system call of well under a
/// microsecond).
#[cfg(any(target_os = "linux", target_os = "android"))]
fn thread_cpu_ns() -> u64 {
    let t = rustix::time::clock_gettime(rustix::time::ClockId::ThreadCPUTime);
    t.tv_sec as u64 * 1_000_000_000 + t.tv_nsec as u64
}

/// No per-thread CPU clock read here: the thread figures stay 0.
#[cfg(not(any(target_os = "linux", target_os = "android")))]
fn thread_cpu_ns() -> u64 {
    0
}

/// The light a frame is shaded with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lighting {
    /// Unit vector towards the sun (east, north, up).
    pub sun_dir: Vec3,
    /// Time-of-day light.
    pub time_of_day: TimeOfDay,
    /// Wang's Cmin / Cmedian / Cmax.
    pub mapping: DirectionalMapping,
    /// Light scattered forward towards the eye (the silver lining).
    pub forward: ForwardScattering,
    /// Which shading model the clouds use.
    pub model: ShadingModel,
    /// The Harris and Lastra model's constants.
    pub harris_lastra: HarrisLastra,
}

/// Everything the sky holds on the GPU, and the blocks and slots behind it: what a long flight
/// watches for growth (`tests/soak.rs`). Bytes are the sizes the buffers and textures were
/// created with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub struct SkyMemory {
    /// The resident sprite, cloud, light, order and cloud-list buffers.
    pub resident_bytes: u64,
    /// What a frame draws with: the frame uniform, the camera view's uniform and draw list, the
    /// build pass's corners and chunk uniforms, the quad indices and the order patch.
    pub draw_bytes: u64,
    /// The impostor ring's textures and buffers (0 with the ring off).
    pub ring_bytes: u64,
    /// The off-screen cloud target's textures at the last recorded frame size (0 at scale 1).
    pub cloud_target_bytes: u64,
    /// The cloud shadow map's texture and buffers (one for all views; a texel while off).
    pub shadow_bytes: u64,
    /// The sprite sheet texture, every mip level.
    pub sheet_bytes: u64,
    /// The far field's cloud map and uniform (0 with the far field off or no map yet).
    pub far_field_bytes: u64,
    /// Blocks (cloud generations) the sky holds.
    pub blocks: u32,
    /// Sprites of those blocks.
    pub sprites: u32,
    /// Sprite slots of the resident buffers, in all.
    pub sprite_slots: u32,
    /// Sprite slots in use (by blocks placed on the GPU).
    pub sprite_slots_used: u32,
    /// Cloud slots of the resident buffers, in all.
    pub cloud_slots: u32,
    /// Cloud slots in use.
    pub cloud_slots_used: u32,
}

impl SkyMemory {
    /// Bytes of every buffer and texture the sky holds.
    pub fn gpu_bytes(&self) -> u64 {
        self.resident_bytes
            + self.draw_bytes
            + self.ring_bytes
            + self.cloud_target_bytes
            + self.shadow_bytes
            + self.sheet_bytes
            + self.far_field_bytes
    }
}
