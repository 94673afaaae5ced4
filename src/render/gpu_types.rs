//! The structs the GPU reads, each with a WGSL twin of the same field names. Keep in sync with
//! `shaders/shared/frame.wgsl` (`Frame`), `shaders/sprites.wgsl` (`Sprite`, `Cloud`, `DrawBlock`,
//! `ListCloud`, `Lock`, `SpriteView`) and
//! `shaders/terrain.wgsl` (`TerrainFrame`, `TerrainVertex`).

use bytemuck::{Pod, Zeroable};

/// Per-frame uniform of the sky passes. Keep in sync with `shaders/shared/frame.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct GpuFrame {
    /// Camera-relative world (east, north, up metres) to clip space.
    pub view_proj: [[f32; 4]; 4],
    /// Inverse of `view_proj`, for sky rays.
    pub inv_view_proj: [[f32; 4]; 4],
    /// xyz: unit vector towards the sun; w: cosine of the disc radius.
    pub sun_dir: [f32; 4],
    /// rgb: sun colour; w: cosine of the glow radius.
    pub sun_rgb: [f32; 4],
    /// rgb: sky colour straight up; w: the camera's height above the haze's base, metres.
    pub sky_zenith_rgb: [f32; 4],
    /// rgb: sky colour at the horizon; w: the camera's distance from the Earth's centre, metres
    /// (0: the flat frame; [`super::earth::EarthSettings::camera_radius_m`]).
    pub sky_horizon_rgb: [f32; 4],
    /// rgb: in-cloud fog colour; a: how far inside a cloud the camera is, 0..=1.
    pub in_cloud_rgba: [f32; 4],
    /// The host's background depth (1 standard Z, 0 reversed), 1 / soft_depth_fade_m (a
    /// multiplication per fragment instead of a division), soft_depth_fade_m,
    /// in_cloud_visibility_m.
    pub params: [f32; 4],
    /// The altitude haze ([`crate::shading::AltitudeHaze::to_gpu`]).
    pub haze: [f32; 4],
    /// The host projection's depth to metres along the view axis ([`super::SkyView::depth_to_view`]).
    pub depth_to_view: [f32; 4],
    /// A lightning flash lighting its cell from inside: xyz its centre, camera-relative
    /// metres; w the light it adds at the centre (0: none). Its reach is `flash_reach[0]` metres.
    pub flash: [f32; 4],
    /// x: the reach of `flash` (its Gaussian's 1/e distance), metres; yzw unused.
    pub flash_reach: [f32; 4],
}
const _: () = assert!(std::mem::size_of::<GpuFrame>() == 288);

/// One sprite as it lives on the GPU from the moment its block arrives until the block goes
/// (written once, never per frame), packed into 32 bytes: at a million sprites within 100 km
/// every byte is a megabyte. Keep in sync with `Sprite` in `shaders/sprites.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuSprite {
    /// Centre, metres from the cloud centre (east, north, up).
    pub offset: [f32; 3],
    /// Width and height, metres, as two half floats (about a metre at 2 km).
    pub size: u32,
    /// Its shading group's centre, metres from the cloud centre, as half floats: x and y here,
    /// z in the low half of `group_z_rotation`.
    pub group_xy: u32,
    /// Low half: the group centre's z (half float); high half: the rotation in the sprite
    /// plane, a turn in 65,536 steps.
    pub group_z_rotation: u32,
    /// Low half: its own fixed transparency factor (`alpha_morph`); high half: its distance from
    /// the cloud centre over the cloud radius (which sprites fade first, Wang 4); both 0..=1 in
    /// 65,535 steps.
    pub morph_radius: u32,
    /// Bits 0..4: sheet cell; bit 8: upright (cylindrical billboard).
    pub bits: u32,
}
const _: () = assert!(std::mem::size_of::<GpuSprite>() == 32);

/// One corner of a sprite as the build pass makes it each frame, relative to the camera. Keep in
/// sync with `BuiltCorner` in `shaders/sprite_build.wgsl` and `VertexIn` in
/// `shaders/sprites.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuSpriteVertex {
    /// xyz: position relative to the camera, metres; w: 1 drawn, 0 faded out.
    pub position_visible: [f32; 4],
    /// Texture coordinate on the sheet.
    pub uv: [f32; 2],
    /// x: how many sprites of its cloud it stands for (1 but in the shadow map's far clouds,
    /// built every few sprites); y: padding.
    pub stands_for: [f32; 2],
    /// Wang 5.3 vertex colour `(C_amb + C_dir)` and alpha (ambient alpha times the fades).
    pub colour: [f32; 4],
}
const _: () = assert!(std::mem::size_of::<GpuSpriteVertex>() == 48);

impl GpuSpriteVertex {
    /// The buffer layout (offsets of uv and colour match the struct).
    pub fn layout() -> wgpu::VertexBufferLayout<'static> {
        const ATTRS: [wgpu::VertexAttribute; 3] = [
            wgpu::VertexAttribute {
                format: wgpu::VertexFormat::Float32x4,
                offset: 0,
                shader_location: 0,
            },
            wgpu::VertexAttribute {
                format: wgpu::VertexFormat::Float32x2,
                offset: 16,
                shader_location: 1,
            },
            wgpu::VertexAttribute {
                format: wgpu::VertexFormat::Float32x4,
                offset: 32,
                shader_location: 2,
            },
        ];
        wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<GpuSpriteVertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &ATTRS,
        }
    }
}

/// The `bits` flag of an upright sprite.
pub const SPRITE_UPRIGHT: u32 = 1 << 8;
/// `GpuSprite::bits`: falling rain or snow, drawn darker and greyer.
pub const SPRITE_PRECIPITATION: u32 = 1 << 9;
/// `GpuSprite::bits`: stands on its cloud's base (`SkySprite::base`): its dense core spans its
/// width and the column under it down to the base (`clouds::core`), as the shadow map draws it.
pub const SPRITE_BASE: u32 = 1 << 10;

/// One cloud's shading constants and base on the GPU (written with its block). Keep in sync
/// with `Cloud` in `shaders/sprite_build.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuCloud {
    /// xyz: centre, metres from its block's centre; w: a heap's shaded base, metres (0: none).
    pub centre_block: [f32; 4],
    /// The five ambient colour levels, RGBA (Wang 5.1).
    pub level_rgba: [[f32; 4]; 5],
    /// Heights of levels 0..4, metres above mean sea level.
    pub level_height: [f32; 4],
    /// x: height of level 4, metres; y: cloud radius, metres; z: 1 for a flat cloud (cirrus);
    /// w: a deck's sunlit depth, metres (0: lit from every side).
    pub level4_radius_flat: [f32; 4],
    /// x: its flat base, metres from its centre ([`FLOOR_NONE_M`] for none): the cores the
    /// shadow map draws are cut there, as every probe's are (`clouds::core`); y: the factor on
    /// the extinction through its cores (`SkyCloud::optical_density`); zw: padding.
    pub floor_pad: [f32; 4],
}
const _: () = assert!(std::mem::size_of::<GpuCloud>() == 144);

/// `GpuCloud::floor_pad` of a cloud without a base (`SkyCloud::floor_m` is `f32::MIN`): far
/// enough below anything drawn, near enough that arithmetic on it stays finite.
pub const FLOOR_NONE_M: f32 = -1.0e6;

/// One block of a frame's draw list, back to front: where it is relative to the camera (f64 on
/// the CPU, so nothing jitters far out), where its clouds' list is, and its fade. Keep in sync
/// with `DrawBlock` in `shaders/sprites.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuDrawBlock {
    /// Block centre (with its drift) minus the camera position, metres.
    pub origin_rel: [f32; 3],
    /// Index of its first sprite in the frame's sequence of drawn sprites.
    pub first: u32,
    /// Where its clouds' list starts in the bound list buffer. A part of a block's list (its
    /// clouds interleaved with a neighbour's) starts within it: the sprites of its first cloud
    /// are the entry's `first`, whatever that cloud's `first` in the list.
    pub list_base: u32,
    /// Clouds in the list.
    pub list_len: u32,
    /// 0 steady, 1 forming, 2 dissipating (Wang 4).
    pub fade_kind: u32,
    /// Progress of the formation or dissipation, 0..=1.
    pub fade_progress: f32,
}
const _: () = assert!(std::mem::size_of::<GpuDrawBlock>() == 32);

/// One cloud of a block's list, back to front (kept until the camera has moved past the
/// block's thresholds). Keep in sync with `ListCloud` in `shaders/sprites.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default, Pod, Zeroable)]
pub struct GpuListCloud {
    /// Its slot in the cloud buffer.
    pub cloud: u32,
    /// Index of its first sprite among its block's drawn sprites.
    pub first: u32,
    /// Where its back-to-front sprite order starts in the bound order buffer.
    pub order_base: u32,
    /// Every how many of its sprites are built (0 or 1: all; the shadow map's far clouds).
    pub stride: u32,
}
const _: () = assert!(std::mem::size_of::<GpuListCloud>() == 16);

/// Most facings locked at once (Wang 3.3); beyond it a sprite faces the camera.
pub const MAX_LOCKS: usize = 128;

/// A locked facing (Wang 3.3). Keep in sync with `Lock` in `shaders/sprites.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuLock {
    /// xyz: the sprite's right axis; w unused.
    pub right: [f32; 4],
    /// xyz: its up axis; w unused.
    pub up: [f32; 4],
    /// Its normal towards the camera when it locked.
    pub normal: [f32; 3],
    /// Its sprite slot.
    pub sprite: u32,
}

/// What the build pass needs besides the sprites: light, thresholds, the locks. One per view (the
/// sky's camera, each impostor's). Nothing in it bounds a loop (the counts are in the draw list's
/// header): lavapipe folds such uniforms into the shader and would compile it every frame. Keep in sync with `SpriteView` in
/// `shaders/sprites.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct GpuSpriteView {
    /// xyz: unit vector towards the sun; w: camera height above mean sea level, metres.
    pub sun_dir_camera_z: [f32; 4],
    /// rgb: time-of-day directional colour; w: time-of-day ambient percentage.
    pub directional_ambient: [f32; 4],
    /// Wang's Cmin, Cmedian, Cmax; w: forward scattering g.
    pub mapping_g: [f32; 4],
    /// x: forward scattering strength; y: lock radius fraction; z, w: cosines of the lock fade
    /// start and end angles.
    pub forward_lock: [f32; 4],
    /// x, y: sines of the upright fade start and end angles; z: lifecycle inner radius fraction;
    /// w: lifecycle outer start opacity.
    pub upright_lifecycle: [f32; 4],
    /// Harris and Lastra: x 1 for that model (0 Wang's); y: the phase function's
    /// Henyey-Greenstein g; z: its lobe weight; w: the sun's strength.
    pub hl_phase: [f32; 4],
    /// Harris and Lastra: rgb the skylight (the sky's mean colour times its strength); w: the
    /// ambient grey.
    pub hl_sky: [f32; 4],
    /// Harris and Lastra: x the part of a deck's optical depth that takes the sun's total
    /// light (direct and scattered forward) away: `1 - forward_fraction`; y: 1 to take each
    /// cloud's sprites in their slots' order instead of the bound order (the shadow map); z: 1
    /// while the far field is drawn (every sprite fades over the hand-over band); w unused.
    pub hl_deck: [f32; 4],
    /// x, y: the distance from the view's camera over which sprites seen above the horizon fade
    /// out (start, end), metres; z, w: sines of the angles over which layer sprites take their
    /// own turn (start, end).
    pub far_fade_layer_turn: [f32; 4],
    /// The locked facings.
    pub locks: [GpuLock; MAX_LOCKS],
}
const _: () = assert!(std::mem::size_of::<GpuSpriteView>() == 144 + 48 * MAX_LOCKS);

/// Per-frame uniform of the demo terrain. Keep in sync with `shaders/terrain.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct GpuTerrainFrame {
    /// Camera-relative world to clip space.
    pub view_proj: [[f32; 4]; 4],
    /// xyz: mesh origin minus camera position, metres; w: the camera's height above the haze's
    /// base, metres.
    pub origin_rel: [f32; 4],
    /// xyz: unit vector towards the sun; w: ambient light factor.
    pub sun_dir: [f32; 4],
    /// rgb: sun colour.
    pub sun_rgb: [f32; 4],
    /// rgb: fog colour; w: the camera's distance from the Earth's centre, metres (0: flat).
    pub fog_rgb: [f32; 4],
    /// The altitude haze ([`crate::shading::AltitudeHaze::to_gpu`]).
    pub haze: [f32; 4],
    /// Camera-relative position to the cloud shadow map's texture coordinates
    /// ([`crate::render::CloudShadowMap`]).
    pub shadow_uv: [[f32; 4]; 4],
}
const _: () = assert!(std::mem::size_of::<GpuTerrainFrame>() == 208);

/// One terrain vertex, relative to the mesh origin. Keep in sync with `shaders/terrain.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuTerrainVertex {
    /// Position from the mesh origin, metres (z above mean sea level minus origin z).
    pub position_m: [f32; 3],
    /// Height above mean sea level, metres (colours the ground).
    pub height_m: f32,
    /// Unit surface normal; w unused.
    pub normal: [f32; 4],
}
const _: () = assert!(std::mem::size_of::<GpuTerrainVertex>() == 32);

/// The impostor ring pass's uniform. Keep in sync with `Ring` in `shaders/impostor_quad.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuRing {
    /// The shown ring's centre relative to the camera, metres; w: the crossfade weight.
    pub old_centre_weight: [f32; 4],
    /// The centre of the ring fading in (the shown one's when not fading), metres.
    pub new_centre: [f32; 4],
    /// Ring radius, half side of a quad, the old and new rings' mean far distance, metres.
    pub size: [f32; 4],
}
const _: () = assert!(std::mem::size_of::<GpuRing>() == 48);
