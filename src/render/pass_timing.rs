//! GPU time of each of the sky's passes: a profiling aid, off by default
//! ([`super::Sky::set_pass_timing`]), for devices with timestamp queries inside encoders.
//! [`super::Sky::record`] writes a timestamp between its groups of passes, resolves them into a
//! buffer of its own and copies them out; [`super::Sky::pass_times`] waits for the frame and
//! reads them. While timing, the impostor ring and the sprites go in passes of their own, one
//! pass boundary more than an untimed frame has. `skycast bench` reports them per frame.

/// Timestamps of one frame: its start, after the compute passes, after the background or the
/// downsample, after the ring, after the sprites, after the composite.
const STAMPS: u32 = 6;
const BYTES: u64 = STAMPS as u64 * 8;

/// GPU milliseconds of one recorded frame's sky passes, by group.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PassTimes {
    /// The compute passes before the drawing: the patch of changed sprite orders and the corner
    /// build (of the first chunk, when the view needs several).
    pub build_ms: f64,
    /// At full resolution the sky background; below it the farthest-depth downsample.
    pub background_ms: f64,
    /// The impostor ring's full-screen pass.
    pub ring_ms: f64,
    /// The sprites (with the corner builds of any later chunks) and the in-cloud fog.
    pub sprites_ms: f64,
    /// Below full resolution the composite over the host's colour (with the sky background);
    /// 0 at full resolution.
    pub composite_ms: f64,
}

impl PassTimes {
    /// All the sky's passes of the frame.
    pub fn total_ms(&self) -> f64 {
        self.build_ms + self.background_ms + self.ring_ms + self.sprites_ms + self.composite_ms
    }
}

/// Where the timestamps go: the stamp after each group of [`PassTimes`].
#[derive(Debug, Clone, Copy)]
pub(super) enum Stamp {
    Start = 0,
    Build = 1,
    Background = 2,
    Ring = 3,
    Sprites = 4,
    Composite = 5,
}

/// The query set and buffers of the timestamps.
pub(super) struct PassTimer {
    queries: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    read: wgpu::Buffer,
    period_ns: f64,
    /// Whether a frame's timestamps were resolved since the timer was made.
    resolved: std::cell::Cell<bool>,
}

impl PassTimer {
    /// The device's features needed: timestamps, written between passes.
    pub const FEATURES: wgpu::Features =
        wgpu::Features::TIMESTAMP_QUERY.union(wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS);

    /// A timer on `device`; `None` where it lacks [`Self::FEATURES`].
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Option<Self> {
        if !device.features().contains(Self::FEATURES) {
            return None;
        }
        let buffer = |label, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: BYTES,
                usage,
                mapped_at_creation: false,
            })
        };
        Some(Self {
            queries: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("sky.pass_times"),
                ty: wgpu::QueryType::Timestamp,
                count: STAMPS,
            }),
            resolve: buffer(
                "sky.pass_times_resolve",
                wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            ),
            read: buffer(
                "sky.pass_times_read",
                wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            ),
            period_ns: queue.get_timestamp_period() as f64,
            resolved: std::cell::Cell::new(false),
        })
    }

    /// Writes timestamp `stamp` (between passes).
    pub fn stamp(&self, encoder: &mut wgpu::CommandEncoder, stamp: Stamp) {
        encoder.write_timestamp(&self.queries, stamp as u32);
    }

    /// Resolves the frame's timestamps and copies them where [`Self::read`] finds them.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.resolve_query_set(&self.queries, 0..STAMPS, &self.resolve, 0);
        encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.read, 0, BYTES);
        self.resolved.set(true);
    }

    /// The last submitted frame's times (waits for the device); `None` before the first timed
    /// frame or if they cannot be read.
    pub fn read(&self, device: &wgpu::Device) -> Option<PassTimes> {
        if !self.resolved.get() {
            return None;
        }
        self.read.map_async(wgpu::MapMode::Read, .., |_| {});
        let waited = device.poll(wgpu::PollType::wait_indefinitely());
        let stamps: Option<Vec<u64>> = waited.ok().and_then(|_| {
            let view = self.read.get_mapped_range(..).ok()?;
            Some(
                view.chunks_exact(8)
                    .map(|b| u64::from_le_bytes(b.try_into().unwrap_or([0; 8])))
                    .collect(),
            )
        });
        // Unmapped whatever happened: the next frame copies into it.
        self.read.unmap();
        let t = stamps?;
        let ms = |a: Stamp, b: Stamp| {
            t[b as usize].saturating_sub(t[a as usize]) as f64 * self.period_ns / 1.0e6
        };
        Some(PassTimes {
            build_ms: ms(Stamp::Start, Stamp::Build),
            background_ms: ms(Stamp::Build, Stamp::Background),
            ring_ms: ms(Stamp::Background, Stamp::Ring),
            sprites_ms: ms(Stamp::Ring, Stamp::Sprites),
            composite_ms: ms(Stamp::Sprites, Stamp::Composite),
        })
    }
}
