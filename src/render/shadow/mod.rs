//! Cloud shadows on the host's ground: the clouds drawn from the sun into a shadow map, which a
//! host looks up with a matrix and multiplies into its direct sunlight (`exp(-tau)`).
//!
//! In: the GPU-resident sprites (`resident`), the sun, the camera and the clouds' drift. Out: an
//! R16Float texture of the optical depth `tau` of the clouds along the sun's ray through each
//! texel, and the matrix from a camera-relative position to its texture coordinates
//! ([`CloudShadowMap`]). The draw (`shaders/cloud_shadow.wgsl`, pass `sky.cloud_shadow`) is
//! orthographic along the sun's rays: the build pass (`cs_build_cores` in
//! `shaders/sprite_build.wgsl`) makes a quad facing the sun around each sprite's dense core
//! (`clouds::core`, what every probe asks), with its formation and dissipation fade (so the
//! shadows fade with the clouds), and each fragment adds the optical depth of its ray inside
//! the core, the probes' extinction times the length (Beer's law; additive, so no sort is
//! needed): `World::sun_occlusion` reads what the map holds.
//! Its own draw list and cloud lists (every cloud of the blocks it covers, a few tens of KB)
//! take each cloud's sprites in their slots' order (not the camera's sort, which would change
//! the half-float sums as the camera moves), so it holds nothing per sprite.
//!
//! The map covers a square across the sun's rays around the camera (`half_extent_m`, at least
//! the sprites' draw distance), centred on a texel of a grid fixed to the world, so a camera
//! moving within a texel leaves every shadow as it was (no shimmer). Its last texels are faded
//! out in the draw, so the shadows end softly at the map's edge. Between drawings the lookup
//! matrix moves the map with the clouds' drift (SilverLining reuses its map across frames the
//! same way), and the map costs only when something in it changes:
//!
//! - **Whole** (the only drawing that clears all of it): the first, after the sun has turned
//!   `rebuild_sun_deg`, every `update_interval_s` of sky time while a cloud it covers forms or
//!   dissipates (its footprint alone drawn again would reach its neighbours' clouds, and a sky
//!   of building cumulus has many such: the Cb circle drew more that way than whole), when
//!   asked ([`CloudShadows::redraw`]) or switched on, when the camera jumped more than a quarter
//!   of the map at once or into another cell of the eye's grid (`layout`), and when more than
//!   `MAX_QUEUED` rectangles wait.
//! - **Scrolled**: when the camera has gone `recentre_fraction` of the half extent from the
//!   map's centre, the map is centred on it again by whole texels: the texels the old and new
//!   map share are copied to their new place (in the map itself, a band of 64 rows at a time
//!   through a small scratch texture, 128 KiB at 1024 texels, so a scroll takes no second map),
//!   and only the strips that came into range are drawn, with the fade bands that were the old
//!   edge and are the new one (the fade depends on a texel's place in the map, so those are
//!   drawn again, not copied). Blocks the move takes across `full_detail_m` (drawn at another
//!   stride by a fresh drawing) are queued as patches, below. The sums are additive (each
//!   fragment adds `-ln(1 - alpha)`), so a strip cleared and drawn with every sprite that
//!   reaches it holds what a whole drawing holds there: a scrolled map equals a fresh one up to
//!   half-float rounding (a test holds them together). The draw's eye stays in its cell as the
//!   map scrolls, so both turn every sprite alike.
//! - **Patched**: a block the map holds that is gone (taken away, or no longer placed) or was
//!   written again (placed again) leaves a rectangle to draw again: the texels its shadow may
//!   fall on. They are queued and drawn a few a frame (`redraw_texels_per_frame` texels beyond a
//!   scroll's strips, one rectangle at least; the map keeps the old shadow there until its
//!   turn), each cleared and filled with the clouds of the map's blocks that reach it, in one
//!   draw whose fragments the shader keeps to the rectangles.
//! - **Added**: a block that arrives (or comes into range with a scroll) is added to the map,
//!   its own sprites drawn over the whole map, the sums being additive: nearest the centre
//!   first, `add_sprites_per_frame` sprites a frame (one block at least), so a sky that fills
//!   draws its map in over frames.
//!
//! What is drawn when is decided on the CPU from plain data (`layout`: the shift, the strips,
//! the footprints, merged so that no texel is drawn twice); the map's view of the resident
//! sprites (`view`) reuses each block's cloud lists, and a frame writes the draw list of the
//! blocks it draws only (a frame that draws nothing writes nothing). Recording: `draw`. With
//! the sun below 1 degree the map is drawn empty (again only as it scrolls). Units: metres.

// The map's settings live here, so the settings tree reads them without the map.
pub(super) mod layout;
// The map's own view of the resident sprites (its draw list and cloud lists), written when a
// drawing is decided.
mod slip;
mod view;
// Its textures, pipelines and the recording of a drawing.
mod draw;

use std::cell::Cell;

use glam::{DVec3, Mat4, Vec3};
use view::{block_sprites, covered, drawing_order, is_covered, is_near};

pub use layout::{
    BandCopy, EYE_DISTANCE_M, MAX_SIZE_PX, RedrawDue, ShadowFrame, ShadowSettings, TexelRect,
    redraw_due,
};

use super::RenderError;
use super::gpu_types::{GpuDrawBlock, GpuListCloud};
use super::id_hash::{IdMap, IdSet};
use super::scene::BandOffsets;
use super::sprites::resident::{Resident, ResidentSet, storage_buffer};
use super::sprites::sprite_view::{ViewBuffers, ViewLight};
use super::stats::FrameStats;

const WGSL: &str = include_str!("../../../shaders/cloud_shadow.wgsl");
/// Optical depth along the sun's ray, summed (half floats: a thousandth at tau 1).
pub const SHADOW_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R16Float;

/// A far fade beyond any sprite (finite: the fade's smoothstep divides by its length).
const NO_FAR_FADE_M: f32 = 1.0e9;

/// The shadow pass's uniform. Keep in sync with `ShadowFrame` in `shaders/cloud_shadow.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
struct GpuCloudShadow {
    /// Positions relative to the draw's eye to clip space (orthographic along the rays).
    clip_from_eye: [[f32; 4]; 4],
    /// x: optical depth per metre of cloud core along the ray (the probes' extinction times
    /// the settings' `opacity_scale`, less as the sun nears the horizon); y: the fraction of
    /// the map across which its edge fades out; zw unused.
    params: [f32; 4],
    /// x: how many of `rects` a masked draw keeps to; yzw unused.
    mask: [u32; 4],
    /// The rectangles drawn again (first column, first row, one past the last of each).
    rects: [[u32; 4]; MASK_RECTS],
}
const _: () = assert!(std::mem::size_of::<GpuCloudShadow>() == 96 + 16 * MASK_RECTS);

/// Most rectangles queued before the map is drawn whole instead: a 9 km move takes a few
/// hundred blocks off the map in each drift band that has clouds there (each band a block of
/// its own over the same ground), and the queue is worked through a texel budget a frame.
const MAX_QUEUED: usize = 1024;

/// Most rectangles a frame draws again (a scroll's strips take four at most). Keep in sync with
/// `MASK_RECTS` in `shaders/cloud_shadow.wgsl`.
const MASK_RECTS: usize = 32;

/// What a host needs to put the clouds' shadows on its ground (from [`super::Sky::cloud_shadows`]).
///
/// Per fragment of ground at `q` metres from the camera (the camera of the last prepared
/// frame): `uv = (uv_from_camera_relative * vec4(q, 1)).xy`, `tau` the texture sampled there
/// (linear filtering, clamped to its edge: its border texels hold 0), and the direct sun
/// multiplied by `exp(-tau)`; the ambient light stays. Switched off, the texture is a single
/// texel of 0: the same lookup finds open sun everywhere, and the ground has the clear sun
/// ([`super::Sky::light`]) everywhere, as open ground does with the map on.
#[derive(Debug, Clone, Copy)]
pub struct CloudShadowMap<'a> {
    /// The optical depth of the clouds along the sun's ray ([`SHADOW_FORMAT`], filterable).
    /// It can be replaced when the shadows are switched on or off: take it every frame.
    pub view: &'a wgpu::TextureView,
    /// From a position relative to the camera (east, north, up metres; w 1) to the map's
    /// texture coordinates in x and y (v down the texture); z 0, w 1.
    pub uv_from_camera_relative: Mat4,
    /// Side of the map, texels.
    pub size_px: u32,
    /// Metres a texel covers across the sun's rays.
    pub texel_m: f32,
    /// Whether the map is drawn (false: open sun everywhere).
    pub enabled: bool,
}

/// The shadow map's optical depth read back (tests and tools).
#[derive(Debug, Clone, PartialEq)]
pub struct ShadowImage {
    /// Side, texels.
    pub size_px: u32,
    /// Optical depth along the sun's ray, row-major from the top left (v = 0).
    pub tau: Vec<f32>,
}

impl ShadowImage {
    /// The optical depth at texture coordinates `uv`, filtered as a host's linear sampler
    /// clamped to the edge does.
    pub fn sample(&self, uv: glam::Vec2) -> f32 {
        let n = self.size_px as i64;
        let at = |x: i64, y: i64| self.tau[(y.clamp(0, n - 1) * n + x.clamp(0, n - 1)) as usize];
        let p = uv * self.size_px as f32 - 0.5;
        let (x0, y0) = (p.x.floor(), p.y.floor());
        let (fx, fy) = (p.x - x0, p.y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let top = at(x0, y0) * (1.0 - fx) + at(x0 + 1, y0) * fx;
        let bottom = at(x0, y0 + 1) * (1.0 - fx) + at(x0 + 1, y0 + 1) * fx;
        top * (1.0 - fy) + bottom * fy
    }
}

/// The map: its texture, pipeline, view of the resident sprites and when it was drawn.
pub struct CloudShadows {
    settings: ShadowSettings,
    /// Optical depth per metre inside a cloud's cores: the probes' (3 / the in-cloud
    /// visibility), so the map and `World::sun_occlusion` answer from the same clouds.
    extinction_per_m: f32,
    device: wgpu::Device,
    pipeline: wgpu::RenderPipeline,
    /// Writes 0 (a rectangle's texels, under its scissor, before they are drawn again).
    clear_pipeline: wgpu::RenderPipeline,
    uniform: wgpu::Buffer,
    group: wgpu::BindGroup,
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    /// The band a scroll moves the map's texels through ([`layout::SCROLL_BAND_ROWS`] rows).
    scratch: wgpu::Texture,
    view_layout: wgpu::BindGroupLayout,
    sprites_view: ViewBuffers,
    draws: Vec<GpuDrawBlock>,
    lists: Vec<GpuListCloud>,
    /// Per block drawn: its clouds' lists as last built, with the placing and stride they were
    /// built for and their sprites. A drawing copies a block's lists when both stand (a whole
    /// drawing, every second while clouds form, read every cloud of every block it covers).
    kept_lists: IdMap<KeptLists>,
    /// The cloud lists on the GPU (grown in powers of two) and how many times it was replaced
    /// (the view's group is made anew then).
    list_buffer: wgpu::Buffer,
    list_buffers_made: u64,
    /// Where the map stands (moved by its scrolls), the sky time of its last whole drawing, and
    /// the clouds' drift at that drawing (every later drawing into it draws the blocks moved back by the drift
    /// since: the map holds the clouds where they were then).
    drawn: Option<(ShadowFrame, f64, DVec3)>,
    /// The blocks whose shadows the map holds (by id): their centre and radius in the map
    /// (moved back by the drift since its whole drawing), and the placing drawn (a block
    /// written again is placed again: its footprint is drawn again).
    in_map: IdMap<(DVec3, f64, u64)>,
    /// Blocks' centres and radii (in the map) whose footprints are yet to be drawn again
    /// (blocks gone or written again, blocks a scroll took across `full_detail_m`), oldest
    /// first.
    dirty: Vec<(DVec3, f64)>,
    /// Blocks that arrived (covered, not yet in the map), drawn in a budget a frame.
    arriving: IdSet,
    /// This frame's drawing: whether it is whole, the copies of a scroll, the rectangles drawn
    /// again (cleared, and the mask of the draw that fills them) and the segments of its draw
    /// list.
    whole: bool,
    copies: Vec<BandCopy>,
    clears: Vec<TexelRect>,
    segments: Vec<Segment>,
    /// Counts whole drawings and scrolls (the cover is looked at again after either).
    drawings: u64,
    /// The last look over every block the sky holds, while it still holds.
    cover: Option<CoverCheck>,
    /// Draw the map at the next prepare whatever changed ([`Self::redraw`]).
    force: bool,
    /// The clouds' drift now ([`super::Sky::set_band_drifts`]): the lowest band's, which the
    /// map moves with between draws.
    drift_m: DVec3,
    /// How far the upper drift bands slipped against the lowest since the last whole drawing.
    band_slip: slip::BandSlip,
    /// This frame's draw: its sprites, if the map is drawn this frame.
    pending: Option<u32>,
    lookup: Mat4,
    /// GPU time of the draw (two timestamps around it), while the sky's passes are timed, and
    /// whether the last prepared frame drew it.
    timer: Option<super::Timestamps>,
    timed: Cell<bool>,
}

/// What a look over every block the sky holds found for the map's drawing: the covered blocks
/// that form or dissipate (the blocks gone and arrived are dealt with as it looks). Looked at
/// again only when a block came, went, was written, moved or changed its fade, or the drift
/// moved a texel, or the map was drawn whole or scrolled: a frame of a steady sky walks none of
/// its thousands of blocks for the map.
#[derive(Debug)]
struct CoverCheck {
    /// `ResidentSet::changes` and `fades`, the whole drawing, and the drift it was made at.
    changes: u64,
    fades: u64,
    drawing: u64,
    drift_m: DVec3,
    /// The covered blocks that form or dissipate.
    changing: Vec<u64>,
}

/// A run of the draw list: the sprites `first..first + sprites` of the view, masked to the
/// rectangles drawn again (the blocks of the map that reach them) or not (a whole drawing,
/// blocks that arrived).
#[derive(Debug, Clone, Copy)]
struct Segment {
    masked: bool,
    first: u32,
    sprites: u32,
}

impl CloudShadows {
    /// The pipelines (their group: the uniform) and the textures (a cleared texel while switched
    /// off). `view_layout`: the build pass's view group; `in_cloud_visibility_m`: the visibility
    /// inside a cloud (`[in_cloud]`).
    pub(super) fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        (settings, in_cloud_visibility_m): (ShadowSettings, f32),
        view_layout: &wgpu::BindGroupLayout,
    ) -> Self {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("sky.cloud_shadow"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("sky.cloud_shadow"),
            size: std::mem::size_of::<GpuCloudShadow>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sky.cloud_shadow"),
            layout: &layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: uniform.as_entire_binding(),
            }],
        });
        let [pipeline, clear_pipeline] = draw::pipelines(device, &layout);
        let (texture, view) = draw::shadow_texture(device, [1, 1]);
        let scratch = draw::shadow_texture(device, [1, 1]).0;
        let mut shadows = Self {
            settings,
            extinction_per_m: 3.0 / in_cloud_visibility_m.max(1e-3),
            device: device.clone(),
            pipeline,
            clear_pipeline,
            uniform,
            group,
            texture,
            view,
            scratch,
            view_layout: view_layout.clone(),
            sprites_view: ViewBuffers::new(device, false),
            draws: Vec::new(),
            lists: Vec::new(),
            kept_lists: IdMap::default(),
            list_buffer: storage_buffer(device, "sky.cloud_shadow_lists", 4096 * 16),
            list_buffers_made: 0,
            drawn: None,
            in_map: IdMap::default(),
            dirty: Vec::new(),
            arriving: IdSet::default(),
            whole: false,
            copies: Vec::new(),
            clears: Vec::new(),
            segments: Vec::new(),
            drawings: 0,
            cover: None,
            force: false,
            drift_m: DVec3::ZERO,
            band_slip: Default::default(),
            pending: None,
            lookup: Mat4::ZERO,
            timer: None,
            timed: Cell::new(false),
        };
        shadows.set_enabled(queue, settings.enabled);
        shadows
    }

    /// Switches the map on (drawn from the next prepared frame) or off (a single texel of 0:
    /// open sun everywhere, no memory taken).
    pub fn set_enabled(&mut self, queue: &wgpu::Queue, enabled: bool) {
        self.settings.enabled = enabled;
        let side = if enabled { self.settings.size_px } else { 1 };
        (self.texture, self.view) = draw::shadow_texture(&self.device, [side, side]);
        let band = if enabled { layout::SCROLL_BAND_ROWS } else { 1 };
        self.scratch = draw::shadow_texture(&self.device, [side, band]).0;
        self.drawn = None;
        if !enabled {
            // Cleared: a texel of tau 0.
            queue.write_texture(
                self.texture.as_image_copy(),
                &[0u8; 2],
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(2),
                    rows_per_image: None,
                },
                wgpu::Extent3d {
                    width: 1,
                    height: 1,
                    depth_or_array_layers: 1,
                },
            );
        }
    }

    /// Draws the map at the next prepare whatever changed (a host that moved its clouds by
    /// other means than the drift, tests).
    pub fn redraw(&mut self) {
        self.force = true;
    }

    /// The settings in use.
    pub fn settings(&self) -> &ShadowSettings {
        &self.settings
    }

    /// The clouds' drift now, each drift band's ([`super::Sky::set_band_drifts`]): between
    /// draws the map moves with the lowest band's.
    pub fn set_drift(&mut self, offsets_m: &BandOffsets) {
        self.drift_m = offsets_m[0];
        self.band_slip.set(offsets_m);
    }

    /// Bytes of its textures and buffers.
    pub fn gpu_bytes(&self) -> u64 {
        let side = self.texture.width() as u64;
        let scratch = self.scratch.width() as u64 * self.scratch.height() as u64 * 2;
        let view = if self.settings.enabled {
            self.sprites_view.gpu_bytes()
        } else {
            0
        };
        side * side * 2 + scratch + self.uniform.size() + view + self.list_buffer.size()
    }

    /// The map and its lookup for the last prepared frame.
    pub fn map(&self) -> CloudShadowMap<'_> {
        CloudShadowMap {
            view: &self.view,
            uv_from_camera_relative: self.lookup,
            size_px: self.texture.width(),
            texel_m: self.settings.texel_m() as f32,
            enabled: self.settings.enabled,
        }
    }

    /// Decides what of the map is drawn this frame ([module docs](self)) and, if anything,
    /// writes its view of the resident sprites (`resident`, lit as `light` says) and its
    /// uniform; sets the lookup for the camera at `camera_m`. Returns the bytes written. Call
    /// [`Self::record`] after, in the frame's own submission, after the patch of the resident
    /// orders.
    pub(super) fn prepare(
        &mut self,
        queue: &wgpu::Queue,
        resident: &ResidentSet,
        light: &ViewLight,
        (camera_m, sun, now_s): (DVec3, Vec3, f64),
        stats: &mut FrameStats,
    ) -> u64 {
        self.pending = None;
        self.copies.clear();
        self.segments.clear();
        self.clears.clear();
        self.timed.set(false);
        stats.shadow_gpu_bytes = self.gpu_bytes();
        if !self.settings.enabled {
            self.lookup = Mat4::ZERO;
            return 0;
        }
        let sun = sun.as_dvec3();
        let s = self.settings;
        // The shadows fade out as the sun nears the horizon (they would reach for ever); with
        // it below 1 degree nothing shows, and the map is drawn with no sprite.
        let dark = sun_fade(sun) <= 0.0;
        let mut whole = std::mem::take(&mut self.force);
        let mut scroll = None;
        match self.drawn {
            None => whole = true,
            Some((frame, at_s, drift_then)) => {
                // The camera in the map (which holds the clouds where they were when it was
                // drawn whole).
                let here = camera_m - (self.drift_m - drift_then);
                // While clouds it covers form or dissipate, drawn whole every
                // `update_interval_s` (their footprints drawn again instead cost more: a sky of
                // building cumulus has many, each reaching its neighbours' clouds); and whole
                // when the queue of rectangles has grown past what patches are for.
                let changing = self.cover.as_ref().is_some_and(|c| !c.changing.is_empty());
                let due = redraw_due(&frame, (at_s, now_s), here, sun, changing, &s);
                whole |= due.turned
                    || due.aged
                    || self.dirty.len() > MAX_QUEUED
                    || self.band_slip.slipped(s.texel_m());
                if due.recentre && !whole {
                    let to = frame.moved_to(here, &s);
                    match layout::scroll_shift(&frame, &to, s.size_px) {
                        Some(shift) => scroll = Some((to, shift)),
                        // A jump of more than a quarter of the map: drawn whole.
                        None => whole = true,
                    }
                }
            }
        }
        let bytes = if whole {
            self.prepare_whole(queue, resident, light, camera_m, sun, now_s, dark)
        } else {
            self.prepare_patches(queue, resident, light, scroll, dark)
        };
        if let Some((frame, _, drift_then)) = &self.drawn {
            self.lookup = frame.uv_from_camera_relative(camera_m, self.drift_m - *drift_then);
        }
        let sprites = self.pending.unwrap_or(0);
        stats.shadow_redrawn = self.pending.is_some();
        stats.shadow_sprites = sprites;
        stats.shadow_texels = self.clears.iter().map(TexelRect::area).sum::<u64>()
            + if self.whole && self.pending.is_some() {
                u64::from(s.size_px).pow(2)
            } else {
                0
            };
        stats.shadow_gpu_bytes = self.gpu_bytes();
        bytes
    }

    /// A whole drawing around the camera at `camera_m` (empty if `dark`).
    #[allow(clippy::too_many_arguments)]
    fn prepare_whole(
        &mut self,
        queue: &wgpu::Queue,
        resident: &ResidentSet,
        light: &ViewLight,
        camera_m: DVec3,
        sun: DVec3,
        now_s: f64,
        dark: bool,
    ) -> u64 {
        let s = self.settings;
        let blocks = &resident.blocks;
        // The sun of the last drawing until it has turned `rebuild_sun_deg` (a shadow 2 km
        // under its cloud moves 17 m at 0.5 degrees): the sun a host gives follows the
        // camera's place and time, and a map turned by a millionth of a radian puts its
        // sprites' edges across other texels' centres.
        let frame = match &self.drawn {
            Some((f, _, _)) if f.sun.angle_between(sun).to_degrees() <= s.rebuild_sun_deg => {
                f.moved_to(camera_m, &s)
            }
            _ => ShadowFrame::new(camera_m, sun, &s),
        };
        self.draws.clear();
        self.lists.clear();
        let order = if dark {
            Vec::new()
        } else {
            drawing_order(blocks.values().filter(|r| is_covered(r, &frame)))
        };
        // Lists of blocks no longer covered are not kept.
        let covered: IdSet = order.iter().map(|r| r.block.id).collect();
        self.kept_lists.retain(|id, _| covered.contains(id));
        let sprites = self.push_draws(&order, &frame, DVec3::ZERO, 0);
        self.arriving.clear();
        self.in_map = order
            .iter()
            .map(|r| (r.block.id, (r.centre_m(), r.radius_m, r.place_serial)))
            .collect();
        self.dirty.clear();
        self.segments.push(Segment {
            masked: false,
            first: 0,
            sprites,
        });
        let mut bytes = self.write_view(queue, resident, light, &frame, sprites);
        bytes += self.write_uniform(queue, &frame);
        self.drawn = Some((frame, now_s, self.drift_m));
        self.band_slip.drawn();
        self.drawings += 1;
        self.whole = true;
        self.pending = Some(sprites);
        self.timed.set(self.timer.is_some());
        bytes
    }

    /// Draws what changed into the map drawn before: its scroll to `scroll` (the new frame and
    /// the shift), the rectangles of blocks gone or written again (a budget of them), the blocks
    /// that arrived (a budget of them). Nothing but a scroll while `dark`.
    fn prepare_patches(
        &mut self,
        queue: &wgpu::Queue,
        resident: &ResidentSet,
        light: &ViewLight,
        scroll: Option<(ShadowFrame, (i32, i32))>,
        dark: bool,
    ) -> u64 {
        let Some((mut frame, at_s, drift_then)) = self.drawn else {
            return 0;
        };
        let s = self.settings;
        let n = s.size_px;
        let blocks = &resident.blocks;
        let back = self.drift_m - drift_then;
        let mut rects = Vec::new();
        if let Some((to, shift)) = scroll {
            // Blocks the scroll takes across `full_detail_m` are drawn at another stride by a
            // fresh drawing: drawn again, as the budget allows.
            let s = &self.settings;
            let crossed = self
                .in_map
                .values()
                .filter(|&&(c, r, _)| is_near(&frame, c, r, s) != is_near(&to, c, r, s))
                .map(|&(c, r, _)| (c, r));
            self.dirty.extend(crossed);
            frame = to;
            self.copies = layout::scroll_copies(shift, n);
            self.drawings += 1;
            rects = layout::scroll_rects(shift, n);
        }
        let mut arrived = Vec::new();
        if !dark {
            let fresh = self.cover.as_ref().is_some_and(|c| {
                c.changes == resident.changes
                    && c.fades == resident.fades
                    && c.drawing == self.drawings
                    && (c.drift_m - self.drift_m).length() <= s.texel_m()
            });
            if !fresh {
                let (now, changing) = covered(blocks, &frame);
                // Blocks gone from the map: their footprints drawn again (nothing, for those
                // the scroll left off the map).
                // Blocks written again (placed again): where they were and where they are.
                let mut gone = Vec::new();
                for (id, held) in self.in_map.iter_mut() {
                    match now.get(id) {
                        None => gone.push(*id),
                        Some(&serial) if serial != held.2 => {
                            self.dirty.push((held.0, held.1));
                            if let Some(r) = blocks.get(id) {
                                *held = (r.centre_m() - back, r.radius_m, serial);
                                self.dirty.push((held.0, held.1));
                            }
                        }
                        Some(_) => {}
                    }
                }
                for id in gone {
                    if let Some((c, r, _)) = self.in_map.remove(&id) {
                        self.dirty.push((c, r));
                    }
                }
                let new: Vec<u64> = now
                    .keys()
                    .filter(|id| !self.in_map.contains_key(id) && !self.arriving.contains(id))
                    .copied()
                    .collect();
                self.arriving.extend(new);
                self.cover = Some(CoverCheck {
                    changes: resident.changes,
                    fades: resident.fades,
                    drawing: self.drawings,
                    drift_m: self.drift_m,
                    changing,
                });
            }
            // The queue's oldest rectangles, within the budget (one at least) and the mask's room.
            let mut budget = u64::from(s.redraw_texels_per_frame);
            let mut taken = 0;
            for &(centre, radius) in &self.dirty {
                if (taken > 0 && budget == 0) || rects.len() == MASK_RECTS {
                    break;
                }
                taken += 1;
                if let Some(rect) = layout::footprint(&frame, centre, radius, n) {
                    budget = budget.saturating_sub(rect.area());
                    rects.push(rect);
                }
            }
            self.dirty.drain(..taken);
            // The blocks that arrived, nearest the map's centre first, within their budget (one
            // at least); the rest wait (and those gone or out of range meanwhile are dropped).
            if !self.arriving.is_empty() {
                let mut queue: Vec<(f64, &Resident)> = self
                    .arriving
                    .iter()
                    .filter_map(|id| blocks.get(id))
                    .filter(|r| is_covered(r, &frame))
                    .map(|r| ((r.centre_m() - back - frame.centre_m).length_squared(), r))
                    .collect();
                queue.sort_by(|a, b| a.0.total_cmp(&b.0));
                let mut budget = s.add_sprites_per_frame;
                let mut taken = Vec::new();
                for (_, r) in queue.iter() {
                    if !taken.is_empty() && budget == 0 {
                        break;
                    }
                    budget = budget.saturating_sub(block_sprites(r, &frame, back, &s));
                    taken.push(*r);
                }
                let waiting: IdSet = queue[taken.len()..].iter().map(|q| q.1.block.id).collect();
                self.arriving = waiting;
                arrived = drawing_order(taken.into_iter());
            }
        }
        self.drawn = Some((frame, at_s, drift_then));
        if rects.is_empty() && arrived.is_empty() && scroll.is_none() {
            return 0;
        }
        // The map's blocks that reach a rectangle, drawn once, masked to the rectangles (each
        // texel in one gets every sprite that reaches it once, however they overlap); then the
        // blocks that arrived, over the whole map.
        let reach = |r: &Resident| layout::footprint(&frame, r.centre_m() - back, r.radius_m, n);
        let meets = |f: TexelRect| rects.iter().any(|rect| rect.overlaps(&f));
        // First on the place the map holds for each block, without reading the block: an upper
        // band's clouds slip at most `BAND_SLIP_TEXELS` against the map between whole drawings
        // (`band_slip`), so a block is within twice that of where the map took it in, and a
        // reach that much wider (and a metre) finds every block the exact test below keeps. A
        // frame of arrivals alone (no rectangle) reads none.
        let margin_m = 2.0 * slip::BAND_SLIP_TEXELS * s.texel_m() + 1.0;
        let held = drawing_order(
            self.in_map
                .iter()
                .filter(|(_, (c, r, _))| {
                    !rects.is_empty()
                        && layout::footprint(&frame, *c, r + margin_m, n).is_some_and(meets)
                })
                .filter_map(|(id, _)| blocks.get(id))
                .filter(|r| is_covered(r, &frame))
                .filter(|r| reach(r).is_some_and(meets)),
        );
        debug_assert_eq!(
            held.len(),
            (self.in_map.keys().filter_map(|id| blocks.get(id)))
                .filter(|r| is_covered(r, &frame) && reach(r).is_some_and(meets))
                .count(),
            "the stored places' reach missed a block that reaches a rectangle"
        );
        self.draws.clear();
        self.lists.clear();
        let sprites = self.push_masked_draws(&held, &frame, back, &rects);
        self.segments.push(Segment {
            masked: true,
            first: 0,
            sprites,
        });
        let added = self.push_draws(&arrived, &frame, back, sprites);
        self.segments.push(Segment {
            masked: false,
            first: sprites,
            sprites: added,
        });
        let sprites = sprites + added;
        for r in &arrived {
            self.in_map.insert(
                r.block.id,
                (r.centre_m() - back, r.radius_m, r.place_serial),
            );
        }
        self.clears = rects;
        let mut bytes = self.write_view(queue, resident, light, &frame, sprites);
        bytes += self.write_uniform(queue, &frame);
        self.whole = false;
        self.pending = Some(sprites);
        self.timed.set(self.timer.is_some());
        bytes
    }

    /// Writes the uniform of a drawing at `frame` (with the mask of this frame's rectangles);
    /// returns the bytes written.
    fn write_uniform(&self, queue: &wgpu::Queue, frame: &ShadowFrame) -> u64 {
        let mut rects = [[0; 4]; MASK_RECTS];
        for (to, r) in rects.iter_mut().zip(&self.clears) {
            *to = [r.x0, r.y0, r.x1, r.y1];
        }
        // The fade of the drawing's own sun (the last one's, within `rebuild_sun_deg`).
        let uniform = GpuCloudShadow {
            clip_from_eye: frame.clip_from_eye_relative().to_cols_array_2d(),
            params: [
                self.extinction_per_m * self.settings.opacity_scale * sun_fade(frame.sun) as f32,
                layout::EDGE_FADE,
                0.0,
                0.0,
            ],
            mask: [self.clears.len().min(MASK_RECTS) as u32, 0, 0, 0],
            rects,
        };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
        std::mem::size_of::<GpuCloudShadow>() as u64
    }

    /// The sprites of this frame's draw (0 if the map is not drawn this frame).
    pub(super) fn pending_sprites(&self) -> u32 {
        self.pending.unwrap_or(0)
    }

    /// Whether the map is drawn this frame.
    pub(super) fn has_pending(&self) -> bool {
        self.pending.is_some()
    }
}

/// How much of their shadows the clouds cast for the sun along `sun`: 1 above 5 degrees, 0
/// below 1 (the shadows would reach for ever).
fn sun_fade(sun: DVec3) -> f64 {
    smoothstep(1.0f64.to_radians().sin(), 5.0f64.to_radians().sin(), sun.z)
}

/// A block's cloud lists for the shadow map, kept between drawings.
#[derive(Debug, Default)]
struct KeptLists {
    /// The block's placing and the stride the lists were built for.
    built_for: Option<(u64, u32)>,
    lists: Vec<GpuListCloud>,
    /// The sprites they draw.
    sprites: u32,
}

fn smoothstep(a: f64, b: f64, x: f64) -> f64 {
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}
