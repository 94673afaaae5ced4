//! GPU time of each of the sky's passes: a profiling aid, off by default
//! ([`super::Sky::set_pass_timing`]), for devices with timestamp queries inside encoders.
//! [`super::Sky::record`] writes a timestamp between its groups of passes, resolves them into a
//! buffer of its own and copies them out; [`super::Sky::pass_times`] waits for the frame and
//! reads them. While timing, the far field, the impostor ring and the sprites go in passes of
//! their own, two pass boundaries more than an untimed frame has. `skycast bench` reports them
//! per frame.
//! [`Timestamps`] (a query set, resolved and read back) also times the demo host's frames.

/// Timestamps of one frame: its start, after the compute passes, after the background or the
/// downsample, after the far field, after the ring, after the sprites, after the composite.
pub(super) const STAMPS: u32 = 7;

/// GPU milliseconds of one recorded frame's sky passes, by group.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PassTimes {
    /// The compute passes before the drawing: the patch of changed sprite orders and the corner
    /// build of the view's first chunk (of 32,768 sprites; the corners of a larger view's later
    /// chunks are built between their draws, in [`Self::sprites_ms`]).
    pub build_ms: f64,
    /// At full resolution the sky background; below it the farthest-depth downsample.
    pub background_ms: f64,
    /// The far field: the clouds from the hand-over band to the horizon
    /// ([`crate::render::far_field`]); 0 when it is off or has no map yet.
    pub far_field_ms: f64,
    /// The impostor ring's full-screen pass, with the distant storm cells drawn behind it.
    pub ring_ms: f64,
    /// The sprites (with the corner builds of a large view's chunks after the first) and the
    /// in-cloud fog.
    pub sprites_ms: f64,
    /// Below full resolution the composite over the host's colour (with the sky background);
    /// 0 at full resolution.
    pub composite_ms: f64,
    /// The cloud shadow map's draw (its corner builds and sprites), in the sky's own submission
    /// from `prepare`; 0 on frames that did not draw it.
    pub shadow_ms: f64,
}

impl PassTimes {
    /// All the sky's passes of the frame.
    pub fn total_ms(&self) -> f64 {
        self.build_ms
            + self.background_ms
            + self.far_field_ms
            + self.ring_ms
            + self.sprites_ms
            + self.composite_ms
            + self.shadow_ms
    }
}

/// Where the timestamps go: the stamp after each group of [`PassTimes`].
#[derive(Debug, Clone, Copy)]
pub(super) enum Stamp {
    Start = 0,
    Build = 1,
    Background = 2,
    FarField = 3,
    Ring = 4,
    Sprites = 5,
    Composite = 6,
}

/// Timestamps written between passes into a query set of their own, resolved and read back
/// (the sky's pass timer, and the demo host's frame timer).
pub struct Timestamps {
    queries: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    read: wgpu::Buffer,
    count: u32,
    period_ns: f64,
    /// Whether they were resolved since they were made.
    resolved: std::cell::Cell<bool>,
}

impl Timestamps {
    /// The device's features needed: timestamps, written between passes.
    pub const FEATURES: wgpu::Features =
        wgpu::Features::TIMESTAMP_QUERY.union(wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS);

    /// `count` timestamps on `device`; `None` where it lacks [`Self::FEATURES`].
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        label: &str,
        count: u32,
    ) -> Option<Self> {
        if !device.features().contains(Self::FEATURES) {
            return None;
        }
        let bytes = count as u64 * 8;
        // One query more than asked for: the one `write` writes after each (see there).
        let queries = count + 1;
        let buffer = |usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes,
                usage,
                mapped_at_creation: false,
            })
        };
        Some(Self {
            queries: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some(label),
                ty: wgpu::QueryType::Timestamp,
                count: queries,
            }),
            resolve: buffer(wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC),
            read: buffer(wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ),
            count,
            period_ns: queue.get_timestamp_period() as f64,
            resolved: std::cell::Cell::new(false),
        })
    }

    /// Writes timestamp `index` (between passes), then the spare query after the timer's own,
    /// which is never read: it only makes a software rasteriser take `index` before the work
    /// that follows. Lavapipe writes a timestamp when its rasteriser threads reach it, and
    /// hands them the commands before it only at the next timestamp or pass, while it runs a
    /// compute dispatch at once on its command thread: compute work recorded after a lone
    /// timestamp (the sprites' corner build after the sky's first one) was counted before it (in
    /// the host's ground-to-sky gap, not in the sky's build). A real GPU orders them anyway.
    pub fn write(&self, encoder: &mut wgpu::CommandEncoder, index: u32) {
        encoder.write_timestamp(&self.queries, index);
        encoder.write_timestamp(&self.queries, self.count);
    }

    /// Resolves them all and copies them where [`Self::read_ms`] finds them (at the end of the
    /// frame's last encoder).
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.resolve_query_set(&self.queries, 0..self.count, &self.resolve, 0);
        encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.read, 0, self.count as u64 * 8);
        self.resolved.set(true);
    }

    /// The last submitted frame's timestamps in milliseconds after the first (waits for the
    /// device); `None` before the first resolve or if they cannot be read.
    pub fn read_ms(&self, device: &wgpu::Device) -> Option<Vec<f64>> {
        if !self.resolved.get() {
            return None;
        }
        self.read.map_async(wgpu::MapMode::Read, .., |_| {});
        let waited = device.poll(wgpu::PollType::wait_indefinitely());
        let ticks: Option<Vec<u64>> = waited.ok().and_then(|_| {
            let view = self.read.get_mapped_range(..).ok()?;
            Some(
                view.chunks_exact(8)
                    .map(|b| u64::from_le_bytes(b.try_into().unwrap_or([0; 8])))
                    .collect(),
            )
        });
        // Unmapped whatever happened: the next frame copies into it.
        self.read.unmap();
        let ticks = ticks?;
        let first = *ticks.first()?;
        Some(
            ticks
                .iter()
                .map(|&t| t.saturating_sub(first) as f64 * self.period_ns / 1.0e6)
                .collect(),
        )
    }
}

/// The groups' times from the frame's stamps (milliseconds after the first, as
/// [`Timestamps::read_ms`] gives them).
pub(super) fn pass_times(stamps_ms: &[f64]) -> Option<PassTimes> {
    let at = |s: Stamp| stamps_ms.get(s as usize).copied();
    let ms = |a: Stamp, b: Stamp| Some((at(b)? - at(a)?).max(0.0));
    Some(PassTimes {
        build_ms: ms(Stamp::Start, Stamp::Build)?,
        background_ms: ms(Stamp::Build, Stamp::Background)?,
        far_field_ms: ms(Stamp::Background, Stamp::FarField)?,
        ring_ms: ms(Stamp::FarField, Stamp::Ring)?,
        sprites_ms: ms(Stamp::Ring, Stamp::Sprites)?,
        composite_ms: ms(Stamp::Sprites, Stamp::Composite)?,
        shadow_ms: 0.0,
    })
}
