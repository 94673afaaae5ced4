//! [`Sky`]: the sky's GPU side (the whole frame step around it is
//! [`SkySystem`](crate::SkySystem)'s). Created once with the host's device,
//! given clouds (uploaded to the GPU once per block), and each frame `prepare`d (CPU: sort blocks
//! and clouds, the cached sprite orders, the draw list; uniforms) and `record`ed into the host's
//! encoder. It draws into the host's colour target and reads the host's depth texture (never
//! writes it): the sky gradient and sun where the host drew nothing, the cloud sprites with soft
//! depth fades (Bahnassi), and in-cloud fog (Wang 7.1).
//!
//! The device needs 7 storage buffers per shader stage (WebGPU's default limit is 8) and compute
//! shaders. The host's depth texture needs `TEXTURE_BINDING` usage; it is read through the
//! host's own projection ([`SkyView`]) in the convention its [`HostTargets`] name (standard or
//! reversed Z, one sample or four). Where it also has `RENDER_ATTACHMENT` usage (a depth buffer
//! the host draws into) and no stencil, the full-screen passes that draw only where the host drew
//! nothing (the sky background, the cloud composite's sky) are also depth-tested against it as a
//! read-only attachment: a software rasteriser then shades only those pixels, while a shader's
//! own test runs the whole shader on every pixel.

use glam::Vec3;

use super::RenderError;
use super::gpu_types::{GpuFrame, GpuSpriteVertex};
use super::impostor::RingFrame;
use super::overhead_ease::OverheadEase;
use super::pass_timing::STAMPS;
use super::settings::RenderSettings;
use super::sprites::build::{CHUNK, SpriteBuild, chunks};
use super::sprites::draw_list::{Copies, Locks, main_view};
use super::sprites::resident::{ResidentSet, quad_index_buffer};
use super::sprites::scatter::Scatter;
use super::sprites::sprite_view::{self, ViewData, ViewLight};
use super::stats::{FrameStats, Lighting, Spent, Stopwatch};
use super::targets::{HostTargets, SkyView};
use super::view::{View, ViewId, ViewShared};
use crate::clouds::LifecycleConfig;
use crate::shading::{SunPosition, TimeOfDay, TimeOfDayTable};
use crate::weather::{BlockLayer, BlockWeather};

// What the sky does apart from conducting a frame, one file each.
mod blocks;
mod build;
mod light;
mod memory;
mod record;

/// The sheet lives in its own leaf module; its path under `sky` stays for hosts that name it.
pub use super::sprites::sheet::SpriteSheet;

/// What the sky is created with.
#[derive(Debug, Clone)]
pub struct SkyConfig {
    /// The host's colour and depth targets: formats, standard or reversed Z, samples.
    pub targets: HostTargets,
    /// Renderer settings (`config/render.toml`).
    pub settings: RenderSettings,
    /// Time-of-day table (`config/time_of_day.toml`).
    pub time_of_day: TimeOfDayTable,
    /// The sprite texture sheet.
    pub sheet: SpriteSheet,
}

impl SkyConfig {
    /// The shipped settings, time-of-day table and sprite sheet for `targets`: nothing read
    /// from files.
    pub fn new(targets: HostTargets) -> Self {
        Self {
            targets,
            settings: RenderSettings::default(),
            time_of_day: TimeOfDayTable::default(),
            sheet: SpriteSheet::generated(),
        }
    }
}

/// The sky subsystem: pipelines, the GPU-resident clouds, their sprite orders and the ring.
/// A host drives it directly only when it has its own weather and cloud handling (it hands the
/// sky blocks of clouds, the sun and its view); otherwise [`crate::SkySystem`] does all of that
/// around it.
pub struct Sky {
    device: wgpu::Device,
    settings: RenderSettings,
    time_of_day: TimeOfDayTable,
    lifecycle: LifecycleConfig,
    frame_layout: wgpu::BindGroupLayout,
    /// The layouts a view is made with (the impostor renders' group 0, the sheet's group).
    ring_frame_layout: wgpu::BindGroupLayout,
    sheet_layout: wgpu::BindGroupLayout,
    targets: HostTargets,
    sheet_group: wgpu::BindGroup,
    /// Bytes of the sheet texture (every mip level), for [`Self::memory`].
    sheet_bytes: u64,
    sky_pipeline: wgpu::RenderPipeline,
    /// The sky background kept by a depth test against the host's depth as a read-only
    /// attachment (in a pass of its own); `None` where the host's depth format has a stencil
    /// aspect.
    sky_tested_pipeline: Option<wgpu::RenderPipeline>,
    sprite_pipeline: wgpu::RenderPipeline,
    in_cloud_pipeline: wgpu::RenderPipeline,
    resident: ResidentSet,
    /// Quad indices for this many sprites (the most one draw needs so far).
    quads: (wgpu::Buffer, u32),
    scatter: Scatter,
    build: SpriteBuild,
    view_layout: wgpu::BindGroupLayout,
    /// Each camera's own state, [`ViewId::MAIN`] first: the blocks, weather and resident
    /// sprites above are shared by all.
    views: Vec<View>,
    /// The clouds beyond the ring, out to the horizon (one for all views: its map and uniform
    /// follow the camera of the last prepared view).
    far_field: super::far_field::FarField,
    elapsed_s: f64,
    /// CPU time of block changes since the last prepare, and the host's field time.
    pending: Spent,
    field: Spent,
    /// The far field's CPU time since the last prepare, wall clock ([`FrameStats::far_field_us`]).
    far_field_us: u64,
    /// Timestamps between the passes, while pass timing is on.
    pass_timer: Option<super::Timestamps>,
    /// Kept to make the pass timer.
    queue: wgpu::Queue,
    /// The time-of-day light of the last frame, clear sky: what the clouds are lit with.
    clear_light: TimeOfDay,
    /// The host's light: the clear sun (the shadow map dims it where clouds stop it, or
    /// nothing does with the shadows off) and the sky colours under the cover over the camera.
    seen_light: TimeOfDay,
    /// The mean share of the direct sun the cover over the camera lets through (1 - the share
    /// of the sky it hides): the sky's own sun glow, and for a host without the map.
    cover_transmittance: f32,
    /// The weather over the camera: its cloud layers and ground elevation, metres.
    overhead: (Vec<BlockLayer>, f32),
    /// The fog settings and the weather over the camera they read (visibility, obscuration).
    fog: (crate::shading::FogSettings, BlockWeather),
    /// The cover and visibility frames show, eased through a change of the weather in time.
    overhead_ease: OverheadEase,
    /// The clouds' shadow map for the host's ground (`shadow`): one for every view, as the
    /// sun is; the main view's prepare draws it.
    shadows: super::shadow::CloudShadows,
    /// The lightning flash lighting a cell now, if any.
    flash: Option<SkyFlash>,
}

/// A lightning flash lighting its cell from inside, as the sprites draw it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkyFlash {
    /// Its centre, metres east/north/up in the local frame.
    pub position_m: glam::DVec3,
    /// How far its light reaches (the Gaussian's 1/e distance), metres.
    pub reach_m: f32,
    /// The light it adds at its centre now, 0..=4 (fraction of white).
    pub light: f32,
}

const SKY_WGSL: &str = include_str!("../../shaders/sky.wgsl");
const SPRITES_WGSL: &str = include_str!("../../shaders/sprites.wgsl");
const IN_CLOUD_WGSL: &str = include_str!("../../shaders/in_cloud.wgsl");

impl Sky {
    /// Creates pipelines, the sheet texture and buffers on the host's device. The device is
    /// checked first ([`super::capabilities`]): one short of what the sky needs gets
    /// [`RenderError::Unsupported`] naming it, and anything the device still refuses while the
    /// sky is built is returned the same way, never wgpu's panic. Where the device cannot draw
    /// into R32Float textures the clouds draw at full resolution (a warning is logged).
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        mut config: SkyConfig,
    ) -> Result<Self, RenderError> {
        config.targets.validate()?;
        let capabilities = super::capabilities::check(device, &config.targets)?;
        let scale = &mut config.settings.clouds.resolution_scale;
        if !capabilities.r32float_renderable && *scale < 1.0 {
            log::warn!(
                "this device cannot draw into R32Float textures (the off-screen cloud target's farthest distance): the clouds are drawn at full resolution instead of {scale}"
            );
            *scale = 1.0;
        }
        let (sky, refused) =
            super::capabilities::refused(device, || Self::build(device, queue, config));
        match refused {
            Some(why) => Err(RenderError::Unsupported(why)),
            None => sky,
        }
    }

    /// Adds a view: another camera with its own targets (of the same formats and samples), its
    /// own draw list, impostor ring and off-screen cloud target; the blocks, the weather and
    /// the resident sprites stay shared. Prepare it with [`Self::prepare_view`] and record it
    /// with [`Self::record_view`]; several views record into one encoder. It costs
    /// [`Self::view_gpu_bytes`] of GPU memory.
    pub fn add_view(&mut self) -> ViewId {
        let view = View::new(
            &self.device,
            &self.queue,
            &ViewShared {
                targets: self.targets,
                settings: &self.settings,
                host_frame_layout: &self.frame_layout,
                ring_frame_layout: &self.ring_frame_layout,
                sheet_layout: &self.sheet_layout,
                view_layout: &self.view_layout,
            },
        );
        self.views.push(view);
        ViewId(self.views.len() - 1)
    }

    /// Whether the sky has this view.
    pub fn has_view(&self, id: ViewId) -> bool {
        id.0 < self.views.len()
    }

    /// The views the sky has, [`ViewId::MAIN`] included.
    pub fn view_count(&self) -> usize {
        self.views.len()
    }

    /// Bytes of one view's own GPU buffers and textures (frame uniform, draw list and locks,
    /// impostor ring, off-screen cloud target as last sized): what a view adds. 0 for an
    /// unknown view.
    pub fn view_gpu_bytes(&self, id: ViewId) -> u64 {
        self.views.get(id.0).map_or(0, View::gpu_bytes)
    }

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
    /// [`FrameStats::blocks_left_out`]. Every block is uploaded again.
    pub fn set_sprite_budget_bytes(&mut self, bytes: u64) {
        let mut old = ResidentSet::new(&self.device, bytes);
        std::mem::swap(&mut old, &mut self.resident);
        for (_, r) in old.blocks {
            self.resident.insert(r.block, r.motion);
        }
        for view in &mut self.views {
            view.locks = Locks::default();
        }
    }

    /// Counts what the host's cloud field work for this frame `spent` (time it with a
    /// [`Stopwatch`], or a [`super::SkyUpdate`]'s `field_cpu`) into the next prepared frame's
    /// [`FrameStats::field_us`] and its thread figure: for a host that drives the sky itself
    /// ([`crate::SkySystem::update`] adds its own to the stats it returns).
    pub fn add_field_cpu(&mut self, spent: Spent) {
        self.field += spent;
    }

    /// Counts the wall-clock microseconds the host's work on the far field's map took this frame
    /// (sampling the weather into its rows, [`Self::set_far_map`]) into the next prepared
    /// frame's [`FrameStats::far_field_us`]. They are part of the field's time too: count that
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
    ) -> Result<Vec<super::SpriteCorner>, RenderError> {
        let main = &self.views[0];
        let mut encoder = self.device.create_command_encoder(&Default::default());
        self.scatter.record(&mut encoder);
        let read = super::readback::read_buffer(&self.device, main.sprites_to_draw);
        let corner_bytes = 4 * std::mem::size_of::<GpuSpriteVertex>() as u64;
        if let Some(view_group) = main.view.group() {
            for (chunk, first, sprites) in chunks(main.sprites_to_draw) {
                let group = &self.resident.group;
                self.build
                    .record(&mut encoder, view_group, group, (chunk, sprites));
                encoder.copy_buffer_to_buffer(
                    self.build.vertices(),
                    0,
                    &read,
                    first as u64 * corner_bytes,
                    sprites as u64 * corner_bytes,
                );
            }
        }
        super::readback::read_corners(&self.device, queue, encoder, &read, main.sprites_to_draw)
    }

    /// Times each group of the sky's passes on the GPU from the next [`Self::record`] on (a
    /// profiling aid: the far field, the ring and the sprites then go in passes of their own),
    /// or stops.
    /// Returns whether timing is on: the device needs timestamp queries inside encoders
    /// (`wgpu::Features::TIMESTAMP_QUERY | TIMESTAMP_QUERY_INSIDE_ENCODERS`).
    pub fn set_pass_timing(&mut self, on: bool) -> bool {
        self.pass_timer = if on {
            super::Timestamps::new(&self.device, &self.queue, "sky.pass_times", STAMPS)
        } else {
            None
        };
        self.shadows
            .set_timing(&self.queue, self.pass_timer.is_some());
        self.pass_timer.is_some()
    }

    /// GPU time of each group of passes of the last recorded frame, once it was submitted:
    /// waits for the device. `None` while pass timing is off or if the times cannot be read.
    pub fn pass_times(&self) -> Option<super::PassTimes> {
        let times =
            super::pass_timing::pass_times(&self.pass_timer.as_ref()?.read_ms(&self.device)?);
        let shadow_ms = self.shadows.last_ms().unwrap_or(0.0);
        times.map(|t| super::PassTimes { shadow_ms, ..t })
    }

    /// The clouds' shadow map of the last prepared frame and the matrix a host looks it up with
    /// ([`super::CloudShadowMap`]): the host multiplies its ground's direct sunlight by
    /// `exp(-tau)`. Take it every frame (after [`Self::prepare`]): the lookup follows the camera
    /// and the clouds' drift, and the texture is replaced when the shadows are switched.
    pub fn cloud_shadows(&self) -> super::CloudShadowMap<'_> {
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
    ) -> Result<super::ShadowImage, RenderError> {
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
    pub fn far_field_settings(&self) -> super::far_field::FarFieldSettings {
        *self.far_field.settings()
    }

    /// The clouds' distance in the main view's last recorded frame (metres from the camera
    /// plane, weighted by what each cloud shows; 0 where none shows) at the cloud target's
    /// resolution: width, height and the texels row by row. `None` with the clouds drawn at full
    /// resolution (no cloud target). Waits for the GPU: for tools and tests.
    pub fn read_cloud_distance_m(&self, queue: &wgpu::Queue) -> Option<(u32, u32, Vec<f32>)> {
        self.views[0].clouds.read_distance_m(&self.device, queue)
    }

    /// CPU work of a frame: advances time by `dt_s`, uploads blocks that arrived, sorts blocks
    /// and clouds, recomputes the sprite orders Wang's cache says are stale, and writes the draw
    /// list and this frame's uniforms (only what changed goes to the GPU). It submits nothing of
    /// its own to the device (the impostor renders of a ring rebuild go into the next
    /// [`Self::record`]), except that a frame prepared and never recorded is flushed by the next
    /// prepare, so nothing piles up however the host drives it; the time that flush holds the
    /// frame thread is `gpu_wait_us`, not in `cpu_update_us`.
    pub fn prepare(
        &mut self,
        queue: &wgpu::Queue,
        view: impl Into<SkyView>,
        sun: &SunPosition,
        dt_s: f64,
    ) -> FrameStats {
        self.prepare_view(ViewId::MAIN, queue, view, sun, dt_s)
    }

    /// [`Self::prepare`] for one view (see [`Self::add_view`]): its draw list, ring and
    /// uniforms from its camera. Every view of a frame is given the frame's `dt_s`: the main
    /// view's advances the sky's clock, the others' only their ring's crossfade. An unknown
    /// view prepares the main one (see [`Self::has_view`]).
    pub fn prepare_view(
        &mut self,
        id: ViewId,
        queue: &wgpu::Queue,
        view: impl Into<SkyView>,
        sun: &SunPosition,
        dt_s: f64,
    ) -> FrameStats {
        let start = Stopwatch::start();
        let i = if id.0 < self.views.len() { id.0 } else { 0 };
        let camera: SkyView = view.into();
        self.views[i].projection = Some(camera.projection);
        let mut gpu_wait = Spent::default();
        if !self.views[i].recorded.replace(false) {
            // The last frame's writes never reached a submit: send them, so they are freed. A
            // device still busy with earlier work can hold the submit (lavapipe waits in it for
            // the submission before): timed apart, as a wait.
            let wait = Stopwatch::start();
            queue.submit([]);
            gpu_wait = wait.spent();
        }
        // The frame's clock is the main view's; the others use `dt_s` for their ring's
        // crossfade only.
        if i == ViewId::MAIN.0 {
            self.elapsed_s += dt_s.max(0.0);
        }
        self.clear_light = self.time_of_day.at(sun.elevation_deg as f32);
        let (hidden, _) = self.overhead_ease.show(
            self.sky_hidden_at(camera.position_m.z),
            self.fog.0.visibility_m(&self.fog.1),
            self.elapsed_s,
        );
        self.seen_light = self
            .clear_light
            .under_cover(hidden, &self.time_of_day.overcast);
        // The host's sun is the clear sun, on or off: the shadow map dims it where the clouds
        // stop it, and with the shadows off nothing does (off casts no shadows; it does not
        // dim the ground evenly). The cover's mean dimming is kept apart for a host without
        // the map.
        self.cover_transmittance = 1.0 - hidden.clamp(0.0, 1.0);
        self.seen_light.directional_rgb = self.clear_light.directional_rgb;
        let sun_dir = sun.direction_enu().as_vec3();
        let lighting = Lighting {
            sun_dir,
            time_of_day: self.clear_light,
            mapping: self.time_of_day.directional_mapping,
            forward: self.time_of_day.forward_scattering,
            model: self.time_of_day.shading.model,
            harris_lastra: self.time_of_day.harris_lastra,
        };
        let mut stats = FrameStats::default();
        (self.resident.lit_sprites, self.resident.light_us) = (0, 0);
        let switched_on = self.resident.light.set(
            self.time_of_day.shading.model,
            &self.time_of_day.harris_lastra,
            sun_dir,
        );
        let mut upload_bytes = 0;
        if switched_on {
            upload_bytes += self.resident.provisional_all(queue);
        }
        let (placed_bytes, left_out) = self.resident.place_and_upload(
            queue,
            camera.position_m,
            self.settings.vertex_cache.max_uploaded_sprites_per_frame,
        );
        stats.blocks_left_out = left_out;
        gpu_wait += self.resident.grow_wait;
        if self.resident.packed() {
            // Blocks moved to other slots: what holds sprite slots from frame to frame follows
            // them, and a patch of orders kept for the old slots goes (the new buffers were
            // written whole from the CPU's copies, which hold its values).
            self.scatter.forget_kept();
            let resident = &self.resident;
            for view in &mut self.views {
                view.locks.follow(|slot| resident.moved_slot(slot));
            }
        }
        upload_bytes += placed_bytes;
        upload_bytes += self.resident.relight(queue, camera.position_m);
        (stats.sprites_lit, stats.light_us) = (self.resident.lit_sprites, self.resident.light_us);
        // While the far field is drawn every sprite has faded out by the end of its hand-over
        // band (a twentieth more: the band is horizontal, the draw distance along the ray):
        // neither the ring nor the sprites go farther.
        let band_m = (self.far_field.hand_over_m()).map(|(start, end)| (start, 1.05 * end));
        let mut drawn = self.settings;
        if let Some((_, end)) = band_m {
            drawn.clouds.draw_distance_m = drawn.clouds.draw_distance_m.min(end);
        }
        (self.views[i].ring)
            .set_reach_limit(band_m.map(|(start, end)| (f64::from(start), f64::from(end))));
        self.views[i]
            .ring
            .split(&mut self.resident, camera.position_m, sun_dir, dt_s);
        // The frame's sorting budget, shared with a ring that is being rebuilt.
        let sort_budget = self.settings.vertex_cache.max_sorted_sprites_per_frame;
        let sort_budget = sort_budget - self.views[i].ring.sort_reserve(sort_budget);
        let resident = &mut self.resident;
        let v = &mut self.views[i];
        let inside = main_view(
            (&mut resident.blocks, v.ring.near()),
            Copies {
                orders: &mut resident.orders_cpu,
                dirty_orders: &mut resident.dirty_orders,
                lists: &mut resident.lists_cpu,
                dirty_lists: &mut resident.dirty_lists,
            },
            (camera.position_m, &camera.frustum()),
            self.elapsed_s,
            (&drawn, sort_budget),
            (&mut v.locks, &mut v.seams),
            &mut v.draws,
            &mut stats,
        );
        let resident = &mut self.resident;
        upload_bytes += self.scatter.prepare(
            &self.device,
            queue,
            (&resident.orders_cpu, &resident.order_buffer),
            &mut resident.dirty_orders,
            (&resident.lists_cpu, &resident.list_buffer),
            &mut resident.dirty_lists,
        );
        let locks = self.views[i].locks.gpu();
        let light = ViewLight {
            lighting: &lighting,
            clouds: &self.settings.clouds,
            lifecycle: &self.lifecycle,
            camera_z_m: camera.position_m.z as f32,
            farthest_m: self.settings.clouds.draw_distance_m,
            hand_over_m: self.far_field.hand_over_m(),
        };
        let header = sprite_view::header(&light);
        let v = &mut self.views[i];
        let changed_locks = v.locks.take_changed().then_some(&locks[..]);
        upload_bytes += v.view.write(
            &self.device,
            queue,
            &self.view_layout,
            &header,
            changed_locks,
            ViewData::Resident {
                counts: [
                    v.draws.len() as u32,
                    locks.len() as u32,
                    stats.sprites_drawn,
                    0,
                ],
                draws: &v.draws,
                lists: &self.resident.list_buffer,
                orders: &self.resident.order_buffer,
                generation: self.resident.generation,
            },
        );
        self.views[i].sprites_to_draw = stats.sprites_drawn;
        self.views[i].distant_sprites =
            super::sprites::draw_list::distant_sprites(&self.views[i].draws, stats.sprites_drawn);
        let in_cloud = inside.cloud;
        self.views[i].in_cloud = in_cloud;
        self.views[i].in_rain = inside.rain;
        stats.in_cloud = in_cloud;

        let view_proj = camera.view_proj();
        let sun_cfg = &self.settings.sun;
        // In-cloud fog: the ambient of a mid-grey cloud at this time of day plus some sun.
        let fog_rgb = Vec3::splat(0.8) * self.clear_light.ambient_percent
            + self.clear_light.directional_rgb * 0.25;
        let cloud_haze = self.fog.0.cloud_haze(
            &self.fog_for(self.views[i].in_rain),
            self.settings.clouds.haze_distance_m,
            self.fog.1.ground_elevation_m,
        );
        let frame = GpuFrame {
            view_proj: view_proj.to_cols_array_2d(),
            inv_view_proj: view_proj.inverse().to_cols_array_2d(),
            sun_dir: sun_dir
                .extend(sun_cfg.disc_radius_deg.to_radians().cos())
                .to_array(),
            // The sky's own sun glow and disc behind the clouds: dimmed by the cover as a
            // whole, the same with the shadows on or off.
            sun_rgb: (self.seen_light.directional_rgb * self.cover_transmittance)
                .extend(sun_cfg.glow_radius_deg.to_radians().cos())
                .to_array(),
            // w: the camera's height above the haze's base; its distance from the Earth's
            // centre (0: flat).
            sky_zenith_rgb: self
                .seen_light
                .sky_zenith_rgb
                .extend(camera.position_m.z as f32 - cloud_haze.base_msl_m)
                .to_array(),
            sky_horizon_rgb: self
                .seen_light
                .sky_horizon_rgb
                .extend(self.settings.earth.camera_radius_m(camera.position_m.z))
                .to_array(),
            in_cloud_rgba: fog_rgb.extend(in_cloud).to_array(),
            params: [
                self.targets.background_depth(),
                self.settings.clouds.soft_depth_fade_m.recip(),
                self.settings.clouds.soft_depth_fade_m,
                self.settings.in_cloud.visibility_m,
            ],
            haze: cloud_haze.to_gpu(),
            flash_reach: [self.flash.map_or(0.0, |f| f.reach_m), 0.0, 0.0, 0.0],
            depth_to_view: camera.depth_to_view(),
            flash: self.flash.map_or([0.0; 4], |f| {
                (f.position_m - camera.position_m)
                    .as_vec3()
                    .extend(f.light)
                    .to_array()
            }),
        };
        queue.write_buffer(&self.views[i].frame_buffer, 0, bytemuck::bytes_of(&frame));
        let far_field = std::time::Instant::now();
        self.far_field.prepare(
            queue,
            (camera.position_m, frame.sky_horizon_rgb[3]),
            &self.clear_light,
            self.elapsed_s,
        );
        self.far_field_us += far_field.elapsed().as_micros() as u64;
        upload_bytes += std::mem::size_of::<GpuFrame>() as u64;
        let ring_frame = RingFrame {
            resident: &self.resident,
            template: &frame,
            view: &light,
            camera_m: camera.position_m,
            cache: &self.settings.vertex_cache,
        };
        upload_bytes += self.views[i]
            .ring
            .prepare_builds(queue, &ring_frame, &mut stats);
        if i == ViewId::MAIN.0 {
            // One map for all views (the sun is shared), around the main view's camera.
            let at = (camera.position_m, sun_dir, self.elapsed_s);
            upload_bytes += (self.shadows).prepare(queue, &self.resident, &light, at, &mut stats);
        }
        // Quad indices and built corners for the largest draw of the frame (the sprites, an
        // impostor's sector, the shadow map's chunk).
        let most = stats
            .sprites_drawn
            .max(self.views[i].ring.most_sprites_pending())
            .max(self.shadows.pending_sprites())
            .min(CHUNK);
        if most > self.quads.1 {
            let sprites = most.next_power_of_two();
            self.quads = (quad_index_buffer(&self.device, sprites), sprites);
        }
        self.build.reserve(&self.device, most);
        stats.upload_bytes = upload_bytes;
        // The shadow map, when due (rarely: see `shadow`), goes in a submission of its own with
        // the patch of changed orders it reads, applied but kept for the host's frame. The
        // ring's impostor renders go in the host's encoder (`record_view`).
        if self.shadows.has_pending() {
            let mut encoder = self
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("sky.cloud_shadows"),
                });
            self.scatter.record_kept(&mut encoder);
            let resident = &self.resident.group;
            (self.shadows).record(
                &mut encoder,
                &self.sheet_group,
                &self.build,
                resident,
                &self.quads.0,
            );
            // lavapipe runs the submission on the frame thread: counted as a wait, as the
            // flush above is.
            let wait = Stopwatch::start();
            queue.submit([encoder.finish()]);
            gpu_wait += wait.spent();
        }
        stats.cloud_scale = self.views[i].clouds.scale();
        stats.cloud_target_bytes = self.views[i].clouds.gpu_bytes();
        stats.sprite_gpu_bytes = self.resident.gpu_bytes()
            + self.quads.0.size()
            + self.build.gpu_bytes()
            + self.views[i].view.gpu_bytes();
        let field = std::mem::take(&mut self.field);
        let update = start.spent().saturating_sub(gpu_wait) + std::mem::take(&mut self.pending);
        stats.far_field_us = std::mem::take(&mut self.far_field_us);
        stats.far_field_gpu_bytes = self.far_field.gpu_bytes();
        stats.field_us = field.wall_us;
        stats.thread.field_us = field.thread_us;
        stats.gpu_wait_us = gpu_wait.wall_us;
        stats.cpu_update_us = update.wall_us;
        stats.thread.update_us = update.thread_us;
        stats
    }
}
