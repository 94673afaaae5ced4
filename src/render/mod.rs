//! The renderer: the only stage that uses wgpu. A host simulator creates a [`Sky`] with its own
//! device and queue, gives it clouds ([`SkyBlock`]s, uploaded to the GPU once each; per frame
//! only a block's [`BlockMotion`] changes), and each frame calls [`Sky::prepare`] (camera, sun,
//! dt: the CPU's small share and the uploads of what changed, returns [`FrameStats`]) and
//! [`Sky::record`] (its passes into the host's encoder, reading the host's depth, never writing
//! it).
//!
//! - `sprites`: the near sprites' pipeline, from the blocks resident on the GPU to the built
//!   corners a draw reads (its own page lists the parts); the impostor ring and the shadow map
//!   draw with its lists and its build too.
//! - `sky`: pipelines and passes: sky gradient and sun, sprites with soft depth fades
//!   (Bahnassi), in-cloud fog (Wang 7.1). Shaders in `shaders/*.wgsl`, structs with twins in
//!   `gpu_types`. `readback`: the built corners read back for tests and tools.
//! - `targets`: the host's targets and view on its terms (formats, reversed Z, MSAA, its own
//!   matrices).
//! - `cloud_target`: below full resolution, the clouds drawn off-screen against the farthest
//!   depth of each block of pixels and composited with a full-resolution depth fix-up.
//! - `earth`: the round Earth every far thing is drawn on (the flat frame's points dropped onto
//!   the sphere; the shaders' `earth_curved`).
//! - `far_field`: the clouds beyond the ring out to the horizon: two curved layers of the
//!   weather's cloud map (`crate::clouds::far_map`), one pass over the band of elevations
//!   they can show.
//! - `shadow`: the clouds drawn from the sun into a shadow map a host multiplies into its
//!   ground's sunlight.
//! - `pass_timing`: GPU time of each of the sky's passes, a profiling aid (off by default).
//!
//! Positions are f64 on the CPU and camera-relative f32 on the GPU. Units: metres, degrees,
//! linear RGB.

pub mod camera;
pub mod capabilities;
pub mod cloud_target;
pub mod earth;
pub mod far_field;
pub mod gpu_types;
mod id_hash;
pub mod impostor;
mod overhead_ease;
mod pass_timing;
mod pipeline;
mod readback;
pub mod scene;
pub mod settings;
pub mod shadow;
pub mod sky;
mod sprites;
pub mod stats;
pub mod targets;
pub mod update;
mod view;

pub use camera::{Camera, Frustum};
// The draw list's module stays public under its old path (benches sort with it).
pub use pass_timing::{PassTimes, Timestamps};
pub use readback::SpriteCorner;
pub use scene::{BandOffsets, BlockMotion, Fade, SkyBlock, SkyCloud, SkySprite, square_sprite};
pub use settings::RenderSettings;
pub use shadow::{CloudShadowMap, ShadowImage, ShadowSettings};
pub use sky::{Sky, SkyConfig, SkyFlash};
pub use sprites::draw_list;
pub use sprites::resident::{BYTES_PER_SPRITE, resident_slots_bound};
pub use sprites::sheet::SpriteSheet;
pub use stats::{FrameStats, Lighting, SkyMemory, Spent, Stopwatch, ThreadCpu};
pub use targets::{HostTargets, SkyView};
pub use update::{DistantChange, SkyReach, SkyUpdate};
pub use view::ViewId;

/// How to install a software Vulkan driver where there is no GPU (Debian, Ubuntu).
pub const INSTALL_HINT: &str = "sudo apt-get install -y mesa-vulkan-drivers libvulkan1";

/// Errors of the renderer.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RenderError {
    /// No graphics adapter at all (no GPU and no software driver).
    #[error(
        "no graphics adapter found ({0}); skycast renders on any GPU or on Mesa's software Vulkan driver, install it with: {hint}",
        hint = INSTALL_HINT
    )]
    NoAdapter(String),
    /// The adapter refused a device, or a device operation failed.
    #[error("graphics device: {0}")]
    Device(String),
    /// The device lacks a format, limit or feature the sky needs (checked in [`Sky::new`]).
    #[error("this graphics device cannot draw the sky: {0}")]
    Unsupported(String),
    /// The requested image size is zero or beyond the device's limit.
    #[error("image size {width}x{height} is not drawable (each side 1..={max})")]
    Size {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
        /// The device's largest texture side.
        max: u32,
    },
    /// The clouds stage could not start (its generation pool or config).
    #[error("clouds: {0}")]
    Clouds(String),
    /// An elevation file could not be read or is not a square 16-bit greyscale PNG.
    #[error("{path}: {message}")]
    Elevation {
        /// The file.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// The sprite sheet's pixel data does not match its size.
    #[error("sprite sheet: {0}")]
    Sheet(String),
    /// The host's targets are ones the sky cannot draw into or read.
    #[error("host targets: {0}")]
    Targets(String),
    /// An output file could not be written.
    #[error("{path}: {message}")]
    Output {
        /// The file.
        path: String,
        /// Why.
        message: String,
    },
}
