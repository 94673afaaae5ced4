//! The flight stage: scripted camera paths for `skycast fly` and the benchmarks.
//!
//! A flight path is a TOML file of timed waypoints (`config/flights/*.toml`): positions as
//! latitude/longitude or local metres, altitude in feet above mean sea level, and a view given as
//! heading/pitch, a point to look at, or nothing (look along the track). [`FlightPlan`] is the file
//! as validated; [`FlightPath`] is the plan placed in a local frame, sampled at any time by
//! [`FlightPath::pose_at`]: Catmull-Rom through the waypoints in time (tangents from the neighbouring
//! waypoints), so position and velocity are continuous, and views blended with a smoothstep
//! between waypoints.

mod path;
mod spline;

pub use path::{CameraPose, FlightPath, FlightPlan, View, Waypoint, WeatherEvent};
