//! Flight-path files and the camera pose along them.

use std::path::{Path, PathBuf};

use glam::{DVec2, DVec3};
use serde::Deserialize;
use toml::Spanned;

use super::spline::{self, Key};
use crate::config::{ConfigError, parse_toml, read_text};
use crate::weather::METRES_PER_FOOT;
use crate::weather::frame::LocalFrame;

/// Where the camera is and where it looks: world position in the local frame and a view angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraPose {
    /// Metres east, north of the frame origin and altitude above mean sea level.
    pub position_m: DVec3,
    /// Compass heading of the view, degrees clockwise from north.
    pub heading_deg: f64,
    /// View pitch, degrees above the horizon.
    pub pitch_deg: f64,
}

/// How a waypoint says to look.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum View {
    /// A fixed heading and pitch, degrees.
    Angles {
        /// Heading, degrees clockwise from north.
        heading_deg: f64,
        /// Pitch, degrees above the horizon.
        pitch_deg: f64,
    },
    /// Look at a point (local metres east, north, altitude MSL).
    LookAt(DVec3),
    /// Look along the direction of travel.
    Track,
}

/// A waypoint placed in the local frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Waypoint {
    /// Seconds from the start of the flight.
    pub time_s: f64,
    /// Metres east, north and altitude above mean sea level.
    pub position_m: DVec3,
    /// The view at this waypoint.
    pub view: View,
}

/// A flight-path file, validated, not yet placed in a frame.
#[derive(Debug, Clone, PartialEq)]
pub struct FlightPlan {
    /// Display name.
    pub name: String,
    /// What the flight shows.
    pub description: String,
    /// Latitude/longitude of the frame origin the flight is meant for.
    pub origin_lat_lon_deg: (f64, f64),
    /// Weather files that replace the sky at given times (a front passing), in time order.
    pub weather_events: Vec<WeatherEvent>,
    waypoints: Vec<WaypointFile>,
}

/// A timed weather change of a scripted flight.
#[derive(Debug, Clone, PartialEq)]
pub struct WeatherEvent {
    /// Seconds from the start of the flight.
    pub time_s: f64,
    /// The weather file (reports or a theme), resolved against the flight file's folder.
    pub weather: PathBuf,
}

/// A flight placed in a local frame: sample it with [`FlightPath::pose_at`].
#[derive(Debug, Clone, PartialEq)]
pub struct FlightPath {
    waypoints: Vec<Waypoint>,
    keys: Vec<Key>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FlightFile {
    name: String,
    #[serde(default)]
    description: String,
    origin: Option<LatLonFile>,
    waypoints: Spanned<Vec<WaypointFile>>,
    #[serde(default)]
    weather_events: Vec<WeatherEventFile>,
}

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
struct WeatherEventFile {
    time_s: Spanned<f64>,
    weather: Spanned<String>,
}

#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
struct LatLonFile {
    lat: f64,
    lon: f64,
}

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
struct WaypointFile {
    time_s: Spanned<f64>,
    lat: Option<Spanned<f64>>,
    lon: Option<Spanned<f64>>,
    east_m: Option<f64>,
    north_m: Option<f64>,
    alt_ft: Spanned<f64>,
    heading_deg: Option<f64>,
    pitch_deg: Option<f64>,
    look_at: Option<PointFile>,
}

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
struct PointFile {
    lat: Option<Spanned<f64>>,
    lon: Option<Spanned<f64>>,
    east_m: Option<f64>,
    north_m: Option<f64>,
    alt_ft: f64,
}

impl FlightPlan {
    /// Reads and validates a flight-path file.
    pub fn load(path: &Path) -> Result<Self, ConfigError> {
        let text = read_text(path)?;
        Self::parse(&text, path)
    }

    /// Parses and validates flight-path text that came from `path` (used in messages).
    pub fn parse(text: &str, path: &Path) -> Result<Self, ConfigError> {
        let file: FlightFile = parse_toml(text, path)?;
        let at = |span: std::ops::Range<usize>, field: &str, message: String| {
            ConfigError::at(path, text, span, field, message)
        };
        let waypoints_span = file.waypoints.span();
        let waypoints = file.waypoints.into_inner();
        if waypoints.len() < 2 {
            return Err(at(
                waypoints_span,
                "waypoints",
                "a flight needs at least two waypoints".into(),
            ));
        }
        let mut first_lat_lon = None;
        for (k, w) in waypoints.iter().enumerate() {
            let t = *w.time_s.get_ref();
            if !t.is_finite() || (k > 0 && t <= *waypoints[k - 1].time_s.get_ref()) {
                let message = format!("{t} s must come after the previous waypoint's time");
                return Err(at(w.time_s.span(), "time_s", message));
            }
            let alt = *w.alt_ft.get_ref();
            if !(-1_500.0..=80_000.0).contains(&alt) {
                return Err(at(
                    w.alt_ft.span(),
                    "alt_ft",
                    format!("{alt} ft is outside -1500..=80000"),
                ));
            }
            let place = check_place(&w.lat, &w.lon, w.east_m, w.north_m)
                .map_err(|message| at(w.time_s.span(), "lat", message))?;
            if let (Place::LatLon(lat, lon), None) = (place, first_lat_lon) {
                first_lat_lon = Some((lat, lon));
            }
            if let Some(look) = &w.look_at {
                check_place(&look.lat, &look.lon, look.east_m, look.north_m)
                    .map_err(|message| at(w.time_s.span(), "look_at", message))?;
                if w.heading_deg.is_some() || w.pitch_deg.is_some() {
                    let message = "give heading_deg/pitch_deg or look_at, not both".to_string();
                    return Err(at(w.time_s.span(), "look_at", message));
                }
            }
        }
        let origin = file
            .origin
            .map(|o| (o.lat, o.lon))
            .or(first_lat_lon)
            .ok_or_else(|| {
                let message =
                    "waypoints in local metres need an `origin = { lat, lon }`".to_string();
                at(waypoints_span, "origin", message)
            })?;
        let folder = path.parent().unwrap_or(Path::new("."));
        let mut weather_events = Vec::with_capacity(file.weather_events.len());
        for (k, event) in file.weather_events.iter().enumerate() {
            let t = *event.time_s.get_ref();
            if !t.is_finite() || (k > 0 && t <= *file.weather_events[k - 1].time_s.get_ref()) {
                let message = format!("{t} s must come after the previous event's time");
                return Err(at(event.time_s.span(), "time_s", message));
            }
            let weather = folder.join(event.weather.get_ref());
            if !weather.is_file() {
                let message = format!(
                    "no such file {} (paths are relative to the flight file)",
                    weather.display()
                );
                return Err(at(event.weather.span(), "weather", message));
            }
            weather_events.push(WeatherEvent { time_s: t, weather });
        }
        Ok(Self {
            name: file.name,
            description: file.description,
            origin_lat_lon_deg: origin,
            weather_events,
            waypoints,
        })
    }

    /// The flight in the local frame `frame` (lat/lon waypoints are projected; local-metre
    /// waypoints are relative to the plan's origin, moved into `frame`).
    pub fn place(&self, frame: &LocalFrame) -> FlightPath {
        let (olat, olon) = self.origin_lat_lon_deg;
        let origin_m = frame.to_local_m(olat, olon);
        let to_local = |lat: &Option<Spanned<f64>>,
                        lon: &Option<Spanned<f64>>,
                        e: Option<f64>,
                        n: Option<f64>| {
            match (lat, lon) {
                (Some(lat), Some(lon)) => frame.to_local_m(*lat.get_ref(), *lon.get_ref()),
                _ => origin_m + DVec2::new(e.unwrap_or(0.0), n.unwrap_or(0.0)),
            }
        };
        let waypoints: Vec<Waypoint> = self
            .waypoints
            .iter()
            .map(|w| {
                let xy = to_local(&w.lat, &w.lon, w.east_m, w.north_m);
                let view = match (&w.look_at, w.heading_deg, w.pitch_deg) {
                    (Some(p), _, _) => {
                        let xy = to_local(&p.lat, &p.lon, p.east_m, p.north_m);
                        View::LookAt(xy.extend(p.alt_ft * METRES_PER_FOOT))
                    }
                    (None, None, None) => View::Track,
                    (None, heading, pitch) => View::Angles {
                        heading_deg: heading.unwrap_or(0.0),
                        pitch_deg: pitch.unwrap_or(0.0),
                    },
                };
                Waypoint {
                    time_s: *w.time_s.get_ref(),
                    position_m: xy.extend(*w.alt_ft.get_ref() * METRES_PER_FOOT),
                    view,
                }
            })
            .collect();
        let keys = waypoints
            .iter()
            .map(|w| Key {
                time_s: w.time_s,
                position_m: w.position_m,
            })
            .collect();
        FlightPath { waypoints, keys }
    }
}

#[derive(Debug, Clone, Copy)]
enum Place {
    LatLon(f64, f64),
    Local,
}

fn check_place(
    lat: &Option<Spanned<f64>>,
    lon: &Option<Spanned<f64>>,
    east_m: Option<f64>,
    north_m: Option<f64>,
) -> Result<Place, String> {
    match (lat, lon, east_m, north_m) {
        (Some(lat), Some(lon), None, None) => {
            let (lat, lon) = (*lat.get_ref(), *lon.get_ref());
            if !(-90.0..=90.0).contains(&lat) || !(-180.0..=180.0).contains(&lon) {
                return Err(format!("{lat},{lon} is not a latitude,longitude"));
            }
            Ok(Place::LatLon(lat, lon))
        }
        (None, None, Some(_), Some(_)) => Ok(Place::Local),
        _ => Err("give either lat and lon, or east_m and north_m".to_string()),
    }
}

impl FlightPath {
    /// Seconds from the first waypoint to the last.
    pub fn duration_s(&self) -> f64 {
        self.keys[self.keys.len() - 1].time_s - self.keys[0].time_s
    }

    /// Time of the first waypoint, seconds.
    pub fn start_s(&self) -> f64 {
        self.keys[0].time_s
    }

    /// The waypoints, placed.
    pub fn waypoints(&self) -> &[Waypoint] {
        &self.waypoints
    }

    /// The camera pose at `time_s` (clamped to the flight).
    pub fn pose_at(&self, time_s: f64) -> CameraPose {
        let (position_m, velocity_m_s) = spline::sample(&self.keys, time_s);
        let i = self
            .waypoints
            .partition_point(|w| w.time_s <= time_s)
            .clamp(1, self.waypoints.len() - 1)
            - 1;
        let (a, b) = (&self.waypoints[i], &self.waypoints[i + 1]);
        let u = ((time_s - a.time_s) / (b.time_s - a.time_s)).clamp(0.0, 1.0);
        let blend = u * u * (3.0 - 2.0 * u);
        let (ha, pa) = view_angles(a.view, position_m, velocity_m_s);
        let (hb, pb) = view_angles(b.view, position_m, velocity_m_s);
        let dh = (hb - ha + 540.0).rem_euclid(360.0) - 180.0;
        CameraPose {
            position_m,
            heading_deg: (ha + dh * blend).rem_euclid(360.0),
            pitch_deg: pa + (pb - pa) * blend,
        }
    }
}

/// Heading and pitch (degrees) that `view` asks for from `position_m` moving at `velocity_m_s`.
fn view_angles(view: View, position_m: DVec3, velocity_m_s: DVec3) -> (f64, f64) {
    let direction = match view {
        View::Angles {
            heading_deg,
            pitch_deg,
        } => return (heading_deg, pitch_deg),
        View::LookAt(target_m) => target_m - position_m,
        View::Track => velocity_m_s,
    };
    if direction.truncate().length() < 1e-6 {
        return (0.0, if direction.z > 0.0 { 89.0 } else { 0.0 });
    }
    let heading = direction
        .x
        .atan2(direction.y)
        .to_degrees()
        .rem_euclid(360.0);
    let pitch = direction
        .z
        .atan2(direction.truncate().length())
        .to_degrees();
    (heading, pitch)
}

#[cfg(test)]
mod tests {
    use super::*;

    const LOCAL: &str = "name = \"t\"\norigin = { lat = 47.0, lon = 11.0 }\n\n[[waypoints]]\ntime_s = 0\neast_m = 0\nnorth_m = 0\nalt_ft = 1000\n\n[[waypoints]]\ntime_s = 100\neast_m = 10000\nnorth_m = 0\nalt_ft = 1000\n";

    fn plan(text: &str) -> Result<FlightPlan, ConfigError> {
        FlightPlan::parse(text, Path::new("config/flights/t.toml"))
    }

    fn error_of(text: &str) -> ConfigError {
        plan(text).unwrap_err()
    }

    #[test]
    fn track_view_looks_along_the_flight() {
        let plan = plan(LOCAL).unwrap();
        let path = plan.place(&LocalFrame::new(47.0, 11.0));
        let pose = path.pose_at(50.0);
        assert!(
            pose.position_m.distance(DVec3::new(5000.0, 0.0, 304.8)) < 1e-6,
            "{pose:?}"
        );
        assert!((pose.heading_deg - 90.0).abs() < 1e-9 && pose.pitch_deg.abs() < 1e-9);
        assert_eq!(path.duration_s(), 100.0);
    }

    #[test]
    fn look_at_points_the_camera_at_the_target() {
        let text = LOCAL.replace("alt_ft = 1000\n\n[[waypoints]]", "alt_ft = 1000\nlook_at = { east_m = 0, north_m = 5000, alt_ft = 1000 }\n\n[[waypoints]]")
            + "look_at = { east_m = 0, north_m = 5000, alt_ft = 1000 }\n";
        let path = plan(&text).unwrap().place(&LocalFrame::new(47.0, 11.0));
        let pose = path.pose_at(0.0);
        assert!(pose.heading_deg.abs() < 1e-9, "{pose:?}");
        let pose = path.pose_at(100.0);
        let expected = (-10_000.0f64).atan2(5000.0).to_degrees().rem_euclid(360.0);
        assert!((pose.heading_deg - expected).abs() < 1e-9, "{pose:?}");
    }

    #[test]
    fn headings_blend_the_short_way_round() {
        let text = LOCAL.replace("alt_ft = 1000\n\n", "alt_ft = 1000\nheading_deg = 350\n\n")
            + "heading_deg = 10\n";
        let path = plan(&text).unwrap().place(&LocalFrame::new(47.0, 11.0));
        let mid = path.pose_at(50.0).heading_deg;
        assert!(mid < 1e-9 || (mid - 360.0).abs() < 1e-9, "{mid}");
    }

    #[test]
    fn lat_lon_waypoints_set_the_origin() {
        let text = "name = \"t\"\n[[waypoints]]\ntime_s = 0\nlat = 29.4\nlon = -98.6\nalt_ft = 5000\n[[waypoints]]\ntime_s = 10\nlat = 29.5\nlon = -98.5\nalt_ft = 900\n";
        let plan = plan(text).unwrap();
        assert_eq!(plan.origin_lat_lon_deg, (29.4, -98.6));
        let path = plan.place(&LocalFrame::new(29.4, -98.6));
        assert!(path.pose_at(0.0).position_m.truncate().length() < 1e-6);
    }

    #[test]
    fn errors_name_line_and_field() {
        let err = error_of(&LOCAL.replace("time_s = 100", "time_s = 0"));
        assert_eq!((err.line, err.field.as_deref()), (Some(11), Some("time_s")));
        let err = error_of(&LOCAL.replace("alt_ft = 1000\n\n", "alt_ft = 99000\n\n"));
        assert_eq!((err.line, err.field.as_deref()), (Some(8), Some("alt_ft")));
        let err = error_of(&LOCAL.replace("north_m = 0\nalt_ft = 1000\n\n", "alt_ft = 1000\n\n"));
        assert_eq!(err.field.as_deref(), Some("lat"));
        let err = error_of(&LOCAL.replace("origin = { lat = 47.0, lon = 11.0 }\n", ""));
        assert_eq!(err.field.as_deref(), Some("origin"));
        let err = error_of(&LOCAL.replace(
            "alt_ft = 1000\n\n",
            "alt_ft = 1000\nheading_deg = 5\nlook_at = { east_m = 0, north_m = 1, alt_ft = 0 }\n\n",
        ));
        assert_eq!(err.field.as_deref(), Some("look_at"));
        assert_eq!(
            error_of(&LOCAL.replace("alt_ft = 1000\n\n", "altitude = 3\nalt_ft = 1000\n\n"))
                .field
                .as_deref(),
            Some("altitude")
        );
        let one = LOCAL
            .split("\n\n[[waypoints]]\ntime_s = 100")
            .next()
            .unwrap()
            .to_string();
        assert_eq!(error_of(&one).field.as_deref(), Some("waypoints"));
    }

    #[test]
    fn shipped_flights_load_and_fly() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("config/flights");
        let mut count = 0;
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            let plan = FlightPlan::load(&path).unwrap_or_else(|err| panic!("{err}"));
            let (lat, lon) = plan.origin_lat_lon_deg;
            let flight = plan.place(&LocalFrame::new(lat, lon));
            let start = flight.pose_at(flight.start_s());
            let end = flight.pose_at(flight.start_s() + flight.duration_s());
            assert!(
                start.position_m.distance(end.position_m) > 0.0 || flight.waypoints().len() > 2,
                "{path:?}"
            );
            count += 1;
        }
        assert!(count >= 3);
    }

    #[test]
    fn weather_events_resolve_against_the_flight_file() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("config/flights/front_passing.toml");
        let plan = FlightPlan::load(&path).unwrap();
        let times: Vec<_> = plan.weather_events.iter().map(|e| e.time_s).collect();
        assert_eq!(times, [0.0, 120.0, 240.0]);
        assert!(plan.weather_events.iter().all(|e| e.weather.is_file()));

        let flights = Path::new(env!("CARGO_MANIFEST_DIR")).join("config/flights/t.toml");
        let with = |events: &str| FlightPlan::parse(&format!("{LOCAL}{events}"), &flights);
        let err = with("[[weather_events]]\ntime_s = 5\nweather = \"../../weather/none.txt\"\n")
            .unwrap_err();
        assert_eq!(
            (err.line, err.field.as_deref()),
            (Some(17), Some("weather"))
        );
        let ok = "[[weather_events]]\ntime_s = 5\nweather = \"../../weather/front/1_clear.txt\"\n";
        let err = with(&format!("{ok}{ok}")).unwrap_err();
        assert_eq!((err.line, err.field.as_deref()), (Some(19), Some("time_s")));
    }
}
