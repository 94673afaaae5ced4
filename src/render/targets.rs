//! The host's side of the frame, on the host's terms: the targets the sky draws into (colour
//! format, depth format, standard or reversed Z, sample count) and the view it draws from (the
//! host's own view and projection matrices). The sky never writes the host's depth; it reads it
//! as a texture to fade clouds into terrain, so it must know how the host's depth encodes
//! distance: [`SkyView::depth_to_view`] works that out from the host's projection, whatever its
//! convention (standard or reversed, finite or infinite far plane).

use glam::{DMat4, DVec3, Mat4};

use super::RenderError;
use super::camera::{Camera, Frustum};

/// What the host's colour and depth targets are. The defaults are a single-sample
/// `Rgba8UnormSrgb` colour target over a standard-Z `Depth32Float` depth. Give the sky the
/// host's own; [`HostTargets::validate`] says what it cannot use.
///
/// ```
/// use skycast::HostTargets;
///
/// // A simulator with reversed Z and 4x MSAA on a depth-stencil buffer:
/// let targets = HostTargets {
///     depth_format: wgpu::TextureFormat::Depth24PlusStencil8,
///     reversed_z: true,
///     sample_count: 4,
///     ..HostTargets::default()
/// };
/// assert!(targets.validate().is_ok());
/// assert_eq!(targets.background_depth(), 0.0); // what the host clears its depth to
/// assert!(HostTargets { sample_count: 2, ..targets }.validate().is_err());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HostTargets {
    /// Format of the colour target the sky draws into.
    pub colour_format: wgpu::TextureFormat,
    /// Format of the host's depth texture (created with `TEXTURE_BINDING`; a view of a
    /// depth-stencil format must select the depth aspect).
    pub depth_format: wgpu::TextureFormat,
    /// Reversed Z: the host clears depth to 0 and nearer is larger (common in flight simulators
    /// for their long view ranges).
    pub reversed_z: bool,
    /// Samples per pixel of the colour and depth targets (1 or 4, MSAA).
    pub sample_count: u32,
}

impl Default for HostTargets {
    fn default() -> Self {
        Self {
            colour_format: wgpu::TextureFormat::Rgba8UnormSrgb,
            depth_format: wgpu::TextureFormat::Depth32Float,
            reversed_z: false,
            sample_count: 1,
        }
    }
}

impl HostTargets {
    /// Checks what the sky can draw into and read: one clear error for anything else.
    pub fn validate(&self) -> Result<(), RenderError> {
        use wgpu::TextureFormat as F;
        let depth_ok = matches!(
            self.depth_format,
            F::Depth32Float | F::Depth24Plus | F::Depth16Unorm | F::Depth24PlusStencil8
        ) || self.depth_format == F::Depth32FloatStencil8;
        if !depth_ok {
            return Err(RenderError::Targets(format!(
                "depth format {:?} cannot be read by the sky (use Depth32Float, Depth24Plus, Depth16Unorm or a depth-stencil format's depth aspect)",
                self.depth_format
            )));
        }
        if self.colour_format.is_depth_stencil_format() {
            return Err(RenderError::Targets(format!(
                "colour format {:?} is a depth format",
                self.colour_format
            )));
        }
        if !matches!(self.sample_count, 1 | 4) {
            return Err(RenderError::Targets(format!(
                "sample count {} (the sky draws into 1 or 4 samples a pixel)",
                self.sample_count
            )));
        }
        Ok(())
    }

    /// Checks the projection a frame is drawn with against [`Self::reversed_z`]: a reversed
    /// projection maps the near plane to depth 1, a standard one to 0. A mismatch would draw a
    /// wrong sky without a word (the background where the host's ground is, clouds faded into
    /// the wrong depth), so it is an error naming both sides.
    pub fn check_projection(&self, projection: Mat4) -> Result<(), RenderError> {
        let reversed = maps_near_to_one(projection).ok_or_else(|| {
            RenderError::Targets(
                "the projection is not a perspective one: depth does not change along the view"
                    .to_string(),
            )
        })?;
        if reversed == self.reversed_z {
            return Ok(());
        }
        let says = |r: bool| {
            if r {
                "reversed (near at depth 1)"
            } else {
                "standard (near at depth 0)"
            }
        };
        Err(RenderError::Targets(format!(
            "HostTargets::reversed_z is {}: the sky expects depth {}, but the projection is {}",
            self.reversed_z,
            says(self.reversed_z),
            says(reversed)
        )))
    }

    /// Checks the host's colour and depth textures against these targets and against what the
    /// sky's pipelines were made for, before anything is recorded: the colour format, the depth
    /// format, the samples of each, the depth's `TEXTURE_BINDING` (the sky reads it), the two
    /// being the same size. Each mismatch names both sides; without the check wgpu's
    /// validation panics inside `record` or `encoder.finish()`.
    ///
    /// The textures' own formats are compared: a view in the other sRGB-ness of its texture
    /// (through `view_formats`) is taken on trust.
    pub fn check_textures(
        &self,
        colour: &wgpu::Texture,
        depth: &wgpu::Texture,
    ) -> Result<(), RenderError> {
        let err = |message: String| Err(RenderError::Targets(message));
        let (c, d) = (colour.format(), depth.format());
        if c != self.colour_format
            && c.remove_srgb_suffix() != self.colour_format.remove_srgb_suffix()
        {
            return err(format!(
                "the colour texture is {c:?} but HostTargets::colour_format (the sky's pipelines) is {:?}",
                self.colour_format
            ));
        }
        if d != self.depth_format {
            return err(format!(
                "the depth texture is {d:?} but HostTargets::depth_format (the sky's pipelines) is {:?}",
                self.depth_format
            ));
        }
        for (what, texture) in [("colour", colour), ("depth", depth)] {
            if texture.sample_count() != self.sample_count {
                return err(format!(
                    "the {what} texture has {} sample(s) a pixel but HostTargets::sample_count is {}",
                    texture.sample_count(),
                    self.sample_count
                ));
            }
        }
        if !depth.usage().contains(wgpu::TextureUsages::TEXTURE_BINDING) {
            return err(format!(
                "the depth texture's usage is {:?}, without TEXTURE_BINDING: the sky reads the host's depth as a texture (it never writes it)",
                depth.usage()
            ));
        }
        if !colour
            .usage()
            .contains(wgpu::TextureUsages::RENDER_ATTACHMENT)
        {
            return err(format!(
                "the colour texture's usage is {:?}, without RENDER_ATTACHMENT: the sky draws into it",
                colour.usage()
            ));
        }
        let (cs, ds) = (colour.size(), depth.size());
        if (cs.width, cs.height) != (ds.width, ds.height) {
            return err(format!(
                "the colour texture is {} x {} but the depth texture {} x {}",
                cs.width, cs.height, ds.width, ds.height
            ));
        }
        Ok(())
    }

    /// The depth value the host clears to: where nothing was drawn.
    pub fn background_depth(&self) -> f32 {
        if self.reversed_z { 0.0 } else { 1.0 }
    }
}

/// Where the sky is seen from this frame: the camera's position in the sky's east-north-up frame
/// (f64 metres, z above mean sea level) and the host's own matrices. A host that drives the
/// [`super::Sky`] itself gives one to [`super::Sky::prepare`] every frame; [`crate::SkySystem`]
/// makes it from the host's [`crate::HostCamera`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkyView {
    /// Camera position, metres east, north and above mean sea level.
    pub position_m: DVec3,
    /// The host's view matrix for camera-relative east-north-up positions: the rotation from
    /// (east, north, up) axes to the host's view space (its translation is ignored). A host
    /// whose world is y-up multiplies its view by the axis swap.
    pub view: Mat4,
    /// The host's projection matrix, clip depth in WebGPU's `[0, 1]`, standard or reversed.
    pub projection: Mat4,
}

/// Whether `projection` maps nearer points to larger depths (reversed Z: the near plane at 1),
/// from two points in front of the camera; `None` when depth does not change with distance.
pub fn maps_near_to_one(projection: Mat4) -> Option<bool> {
    // In front is where clip w is positive: -z for a right-handed view space, +z left-handed.
    let forward = if projection.z_axis.w <= 0.0 {
        -1.0
    } else {
        1.0
    };
    let depth = |metres: f32| {
        let clip = projection * glam::Vec4::new(0.0, 0.0, forward * metres, 1.0);
        clip.z / clip.w
    };
    let (near, far) = (depth(10.0), depth(10_000.0));
    (near.is_finite() && far.is_finite() && near != far).then_some(near > far)
}

impl SkyView {
    /// Projection times view for camera-relative positions.
    pub fn view_proj(&self) -> Mat4 {
        self.projection * self.view_rotation()
    }

    /// The view with its translation dropped: the sky works camera-relative.
    fn view_rotation(&self) -> Mat4 {
        let mut v = self.view;
        v.w_axis = glam::Vec4::W;
        v
    }

    /// The view volume, for culling whole blocks.
    pub fn frustum(&self) -> Frustum {
        Frustum::from_view_proj(self.view_proj())
    }

    /// How a depth value `d` of the host's projection becomes metres along the view axis:
    /// `-(a d + b) / (c d + e)` for `[a, b, c, e]` (the inverse projection's z and w rows; exact
    /// for any perspective projection, reversed or infinite included).
    pub fn depth_to_view(&self) -> [f32; 4] {
        let inv: DMat4 = self.projection.as_dmat4().inverse();
        [
            inv.z_axis.z as f32,
            inv.w_axis.z as f32,
            inv.z_axis.w as f32,
            inv.w_axis.w as f32,
        ]
    }
}

// Here rather than in `camera`, which stays a leaf that knows nothing of the host's view.
impl Camera {
    /// The camera as the sky takes a host's view: position and matrices.
    pub fn sky_view(&self) -> SkyView {
        self.into()
    }
}

impl From<&Camera> for SkyView {
    fn from(camera: &Camera) -> Self {
        Self {
            position_m: camera.position_m,
            view: camera.view_relative(),
            projection: camera.projection(),
        }
    }
}

impl From<Camera> for SkyView {
    fn from(camera: Camera) -> Self {
        Self::from(&camera)
    }
}

/// The host's depth as the sky's passes read it (group 0, binding 1): an unfilterable float
/// texture, multisampled when the host's targets are.
pub(super) fn frame_layout(device: &wgpu::Device, multisampled: bool) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(if multisampled {
            "sky.frame_layout_msaa"
        } else {
            "sky.frame_layout"
        }),
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
            wgpu::BindGroupLayoutEntry {
                binding: 1,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled,
                },
                count: None,
            },
        ],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn linear(view: &SkyView, d: f32) -> f32 {
        let [a, b, c, e] = view.depth_to_view();
        -(a * d + b) / (c * d + e)
    }

    #[test]
    fn depth_becomes_metres_for_standard_reversed_and_infinite_projections() {
        let camera = Camera {
            position_m: DVec3::ZERO,
            heading_deg: 0.0,
            pitch_deg: 0.0,
            fov_y_deg: 60.0,
            aspect: 1.5,
            near_m: 1.0,
            far_m: 100_000.0,
        };
        let fov = 60f32.to_radians();
        let reversed = glam::camera::rh::proj::directx::perspective(fov, 1.5, 100_000.0, 1.0);
        let infinite = glam::camera::rh::proj::directx::perspective_infinite_reverse(fov, 1.5, 1.0);
        for projection in [camera.projection(), reversed, infinite] {
            let view = SkyView {
                projection,
                ..SkyView::from(&camera)
            };
            for metres in [2.0f32, 150.0, 3_000.0, 40_000.0] {
                let clip = projection * glam::Vec4::new(0.0, 0.0, -metres, 1.0);
                let back = linear(&view, clip.z / clip.w);
                // Within what an f32 depth holds: standard Z at 40 km with a 1 m near plane
                // keeps about 40 m.
                assert!(
                    (back - metres).abs() < metres * 2.5e-3,
                    "{metres} m came back as {back}"
                );
            }
        }
    }

    #[test]
    fn the_depth_convention_is_read_from_the_projection() {
        let fov = 60f32.to_radians();
        let rh = glam::camera::rh::proj::directx::perspective(fov, 1.5, 1.0, 100_000.0);
        let reversed = glam::camera::rh::proj::directx::perspective(fov, 1.5, 100_000.0, 1.0);
        let infinite = glam::camera::rh::proj::directx::perspective_infinite_reverse(fov, 1.5, 0.5);
        let lh = glam::camera::lh::proj::directx::perspective(fov, 1.5, 1.0, 100_000.0);
        assert_eq!(maps_near_to_one(rh), Some(false));
        assert_eq!(maps_near_to_one(lh), Some(false));
        assert_eq!(maps_near_to_one(reversed), Some(true));
        assert_eq!(maps_near_to_one(infinite), Some(true));
        // Depth the same at every distance: no convention to read.
        let flat = Mat4::from_cols(
            glam::Vec4::X,
            glam::Vec4::Y,
            glam::Vec4::new(0.0, 0.0, 0.0, -1.0),
            glam::Vec4::ZERO,
        );
        assert_eq!(maps_near_to_one(flat), None);
    }

    #[test]
    fn targets_the_sky_cannot_use_are_refused_with_a_reason() {
        assert!(HostTargets::default().validate().is_ok());
        let msaa8 = HostTargets {
            sample_count: 8,
            ..Default::default()
        };
        assert!(
            msaa8
                .validate()
                .unwrap_err()
                .to_string()
                .contains("sample count 8")
        );
        let stencil = HostTargets {
            depth_format: wgpu::TextureFormat::Stencil8,
            ..Default::default()
        };
        assert!(stencil.validate().is_err());
    }
}
