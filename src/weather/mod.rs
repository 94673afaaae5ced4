//! The weather stage: weather files in, the weather of any 4 km x 4 km block out.
//!
//! `metar` decodes reports; `files` reads bulk files (the aviation weather service's
//! `metars.cache.csv`, NOAA cycle files, plain METAR lines) and places them with `stations`;
//! `field` triangulates the placed reports (spade, Delaunay) and interpolates by natural
//! neighbours; `block` holds the per-block result the clouds stage consumes, `block_cover` how its
//! cover varies across the block.

pub mod air;
pub mod block;
pub mod block_cover;
pub mod cloud_type;
pub mod error;
pub mod field;
pub mod files;
pub mod frame;
pub mod input;
pub mod live;
pub mod metar;
pub mod model;
pub mod remarks;
pub mod stations;
pub mod storms;
pub mod theme;
pub mod watch;
pub mod winds_aloft;

pub use block::{
    BLOCK_SIZE_M, BlockIndex, BlockLayer, BlockWeather, METRES_PER_FOOT, METRES_PER_KNOT,
    TypeSource, Wind,
};
pub use block_cover::{BlockCover, LayerCover, RimLayer};
pub use cloud_type::CloudType;
pub use error::{LineWarning, SkipCount, Skipped, WarningKind, WeatherError};
pub use field::{CloudTypeRule, FieldSettings, WeatherField};
pub use files::{FileFormat, PlacedReport, Position, WeatherFile};
pub use frame::LocalFrame;
pub use input::WeatherInput;
pub use stations::{Station, StationTable};
