//! The demo host (feature `demo`): what the command line, the tests and the benchmarks draw
//! with, and nothing a simulator needs. A headless device and off-screen target on any adapter
//! (lavapipe included), a height-field ground with fog drawn first into colour and depth, the
//! sky drawn over it through the same [`SkySystem`](crate::SkySystem) a simulator embeds, and
//! the frame read back as PNG or EXR.

pub mod headless;
pub mod host;
pub mod output;
pub mod terrain;

pub use headless::{Frame, HeadlessGpu, OffscreenTarget};
pub use host::{DemoHost, GroundSettings, demo_ground, ground_from_field};
pub use terrain::{HeightField, Terrain, TerrainLight};
