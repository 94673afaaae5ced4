//! The demo host: what a flight simulator would do around a [`SkySystem`], packaged for the
//! CLI, the render tests and the benchmarks. It owns a headless device, an offscreen colour + depth
//! target and the demo [`Terrain`]; each frame it draws the ground first (colour and depth), then
//! lets the sky record its passes reading that depth, then reads the frame back.
//!
//! [`ground_from_field`] builds the ground so it agrees with the weather: the field's ground
//! elevation (interpolated from station elevations) plus gentle procedural relief, so a METAR
//! base above ground lands above this ground.

use glam::DVec2;

use super::headless::{self, Frame, HeadlessGpu, OffscreenTarget};
use super::terrain::{HeightField, Terrain, TerrainLight, procedural_relief_m};
use crate::flight::{HostCamera, SkyError, SkySystem, SkySystemConfig};
use crate::render::gpu_types::GpuSprite;
use crate::render::{Camera, FrameStats, RenderError, Timestamps};
use crate::shading::SunPosition;
use crate::weather::field::WeatherField;

/// A headless device, target, ground and sky.
pub struct DemoHost {
    /// The device.
    pub gpu: HeadlessGpu,
    /// The offscreen target.
    pub target: OffscreenTarget,
    /// The ground.
    pub terrain: Terrain,
    /// The sky: the same object a simulator embeds (its frame step in [`Self::step`]; the
    /// renderer underneath reached through it for tests that drive the sky by hand).
    pub sky: SkySystem,
    timer: Option<GpuTimer>,
}

/// Three timestamps in the frame's encoder: before the ground, between the ground and the sky,
/// after the sky; where the device has timestamp queries. The sky times the submission its
/// `prepare` makes of its own ([`crate::render::Sky::set_prepare_timing`]): stamps around the
/// whole prepare, in submissions of their own, would also count the CPU's prepare (the device
/// idles through it) and the latency of those submissions, and the sky's GPU time is only
/// what the device spends on its commands.
struct GpuTimer {
    stamps: Timestamps,
}

impl GpuTimer {
    /// The timer, and the sky's prepare timed with it; `None` without timestamp queries.
    fn new(gpu: &HeadlessGpu, sky: &mut SkySystem) -> Option<Self> {
        let stamps = Timestamps::new(&gpu.device, &gpu.queue, "host.frame_time", 3)?;
        sky.sky_mut().set_prepare_timing(true);
        Some(Self { stamps })
    }

    /// Milliseconds of the ground and of the sky (what its `prepare` submitted, and its passes
    /// in the frame, impostor renders included) of the last submitted frame (waits for it).
    fn read_ms(&self, gpu: &HeadlessGpu, sky: &SkySystem) -> Option<[f64; 2]> {
        let t = self.stamps.read_ms(&gpu.device)?;
        let ms = |a: usize, b: usize| (t[b] - t[a]).max(0.0);
        let prepare = sky.sky().prepare_gpu_ms().unwrap_or(0.0);
        Some([ms(0, 1), prepare + ms(1, 2)])
    }
}

impl DemoHost {
    /// Creates the device (any adapter), a `width` x `height` target, the ground and the sky.
    pub fn new(
        width: u32,
        height: u32,
        ground: &HeightField,
        sky: impl Into<SkySystemConfig>,
    ) -> Result<Self, SkyError> {
        Self::with_gpu(HeadlessGpu::new()?, width, height, ground, sky)
    }

    /// [`Self::new`] on a device the caller made (one that can also present to a window).
    pub fn with_gpu(
        gpu: HeadlessGpu,
        width: u32,
        height: u32,
        ground: &HeightField,
        sky: impl Into<SkySystemConfig>,
    ) -> Result<Self, SkyError> {
        let target = OffscreenTarget::new(&gpu, width, height)?;
        let terrain = Terrain::new(&gpu.device, headless::COLOUR_FORMAT, ground);
        let mut config: SkySystemConfig = sky.into();
        config.sky.targets = headless::TARGETS;
        let mut sky = SkySystem::with_config(&gpu.device, &gpu.queue, config)?;
        let timer = GpuTimer::new(&gpu, &mut sky);
        Ok(Self {
            gpu,
            target,
            terrain,
            sky,
            timer,
        })
    }

    /// Rebuilds the off-screen target at a new size (a window resized); the ground and the sky
    /// keep everything else.
    pub fn resize(&mut self, width: u32, height: u32) -> Result<(), RenderError> {
        self.target = OffscreenTarget::new(&self.gpu, width, height)?;
        Ok(())
    }

    /// A camera with the sky's projection settings and this target's aspect.
    pub fn camera(&self, position_m: glam::DVec3, heading_deg: f64, pitch_deg: f64) -> Camera {
        let c = &self.sky.settings().camera;
        Camera {
            position_m,
            heading_deg,
            pitch_deg,
            fov_y_deg: c.fov_y_deg,
            aspect: self.target.width as f32 / self.target.height as f32,
            near_m: c.near_m,
            far_m: c.far_m,
        }
    }

    /// The frame step of the sky a simulator embeds ([`SkySystem::update`]: weather, living
    /// clouds, sun for `utc_unix_s`, the sky's CPU share), then, when `draw`, the ground and the
    /// sky drawn (not read back). Returns the sky's stats and the weather files that arrived.
    pub fn step(
        &mut self,
        camera: &Camera,
        utc_unix_s: f64,
        dt_s: f64,
        draw: bool,
    ) -> Result<(FrameStats, Vec<Result<std::path::PathBuf, String>>), SkyError> {
        let (stats, changes) =
            self.sky
                .update(&self.gpu.queue, &HostCamera::from(camera), utc_unix_s, dt_s)?;
        if !draw {
            return Ok((stats, changes));
        }
        let sun_dir = self.sky.lighting().sun_direction;
        // The ground's visibility is the sky's fog alone: the weather over the camera, eased
        // through a change of the report as its clouds form (`Sky::ease_weather_overhead`).
        Ok((
            self.draw_prepared(camera, sun_dir, f32::INFINITY, stats)?,
            changes,
        ))
    }

    /// [`Self::step`] with `draw`, and the frame read back.
    pub fn step_frame(
        &mut self,
        camera: &Camera,
        utc_unix_s: f64,
        dt_s: f64,
    ) -> Result<(Frame, FrameStats), SkyError> {
        let (stats, _) = self.step(camera, utc_unix_s, dt_s, true)?;
        Ok((self.target.read_back(&self.gpu)?, stats))
    }

    /// Draws one frame (ground, then sky) without reading it back, the sky prepared by hand
    /// (the clouds given to the renderer directly, no frame step); returns the sky's stats, or
    /// why the sky refused the frame ([`Sky::record`](crate::render::Sky::record)'s checks).
    pub fn draw(
        &mut self,
        camera: &Camera,
        sun: &SunPosition,
        dt_s: f64,
        visibility_m: f32,
    ) -> Result<FrameStats, RenderError> {
        let stats = (self.sky.sky_mut()).prepare(&self.gpu.queue, camera, sun, dt_s);
        self.draw_prepared(camera, sun.direction_enu().as_vec3(), visibility_m, stats)
    }

    /// The ground, then the sky's passes, of a prepared frame.
    fn draw_prepared(
        &mut self,
        camera: &Camera,
        sun_dir: glam::Vec3,
        visibility_m: f32,
        mut stats: FrameStats,
    ) -> Result<FrameStats, RenderError> {
        let light = self.sky.sky().light();
        let shadows = self.sky.cloud_shadows();
        self.terrain.prepare(
            (&self.gpu.device, &self.gpu.queue),
            camera,
            &TerrainLight {
                sun_dir,
                sun_rgb: light.directional_rgb,
                ambient: skylight(light.directional_rgb, sun_dir, light.ambient_percent),
                fog_rgb: self.sky.sky().fog().rgb,
                haze: self.sky.ground_haze(visibility_m),
                camera_radius_m: self.sky.earth().camera_radius_m(camera.position_m.z),
            },
            &shadows,
        );
        let mut encoder = self
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("host.frame"),
            });
        if let Some(t) = &self.timer {
            t.stamps.write(&mut encoder, 0);
        }
        self.terrain.record(
            &mut encoder,
            &self.target.colour_view,
            &self.target.depth_view,
        );
        if let Some(t) = &self.timer {
            t.stamps.write(&mut encoder, 1);
        }
        // The renderer's own record: `draw` prepares it by hand, without the frame step.
        self.sky.sky().record(
            &mut encoder,
            &self.target.colour_view,
            &self.target.depth_view,
        )?;
        stats.set_record(self.sky.last_record());
        if let Some(t) = &self.timer {
            t.stamps.write(&mut encoder, 2);
            t.stamps.resolve(&mut encoder);
        }
        self.gpu.queue.submit([encoder.finish()]);
        Ok(stats)
    }

    /// GPU time of the last drawn frame (ground and sky passes), milliseconds, where the device
    /// has timestamp queries. Waits for the frame.
    pub fn last_gpu_ms(&self) -> Option<f64> {
        self.last_gpu_split_ms().map(|[ground, sky]| ground + sky)
    }

    /// GPU time of the last drawn frame's ground passes and of its sky passes (impostor
    /// renders included), milliseconds, where the device has timestamp queries. Waits for it.
    pub fn last_gpu_split_ms(&self) -> Option<[f64; 2]> {
        self.timer.as_ref()?.read_ms(&self.gpu, &self.sky)
    }

    /// Waits until the device has finished everything submitted (the benchmark's wall-time
    /// frame clock where the device has no timestamp queries).
    pub fn wait_idle(&self) -> Result<(), RenderError> {
        self.gpu
            .device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| RenderError::Device(e.to_string()))
    }

    /// The most sprites the sky can hold on the GPU on this device: its sprite records
    /// ([`GpuSprite`]) in one storage buffer, and as many drawn at once, six quad indices each in
    /// one index buffer.
    pub fn max_sprites(&self) -> u64 {
        let limits = self.gpu.device.limits();
        let records = limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size)
            / std::mem::size_of::<GpuSprite>() as u64;
        records.min(limits.max_buffer_size / 24)
    }

    /// Draws one frame and reads it back.
    pub fn frame(
        &mut self,
        camera: &Camera,
        sun: &SunPosition,
        dt_s: f64,
        visibility_m: f32,
    ) -> Result<(Frame, FrameStats), RenderError> {
        let stats = self.draw(camera, sun, dt_s, visibility_m)?;
        Ok((self.target.read_back(&self.gpu)?, stats))
    }
}

/// The demo ground's extent: what `render`, `fly` and `bench` draw under the sky.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GroundSettings {
    /// Side of the square of ground around the origin, metres.
    pub size_m: f64,
    /// Samples per side.
    pub samples: u32,
    /// Procedural relief on top of the station elevations, metres.
    pub relief_m: f64,
}

impl Default for GroundSettings {
    fn default() -> Self {
        Self {
            size_m: 130_000.0,
            samples: 257,
            relief_m: 40.0,
        }
    }
}

/// The demo ground around the field's origin: the stations' elevations plus gentle relief, so
/// a METAR base above ground lands above this ground.
pub fn demo_ground(field: &WeatherField, settings: &GroundSettings) -> HeightField {
    ground_from_field(
        field,
        DVec2::ZERO,
        settings.size_m,
        settings.samples,
        settings.relief_m,
    )
}

/// Ground around `centre_m` (`size_m` square, `samples` per side) at the field's interpolated
/// station elevations plus `relief_m` of procedural relief. The field is sampled on a coarser
/// grid (every 4th sample) and interpolated; it changes slowly.
pub fn ground_from_field(
    field: &WeatherField,
    centre_m: DVec2,
    size_m: f64,
    samples: u32,
    relief_m: f64,
) -> HeightField {
    let coarse_samples = (samples / 4).max(2);
    let coarse = HeightField::from_fn(centre_m, size_m, coarse_samples, |p| {
        field.weather_at(p).ground_elevation_m as f64
    });
    HeightField::from_fn(centre_m, size_m, samples, |p| {
        coarse.height_at_m(p) + procedural_relief_m(p, relief_m, 11)
    })
}

/// How much of the clear sky's light reaches level ground besides the sun's beam, per the
/// beam's luminance and the square root of the sun's elevation's sine: a quarter of the ground's
/// light at 24 degrees of sun (clear-sky diffuse shares, e.g. Duffie and Beckman, "Solar
/// Engineering of Thermal Processes", section 2.16), most of it with the sun on the horizon.
const SKYLIGHT: f32 = 0.27;

/// The light of the sky alone on the demo ground (the ground in a cloud's shadow has only it):
/// [`SKYLIGHT`] of the sun's luminance, by the square root of its elevation's sine, and at least
/// a twentieth of the time of day's ambient (twilight and night).
fn skylight(sun_rgb: glam::Vec3, sun_dir: glam::Vec3, ambient_percent: f32) -> f32 {
    let luminance = crate::shading::luminance(sun_rgb);
    (SKYLIGHT * luminance * sun_dir.z.max(0.0).sqrt()).max(0.05 * ambient_percent * 0.35)
}

#[cfg(test)]
mod skylight_tests {
    use super::*;

    /// The demo ground in a thick cloud's shadow (no beam, the sky alone) against the same
    /// ground in the sun, in the terrain shader's light (`sun_rgb * sin(elevation) + ambient`):
    /// a quarter to a third at 24 degrees of sun, the share of clear-sky light that is diffuse;
    /// more with the sun low, as the sky's share grows.
    #[test]
    fn shadowed_ground_is_lit_by_the_sky_alone() {
        let sun_rgb = glam::Vec3::new(1.0, 0.97, 0.9);
        let ratio = |elevation_deg: f32| {
            let e = elevation_deg.to_radians();
            let sun_dir = glam::Vec3::new(e.cos(), 0.0, e.sin());
            let sky = skylight(sun_rgb, sun_dir, 1.0);
            let beam = crate::shading::luminance(sun_rgb) * e.sin();
            sky / (sky + beam)
        };
        let at_24 = ratio(24.0);
        assert!((0.2..=0.4).contains(&at_24), "{at_24}");
        assert!(ratio(60.0) < at_24 && ratio(5.0) > at_24);
        assert!(ratio(60.0) >= 0.15, "{}", ratio(60.0));
    }
}
