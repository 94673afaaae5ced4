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

use super::RenderError;
use super::gpu_types::GpuFrame;
use super::impostor::RingFrame;
use super::overhead_ease::OverheadEase;
use super::settings::RenderSettings;
use super::sprites::pass::{SpriteFrame, SpritePass, SpriteViewState};
use super::sprites::sprite_view::{self, ViewLight};
use super::stats::{FrameStats, Spent, Stopwatch};
use super::targets::{HostTargets, SkyView};
use super::view::{View, ViewId, ViewShared};
use crate::clouds::LifecycleConfig;
use crate::shading::{SunPosition, TimeOfDay, TimeOfDayTable};
use crate::weather::{BlockLayer, BlockWeather};

// What the sky does apart from conducting a frame, one file each.
mod blocks;
mod build;
mod controls;
// The sky pass's plan: the frame uniform every pass into the host's targets reads.
mod frame;
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
    /// The near sprites' pass, with the resident sprites, the corner build and the quads the
    /// ring and the shadow map draw through too.
    sprites: SpritePass,
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
    /// Two timestamps around the submission `prepare` makes of its own (the shadow map's),
    /// while its timing is on ([`Self::set_prepare_timing`]), and whether the last prepare
    /// made one.
    prepare_timer: Option<super::Timestamps>,
    prepare_submitted: bool,
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
        let main = i == ViewId::MAIN.0;
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
        if main {
            self.elapsed_s += dt_s.max(0.0);
        }
        let lighting = self.light_frame(sun, camera.position_m.z);
        let sun_dir = lighting.sun_dir;
        let mut stats = FrameStats::default();

        // The resident sprites every pass draws from: arrived blocks placed and written.
        let ts = &self.time_of_day;
        let (mut upload_bytes, grow_wait) = self.sprites.place(
            queue,
            (
                camera.position_m,
                self.settings.vertex_cache.max_uploaded_sprites_per_frame,
            ),
            (ts.shading.model, &ts.harris_lastra, sun_dir),
            self.views.iter_mut().map(|v| &mut v.locks),
            &mut stats,
        );
        gpu_wait += grow_wait;

        // Plans, on the CPU. The ring first: which blocks it holds and which it leaves to the
        // sprites. While the far field is drawn every sprite has faded out by the end of its
        // hand-over band (a twentieth more: the band is horizontal, the draw distance along
        // the ray): neither the ring nor the sprites go farther.
        let hand_over_m = self.far_field.hand_over_m();
        let band_m = hand_over_m.map(|(start, end)| (start, 1.05 * end));
        let mut drawn = self.settings;
        if let Some((_, end)) = band_m {
            drawn.clouds.draw_distance_m = drawn.clouds.draw_distance_m.min(end);
        }
        let v = &mut self.views[i];
        (v.ring).set_reach_limit(band_m.map(|(start, end)| (f64::from(start), f64::from(end))));
        (v.ring).plan(&self.sprites.resident, camera.position_m, sun_dir, dt_s);
        // The near sprites and the far storm cells: the view's draw list, within the frame's
        // sorting budget (shared with a ring that is being rebuilt).
        let sort_budget = self.settings.vertex_cache.max_sorted_sprites_per_frame;
        let sprite_plan = self.sprites.plan(
            SpriteViewState {
                near: v.ring.near(),
                locks: &mut v.locks,
                seams: &mut v.seams,
                draws: &mut v.draws,
            },
            &SpriteFrame {
                camera_m: camera.position_m,
                frustum: &camera.frustum(),
                time_s: self.elapsed_s,
                drawn: &drawn,
                sort_budget: sort_budget - v.ring.sort_reserve(sort_budget),
            },
            &mut stats,
        );
        (v.sprites_to_draw, v.distant_sprites) = (sprite_plan.sprites, sprite_plan.distant);
        (v.in_cloud, v.in_rain) = (sprite_plan.inside.cloud, sprite_plan.inside.rain);
        stats.in_cloud = sprite_plan.inside.cloud;
        // The sky pass's frame uniform, which every pass into the host's targets reads.
        let haze = self.fog.0.cloud_haze(
            &self.fog_for(sprite_plan.inside.rain),
            self.settings.clouds.haze_distance_m,
            self.fog.1.ground_elevation_m,
        );
        let frame = frame::plan(&frame::FrameParts {
            camera: &camera,
            sun_dir,
            settings: &self.settings,
            clear_light: &self.clear_light,
            seen_light: &self.seen_light,
            cover_transmittance: self.cover_transmittance,
            haze: &haze,
            in_cloud: sprite_plan.inside.cloud,
            background_depth: self.targets.background_depth(),
            flash: self.flash,
        });

        // Uploads: the sprites' patch and view, the frame uniform, the far field's uniform,
        // the ring's impostor renders, the shadow map (the main view's).
        let light = ViewLight {
            lighting: &lighting,
            clouds: &self.settings.clouds,
            lifecycle: &self.lifecycle,
            camera_z_m: camera.position_m.z as f32,
            farthest_m: self.settings.clouds.draw_distance_m,
            hand_over_m,
        };
        let v = &mut self.views[i];
        upload_bytes += self.sprites.upload(
            (&self.device, queue),
            &self.view_layout,
            &sprite_plan,
            &sprite_view::header(&light),
            (&mut v.locks, &v.draws),
            &mut v.view,
        );
        queue.write_buffer(&v.frame_buffer, 0, bytemuck::bytes_of(&frame));
        upload_bytes += std::mem::size_of::<GpuFrame>() as u64;
        let far_field = std::time::Instant::now();
        let far = (camera.position_m, frame.sky_horizon_rgb[3]);
        if let Some(plan) = self.far_field.plan(far, &self.clear_light, self.elapsed_s) {
            self.far_field.upload(queue, &plan);
        }
        self.far_field_us += far_field.elapsed().as_micros() as u64;
        let ring_frame = RingFrame {
            resident: &self.sprites.resident,
            template: &frame,
            view: &light,
            camera_m: camera.position_m,
            cache: &self.settings.vertex_cache,
        };
        upload_bytes += (v.ring).prepare_builds(queue, &ring_frame, &mut stats);
        if main {
            // One map for all views (the sun is shared), around the main view's camera.
            let at = (camera.position_m, sun_dir, self.elapsed_s);
            let resident = &self.sprites.resident;
            let shadows = std::time::Instant::now();
            upload_bytes += (self.shadows).prepare(queue, resident, &light, at, &mut stats);
            stats.shadow_us = shadows.elapsed().as_micros() as u64;
        }
        // Quad indices and built corners for the largest draw of the frame (the sprites, an
        // impostor's sector, the shadow map's chunk).
        let most = (stats.sprites_drawn)
            .max(self.views[i].ring.most_sprites_pending())
            .max(self.shadows.pending_sprites());
        self.sprites.reserve(&self.device, most);
        stats.upload_bytes = upload_bytes;
        self.prepare_submitted = self.shadows.has_pending();
        gpu_wait += self.record_shadows(queue);
        self.count_costs(i, start.spent().saturating_sub(gpu_wait), gpu_wait, stats)
    }

    /// The shadow map, when due (rarely: see `shadow`), in a submission of its own with the
    /// patch of changed orders it reads, applied but kept for the host's frame (the ring's
    /// impostor renders go in the host's encoder, `record_view`). Returns the time the submit
    /// held the frame thread: lavapipe runs the submission there, counted as a wait.
    fn record_shadows(&self, queue: &wgpu::Queue) -> Spent {
        if !self.shadows.has_pending() {
            return Spent::default();
        }
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("sky.cloud_shadows"),
            });
        // Timed from its first command to its last, on the device: the frame's GPU time
        // without the CPU's prepare before the submission (the device idles through it).
        if let Some(timer) = &self.prepare_timer {
            timer.write(&mut encoder, 0);
        }
        self.sprites.scatter.record_kept(&mut encoder);
        let sprites = &self.sprites;
        (self.shadows).record(
            &mut encoder,
            &sprites.build,
            &sprites.resident.group,
            &sprites.quads.0,
        );
        if let Some(timer) = &self.prepare_timer {
            timer.write(&mut encoder, 1);
            timer.resolve(&mut encoder);
        }
        let wait = Stopwatch::start();
        queue.submit([encoder.finish()]);
        wait.spent()
    }

    /// The frame's costs added up: the view's memory, the CPU time of the prepare (`own`,
    /// waits apart), of the block changes and of the host's field since the last prepare.
    fn count_costs(
        &mut self,
        i: usize,
        own: Spent,
        gpu_wait: Spent,
        mut stats: FrameStats,
    ) -> FrameStats {
        let v = &self.views[i];
        stats.cloud_scale = v.clouds.scale();
        stats.cloud_target_bytes = v.clouds.gpu_bytes();
        stats.sprite_gpu_bytes = self.sprites.gpu_bytes() + v.view.gpu_bytes();
        let field = std::mem::take(&mut self.field);
        let update = own + std::mem::take(&mut self.pending);
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
