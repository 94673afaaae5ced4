//! The clouds stage: the weather of a 4 km x 4 km block in, clouds made of sprites out.
//!
//! After Wang 2003 ("Realistic and Fast Cloud Rendering", `papers/`), sections 3 and 4:
//! - [`config`]: the cloud types of `config/cloud_types.toml` (thickness, cloud size, boxes,
//!   sprites, texture bands, rotations, cull radius, five colour levels, shading group size, §3.1,
//!   §3.2, §5.1) and the lifecycle timings of `config/clouds.toml` (§4).
//! - [`sheet`]: the 512 x 512 sheet of 16 procedural textures (3 foggy, 1 flat-bottomed, 6 wispy,
//!   6 puffy, §3.2) with its mip chain down to 32 x 32, computed cell by cell.
//! - [`generate`]: [`generate_block`], a pure function of (block index, block weather, seed):
//!   clouds are boxes filled with random sprite centres, then culled (§3.1); a layer whose
//!   cover varies over its block is filled to the cover at each place (module `uneven`).
//! - [`lifecycle`]: formation and dissipation as a per-sprite `alpha_morph` (§4).
//! - [`field`]: [`CloudField`], the blocks around a point: background generation, weather changes
//!   that dissipate old clouds while new ones form, and drift with the wind.
//! - [`far_map`]: the far field's cloud map: the weather field on a coarse grid out to the
//!   horizon of cruise altitude, cover, base and top of a low and a high layer per cell.
//! - [`preview`]: a CPU orthographic splat of a block to an image, for eyes and tests.
//!
//! Units: world positions are f64 metres east, north and up (above mean sea level); everything
//! inside a cloud is f32 metres relative to the cloud centre, ready for a GPU.

pub mod bands;
pub mod block;
pub mod boxes;
pub mod config;
pub mod core;
pub mod far_map;
pub mod field;
pub mod generate;
mod heap;
pub mod lifecycle;
pub mod noise;
pub mod preview;
pub mod probe;
pub mod probe_bands;
pub mod rain;
pub mod rng;
pub mod sheet;
mod sight;
pub mod storm;
mod uneven;

pub use bands::DriftBand;
pub use block::{Cloud, CloudBlock, ColourLevel, LayerSummary, ShadingGroup, Sprite};
pub use config::{CloudTypeConfig, CloudTypes, CloudsConfig, LifecycleConfig, TextureCategory};
pub use field::{BlockGenerator, CloudField};
pub use generate::generate_block;
pub use sheet::{CELL_PX, CELLS_PER_ROW, SHEET_PX, TEXTURE_COUNT, TextureSheet};

use std::path::PathBuf;

/// Everything that can go wrong in the clouds stage; each names the file, line and field at fault.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CloudsError {
    /// A config file could not be read.
    #[error("{path}: cannot read: {source}")]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A config file is not valid TOML, or a field is missing, unknown or of the wrong type.
    #[error("{path}:{line}: field `{field}`: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line of the fault.
        line: usize,
        /// The field at fault (dotted, e.g. `stratus.thickness_m`).
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A field parses but its value is out of range or inconsistent.
    #[error("{path}:{line}: field `{field}`: {message}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// 1-based line of the field.
        line: usize,
        /// The field at fault (dotted, e.g. `stratus.thickness_m`).
        field: String,
        /// What is wrong and what is allowed.
        message: String,
    },
    /// A cloud type the weather can ask for has no section in the config.
    #[error("{path}: no section `[{cloud_type}]`: every cloud type needs one")]
    MissingType {
        /// The file.
        path: PathBuf,
        /// The type without a section.
        cloud_type: crate::weather::CloudType,
    },
    /// The generation thread pool could not be started.
    #[error("cannot start the cloud generation threads: {0}")]
    ThreadPool(String),
    /// An image could not be written.
    #[error("{path}: cannot write image: {source}")]
    Image {
        /// The file.
        path: PathBuf,
        /// Why.
        source: image::ImageError,
    },
}
