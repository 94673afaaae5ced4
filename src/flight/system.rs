//! [`SkySystem`]: the sky a simulator embeds, as one object. The host keeps it beside its own
//! renderer: built from the host's device, queue and targets ([`HostTargets`]); given weather
//! (a report file, bytes, a theme or a watched file); each frame given the host's camera as the
//! host has it ([`HostCamera`]: position and its own view and projection), the UTC time and
//! the frame's dt; then it records its passes into the host's encoder. Between them it runs the
//! frame step: new weather switched in without a pop, the living clouds around the camera
//! advanced and handed to the GPU (only what changed), the sky greyed under the weather
//! overhead, the sun placed, the CPU share of the frame done ([`Sky::prepare`]).
//!
//! What the host needs to light and fog its own scene the same way comes back from
//! [`SkySystem::lighting`].

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

use glam::{DVec3, Mat4, Vec3};

use super::world::{World, WorldSettings};
use crate::render::{
    Camera, FrameStats, HostTargets, RenderError, Sky, SkyConfig, SkyView, Stopwatch, ViewId,
};
use crate::shading::sun_position;
use crate::weather::field::{CloudTypeRule, FieldSettings, WeatherField};
use crate::weather::live::{LiveChange, LiveWeather, Prepare};
use crate::weather::model::{ModelField, ModelSettings};
use crate::weather::watch::{WatchUpdate, WeatherWatch};
use crate::weather::winds_aloft::WindsAloft;
use crate::weather::{LocalFrame, Skipped, StationTable, WeatherError, WeatherInput};

/// Why the sky could not be built or given its weather.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SkyError {
    /// The device or the host's targets.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// A weather file, its bytes or the station table.
    #[error(transparent)]
    Weather(#[from] WeatherError),
}

/// How a [`SkySystem`] is set up. [`SkySystemConfig::new`] needs no files; a host that keeps
/// settings of its own (loaded from its files, a wider cloud radius) changes the fields and hands
/// the result to [`SkySystem::with_config`].
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct SkySystemConfig {
    /// The sky's look and the host's targets (formats, reversed Z, samples).
    pub sky: SkyConfig,
    /// Latitude and longitude, degrees, of the local frame's origin: the middle of the area
    /// flown (positions in metres are east and north of it).
    pub origin_lat_lon_deg: (f64, f64),
    /// How far around the camera clouds live, and the seed they are generated from.
    pub world: WorldSettings,
    /// How the weather field is built from reports.
    pub field: FieldSettings,
    /// Which cloud type a reported layer is, where the report does not say.
    pub rule: CloudTypeRule,
    /// Places the reports of files that give no positions (plain METAR lines, NOAA cycle
    /// files). `None`: NOAA's table shipped inside the library ([`StationTable::builtin`]); a
    /// host with a newer table passes its own.
    pub stations: Option<Arc<StationTable>>,
}

impl From<SkyConfig> for SkySystemConfig {
    /// The sky's own config around latitude and longitude 0 (clear weather until it is given).
    fn from(sky: SkyConfig) -> Self {
        Self {
            sky: sky.clone(),
            ..Self::new(sky.targets, (0.0, 0.0))
        }
    }
}

impl SkySystemConfig {
    /// The shipped settings for `targets`, the local frame around `origin_lat_lon_deg`.
    pub fn new(targets: HostTargets, origin_lat_lon_deg: (f64, f64)) -> Self {
        Self {
            sky: SkyConfig::new(targets),
            origin_lat_lon_deg,
            world: WorldSettings::default(),
            field: FieldSettings::default(),
            rule: CloudTypeRule::default(),
            stations: None,
        }
    }
}

/// Weather for the sky, given to [`SkySystem::set_weather`]: a file read once (a simulator's
/// scenario), the same already in memory (downloaded by the host), or a file the sky keeps
/// watching (one the host replaces every few minutes with fresh reports).
///
/// ```
/// use skycast::Weather;
/// use std::{path::Path, time::Duration};
///
/// let once = Weather::File(Path::new("weather/themes/fair_weather_cumulus.toml"));
/// let downloaded = Weather::Bytes {
///     name: Path::new("metars.txt"), // tells a theme (.toml) from reports, and names errors
///     bytes: b"KLAX 272153Z 25010KT 10SM FEW025 SCT040 18/09 A2992\n",
/// };
/// let live = Weather::Watch {
///     path: Path::new("metars.cache.csv"),
///     settle: Duration::from_millis(500),
/// };
/// # let _ = (once, downloaded, live);
/// ```
#[derive(Debug, Clone, Copy)]
#[non_exhaustive]
pub enum Weather<'a> {
    /// A report file (the aviation weather service's `metars.cache.csv`, a NOAA cycle file,
    /// one METAR a line), a weather theme (`.toml`) or a weather model's GRIB2 file (told by its
    /// content; the model alone, see [`SkySystem::set_model`] for a model under reports), read
    /// now.
    File(&'a Path),
    /// The same, already in memory; `name` tells a theme by its extension and names it in
    /// errors.
    Bytes {
        /// The name of what the bytes are (a path or a file name).
        name: &'a Path,
        /// Its contents.
        bytes: &'a [u8],
    },
    /// A file read now and again whenever it changes (a change is read and built off the frame
    /// thread and applied `settle` after the last write; a broken file keeps the last good sky).
    Watch {
        /// The file.
        path: &'a Path,
        /// Quiet time after a write before the file is read.
        settle: Duration,
    },
}

/// Where the host's camera is: latitude, longitude and altitude for a host that flies the globe,
/// or metres from the origin given to [`SkySystem::new`] for one that works in a local frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HostPosition {
    /// Latitude and longitude in degrees, altitude in metres above mean sea level.
    LatLonAlt {
        /// Degrees north.
        lat_deg: f64,
        /// Degrees east.
        lon_deg: f64,
        /// Metres above mean sea level.
        alt_m: f64,
    },
    /// Metres east and north of the origin, and above mean sea level.
    Local(DVec3),
}

/// The host's camera this frame, as the host has it, given to [`SkySystem::update`] every
/// frame. The sky reads the host's depth through `projection`, so it must be the projection the
/// host drew its scene with.
///
/// ```
/// use glam::camera::rh::{proj::directx as proj, view::look_to_mat4};
/// use glam::{DVec3, Vec3};
/// use skycast::{HostCamera, HostPosition};
///
/// // Looking north, level, from 1,500 m above the origin; east-north-up axes (z up); clip
/// // depth 0 to 1, reversed Z with an infinite far plane (the host's targets say reversed).
/// let view = look_to_mat4(Vec3::ZERO, Vec3::Y, Vec3::Z);
/// let projection = proj::perspective_infinite_reverse(60f32.to_radians(), 16.0 / 9.0, 1.0);
/// let camera = HostCamera {
///     position: HostPosition::Local(DVec3::new(0.0, 0.0, 1500.0)),
///     view,
///     projection,
/// };
/// # let _ = camera;
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HostCamera {
    /// Where it is.
    pub position: HostPosition,
    /// The host's view matrix for east-north-up axes (its translation is ignored: the sky
    /// works relative to the camera). A y-up host multiplies its view by the axis swap.
    pub view: Mat4,
    /// The host's projection, clip depth `[0, 1]`, standard or reversed as its targets say.
    pub projection: Mat4,
}

impl From<&Camera> for HostCamera {
    /// skycast's own heading/pitch camera as a host's: local position, its view and projection.
    fn from(camera: &Camera) -> Self {
        Self {
            position: HostPosition::Local(camera.position_m),
            view: camera.view_relative(),
            projection: camera.projection(),
        }
    }
}

/// What the host needs to light and fog its own scene like the sky (linear RGB).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct HostLighting {
    /// Unit vector towards the sun, east-north-up.
    pub sun_direction: Vec3,
    /// Direct sunlight colour: the clear sun, with the cloud shadows on or off. The host
    /// multiplies it by the shadow map's `exp(-tau)` ([`Sky::cloud_shadows`]) where clouds stop
    /// it; with the shadows off the clouds cast none and the ground has this sun everywhere.
    pub sun_rgb: Vec3,
    /// The mean share (0..=1) of the direct sun the cloud cover over the camera lets through
    /// ([`Sky::sun_cover_transmittance`]). Not applied to `sun_rgb`: for a host that draws
    /// without the shadow map and wants its ground dimmed evenly under a cover instead
    /// (`sun_rgb * sun_cover_transmittance`). skycast's own ground and `examples/host.rs` use the
    /// map and do not apply it.
    pub sun_cover_transmittance: f32,
    /// Ambient light as a fraction of full daylight.
    pub ambient: f32,
    /// Sky colour straight up and at the horizon.
    pub zenith_rgb: Vec3,
    /// Sky colour at the horizon (what distant terrain fades into).
    pub horizon_rgb: Vec3,
    /// The visibility at the camera, metres: 95% fog at this distance.
    pub fog_distance_m: f32,
    /// The fog's colour at the camera (haze, mist, smoke, dust).
    pub fog_rgb: Vec3,
}

/// The sky a simulator embeds: one per simulator (a second monitor or an outside camera is a
/// view of the same sky, [`SkySystem::add_view`]), built once on the host's device with
/// [`SkySystem::new`] (or [`SkySystem::with_config`] for settings of the host's own), given
/// weather with [`SkySystem::set_weather`], then every frame [`SkySystem::update`] and
/// [`SkySystem::record`] after the host drew its scene. The crate's front page shows the frame in
/// code; `examples/host.rs` is a complete host.
pub struct SkySystem {
    sky: Sky,
    world: World,
    frame: LocalFrame,
    live: LiveWeather<(WeatherField, Skipped)>,
    prepare_field: Prepare<(WeatherField, Skipped)>,
    /// The model under every report file ([`Self::set_model`]), shared with `prepare_field`.
    model: Arc<std::sync::RwLock<Option<Arc<ModelField>>>>,
    /// A watched FB file of winds aloft ([`Self::watch_winds_aloft`]).
    aloft_watch: Option<WeatherWatch<WindsAloft>>,
    /// What the weather in use left out, counted.
    skipped: Skipped,
    stations: Option<Arc<StationTable>>,
    /// Seconds of frames so far (the clock of weather changes).
    clock_s: f64,
    sun_direction: Vec3,
    /// The sun and time step of the last [`Self::update`], for the other views of its frame.
    sun: Option<crate::shading::SunPosition>,
    dt_s: f64,
    /// The far field's cloud map around the camera, built from the weather field a few rows a
    /// frame (docs/src/horizon.md).
    far_map: crate::clouds::far_map::FarMapFeed,
}

impl SkySystem {
    /// The sky on the host's device for its `targets`, the local frame around
    /// `origin_lat_lon_deg`; clear weather until [`Self::set_weather`].
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        targets: HostTargets,
        origin_lat_lon_deg: (f64, f64),
    ) -> Result<Self, SkyError> {
        Self::with_config(
            device,
            queue,
            SkySystemConfig::new(targets, origin_lat_lon_deg),
        )
    }

    /// The sky with settings of its own (files loaded by the host, a wider cloud radius, ...).
    pub fn with_config(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        config: SkySystemConfig,
    ) -> Result<Self, SkyError> {
        let (lat, lon) = config.origin_lat_lon_deg;
        let frame = LocalFrame::new(lat, lon);
        let (settings, rule) = (config.field.clone(), config.rule.clone());
        let model: Arc<std::sync::RwLock<Option<Arc<ModelField>>>> = Arc::default();
        let model_under = Arc::clone(&model);
        let prepare_field: Prepare<(WeatherField, Skipped)> = Arc::new(move |input| {
            // A report file goes over the model set; a theme or a model file stands alone.
            let under = model_under.read().ok().and_then(|m| m.clone());
            let input = match (under, input) {
                (Some(model), WeatherInput::Reports(file)) => WeatherInput::Model {
                    model,
                    reports: Some(file),
                },
                (_, input) => input,
            };
            let field = input.field(LocalFrame::new(lat, lon), &settings, &rule);
            (field, input.skipped())
        });
        let clear = WeatherField::build(frame, &[], &config.field, &config.rule);
        let far = config.sky.settings.far_field;
        Ok(Self {
            far_map: crate::clouds::far_map::FarMapFeed::new(
                far.texels,
                far.texel_m,
                far.move_texels,
                far.rows_per_frame,
            ),
            sky: Sky::new(device, queue, config.sky)?,
            world: World::new(clear, &config.world),
            frame,
            live: LiveWeather::new(),
            prepare_field,
            model,
            aloft_watch: None,
            skipped: Skipped::default(),
            stations: config.stations,
            clock_s: 0.0,
            sun_direction: Vec3::Z,
            sun: None,
            dt_s: 0.0,
        })
    }

    /// Takes new weather. A file or bytes are read now (an error names file, line and field,
    /// and the sky keeps its last good weather); a watched file is read off the frame thread and
    /// applied by the frames that follow. The clouds of every block whose weather changed
    /// dissipate while the new ones form, and the light and fog under them go over with them
    /// ([`Sky::ease_weather_overhead`]).
    ///
    /// Returns what the input left out and why, counted ("31 reports without a position,
    /// lines ..."; also [`Self::weather_skipped`]). An input none of whose reports can be used
    /// is [`WeatherError::NoUsableReport`], not an empty sky.
    pub fn set_weather(&mut self, weather: Weather) -> Result<Skipped, SkyError> {
        let table = self.stations();
        let stations = Some(&*table);
        let input = match weather {
            Weather::File(path) => WeatherInput::load(path, stations)?,
            Weather::Bytes { name, bytes } => WeatherInput::parse(name, bytes, stations)?,
            // Read now, so the sky has this weather from the next frame; then watched.
            Weather::Watch { path, .. } => WeatherInput::load(path, stations)?,
        };
        // Checked before the watch starts, so a file with nothing usable is not watched either.
        let input = input.usable()?;
        if let Weather::Watch { path, settle } = weather {
            self.live
                .watch(path, Some(table), settle, Arc::clone(&self.prepare_field))?;
        }
        let (field, skipped) = (self.prepare_field)(input);
        self.set_weather_field(field);
        self.skipped = skipped.clone();
        Ok(skipped)
    }

    /// What the weather in use left out and why, counted: of the last [`Self::set_weather`],
    /// or of the last file a watch or schedule applied (an update's applied files).
    pub fn weather_skipped(&self) -> &Skipped {
        &self.skipped
    }

    /// Puts a numerical weather model's fields (a GRIB2 file,
    /// [`ModelField::load`]) under the weather, or takes it away (`None`): near a station its
    /// report rules, the model between and beyond the stations and above their reach
    /// (`config/weather_model.toml`). It stays under every report file set, watched or
    /// scheduled after; the weather in use now takes it at once. (A GRIB2 file given to
    /// [`Self::set_weather`] is the model alone.) A model valid far from the simulated time is
    /// used all the same: [`ModelField::time_warning`] says so.
    pub fn set_model(&mut self, model: Option<Arc<ModelField>>) {
        if let Ok(mut under) = self.model.write() {
            under.clone_from(&model);
        }
        let mut field = self.world.field().clone();
        field.set_model(model.map(|m| (m, ModelSettings::default())));
        let skipped = self.skipped.clone();
        self.set_weather_field(field);
        self.skipped = skipped;
    }

    /// Takes a weather field the host built itself (same as [`Self::set_weather`] otherwise).
    pub fn set_weather_field(&mut self, field: WeatherField) {
        self.skipped = Skipped::default();
        self.world.set_field(field);
        self.far_map.weather_changed();
        self.sky.ease_weather_overhead();
    }

    /// Timed weather events ([`Self::schedule_weather`]) not applied yet: a queue a long flight
    /// watches (it empties as their times come).
    pub fn weather_events_pending(&self) -> usize {
        self.live.scheduled()
    }

    /// Schedules a weather file for `at_s` seconds of frames from now (a front passing in a
    /// scripted flight): read and built off the frame thread, applied on the first frame at or
    /// after its time.
    pub fn schedule_weather(&mut self, path: &Path, at_s: f64) -> Result<(), SkyError> {
        self.live.schedule(
            self.clock_s + at_s,
            path,
            Some(self.stations()),
            Arc::clone(&self.prepare_field),
        )?;
        Ok(())
    }

    /// Uses the winds aloft of an FB file (see [`Self::set_winds_aloft`], its sites placed
    /// through the host's station table or the built-in one) and keeps watching it, as a
    /// watched weather file: a new version is read and checked off the frame thread and taken
    /// by the next [`Self::update`] (listed in its changes); a broken one is listed there with
    /// the one line that says why (file, line and field) and the last good winds stay.
    /// Returns how many sites were placed and the ids of those that were not.
    pub fn watch_winds_aloft(
        &mut self,
        path: &Path,
        settle: Duration,
    ) -> Result<(usize, Vec<String>), SkyError> {
        // Read now, so the air data has it from the next frame; a broken file is not watched.
        let fb = WindsAloft::load(path)?;
        self.aloft_watch = Some(WeatherWatch::start_loading(
            path,
            settle,
            WindsAloft::load_whole,
        )?);
        Ok(self.world.set_winds_aloft(Some(&fb), &self.stations()))
    }

    /// The winds aloft of the watched FB file that arrived since the last frame, taken in.
    fn take_winds_aloft(&mut self, changes: &mut Vec<Result<PathBuf, String>>) {
        let Some(watch) = &self.aloft_watch else {
            return;
        };
        let path = watch.path().to_path_buf();
        for update in watch.poll() {
            changes.push(match update {
                WatchUpdate::Loaded(fb) => {
                    self.world.set_winds_aloft(Some(&fb), &self.stations());
                    Ok(path.clone())
                }
                // The watch logged it already.
                WatchUpdate::Rejected(why) => Err(why),
            });
        }
    }

    /// The station table reports without a position are placed with: the host's, or the one
    /// shipped inside the library.
    fn stations(&self) -> Arc<StationTable> {
        self.stations.clone().unwrap_or_else(StationTable::builtin)
    }

    /// The frame step, CPU side: applies weather that is ready, advances the living clouds by
    /// `dt_s` around the camera and hands the sky what changed, places the sun for `utc_unix_s`,
    /// and prepares the sky's frame. Returns the frame's stats (its CPU cost included, the
    /// weather's in `weather_us`, the previous frame's [`Self::record`] in `record_us`, all of
    /// it in [`FrameStats::sky_cpu_us`]) and the weather files (and watched winds aloft,
    /// [`Self::watch_winds_aloft`]) that arrived this frame: applied, or
    /// rejected with the one line that says why (the last good sky stays). Call
    /// [`Self::record`] after it, in the frame's encoder.
    pub fn update(
        &mut self,
        queue: &wgpu::Queue,
        camera: &HostCamera,
        utc_unix_s: f64,
        dt_s: f64,
    ) -> Result<(FrameStats, Vec<Result<PathBuf, String>>), SkyError> {
        // A wrong depth convention is refused before the frame does any work.
        self.sky.targets().check_projection(camera.projection)?;
        let start = Stopwatch::start();
        let dt_s = dt_s.max(0.0);
        self.dt_s = dt_s;
        self.clock_s += dt_s;
        let mut changes = Vec::new();
        for change in self.live.poll(self.clock_s) {
            changes.push(match change {
                LiveChange::Loaded {
                    source,
                    weather: (field, skipped),
                } => {
                    self.set_weather_field(field);
                    if !skipped.is_empty() {
                        log::info!("{}: {skipped}", source.display());
                    }
                    self.skipped = skipped;
                    Ok(source)
                }
                LiveChange::Rejected(why) => Err(why),
            });
        }
        self.take_winds_aloft(&mut changes);
        // The weather's part on the wall clock alone: the thread's clock is a system call of
        // a microsecond or two a read, and this span goes on into the field's (read once, at
        // its end).
        let weather_us = start.wall_us();
        let position_m = self.local_m(camera.position);
        // The far field's map first: the far storm cells hand over in its band once it is
        // drawn (`flight::far_cells`).
        let far_part = std::time::Instant::now();
        if self.sky.far_field_settings().enabled
            && let Some(map) = self.far_map.update(
                position_m.truncate(),
                self.world.synchronous_clouds(),
                self.world.far_map_cell(),
            )
        {
            let fade_s = self.world.arrival_fade_s();
            self.sky.set_far_map(queue, &map, fade_s);
        }
        // The far field's part alone on the wall clock; the weather and the sun over the
        // camera go with it into the field's time.
        self.sky
            .add_far_field_us(far_part.elapsed().as_micros() as u64);
        self.sky
            .set_weather_overhead(&self.world.weather_over(position_m));
        let (lat, lon) = self.frame.to_lat_lon_deg(position_m.truncate());
        let sun = sun_position(utc_unix_s, lat, lon);
        self.sun_direction = sun.direction_enu().as_vec3();
        self.sun = Some(sun);
        let own = start.spent();
        // Read after the far map above: the far field's band holds from its first map on. A
        // host may switch the ring or the far field between frames (through `sky_mut`).
        self.world.set_sky_reach(self.sky.reach());
        let update = self.world.advance_sky(position_m, dt_s)?;
        // The field's time is the weather, the far map, the sun and the world's own; the
        // sky's applying goes into its update time.
        let field = own + update.field_cpu;
        self.sky.apply(update);
        self.sky.set_flash(self.world.flash_now());
        let view = SkyView {
            position_m,
            view: camera.view,
            projection: camera.projection,
        };
        let mut stats = self.sky.prepare(queue, view, &sun, dt_s);
        stats.add_field(field);
        stats.weather_us = weather_us;
        // This frame is not recorded yet: the last recording is the previous frame's.
        stats.set_record(self.sky.last_record());
        Ok((stats, changes))
    }

    /// The lightning flashes since the last call (each an in-cloud flash or a stroke to the
    /// ground, with its time and place in the local frame), oldest first: drain it each frame,
    /// for thunder and for lighting the host's own scene. Only cells under a report with TS
    /// (or a theme's `thunder`) flash.
    pub fn drain_flashes(&mut self) -> Vec<crate::weather::storms::Flash> {
        self.world.drain_flashes()
    }

    /// Records the sky's passes into the host's encoder after the host drew its scene: the sky
    /// behind everything, the clouds faded softly into the host's depth (read, never written),
    /// the fog inside a cloud. The host's textures are checked first ([`Sky::record`]): colour
    /// and depth formats, samples, the depth's `TEXTURE_BINDING`, the depth convention against
    /// the projection; a mismatch is an error naming both sides, and nothing is recorded.
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        colour: &wgpu::TextureView,
        depth: &wgpu::TextureView,
    ) -> Result<(), SkyError> {
        Ok(self.sky.record(encoder, colour, depth)?)
    }

    /// Adds a view of the same sky: another camera with its own targets (of the same formats
    /// and samples as the [`HostTargets`] the sky was made for; any size), e.g. a second
    /// monitor, a mirror, an outside camera near the aircraft. It has its own draw list,
    /// impostor ring and off-screen cloud target; the clouds, the weather and the resident
    /// sprites are shared (the clouds live around the camera of [`Self::update`]). Each frame:
    /// [`Self::update`] for the main camera, then [`Self::update_view`] for each other view,
    /// then [`Self::record`] and [`Self::record_view`], into one encoder or several. A view
    /// costs [`Sky::view_gpu_bytes`] of GPU memory.
    pub fn add_view(&mut self) -> ViewId {
        self.sky.add_view()
    }

    /// A view's share of the frame step, after [`Self::update`] (whose time, sun and clouds
    /// it uses): its draw list, ring and uniforms from `camera`. The projection is checked
    /// against the targets as in `update`. Returns the view's stats (`record_us`: its previous
    /// recording). [`Self::lighting`] is then this view's.
    pub fn update_view(
        &mut self,
        id: ViewId,
        queue: &wgpu::Queue,
        camera: &HostCamera,
    ) -> Result<FrameStats, SkyError> {
        self.sky.targets().check_projection(camera.projection)?;
        if !self.sky.has_view(id) {
            return Err(RenderError::Targets(format!(
                "{id:?} does not exist (the sky has {} views)",
                self.sky.view_count()
            ))
            .into());
        }
        let position_m = self.local_m(camera.position);
        let (lat, lon) = self.frame.to_lat_lon_deg(position_m.truncate());
        let sun = self.sun.unwrap_or_else(|| sun_position(0.0, lat, lon));
        let view = SkyView {
            position_m,
            view: camera.view,
            projection: camera.projection,
        };
        let mut stats = self.sky.prepare_view(id, queue, view, &sun, self.dt_s);
        stats.set_record(self.sky.view_record(id));
        Ok(stats)
    }

    /// [`Self::record`] for a view of [`Self::add_view`], into its own targets.
    pub fn record_view(
        &self,
        id: ViewId,
        encoder: &mut wgpu::CommandEncoder,
        colour: &wgpu::TextureView,
        depth: &wgpu::TextureView,
    ) -> Result<(), SkyError> {
        Ok(self.sky.record_view(id, encoder, colour, depth)?)
    }

    /// The light and fog of the last [`Self::update`], for the host's own scene.
    pub fn lighting(&self) -> HostLighting {
        let light = self.sky.light();
        let fog = self.sky.fog();
        HostLighting {
            sun_direction: self.sun_direction,
            sun_rgb: light.directional_rgb,
            sun_cover_transmittance: self.sky.sun_cover_transmittance(),
            ambient: light.ambient_percent,
            zenith_rgb: light.sky_zenith_rgb,
            horizon_rgb: light.sky_horizon_rgb,
            fog_distance_m: fog.distance_m,
            fog_rgb: fog.rgb,
        }
    }

    /// The clouds' shadow map of the last [`Self::update`] and the matrix the host looks it up
    /// with ([`Sky::cloud_shadows`]): the host multiplies its ground's direct sunlight by
    /// `exp(-tau)`. Take it every frame.
    pub fn cloud_shadows(&self) -> crate::render::CloudShadowMap<'_> {
        self.sky.cloud_shadows()
    }

    /// The haze the host fogs its ground with along a view ray, its visibility at most
    /// `visibility_m` ([`Sky::ground_haze`]): the clouds fade into the same haze.
    pub fn ground_haze(&self, visibility_m: f32) -> crate::shading::AltitudeHaze {
        self.sky.ground_haze(visibility_m)
    }

    /// The round Earth the sky draws on; the host draws its far ground on the same
    /// ([`Sky::earth`]).
    pub fn earth(&self) -> crate::render::earth::EarthSettings {
        self.sky.earth()
    }

    /// The renderer settings the sky was made with (its camera's projection, the clouds' reach,
    /// what is switched on).
    pub fn settings(&self) -> &crate::render::RenderSettings {
        self.sky.settings()
    }

    /// Time the last [`Self::record`] spent.
    pub fn last_record(&self) -> crate::render::Spent {
        self.sky.last_record()
    }

    /// The renderer under the frame step, to read: its memory, pass times, blocks and the
    /// state of its switches.
    pub fn sky(&self) -> &Sky {
        &self.sky
    }

    /// The renderer under the frame step, for its lower-level controls between frames
    /// (switching the ring, the far field, the shadows or pass timing; fades and blocks given
    /// by hand for tests and tools). The frame step reads the ring and the far field's reach
    /// back from it every [`Self::update`], so a switch holds from the next frame on.
    pub fn sky_mut(&mut self) -> &mut Sky {
        &mut self.sky
    }

    /// The local frame: latitude/longitude to the metres positions are given in.
    pub fn frame(&self) -> &LocalFrame {
        &self.frame
    }

    /// The weather field and the clouds built from it.
    pub fn world(&self) -> &World {
        &self.world
    }

    /// The weather field and clouds, mutable (e.g. synchronous generation for reproducible
    /// frames).
    pub fn world_mut(&mut self) -> &mut World {
        &mut self.world
    }
}

#[cfg(test)]
mod tests {
    use glam::camera::rh::view::look_at_mat4;
    use glam::{Mat4, Vec3, Vec4};

    /// What the embedding chapter (docs/src/host-errors.md) tells a y-up host: its view times
    /// the axis swap is the view for east-north-up axes.
    #[test]
    fn a_y_up_hosts_view_times_the_axis_swap_is_the_east_north_up_view() {
        // East, north, up to a y-up right-handed world's (x east, y up, z south).
        let enu_to_host = Mat4::from_cols(Vec4::X, Vec4::NEG_Z, Vec4::Y, Vec4::W);
        // Looking north-east and a little up, in each world's own axes.
        let forward_enu = Vec3::new(0.6, 0.7, 0.2).normalize();
        let forward_host = Vec3::new(forward_enu.x, forward_enu.z, -forward_enu.y);
        let enu = look_at_mat4(Vec3::ZERO, forward_enu, Vec3::Z);
        let host = look_at_mat4(Vec3::ZERO, forward_host, Vec3::Y);
        assert!((host * enu_to_host).abs_diff_eq(enu, 1e-6));
        // Without the swap it is another view.
        assert!(!host.abs_diff_eq(enu, 1e-3));
    }
}
