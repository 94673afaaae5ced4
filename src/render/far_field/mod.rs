//! The far field: the clouds beyond the sprites and the impostor ring, out to the horizon of
//! the camera's altitude (docs/src/horizon.md). In: a [`FarMap`] (the weather field on a coarse
//! grid, `src/clouds/far_map.rs`, built on the CPU a few rows a frame) and the frame's camera and
//! light. Out: one pass (`shaders/far_field.wgsl`) drawn before the ring into the same target,
//! over the band of elevations where its clouds can show (a ring of [`BAND_SEGMENTS`] quads
//! around the camera, not the whole screen: [`band_elevations`]), which meets two curved layers (the low and middle clouds, the high ones) on the
//! round Earth ([`super::earth`]), cuts them into clouds with a world-anchored noise thresholded
//! by the map's cover, and fades them in over the band where the sprites and the ring fade out.
//! The map lives in one small texture (three RGBA half-float layers a cell: the two layers and
//! their types' looks, and three more for the map of the weather before while a new weather
//! crossfades in: 96 x 96 cells of 10 km are 442 KB). Settings: `[far_field]` of
//! `config/render.toml`.

use glam::{DVec3, Vec3};
use serde::{Deserialize, Serialize};

use crate::clouds::far_map::FarMap;
use crate::shading::TimeOfDay;

use super::pipeline::{PassDesc, SceneDepth, premultiplied_over};
use plan::{FarFrame, MapPlace, crossfade_progress};

// The frame's uniform from the map's place, the camera and the light: plain data.
mod plan;

/// The far field's shader.
const WGSL: &str = include_str!("../../../shaders/far_field.wgsl");

/// Quads of the band the pass is drawn over, around the horizon (keep in sync with
/// `BAND_SEGMENTS` in `shaders/far_field.wgsl`).
pub const BAND_SEGMENTS: u32 = 64;

/// Radians the band is widened by on each side: its quads' edges are straight on the screen
/// (great circles) where the band's are not (one 64th of a turn bends them by under 0.03
/// degrees at 20 degrees from the horizon), and a pixel's footprint.
const BAND_MARGIN_RAD: f32 = 0.01;

/// The band of elevations (radians above the camera's level plane, lowest first) where the far
/// field's layers can show: for each layer that has cloud, the `(lowest base, highest top)`
/// metres above sea level in `layers`, the points between those heights from `s_min_m` to
/// `s_max_m` horizontally from the camera (at `camera_m` above sea level; `camera_radius_m` its
/// distance from the Earth's centre, 0 for the flat frame), placed on the round Earth as the
/// shader meets them. `None` when no layer has cloud. The pass is drawn over this band alone:
/// from FL350 over a low layer it is about a sixth of the screen's height, where the
/// full-screen pass it replaces ran the shader on every pixel.
pub fn band_elevations(
    camera_m: f32,
    camera_radius_m: f32,
    layers: &[(f32, f32)],
    (s_min_m, s_max_m): (f32, f32),
) -> Option<(f32, f32)> {
    let elevation = |s: f32, h: f32| {
        let p = super::earth::curved_rel(Vec3::new(s, 0.0, h - camera_m), camera_radius_m);
        p.z.atan2(p.x)
    };
    let mut band: Option<(f32, f32)> = None;
    for &(low, high) in layers {
        // A height's elevation falls from the nearest point, or rises to the layer's horizon
        // (below the camera) and falls again beyond it: its extremes are at the ends of the
        // range or at that horizon. Heights between the lowest and the highest lie between.
        let mut samples: Vec<(f32, f32)> = [s_min_m, s_max_m]
            .iter()
            .flat_map(|&s| [(s, low), (s, high)])
            .collect();
        if camera_radius_m > 0.0 && high < camera_m {
            let r = camera_radius_m - camera_m + high;
            let s_horizon = camera_radius_m * (r / camera_radius_m).clamp(-1.0, 1.0).acos();
            if (s_min_m..=s_max_m).contains(&s_horizon) {
                samples.push((s_horizon, high));
            }
        }
        for (s, h) in samples {
            let e = elevation(s, h);
            band = Some(band.map_or((e, e), |(lo, hi)| (lo.min(e), hi.max(e))));
        }
    }
    let half_pi = std::f32::consts::FRAC_PI_2;
    band.map(|(lo, hi)| {
        (
            (lo - BAND_MARGIN_RAD).max(-half_pi),
            (hi + BAND_MARGIN_RAD).min(half_pi),
        )
    })
}

/// Settings of the far field (`[far_field]` of `config/render.toml`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FarFieldSettings {
    /// Draw the far field (false: the clouds end where the sprites and the ring do).
    pub enabled: bool,
    /// Cells per side of the cloud map.
    pub texels: u32,
    /// Side of a cell, metres.
    pub texel_m: f64,
    /// A new map is built after the camera moved this many cells from the shown one's centre.
    pub move_texels: f64,
    /// Rows of a new map built a frame (at once for an offline frame, clouds synchronous).
    pub rows_per_frame: u32,
    /// The hand-over: the far field fades in, the sprites and the ring fade out, between these
    /// horizontal distances from the camera, metres.
    pub fade_start_m: f32,
    /// See `fade_start_m`.
    pub fade_end_m: f32,
    /// Size of the lumps of heaped (cumuliform) layers, metres; sheets' patches are 8 times it.
    /// Also the cell of the lattice the heaped layers' puffs stand on, where a pixel resolves
    /// them (a puff or none a cell, anywhere in it).
    pub heaped_scale_m: f32,
    /// The heaped layers' puffs' smallest and largest diameter, metres, at a cover they fill
    /// without growing (the near cumulus' `cloud_size_m`, config/cloud_types.toml).
    pub heaped_cloud_size_m: [f32; 2],
    /// A puff's greatest height over its diameter (the cumulus' `max_height_over_size`); the
    /// layer's top caps it.
    pub heaped_height_over_size: f32,
}

impl Default for FarFieldSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            texels: 96,
            texel_m: 10_000.0,
            move_texels: 2.0,
            rows_per_frame: 1,
            fade_start_m: 42_000.0,
            fade_end_m: 60_000.0,
            heaped_scale_m: 2_000.0,
            heaped_cloud_size_m: [800.0, 1600.0],
            heaped_height_over_size: 1.0,
        }
    }
}

impl FarFieldSettings {
    /// The first field that is out of range and why, if any.
    pub fn invalid_field(&self) -> Option<(&'static str, String)> {
        if !(2..=1024).contains(&self.texels) {
            return Some(("far_field.texels", "must be 2..=1024".into()));
        }
        if !(self.texel_m >= 100.0 && self.texel_m.is_finite()) {
            return Some(("far_field.texel_m", "must be at least 100 metres".into()));
        }
        if !(self.move_texels >= 0.0 && self.move_texels.is_finite()) {
            return Some(("far_field.move_texels", "must be 0 or more".into()));
        }
        if self.rows_per_frame == 0 {
            return Some(("far_field.rows_per_frame", "must be at least 1".into()));
        }
        if !(self.fade_start_m >= 0.0 && self.fade_end_m > self.fade_start_m) {
            return Some((
                "far_field.fade_end_m",
                "must be above fade_start_m, which must be 0 or more".into(),
            ));
        }
        if !(self.heaped_scale_m >= 10.0 && self.heaped_scale_m.is_finite()) {
            return Some((
                "far_field.heaped_scale_m",
                "must be at least 10 metres".into(),
            ));
        }
        let [small, large] = self.heaped_cloud_size_m;
        if !(small >= 10.0 && large >= small && large <= 0.9 * self.heaped_scale_m) {
            return Some((
                "far_field.heaped_cloud_size_m",
                "must be [smallest, largest], at least 10 metres and at most 0.9 heaped_scale_m"
                    .into(),
            ));
        }
        if !(self.heaped_height_over_size > 0.0 && self.heaped_height_over_size <= 20.0) {
            return Some((
                "far_field.heaped_height_over_size",
                "must be above 0 and at most 20".into(),
            ));
        }
        None
    }

    /// The share of a heaped layer its puffs cover on average when every cell holds one (their
    /// overlaps counted twice): a disc's mean area over the cell's, the diameters spread evenly
    /// between the smallest and the largest.
    pub fn puff_share(&self) -> f32 {
        let [a, b] = self.heaped_cloud_size_m;
        let mean_square = (a * a + a * b + b * b) / 3.0;
        std::f32::consts::FRAC_PI_4 * mean_square / (self.heaped_scale_m * self.heaped_scale_m)
    }

    /// The noise's period, metres: a power of two of the heaped and the sheet cells (1024 and
    /// 256 of them; the shader wraps its octaves with a mask).
    fn noise_period_m(&self) -> f64 {
        1024.0 * f64::from(self.heaped_scale_m)
    }
}

/// The far field's uniform. Keep in sync with `FarField` in `shaders/far_field.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuFarField {
    /// xy: the map's centre relative to the camera, metres; z: the map's side, metres; w: cells
    /// per side.
    pub centre_rel_size: [f32; 4],
    /// xy: the map's centre in the noise's period, metres; z, w: the hand-over band, metres.
    pub noise_fade: [f32; 4],
    /// rgb: a cloud top's colour in the sun; w: the camera's height above sea level, metres.
    pub lit_rgb: [f32; 4],
    /// rgb: a cloud base's colour; w: the heaped layers' noise scale, metres.
    pub shade_rgb: [f32; 4],
    /// x, y: the low and high layers' mean middle height above sea level, metres; z: the
    /// sheets' noise scale, metres; w: the noise's period, metres.
    pub heights: [f32; 4],
    /// x: how far the map has faded in, 0..=1; y, z: the band of elevations the pass is drawn
    /// over, radians (lowest first; equal: nothing to draw); w: how far the map has crossfaded
    /// from the one before it (texture layers 2 and 3), 0..=1.
    pub fade: [f32; 4],
    /// The heaped layers' puffs: x, y: their smallest and largest diameter, metres; z: their
    /// greatest height over their diameter; w: [`FarFieldSettings::puff_share`].
    pub puffs: [f32; 4],
    /// rgb: a sheet's top's ambient light in the hue of the near decks' textures (times its
    /// type's top level's grey, from the map).
    pub sheet_ambient_rgb: [f32; 4],
    /// rgb: a sheet's top's sunlight, in that hue.
    pub sheet_sun_rgb: [f32; 4],
}
const _: () = assert!(std::mem::size_of::<GpuFarField>() == 144);

/// What the far field needs of the sky's layouts and targets.
pub(super) struct FarFieldShared<'a> {
    /// Group 0 of the passes into the host's targets.
    pub host_frame_layout: &'a wgpu::BindGroupLayout,
    /// Group 0 of the passes into the off-screen cloud target.
    pub offscreen_frame_layout: &'a wgpu::BindGroupLayout,
    /// The host's colour format and samples.
    pub targets: super::targets::HostTargets,
    /// The off-screen cloud target's colour targets, where the clouds are drawn below full
    /// resolution.
    pub cloud_targets: Option<&'a [(wgpu::TextureFormat, Option<wgpu::BlendState>)]>,
    /// The mean colour of the sheet's foggy textures, which the near decks' sprites are drawn
    /// with ([`SpriteSheet::mean_rgb`](super::SpriteSheet::mean_rgb)): its hue tints the far
    /// field's sheets.
    pub sheet_rgb: Vec3,
}

/// The hue of a mean texture colour: the colour over its luminance (white where it is black).
fn hue(rgb: Vec3) -> Vec3 {
    let luminance = crate::shading::luminance(rgb);
    if luminance > 1e-3 {
        rgb / luminance
    } else {
        Vec3::ONE
    }
}

/// The map on the GPU, and where it lies.
struct MapOnGpu {
    texture: wgpu::Texture,
    group: wgpu::BindGroup,
    place: MapPlace,
}

/// The far field's pipelines, map and uniform (module docs).
pub struct FarField {
    settings: FarFieldSettings,
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
    offscreen_pipeline: Option<wgpu::RenderPipeline>,
    sampler: wgpu::Sampler,
    uniform: wgpu::Buffer,
    map: Option<MapOnGpu>,
    /// When the shown map began to fade in (the sky's clock, seconds) and over how long.
    fade: Option<(f64, f64)>,
    /// The map shown (its cells, kept to crossfade from when the weather changes).
    shown: Option<FarMap>,
    /// The map of the weather before, while the shown one crossfades from it: its cells (where
    /// the shown map's are), when the crossfade began (the sky's clock) and over how long.
    crossfade: Option<(FarMap, f64, f64)>,
    /// The hue of the near decks' textures ([`FarFieldShared::sheet_rgb`]).
    sheet_hue: Vec3,
}

impl FarField {
    /// Builds the pipelines and the uniform (the map comes with [`Self::set_map`]).
    pub(super) fn new(
        device: &wgpu::Device,
        settings: FarFieldSettings,
        shared: &FarFieldShared,
    ) -> Self {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("far_field.layout"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2Array,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    // The vertex stage reads the band's elevations. A read-only storage buffer,
                    // not a uniform: lavapipe specialises a shader on the uniform values its
                    // branches test (the camera's height, new every frame of a climb) and keeps
                    // every copy (tests/memory.rs).
                    visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: true },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
            ],
        });
        let over = Some(premultiplied_over());
        let direct = super::pipeline::pipeline(
            device,
            &PassDesc {
                label: "far_field.layers",
                wgsl: WGSL,
                vs: "vs_far_field",
                fs: "fs_far_field",
                bind_groups: &[Some(shared.host_frame_layout), Some(&layout)],
                buffers: &[],
                targets: &[(shared.targets.colour_format, over)],
                samples: shared.targets.sample_count,
                scene: SceneDepth::host(shared.targets.sample_count),
            },
        );
        let offscreen_pipeline = shared.cloud_targets.map(|targets| {
            super::pipeline::pipeline(
                device,
                &PassDesc {
                    label: "far_field.layers_offscreen",
                    wgsl: WGSL,
                    vs: "vs_far_field",
                    fs: "fs_far_field_offscreen",
                    bind_groups: &[Some(shared.offscreen_frame_layout), Some(&layout)],
                    buffers: &[],
                    targets,
                    samples: 1,
                    scene: SceneDepth::FarthestMetres,
                },
            )
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("far_field.sampler"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("far_field.uniform"),
            size: std::mem::size_of::<GpuFarField>() as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self {
            settings,
            layout,
            pipeline: direct,
            offscreen_pipeline,
            sampler,
            uniform,
            map: None,
            fade: None,
            shown: None,
            crossfade: None,
            sheet_hue: hue(shared.sheet_rgb),
        }
    }

    /// The settings it was made with.
    pub fn settings(&self) -> &FarFieldSettings {
        &self.settings
    }

    /// Whether it draws (enabled, with a map).
    pub fn is_drawn(&self) -> bool {
        self.settings.enabled && self.map.is_some()
    }

    /// Switches it on or off at run time (the sprites and the ring then fade as before).
    pub fn set_enabled(&mut self, enabled: bool) {
        self.settings.enabled = enabled;
    }

    /// The hand-over band (start, end metres) the sprites and the ring fade out over, while the
    /// far field is drawn.
    pub fn hand_over_m(&self) -> Option<(f32, f32)> {
        self.is_drawn()
            .then_some((self.settings.fade_start_m, self.settings.fade_end_m))
    }

    /// Uploads a new map (a texture of its size; the old one is dropped). `(now_s, fade_in_s,
    /// crossfade_s)`: the sky's clock, how long the first map takes to fade in, and how long a
    /// map of another weather ([`FarMap::weather_epoch`]) takes to crossfade from the one shown
    /// (0: at once). A map that only moved with the camera shows at once: its cells keep
    /// their weather.
    pub(super) fn set_map(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        map: &FarMap,
        (now_s, fade_in_s, crossfade_s): (f64, Option<f64>, f64),
    ) {
        let n = map.texels;
        if map.cells.len() != (n * n) as usize {
            log::warn!(
                "far field: a map of {} cells for {n} x {n}",
                map.cells.len()
            );
            return;
        }
        // A crossfade that has ended is forgotten: its map no longer widens the band drawn.
        if self
            .crossfade
            .as_ref()
            .is_some_and(|(_, start, over)| crossfade_progress(now_s, *start, *over) >= 1.0)
        {
            self.crossfade = None;
        }
        match &self.shown {
            None => {
                self.fade = fade_in_s.map(|s| (now_s, s));
                self.crossfade = None;
            }
            Some(shown) if shown.weather_epoch != map.weather_epoch => {
                // From what shows now: a crossfade under way goes on from where it has come.
                let now = match &self.crossfade {
                    Some((old, start, over)) => {
                        old.blended_towards(shown, crossfade_progress(now_s, *start, *over))
                    }
                    None => shown.clone(),
                };
                self.crossfade = Some((now, now_s, crossfade_s));
            }
            Some(_) => {}
        }
        // The map from before where the new one's cells are (a crossfade outlives moves).
        if let Some((old, _, _)) = &mut self.crossfade {
            *old = old.moved_to(map);
        }
        self.shown = Some(map.clone());
        let before = self.crossfade.as_ref().map_or(map, |(old, _, _)| old);
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("far_field.map"),
            size: wgpu::Extent3d {
                width: n,
                height: n,
                depth_or_array_layers: 6,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba16Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        // Texture layers 0 and 1: the map's low and high layers; 2 and 3: the map crossfaded
        // from (the map again without a crossfade); 4 and 5: the two maps' layers' looks. The
        // band and the layers' mean heights are those of both: clouds fading out are drawn too.
        let mut sums = [(0.0f64, 0.0f64); 2];
        let mut extents = Vec::new();
        for layer in 0..2usize {
            // Cells the shader takes for cloud (its cover above 0.01).
            let clouded = [map, before]
                .into_iter()
                .flat_map(|m| &m.cells)
                .filter(|c| c[layer * 4] > 0.01);
            let extent = clouded.fold(None, |e: Option<(f32, f32)>, c| {
                let (base, top) = (c[layer * 4 + 1], c[layer * 4 + 2]);
                Some(e.map_or((base, top), |(lo, hi)| (lo.min(base), hi.max(top))))
            });
            extents.extend(extent);
        }
        for z in 0..6u32 {
            let (source, at) = match z {
                0 | 1 => (map, z as usize * 4),
                2 | 3 => (before, (z - 2) as usize * 4),
                4 => (map, 8),
                _ => (before, 8),
            };
            let data: Vec<u16> = source
                .cells
                .iter()
                .flat_map(|c| {
                    if at < 8 {
                        let (s, w) = &mut sums[at / 4];
                        *s += f64::from(c[at] * 0.5 * (c[at + 1] + c[at + 2]));
                        *w += f64::from(c[at]);
                    }
                    c[at..at + 4]
                        .iter()
                        .map(|&v| half::f16::from_f32(v).to_bits())
                })
                .collect();
            queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d { x: 0, y: 0, z },
                    aspect: wgpu::TextureAspect::All,
                },
                bytemuck::cast_slice(&data),
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(n * 8),
                    rows_per_image: Some(n),
                },
                wgpu::Extent3d {
                    width: n,
                    height: n,
                    depth_or_array_layers: 1,
                },
            );
        }
        // A layer with no cloud anywhere goes 10,000 km up: every ray leaves the map before it
        // meets it, and the pass spends nothing on it.
        let mean = |(s, w): (f64, f64), _: f64| (if w > 0.0 { s / w } else { 1.0e7 }) as f32;
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("far_field.group"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Sampler(&self.sampler),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: self.uniform.as_entire_binding(),
                },
            ],
        });
        self.map = Some(MapOnGpu {
            texture,
            group,
            place: MapPlace {
                centre_m: map.centre_m,
                side_m: f64::from(n) * map.texel_m,
                texels: n,
                heights: [mean(sums[0], 1500.0), mean(sums[1], 9000.0)],
                extents,
            },
        });
    }

    /// This frame's uniform for a camera at `camera_m` (`camera_radius_m` from the Earth's
    /// centre, 0 for the flat frame) under the light `light`, at `now_s` of the sky's clock;
    /// `None` before the first map. CPU only ([`plan::plan`]): [`Self::upload`] writes it.
    pub(super) fn plan(
        &self,
        camera: (DVec3, f32),
        light: &TimeOfDay,
        now_s: f64,
    ) -> Option<GpuFarField> {
        let map = self.map.as_ref()?;
        let frame = FarFrame {
            settings: &self.settings,
            map: &map.place,
            fade: self.fade,
            crossfade: (self.crossfade.as_ref()).map(|(_, start, over)| (*start, *over)),
            sheet_hue: self.sheet_hue,
        };
        Some(plan::plan(&frame, camera, light, now_s))
    }

    /// Writes a planned uniform ([`Self::plan`]).
    pub(super) fn upload(&self, queue: &wgpu::Queue, plan: &GpuFarField) {
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(plan));
    }

    /// Draws the far field into `pass` (the sky pass, or the off-screen cloud pass when
    /// `offscreen`), if it is drawn.
    pub(super) fn draw(&self, pass: &mut wgpu::RenderPass, offscreen: bool) {
        let Some(map) = self.map.as_ref().filter(|_| self.settings.enabled) else {
            return;
        };
        let p = match (offscreen, &self.offscreen_pipeline) {
            (true, Some(p)) => p,
            _ => &self.pipeline,
        };
        pass.set_pipeline(p);
        pass.set_bind_group(1, &map.group, &[]);
        pass.draw(0..6 * BAND_SEGMENTS, 0..1);
    }

    /// Bytes of GPU memory it holds (the map texture and the uniform).
    pub fn gpu_bytes(&self) -> u64 {
        self.uniform.size()
            + self.map.as_ref().map_or(0, |m| {
                let e = m.texture.size();
                u64::from(e.width) * u64::from(e.height) * u64::from(e.depth_or_array_layers) * 8
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The elevation of a point `s` metres along the Earth (at the camera's radius) and `h` above
    /// sea level, seen from a camera `c` above sea level: the sphere's own geometry in f64.
    fn sphere_elevation(s: f64, h: f64, c: f64) -> f64 {
        let r = 6_371_000.0;
        let theta = s / (r + c);
        let (x, z) = ((r + h) * theta.sin(), (r + h) * theta.cos() - (r + c));
        z.atan2(x)
    }

    /// The far field's sheets take the hue of the near decks' foggy textures: blue-grey, at
    /// the luminance of white.
    #[test]
    fn the_sheets_take_the_foggy_textures_hue() {
        let sheet = super::super::sprites::sheet::SpriteSheet::generated();
        let foggy = sheet.mean_rgb(crate::clouds::TextureCategory::Foggy.cells());
        let h = hue(foggy);
        assert!(foggy.min_element() > 0.3, "{foggy}");
        assert!(h.z > h.x * 1.02, "not blue-grey: {h}");
        let luminance = crate::shading::luminance(h);
        assert!((luminance - 1.0).abs() < 1e-5, "{luminance}");
        assert_eq!(hue(Vec3::ZERO), Vec3::ONE);
        assert_eq!(sheet.mean_rgb(20..24), Vec3::ZERO);
    }

    /// The shipped far field's heaped clouds are the near cumulus' size and shape: their
    /// diameters and height over diameter are cumulus mediocris' in config/cloud_types.toml.
    #[test]
    fn the_shipped_puffs_are_the_cumulus_of_the_cloud_types() {
        let shipped = crate::render::RenderSettings::default().far_field;
        let types = crate::clouds::CloudTypes::builtin();
        let cumulus = types.get(crate::weather::CloudType::CumulusMediocris);
        assert_eq!(shipped.heaped_cloud_size_m, cumulus.cloud_size_m);
        assert_eq!(
            shipped.heaped_height_over_size,
            cumulus.max_height_over_size
        );
        assert!(shipped.invalid_field().is_none());
        let mut too_big = shipped;
        too_big.heaped_cloud_size_m[1] = shipped.heaped_scale_m;
        assert_eq!(
            too_big.invalid_field().map(|f| f.0),
            Some("far_field.heaped_cloud_size_m")
        );
    }

    /// From FL350 over a layer from 1,000 to 3,000 m, out to 700 km: every point of the layer
    /// the pass may draw lies inside the band (its highest near the layer's own horizon, 330 km
    /// out), and the band is a narrow strip below the horizon, not the screen.
    #[test]
    fn the_band_holds_every_point_of_the_layers_and_little_else() {
        let camera = 10_668.0f32;
        let rc = 6_371_000.0 + camera;
        let (lo, hi) =
            band_elevations(camera, rc, &[(1000.0, 3000.0)], (37_600.0, 700_000.0)).unwrap();
        for k in 0..=2000 {
            let s = 37_600.0 + (700_000.0 - 37_600.0) * f64::from(k) / 2000.0;
            for h in [1000.0, 2000.0, 3000.0] {
                let e = sphere_elevation(s, h, f64::from(camera)) as f32;
                assert!(
                    e >= lo && e <= hi,
                    "{s} m out at {h} m: {} deg outside {} to {} deg",
                    e.to_degrees(),
                    lo.to_degrees(),
                    hi.to_degrees()
                );
            }
        }
        assert!(
            hi < -2f32.to_radians() && hi - lo < 16f32.to_radians(),
            "{lo} to {hi}"
        );
        assert!(band_elevations(camera, rc, &[], (37_600.0, 700_000.0)).is_none());
    }
}
