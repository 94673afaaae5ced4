//! skycast: a cloud and weather sky for flight simulators.
//!
//! Real weather reports go in (METAR, bulk weather files); clouds come out as 4 km x 4 km blocks
//! of camera-facing sprites (Wang 2003), drawn with wgpu into the host's frame. Data flows one way,
//! one module per stage: [`weather`] -> `clouds` -> [`shading`] -> `render` -> `flight`.
//! Only `render` knows wgpu; every stage before it is plain data, testable without a device.

pub mod clouds;
pub mod config;
pub mod flight;
pub mod render;
pub mod shading;
pub mod weather;
