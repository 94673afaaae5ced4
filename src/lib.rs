//! skycast: a cloud and weather sky for flight simulators.
//!
//! Real weather reports go in (METAR, bulk weather files, themes); clouds come out as 4 km x 4 km
//! blocks of camera-facing sprites (Wang 2003), drawn with wgpu into the host's own frame, on the
//! host's terms: its device, its camera matrices, its depth (standard or reversed Z, MSAA).
//!
//! # Embedding
//!
//! One object, [`SkySystem`], built from the host's device, queue and targets:
//!
//! ```no_run
//! # fn frame(device: &wgpu::Device, queue: &wgpu::Queue, encoder: &mut wgpu::CommandEncoder,
//! #          colour: &wgpu::TextureView, depth: &wgpu::TextureView,
//! #          view: glam::Mat4, projection: glam::Mat4) -> Result<(), skycast::SkyError> {
//! use skycast::{HostCamera, HostPosition, HostTargets, SkySystem, Weather};
//!
//! let targets = HostTargets { reversed_z: true, ..HostTargets::default() };
//! let mut sky = SkySystem::new(device, queue, targets, (34.0, -118.4))?;
//! sky.set_weather(Weather::File("metars.cache.csv".as_ref()))?;
//! // Every frame, after the host drew its scene into colour and depth:
//! let camera = HostCamera {
//!     position: HostPosition::LatLonAlt { lat_deg: 34.05, lon_deg: -118.3, alt_m: 1500.0 },
//!     view,       // the host's view for east-north-up axes
//!     projection, // the host's projection, as its depth convention has it
//! };
//! let (stats, _applied) = sky.update(queue, &camera, 1_738_015_200.0, 1.0 / 60.0)?;
//! sky.record(encoder, colour, depth)?; // checks the targets; reads the host's depth, never writes it
//! let light = sky.lighting();         // sun, ambient, horizon and fog for the host's scene
//! # let _ = (stats, light); Ok(()) }
//! ```
//!
//! `examples/host.rs` is a complete host (its own device, targets and ground) that the tests run
//! with standard Z, reversed Z and 4x MSAA. A host that writes `default-features = false`
//! compiles none of the command line's crates.
//!
//! The types a host touches: [`SkySystem`] (the sky), [`HostTargets`] (its colour and depth
//! targets), [`Weather`] (what the sky is given), [`HostCamera`] and [`HostPosition`] (its camera
//! each frame), [`FrameStats`] (what a frame cost), [`HostLighting`] (the light to draw its own
//! scene with) and [`SkyError`]. [`SkySystemConfig`] holds settings of the host's own; [`Sky`]
//! and [`SkyView`] are the renderer underneath, for a host with its own weather and cloud
//! handling. The book (`docs/src/embedding.md` in the repository) has the host's terms in full.
//!
//! # Stages
//!
//! Data flows one way, one module per stage: [`weather`] (reports, the weather field) ->
//! [`clouds`] (cloud blocks, their lifecycle) -> [`shading`] (sun, light, fog) -> [`render`]
//! (the only stage that uses wgpu: the sky on the GPU) -> [`flight`] ([`SkySystem`], the frame
//! step; flight paths). Every stage before `render` is plain data, testable without a device.
//! `demo` (feature `demo`, on by default with the command line) is the demo host the command
//! line, tests and benchmarks draw with.

#![deny(missing_docs)]

pub mod clouds;
pub mod config;
#[cfg(feature = "demo")]
pub mod demo;
pub mod flight;
pub mod render;
pub mod shading;
pub mod weather;

/// The glam of the API's vectors and matrices (0.34), for the same reason.
pub use glam;
/// The wgpu the sky draws with (30): a host builds its device with this one, so the types agree
/// (`skycast::wgpu::Device`), and needs no version of its own to keep in step.
pub use wgpu;

pub use flight::{
    HostCamera, HostLighting, HostPosition, SkyError, SkySystem, SkySystemConfig, Weather,
};
pub use render::{FrameStats, HostTargets, Sky, SkyView, ViewId};

/// The README's embedding snippet, compiled by `cargo test --doc` so that it cannot drift from
/// the API (the README's only Rust block; its shell blocks are checked by `tests/docs.rs`).
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
