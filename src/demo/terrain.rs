//! The demo host's ground: a height-field mesh around a centre, drawn first into colour and
//! depth with sun light and distance fog. A real simulator draws its own terrain; this one shows
//! what the sky needs from a host (a depth buffer drawn with [`Camera::projection`]).
//!
//! Heights come from any function of the local position (metres east/north to metres above mean
//! sea level): [`procedural_relief_m`] gives rolling hills; the CLI adds the ground elevation the
//! weather field interpolates from station elevations, so METAR bases (above ground) agree with it.

use glam::{DVec2, DVec3, Vec3};
use wgpu::util::DeviceExt;

use super::headless::DEPTH_FORMAT;
use crate::render::gpu_types::{GpuTerrainFrame, GpuTerrainVertex};
use crate::render::{Camera, CloudShadowMap, RenderError};

/// A square grid of heights, plain data.
#[derive(Debug, Clone, PartialEq)]
pub struct HeightField {
    /// Centre of the grid, metres east/north.
    pub centre_m: DVec2,
    /// Side of the square, metres.
    pub size_m: f64,
    /// Samples per side (at least 2).
    pub samples: u32,
    /// Heights above mean sea level, metres, row-major from the south-west corner.
    pub heights_m: Vec<f32>,
}

impl HeightField {
    /// Samples `height_m(point)` on a `samples` x `samples` grid.
    pub fn from_fn(
        centre_m: DVec2,
        size_m: f64,
        samples: u32,
        height_m: impl Fn(DVec2) -> f64,
    ) -> Self {
        let samples = samples.max(2);
        let step = size_m / (samples - 1) as f64;
        let origin = centre_m - DVec2::splat(size_m / 2.0);
        let heights_m = (0..samples)
            .flat_map(|j| (0..samples).map(move |i| (i, j)))
            .map(|(i, j)| height_m(origin + DVec2::new(i as f64, j as f64) * step) as f32)
            .collect();
        Self {
            centre_m,
            size_m,
            samples,
            heights_m,
        }
    }

    /// A square 16-bit greyscale PNG elevation file covering `size_m` around `centre_m`: the top
    /// row is the northern edge, value 0 is `min_m` and 65535 is `max_m` metres above mean sea
    /// level.
    pub fn from_png16(
        path: &std::path::Path,
        centre_m: DVec2,
        size_m: f64,
        min_m: f64,
        max_m: f64,
    ) -> Result<Self, RenderError> {
        let bad = |message: String| RenderError::Elevation {
            path: path.display().to_string(),
            message,
        };
        let img = image::open(path).map_err(|e| bad(e.to_string()))?;
        let image::DynamicImage::ImageLuma16(grey) = img else {
            return Err(bad("not a 16-bit greyscale PNG".into()));
        };
        let (w, h) = grey.dimensions();
        if w != h || w < 2 {
            return Err(bad(format!(
                "{w} x {h} pixels; needs a square of at least 2 x 2"
            )));
        }
        let scale = (max_m - min_m) / 65_535.0;
        let heights_m = (0..h)
            .rev()
            .flat_map(|row| (0..w).map(move |col| (col, row)))
            .map(|(col, row)| (min_m + grey.get_pixel(col, row)[0] as f64 * scale) as f32)
            .collect();
        Ok(Self {
            centre_m,
            size_m,
            samples: w,
            heights_m,
        })
    }

    /// Height at a grid sample.
    fn at(&self, i: u32, j: u32) -> f32 {
        self.heights_m[(j.min(self.samples - 1) * self.samples + i.min(self.samples - 1)) as usize]
    }

    /// Height at a local point (bilinear; clamped to the edge outside the grid).
    pub fn height_at_m(&self, point_m: DVec2) -> f64 {
        let step = self.size_m / (self.samples - 1) as f64;
        let g = (point_m - self.centre_m + DVec2::splat(self.size_m / 2.0)) / step;
        let max = (self.samples - 1) as f64;
        let (x, y) = (g.x.clamp(0.0, max), g.y.clamp(0.0, max));
        let (i, j) = (x.floor() as u32, y.floor() as u32);
        let (fx, fy) = ((x - i as f64) as f32, (y - j as f64) as f32);
        let a = self.at(i, j) + (self.at(i + 1, j) - self.at(i, j)) * fx;
        let b = self.at(i, j + 1) + (self.at(i + 1, j + 1) - self.at(i, j + 1)) * fx;
        (a + (b - a) * fy) as f64
    }

    /// Mesh vertices relative to `(centre, 0)` and triangle indices.
    pub fn mesh(&self) -> (Vec<GpuTerrainVertex>, Vec<u32>) {
        let n = self.samples;
        let step = (self.size_m / (n - 1) as f64) as f32;
        let half = (self.size_m / 2.0) as f32;
        let mut vertices = Vec::with_capacity((n * n) as usize);
        for j in 0..n {
            for i in 0..n {
                let h = self.at(i, j);
                let dx = self.at(i + 1, j) - self.at(i.saturating_sub(1), j);
                let dy = self.at(i, j + 1) - self.at(i, j.saturating_sub(1));
                let normal = Vec3::new(-dx, -dy, 2.0 * step).normalize();
                vertices.push(GpuTerrainVertex {
                    position_m: [i as f32 * step - half, j as f32 * step - half, h],
                    height_m: h,
                    normal: normal.extend(0.0).to_array(),
                });
            }
        }
        let mut indices = Vec::with_capacity(((n - 1) * (n - 1) * 6) as usize);
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let a = j * n + i;
                indices.extend_from_slice(&[a, a + 1, a + n, a + 1, a + n + 1, a + n]);
            }
        }
        (vertices, indices)
    }
}

fn hash2(i: i64, j: i64, seed: u32) -> f64 {
    let mut h = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (j as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
        ^ seed as u64;
    h ^= h >> 31;
    h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    h ^= h >> 29;
    (h >> 11) as f64 / (1u64 << 53) as f64
}

fn value_noise(p: DVec2, seed: u32) -> f64 {
    let (i, j) = (p.x.floor() as i64, p.y.floor() as i64);
    let (fx, fy) = (p.x - i as f64, p.y - j as f64);
    let (sx, sy) = (fx * fx * (3.0 - 2.0 * fx), fy * fy * (3.0 - 2.0 * fy));
    let a = hash2(i, j, seed) + (hash2(i + 1, j, seed) - hash2(i, j, seed)) * sx;
    let b = hash2(i, j + 1, seed) + (hash2(i + 1, j + 1, seed) - hash2(i, j + 1, seed)) * sx;
    a + (b - a) * sy - 0.5
}

/// Rolling procedural relief, metres (about +-`amplitude_m`), a pure function of position.
pub fn procedural_relief_m(point_m: DVec2, amplitude_m: f64, seed: u32) -> f64 {
    let mut sum = 0.0;
    let mut freq = 1.0 / 9_000.0;
    let mut amp = amplitude_m;
    for octave in 0..5 {
        sum += value_noise(point_m * freq, seed.wrapping_add(octave)) * amp;
        freq *= 2.1;
        amp *= 0.45;
    }
    sum
}

/// The demo terrain on the GPU.
pub struct Terrain {
    pipeline: wgpu::RenderPipeline,
    frame_buffer: wgpu::Buffer,
    layout: wgpu::BindGroupLayout,
    shadow_sampler: wgpu::Sampler,
    /// Its uniform and the sky's shadow map of this frame (made by [`Self::prepare`]).
    frame_group: Option<wgpu::BindGroup>,
    vertex_buffer: wgpu::Buffer,
    index_buffer: wgpu::Buffer,
    index_count: u32,
    centre_m: DVec2,
}

/// Light and fog for one terrain frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TerrainLight {
    /// Unit vector towards the sun.
    pub sun_dir: Vec3,
    /// Sun colour (the time-of-day directional colour).
    pub sun_rgb: Vec3,
    /// Ambient light factor.
    pub ambient: f32,
    /// Fog colour (the sky's horizon colour).
    pub fog_rgb: Vec3,
    /// The haze along view rays ([`crate::render::Sky::ground_haze`]).
    pub haze: crate::shading::AltitudeHaze,
    /// The camera's distance from the Earth's centre, metres (0: a flat ground;
    /// [`crate::render::earth::EarthSettings::camera_radius_m`]).
    pub camera_radius_m: f32,
}

impl Terrain {
    /// Uploads the mesh and builds the pipeline for `colour_format`.
    pub fn new(
        device: &wgpu::Device,
        colour_format: wgpu::TextureFormat,
        field: &HeightField,
    ) -> Self {
        let (vertices, indices) = field.mesh();
        let module = device.create_shader_module(wgpu::include_wgsl!("../../shaders/terrain.wgsl"));
        let frame_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("host.terrain_frame"),
            size: std::mem::size_of::<GpuTerrainFrame>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("host.terrain_layout"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                // The sky's cloud shadow map (optical depth, R16Float) and a linear sampler
                // clamped to its edge.
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let shadow_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("host.terrain_shadow_sampler"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("host.terrain"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        const ATTRS: [wgpu::VertexAttribute; 3] =
            wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32, 2 => Float32x4];
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("host.terrain"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_terrain"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: std::mem::size_of::<GpuTerrainVertex>() as u64,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &ATTRS,
                })],
            },
            primitive: wgpu::PrimitiveState {
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_terrain"),
                compilation_options: Default::default(),
                targets: &[Some(colour_format.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        let vertex_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("host.terrain_vertices"),
            contents: bytemuck::cast_slice(&vertices),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let index_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("host.terrain_indices"),
            contents: bytemuck::cast_slice(&indices),
            usage: wgpu::BufferUsages::INDEX,
        });
        Self {
            pipeline,
            frame_buffer,
            layout,
            shadow_sampler,
            frame_group: None,
            vertex_buffer,
            index_buffer,
            index_count: indices.len() as u32,
            centre_m: field.centre_m,
        }
    }

    /// Writes this frame's uniforms and binds the sky's cloud shadow map of this frame
    /// (`shadows`: [`crate::render::Sky::cloud_shadows`]), which dims the ground's sunlight.
    pub fn prepare(
        &mut self,
        (device, queue): (&wgpu::Device, &wgpu::Queue),
        camera: &Camera,
        light: &TerrainLight,
        shadows: &CloudShadowMap,
    ) {
        let origin_rel =
            (DVec3::new(self.centre_m.x, self.centre_m.y, 0.0) - camera.position_m).as_vec3();
        let frame = GpuTerrainFrame {
            view_proj: camera.view_proj_relative().to_cols_array_2d(),
            origin_rel: origin_rel
                .extend(camera.position_m.z as f32 - light.haze.base_msl_m)
                .to_array(),
            sun_dir: light.sun_dir.extend(light.ambient).to_array(),
            sun_rgb: light.sun_rgb.extend(1.0).to_array(),
            fog_rgb: light.fog_rgb.extend(light.camera_radius_m).to_array(),
            haze: light.haze.to_gpu(),
            shadow_uv: shadows.uv_from_camera_relative.to_cols_array_2d(),
        };
        queue.write_buffer(&self.frame_buffer, 0, bytemuck::bytes_of(&frame));
        self.frame_group = Some(device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("host.terrain_group"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: self.frame_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(shadows.view),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::Sampler(&self.shadow_sampler),
                },
            ],
        }));
    }

    /// Clears colour and depth and draws the ground.
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        colour_view: &wgpu::TextureView,
        depth_view: &wgpu::TextureView,
    ) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("host.terrain"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: colour_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        let Some(group) = &self.frame_group else {
            // Not prepared yet: the cleared target only.
            return;
        };
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, group, &[]);
        pass.set_vertex_buffer(0, self.vertex_buffer.slice(..));
        pass.set_index_buffer(self.index_buffer.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..self.index_count, 0, 0..1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn height_field_samples_and_interpolates() {
        let f = HeightField::from_fn(DVec2::new(1000.0, 0.0), 200.0, 3, |p| p.x * 0.1);
        // Samples at x = 900, 1000, 1100.
        assert_eq!(&f.heights_m[0..3], &[90.0, 100.0, 110.0]);
        assert!((f.height_at_m(DVec2::new(950.0, 20.0)) - 95.0).abs() < 1e-4);
        assert!((f.height_at_m(DVec2::new(5000.0, 0.0)) - 110.0).abs() < 1e-4);
        let (v, i) = f.mesh();
        assert_eq!((v.len(), i.len()), (9, 24));
        assert!(
            v[4].normal[0] < 0.0,
            "slope up to the east tilts the normal west"
        );
    }

    #[test]
    fn png16_elevation_file_reads_north_up() {
        let dir = std::env::temp_dir().join(format!("skycast-png16-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("dem.png");
        // 2 x 2: north row 0 and 65535, south row 32768 and 0.
        let img = image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_raw(
            2,
            2,
            vec![0, 65_535, 32_768, 0],
        )
        .unwrap();
        img.save(&path).unwrap();
        let f = HeightField::from_png16(&path, DVec2::ZERO, 1000.0, 100.0, 1100.0).unwrap();
        // South-west first: (SW, SE, NW, NE).
        let expect = [100.0 + 32_768.0 / 65_535.0 * 1000.0, 100.0, 100.0, 1100.0];
        for (got, want) in f.heights_m.iter().zip(expect) {
            assert!((*got as f64 - want).abs() < 0.01, "{:?}", f.heights_m);
        }
        assert!((f.height_at_m(DVec2::new(500.0, 500.0)) - 1100.0).abs() < 0.01);
        let rgb = image::RgbImage::new(2, 2);
        rgb.save(&path).unwrap();
        let err = HeightField::from_png16(&path, DVec2::ZERO, 1000.0, 0.0, 1.0)
            .unwrap_err()
            .to_string();
        assert!(err.contains("dem.png") && err.contains("16-bit"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn relief_is_deterministic_and_bounded() {
        let p = DVec2::new(12_345.0, -6_789.0);
        assert_eq!(
            procedural_relief_m(p, 300.0, 7),
            procedural_relief_m(p, 300.0, 7)
        );
        for k in 0..200 {
            let h = procedural_relief_m(DVec2::new(k as f64 * 731.0, k as f64 * -377.0), 300.0, 7);
            assert!(h.abs() < 300.0, "{h}");
        }
    }
}
