//! The near sprites: the clouds' sprites drawn one by one around the camera, from the blocks
//! resident on the GPU to the corners the sprite draw reads. The impostor ring and the shadow
//! map draw the same resident sprites through the same lists and build.
//!
//! - `resident`, `slots`: the sprites and clouds on the GPU, each block in slots it keeps;
//!   `records`: a sprite's and a cloud's GPU record.
//! - `cloud_light`: under Harris and Lastra's model, the light each resident sprite gets through
//!   its cloud (computed on the CPU when a block arrives and after the sun turned, a budget a
//!   frame), in a buffer beside the sprites; `resident_light` runs it over the resident set.
//! - `draw_list`: per frame on the CPU: the near blocks back to front, each block's cloud list
//!   and each cloud's sprite order recomputed only when Wang's cache thresholds say (6.1), the
//!   facing locks (3.3), the draw list (its entries, seams between deck blocks included, in
//!   `draw_entries`). `sprite_view`: a view's uniform, draw list, lists and
//!   orders on the GPU. `scatter`: the changed lists and orders sent as one patch. `build`: the
//!   compute pass that makes the sprites' corners (facing, Wang 5 shading, fades) for the draw;
//!   `sheet_crop`: the part of each sheet cell its texture covers, for the build.
//! - `settings`: the `[clouds]` and `[vertex_cache]` tables these stages read; `sheet`: the
//!   sprite texture sheet.
//!
//! The sky ([`Sky`](super::Sky)) conducts these parts; none of them imports it.

pub(super) mod build;
pub(super) mod cloud_light;
mod draw_entries;
pub mod draw_list;
// The near sprites as one pass of the sky: new, place, plan, upload, record.
pub(super) mod pass;
pub(super) mod records;
pub(super) mod resident;
mod resident_light;
pub(super) mod scatter;
pub(super) mod settings;
pub(super) mod sheet;
pub(super) mod sheet_crop;
pub(super) mod slots;
pub(super) mod sprite_view;
