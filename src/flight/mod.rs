//! The flight stage, the last before the command line: [`SkySystem`], the sky a simulator
//! embeds (the frame step: live weather, the living clouds, the sun, the sky's frame), and
//! scripted camera paths for `skycast fly` and the benchmarks.
//!
//! A flight path is a TOML file of timed waypoints (`config/flights/*.toml`): positions as
//! latitude/longitude or local metres, altitude in feet above mean sea level, and a view given as
//! heading/pitch, a point to look at, or nothing (look along the track). [`FlightPlan`] is the file
//! as validated; [`FlightPath`] is the plan placed in a local frame, sampled at any time by
//! [`FlightPath::pose_at`]: Catmull-Rom through the waypoints in time (tangents from the neighbouring
//! waypoints), so position and velocity are continuous, and views blended with a smoothstep
//! between waypoints.

pub mod air;
mod block_weathers;
pub mod ceilometer;
mod far_cells;
mod living;
mod path;
pub mod radar;
mod spline;
pub mod system;
pub mod world;

pub use air::{AirData, AirLayer, PrecipitationType, TurbulenceCategory};
pub use path::{CameraPose, FlightPath, FlightPlan, View, Waypoint, WeatherEvent};
pub use system::{
    HostCamera, HostLighting, HostPosition, SkyError, SkySystem, SkySystemConfig, Weather,
};
pub use world::{World, WorldSettings};
