//! The sky's controls between frames: what a host or a tool switches (the shading model, the
//! lifecycle, the sprite budget, the ring, the vertex cache, the far field, the shadows, pass
//! timing), the costs a host hands in for the next frame's stats, and what tools read back
//! (corners, pass times, the shadow map, the clouds' distance). A frame only reads what these
//! set.

use super::Sky;
use crate::clouds::LifecycleConfig;
use crate::render::RenderError;
use crate::render::gpu_types::GpuSpriteVertex;
use crate::render::pass_timing::STAMPS;
use crate::render::settings::RenderSettings;
use crate::render::sprites::build::chunks;
use crate::render::sprites::draw_list::Locks;
use crate::render::sprites::resident::ResidentSet;
use crate::render::stats::Spent;
use crate::render::targets::HostTargets;
use crate::render::view::ViewId;

impl Sky {
    /// Switches the cloud shading model (`[shading] model` of the time-of-day table). Switched
    /// to Harris and Lastra's, the clouds held get a provisional light at the next
    /// [`Self::prepare`] and their own within the model's budget of sprites a frame.
    pub fn set_shading_model(&mut self, model: crate::shading::ShadingModel) {
        self.time_of_day.shading.model = model;
    }

    /// The cloud shading model in use.
    pub fn shading_model(&self) -> crate::shading::ShadingModel {
        self.time_of_day.shading.model
    }

    /// How clouds form and dissipate (the clouds stage's `[lifecycle]`): which sprites of a
    /// forming or dissipating block show at a given progress.
    pub fn set_lifecycle(&mut self, lifecycle: LifecycleConfig) {
        self.lifecycle = lifecycle;
    }

    /// Caps the GPU memory of the sprites (records, orders, quad indices) at `bytes` (0: only
    /// the device's limits). Past it the farthest blocks are left out and counted in
    /// [`FrameStats::blocks_left_out`](crate::render::FrameStats::blocks_left_out). Every block is uploaded again.
    pub fn set_sprite_budget_bytes(&mut self, bytes: u64) {
        let mut old = ResidentSet::new(&self.device, bytes);
        std::mem::swap(&mut old, &mut self.sprites.resident);
        self.sprites.resident.set_drift(&old.drift_m());
        for (_, r) in old.blocks {
            let motion = r.motion();
            self.sprites.resident.insert(r.block, motion);
        }
        for view in &mut self.views {
            view.locks = Locks::default();
        }
    }

    /// Counts what the host's cloud field work for this frame `spent` (time it with a
    /// [`Stopwatch`](crate::render::Stopwatch), or a [`crate::render::SkyUpdate`]'s `field_cpu`) into the next prepared frame's
    /// [`FrameStats::field_us`](crate::render::FrameStats::field_us) and its thread figure: for a host that drives the sky itself
    /// ([`crate::SkySystem::update`] adds its own to the stats it returns).
    pub fn add_field_cpu(&mut self, spent: Spent) {
        self.field += spent;
    }

    /// Counts the wall-clock microseconds the host's work on the far field's map took this frame
    /// (sampling the weather into its rows, [`Self::set_far_map`]) into the next prepared
    /// frame's [`FrameStats::far_field_us`](crate::render::FrameStats::far_field_us). They are part of the field's time too: count that
    /// span with [`Self::add_field_cpu`] as well.
    pub fn add_far_field_us(&mut self, us: u64) {
        self.far_field_us += us;
    }

    /// The corners of the last prepared frame's sprites, four per sprite in drawing order, as
    /// the build pass makes them for the draw (position relative to the camera, colour, drawn or
    /// not): for tests and tools. Runs the frame's patch and build passes and waits.
    pub fn read_back_corners(
        &self,
        queue: &wgpu::Queue,
    ) -> Result<Vec<crate::render::SpriteCorner>, RenderError> {
        let main = &self.views[0];
        let mut encoder = self.device.create_command_encoder(&Default::default());
        self.sprites.scatter.record(&mut encoder);
        let read = crate::render::readback::read_buffer(&self.device, main.sprites_to_draw);
        let corner_bytes = 4 * std::mem::size_of::<GpuSpriteVertex>() as u64;
        if let Some(view_group) = main.view.group() {
            for (chunk, first, sprites) in chunks(main.sprites_to_draw) {
                (self.sprites).record_build(&mut encoder, view_group, (chunk, sprites));
                encoder.copy_buffer_to_buffer(
                    self.sprites.build.vertices(),
                    0,
                    &read,
                    first as u64 * corner_bytes,
                    sprites as u64 * corner_bytes,
                );
            }
        }
        crate::render::readback::read_corners(
            &self.device,
            queue,
            encoder,
            &read,
            main.sprites_to_draw,
        )
    }

    /// Times each group of the sky's passes on the GPU from the next [`Self::record`] on (a
    /// profiling aid: the far field, the ring and the sprites then go in passes of their own),
    /// or stops.
    /// Returns whether timing is on: the device needs timestamp queries inside encoders
    /// (`wgpu::Features::TIMESTAMP_QUERY | TIMESTAMP_QUERY_INSIDE_ENCODERS`).
    pub fn set_pass_timing(&mut self, on: bool) -> bool {
        self.pass_timer = if on {
            crate::render::Timestamps::new(&self.device, &self.queue, "sky.pass_times", STAMPS)
        } else {
            None
        };
        self.shadows
            .set_timing(&self.queue, self.pass_timer.is_some());
        self.pass_timer.is_some()
    }

    /// Times on the GPU, from the next [`Self::prepare`] on, the submission a prepare makes of
    /// its own (the cloud shadow map's draw, with the patch of changed orders it reads), from
    /// its first command to its last, or stops. Returns whether timing is on (the device needs
    /// [`crate::render::Timestamps::FEATURES`]). A host that times its frames adds
    /// [`Self::prepare_gpu_ms`] to the span of [`Self::record`]'s passes in its encoder: the
    /// sky's GPU time. Timestamps around the whole prepare would also count the CPU's prepare
    /// before the submission, through which the device idles.
    pub fn set_prepare_timing(&mut self, on: bool) -> bool {
        self.prepare_timer = if on {
            crate::render::Timestamps::new(&self.device, &self.queue, "sky.prepare_time", 2)
        } else {
            None
        };
        self.prepare_timer.is_some()
    }

    /// GPU milliseconds of the submission the last [`Self::prepare`] made of its own (0 when
    /// it made none), once submitted; `None` while [`Self::set_prepare_timing`] is off or if
    /// the time cannot be read. Waits for the device.
    pub fn prepare_gpu_ms(&self) -> Option<f64> {
        let timer = self.prepare_timer.as_ref()?;
        if !self.prepare_submitted {
            return Some(0.0);
        }
        timer.read_ms(&self.device)?.get(1).copied()
    }

    /// GPU time of each group of passes of the last recorded frame, once it was submitted:
    /// waits for the device. `None` while pass timing is off or if the times cannot be read.
    pub fn pass_times(&self) -> Option<crate::render::PassTimes> {
        let times = crate::render::pass_timing::pass_times(
            &self.pass_timer.as_ref()?.read_ms(&self.device)?,
        );
        let shadow_ms = self.shadows.last_ms().unwrap_or(0.0);
        times.map(|t| crate::render::PassTimes { shadow_ms, ..t })
    }

    /// The clouds' shadow map of the last prepared frame and the matrix a host looks it up with
    /// ([`crate::render::CloudShadowMap`]): the host multiplies its ground's direct sunlight by
    /// `exp(-tau)`. Take it every frame (after [`Self::prepare`]): the lookup follows the camera
    /// and the clouds' drift, and the texture is replaced when the shadows are switched.
    pub fn cloud_shadows(&self) -> crate::render::CloudShadowMap<'_> {
        self.shadows.map()
    }

    /// Switches the cloud shadows on (drawn from the next [`Self::prepare`]) or off (the map a
    /// single texel of open sun).
    pub fn set_cloud_shadows(&mut self, on: bool) {
        self.shadows.set_enabled(&self.queue, on);
        self.settings.cloud_shadows.enabled = on;
    }

    /// Draws the cloud shadow map at the next [`Self::prepare`] whatever changed (it is drawn
    /// again by itself when the camera has gone far, the sun turned, a block near went (one
    /// that arrives is added to it), or, while clouds form or dissipate, after
    /// `update_interval_s`).
    pub fn redraw_cloud_shadows(&mut self) {
        self.shadows.redraw();
    }

    /// The shadow map's optical depth read back (tests and tools); waits for the device.
    pub fn read_back_cloud_shadows(
        &self,
        queue: &wgpu::Queue,
    ) -> Result<crate::render::ShadowImage, RenderError> {
        self.shadows.read_back(queue)
    }

    /// Time the last [`Self::record`] spent.
    pub fn last_record(&self) -> Spent {
        self.views[0].record.get()
    }

    /// Time the last [`Self::record_view`] of `id` spent (0 for an unknown view).
    pub fn view_record(&self, id: ViewId) -> Spent {
        self.views
            .get(id.0)
            .map_or_else(Spent::default, |v| v.record.get())
    }

    /// The host's targets the sky was made for.
    pub fn targets(&self) -> &HostTargets {
        &self.targets
    }

    /// The settings the sky was made with.
    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    /// Turns the far-cloud impostor ring off (every block drawn as sprites) or back on (built
    /// afresh). Returns false and changes nothing when turning it on in a sky made with
    /// `impostors.enabled = false`: the ring's textures are made at start-up only.
    pub fn set_impostors(&mut self, enabled: bool) -> bool {
        let mut switched = true;
        for view in &mut self.views {
            switched &= view.ring.set_enabled(enabled);
        }
        if switched {
            self.settings.impostors.enabled = enabled;
        }
        switched
    }

    /// Turns the vertex cache on or off (off: every cloud recomputed every frame).
    pub fn set_vertex_cache(&mut self, enabled: bool) {
        self.settings.vertex_cache.enabled = enabled;
    }

    /// Hands the far field a new cloud map ([`crate::clouds::far_map::FarMapFeed`] makes them
    /// from the weather field as the camera moves); uploaded now. The first map fades in over
    /// `fade_in_s` when given (as arriving clouds do); a map of another weather
    /// ([`crate::clouds::far_map::FarMap::weather_epoch`]) crossfades from the one shown over
    /// the lifecycle's formation time, as the blocks' clouds form and dissipate; a map moved
    /// with the camera shows at once (its cells keep their weather).
    pub fn set_far_map(
        &mut self,
        queue: &wgpu::Queue,
        map: &crate::clouds::far_map::FarMap,
        fade_in_s: Option<f64>,
    ) {
        let crossfade_s = f64::from(self.lifecycle.formation_s);
        self.far_field.set_map(
            &self.device,
            queue,
            map,
            (self.elapsed_s, fade_in_s, crossfade_s),
        );
    }

    /// Where the far field takes over from the sprites and the ring while it is drawn: the band
    /// over which they fade out and it fades in (metres from the camera), and the distant
    /// blocks fade in ([`Self::insert_distant_block`]). `None` while it is not drawn.
    pub fn far_field_hand_over_m(&self) -> Option<(f32, f32)> {
        self.far_field.hand_over_m()
    }

    /// Switches the far field on or off at run time (for comparisons; the sprites and the ring
    /// fade out as before without it).
    pub fn set_far_field_enabled(&mut self, enabled: bool) {
        self.far_field.set_enabled(enabled);
    }

    /// The far field's settings (the map's size, the hand-over band).
    pub fn far_field_settings(&self) -> crate::render::far_field::FarFieldSettings {
        *self.far_field.settings()
    }

    /// The clouds' distance in the main view's last recorded frame (metres from the camera
    /// plane, weighted by what each cloud shows; 0 where none shows) at the cloud target's
    /// resolution: width, height and the texels row by row. `None` with the clouds drawn at full
    /// resolution (no cloud target). Waits for the GPU: for tools and tests.
    pub fn read_cloud_distance_m(&self, queue: &wgpu::Queue) -> Option<(u32, u32, Vec<f32>)> {
        self.views[0].clouds.read_distance_m(&self.device, queue)
    }
}
