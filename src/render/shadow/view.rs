//! The shadow map's view of the resident sprites: the draw list of the blocks a drawing draws
//! (all it covers, or those reaching its rectangles, or those that arrived), each with every
//! cloud of its in its list (kept between drawings, `KeptLists`), and their upload with the
//! view's uniform ([`CloudShadows::write_view`]). What [`CloudShadows::prepare`] writes once it
//! has decided what to draw.

use glam::DVec3;

use super::layout::ShadowSettings;
use super::layout::{TexelRect, footprint};
use super::{CloudShadows, NO_FAR_FADE_M, ShadowFrame};
use crate::render::gpu_types::{GpuDrawBlock, GpuListCloud};
use crate::render::id_hash::IdMap;
use crate::render::sprites::draw_list::Blocks;
use crate::render::sprites::draw_list::fade_code;
use crate::render::sprites::resident::{Resident, ResidentSet, storage_buffer};
use crate::render::sprites::sprite_view::{self, ViewData, ViewLight};

impl CloudShadows {
    /// Writes the cloud lists and the view of the resident sprites for a drawing at `frame` of
    /// `sprites` (the draw list `push_draws` made); returns the bytes written.
    pub(super) fn write_view(
        &mut self,
        queue: &wgpu::Queue,
        resident: &ResidentSet,
        light: &ViewLight,
        frame: &ShadowFrame,
        sprites: u32,
    ) -> u64 {
        let mut bytes = 0;
        let mut header = sprite_view::header(&ViewLight {
            camera_z_m: frame.eye_m.z as f32,
            farthest_m: NO_FAR_FADE_M,
            ..*light
        });
        // The cores' rays run along the map's own sun (`build_core`).
        header.sun_dir_camera_z[..3].copy_from_slice(&frame.sun.as_vec3().to_array());
        // Seen from the sun: no facing locks (the eye is never near), upright base sprites
        // never fade (from a high sun they are edge on anyway), no far fade.
        header.forward_lock[1] = 0.0;
        header.upright_lifecycle[0] = 2.0;
        header.upright_lifecycle[1] = 3.0;
        // Each cloud's sprites in their slots' order: the half-float sums then come out the
        // same wherever the camera's sort has put them (a moved camera re-sorts clouds).
        header.hl_deck[1] = 1.0;
        header.far_fade_layer_turn[0] = NO_FAR_FADE_M;
        header.far_fade_layer_turn[1] = 2.0 * NO_FAR_FADE_M;
        let list_bytes = (self.lists.len() as u64 * 16).max(16);
        if list_bytes > self.list_buffer.size() {
            let size = list_bytes.next_power_of_two();
            self.list_buffer = storage_buffer(&self.device, "sky.cloud_shadow_lists", size);
            self.list_buffers_made += 1;
        }
        if !self.lists.is_empty() {
            let data = bytemuck::cast_slice(&self.lists);
            queue.write_buffer(&self.list_buffer, 0, data);
            bytes += data.len() as u64;
        }
        bytes += self.sprites_view.write(
            &self.device,
            queue,
            &self.view_layout,
            &header,
            None,
            ViewData::Resident {
                counts: [self.draws.len() as u32, 0, sprites, 0],
                draws: &self.draws,
                lists: &self.list_buffer,
                orders: &resident.order_buffer,
                // A new group when either buffer was replaced.
                generation: resident
                    .generation
                    .wrapping_mul(1_000_003)
                    .wrapping_add(self.list_buffers_made),
            },
        );
        bytes
    }

    /// Appends the draws of the blocks of `order` (in [`drawing_order`]) to the map's draw
    /// list, each with every cloud of its in its list (its sprites in the resident order) and
    /// moved back by `back_m` (the clouds' drift since the map was drawn whole), after the
    /// `first` sprites the list holds; returns the sprites appended. A block's lists are kept
    /// between drawings.
    pub(super) fn push_draws(
        &mut self,
        order: &[&Resident],
        frame: &ShadowFrame,
        back_m: DVec3,
        first: u32,
    ) -> u32 {
        let mut total = 0u32;
        for r in order {
            let list_base = self.lists.len() as u32;
            // Beyond `full_detail_m` across the rays, every `far_sprite_stride`th sprite of a
            // cloud stands for that many (its optical depth times the stride): far shadows lie
            // under the haze, and the far field holds most of the sprites.
            let stride = if is_near(frame, r.centre_m() - back_m, r.radius_m, &self.settings) {
                1
            } else {
                self.settings.far_sprite_stride
            };
            let kept = self.kept_lists.entry(r.block.id).or_default();
            if kept.built_for != Some((r.place_serial, stride)) {
                kept.lists.clear();
                let mut first = 0u32;
                for state in r.clouds.iter().filter(|c| c.sprites > 0) {
                    kept.lists.push(GpuListCloud {
                        cloud: state.cloud_slot,
                        first,
                        order_base: state.sprite_base,
                        stride,
                    });
                    first += state.sprites.div_ceil(stride);
                }
                (kept.built_for, kept.sprites) = (Some((r.place_serial, stride)), first);
            }
            self.lists.extend_from_slice(&kept.lists);
            let (fade_kind, fade_progress) = fade_code(r.fade());
            self.draws.push(GpuDrawBlock {
                origin_rel: (r.centre_m() - back_m - frame.eye_m).as_vec3().to_array(),
                first: first + total,
                list_base,
                list_len: self.lists.len() as u32 - list_base,
                fade_kind,
                fade_progress,
            });
            total += kept.sprites;
        }
        total
    }
}

impl CloudShadows {
    /// Appends the draws of the blocks of `order` (in [`drawing_order`]) to an empty draw list
    /// as [`Self::push_draws`] does, but with only the clouds whose shadow may fall in one of
    /// `rects` (a block's sprites are listed cloud by cloud, so the rest are left out: a
    /// rectangle drawn again costs the clouds that reach it, not whole blocks); returns the
    /// sprites.
    pub(super) fn push_masked_draws(
        &mut self,
        order: &[&Resident],
        frame: &ShadowFrame,
        back_m: DVec3,
        rects: &[TexelRect],
    ) -> u32 {
        let n = self.settings.size_px;
        let mut total = 0u32;
        for r in order {
            let offset = r.centre_m() - r.block.centre_m - back_m;
            let Some(reach) = footprint(frame, r.centre_m() - back_m, r.radius_m, n) else {
                continue;
            };
            let near: Vec<&TexelRect> = rects.iter().filter(|q| q.overlaps(&reach)).collect();
            let stride = if is_near(frame, r.centre_m() - back_m, r.radius_m, &self.settings) {
                1
            } else {
                self.settings.far_sprite_stride
            };
            let list_base = self.lists.len() as u32;
            let mut first = 0u32;
            for state in r.clouds.iter().filter(|c| c.sprites > 0) {
                let at = footprint(frame, state.centre_m + offset, state.radius_m as f64, n);
                if !at.is_some_and(|f| near.iter().any(|q| q.overlaps(&f))) {
                    continue;
                }
                self.lists.push(GpuListCloud {
                    cloud: state.cloud_slot,
                    first,
                    order_base: state.sprite_base,
                    stride,
                });
                first += state.sprites.div_ceil(stride);
            }
            if first == 0 {
                continue;
            }
            let (fade_kind, fade_progress) = fade_code(r.fade());
            self.draws.push(GpuDrawBlock {
                origin_rel: (r.centre_m() - back_m - frame.eye_m).as_vec3().to_array(),
                first: total,
                list_base,
                list_len: self.lists.len() as u32 - list_base,
                fade_kind,
                fade_progress,
            });
            total += first;
        }
        total
    }
}

/// `blocks` in the order every drawing of the map draws them (by place, then id): the
/// half-float sums then come out the same every run, and a rectangle drawn again adds its
/// sprites in the order a whole drawing does. Sorted on keys copied out of the blocks (a
/// comparison that reads two blocks costs two cache misses).
pub(super) fn drawing_order<'a>(blocks: impl Iterator<Item = &'a Resident>) -> Vec<&'a Resident> {
    let mut keyed: Vec<(f64, f64, u64, &Resident)> = blocks
        .map(|r| (r.block.centre_m.x, r.block.centre_m.y, r.block.id, r))
        .collect();
    keyed.sort_by(|a, b| {
        a.0.total_cmp(&b.0)
            .then(a.1.total_cmp(&b.1))
            .then(a.2.cmp(&b.2))
    });
    keyed.into_iter().map(|k| k.3).collect()
}

/// Whether a block (placed on the GPU) may cast a shadow into the map: its sphere's shadow
/// reaches the square across the rays.
pub(super) fn is_covered(r: &Resident, frame: &ShadowFrame) -> bool {
    if r.place.is_none() || !r.uploaded {
        return false;
    }
    let (x, y) = frame.across(r.centre_m());
    let reach = frame.half_extent_m + r.radius_m;
    x.abs() <= reach && y.abs() <= reach
}

/// Whether a block's shadow (centre and radius, placed) lies within `full_detail_m` of the
/// map's centre across the rays.
pub(super) fn is_near(
    frame: &ShadowFrame,
    centre_m: DVec3,
    radius_m: f64,
    s: &ShadowSettings,
) -> bool {
    let (x, y) = frame.across(centre_m);
    x.abs().max(y.abs()) - radius_m <= s.full_detail_m
}

/// The blocks a drawing at `frame` covers (their ids, with their placing), and those of them
/// that form or dissipate.
pub(super) fn covered(blocks: &Blocks, frame: &ShadowFrame) -> (IdMap<u64>, Vec<u64>) {
    let mut changing = Vec::new();
    let ids = blocks
        .values()
        .filter(|r| is_covered(r, frame))
        .map(|r| {
            if r.fade() != crate::render::Fade::Steady {
                changing.push(r.block.id);
            }
            (r.block.id, r.place_serial)
        })
        .collect();
    (ids, changing)
}

/// The sprites a drawing at `frame` draws of a block moved back by `back_m` (every
/// `far_sprite_stride`th beyond `full_detail_m`).
pub(super) fn block_sprites(
    r: &Resident,
    frame: &ShadowFrame,
    back_m: DVec3,
    s: &ShadowSettings,
) -> u32 {
    let stride = if is_near(frame, r.centre_m() - back_m, r.radius_m, s) {
        1
    } else {
        s.far_sprite_stride
    };
    r.clouds.iter().map(|c| c.sprites.div_ceil(stride)).sum()
}
