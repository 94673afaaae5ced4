//! The air data a simulator's flight model and systems ask for at any point, every frame:
//! wind (direction, speed, gust), temperature, dewpoint, pressure, pressure and density
//! altitude ([`crate::weather::air`]), the visibility the renderer fogs with, precipitation type
//! and rate, in-cloud and the distance to the nearest cloud ([`crate::clouds::probe`]),
//! turbulence, icing risk, the cloud layers around and the ceiling, the cover overhead and how
//! much of the sun the clouds hide. Lines of sight come from the same probe.
//!
//! The rules (settings and sources: `config/air.toml`; the book: `docs/src/air-data.md`):
//! - visibility: the fog's ([`crate::shading::FogSettings::visibility_m`]), thicker in a rain
//!   shaft ([`crate::shading::FogSettings::in_rain`]) and inside a cloud (`visibility_m /
//!   in_cloud`), as the renderer draws it;
//! - precipitation: the reports' intensity (light, moderate, heavy) as a rate, linear between
//!   the configured rates, from the ground to the top of the highest layer or in a shaft; snow at
//!   or below `snow_below_c` at the point, else rain;
//! - turbulence 0..1: inside a cumulonimbus `cb_inside` (severe); within `cb_near_m` of one, or
//!   in the height band of a block's reported CB layer, `cb_near` (moderate); inside towering
//!   cumulus or cumulus `congestus` / `cumulus`; mechanical from the surface wind and gusts,
//!   fading to none at the top of the boundary layer; the largest of them; none in still, clear
//!   air;
//! - icing: visible moisture (in cloud from `in_cloud_min`, or in precipitation) between
//!   `coldest_c` and `warmest_c`.

use std::sync::Mutex;

use glam::{DVec2, DVec3};
use serde::Serialize;

use crate::clouds::DriftBand;
use crate::clouds::config::MAX_DRIFT_BANDS;
use crate::clouds::probe::{BoxCache, CloudsAtPoint, SightHit};
use crate::clouds::probe_bands::BandedProbe;
use crate::shading::FogSettings;
use crate::weather::StationTable;
use crate::weather::air::{AirSettings, SurfaceAir, air_at_aloft, feet};
use crate::weather::block::ceiling_ft;
use crate::weather::winds_aloft::{AloftColumn, WindsAloft, WindsAloftField};
use crate::weather::{BlockWeather, CloudType, METRES_PER_FOOT};

use super::world::World;

/// Turbulence categories.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TurbulenceCategory {
    /// Below the light threshold.
    None,
    /// Light.
    Light,
    /// Moderate.
    Moderate,
    /// Severe.
    Severe,
}

/// What falls at a point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PrecipitationType {
    /// Nothing.
    None,
    /// Rain.
    Rain,
    /// Snow.
    Snow,
}

/// One cloud layer of the weather over a point.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct AirLayer {
    /// Its type.
    pub cloud_type: CloudType,
    /// Its own cover, oktas.
    pub coverage_oktas: f32,
    /// Base, feet MSL.
    pub base_ft_msl: f64,
    /// Top, feet MSL.
    pub top_ft_msl: f64,
}

/// The air at a point. Units in every name; directions in degrees true the wind blows from.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[non_exhaustive]
pub struct AirData {
    /// Wind direction, degrees true it blows from.
    pub wind_from_deg: f64,
    /// Wind speed, knots.
    pub wind_kt: f64,
    /// Gust speed, knots (the wind speed without gusts).
    pub gust_kt: f64,
    /// Temperature, C.
    pub temperature_c: f64,
    /// Dewpoint, C.
    pub dewpoint_c: f64,
    /// Static pressure, hPa.
    pub pressure_hpa: f64,
    /// QNH there, hPa.
    pub qnh_hpa: f64,
    /// Pressure altitude, feet.
    pub pressure_altitude_ft: f64,
    /// Density altitude, feet.
    pub density_altitude_ft: f64,
    /// Height above the ground, feet.
    pub height_agl_ft: f64,
    /// Visibility, metres (what the renderer fogs with there).
    pub visibility_m: f32,
    /// What falls.
    pub precipitation: PrecipitationType,
    /// How much, mm/h.
    pub precipitation_mm_h: f32,
    /// In-cloud measure 0..=1 (`FrameStats::in_cloud` at any point).
    pub in_cloud: f32,
    /// Distance to the nearest cloud, metres (0 inside; `None` beyond the search radius).
    pub nearest_cloud_m: Option<f64>,
    /// Turbulence intensity 0..=1.
    pub turbulence: f32,
    /// Its category.
    pub turbulence_category: TurbulenceCategory,
    /// Icing risk: visible moisture at 0 to -20 C.
    pub icing: bool,
    /// Layers with their base above the point, lowest first.
    pub layers_above: Vec<AirLayer>,
    /// Layers with their top below the point, lowest first.
    pub layers_below: Vec<AirLayer>,
    /// The layer whose height band holds the point.
    pub layer_at: Option<AirLayer>,
    /// The ceiling (lowest base broken or more seen from below), feet AGL.
    pub ceiling_ft_agl: Option<f32>,
    /// Share of the sky the layers above the point cover, 0..=1.
    pub sky_coverage: f32,
    /// Share of the sun the clouds hide from the point, 0..=1.
    pub sun_occlusion: f32,
}

/// Lengths of the line of sight towards the sun, metres.
const SUN_SIGHT_M: f64 = 30_000.0;

/// The optical depth towards the sun past which the walk along the sun line stops: the
/// occlusion, `1 - exp(-depth)`, is then within `exp(-17)` (4e-8) of 1, less than an f32's step
/// below 1 (6e-8).
const SUN_OPAQUE_DEPTH: f64 = 17.0;

/// How far above the weather's highest cloud top the air data's sun line goes, metres (the
/// clouds' boxes reach a little above the layer tops).
const SUN_TOP_MARGIN_M: f64 = 1_000.0;

impl World {
    /// The settings the air data is read with.
    pub fn air_settings(&self) -> &AirSettings {
        &self.air.settings
    }

    /// Uses the winds and temperatures aloft of an FB product above the boundary layer (`None`:
    /// the documented profile), its sites placed through `table`; returns how many sites were
    /// placed and the ids of those that were not.
    pub fn set_winds_aloft(
        &mut self,
        fb: Option<&WindsAloft>,
        table: &StationTable,
    ) -> (usize, Vec<String>) {
        self.air.aloft = fb.map(|fb| WindsAloftField::build(self.field().frame(), fb, table));
        self.air
            .aloft
            .as_ref()
            .map_or((0, Vec::new()), |f| (f.placed, f.unplaced.clone()))
    }

    /// How the clouds at `point_m` (local metres, up above mean sea level) drift: the air
    /// data's wind there ([`Self::air_at`]'s, the winds aloft included), as the velocity it
    /// blows towards, metres a second east and north. The living clouds of each drift band
    /// drift with it at the middle of their layer over the camera
    /// ([`Self::band_drift_height_m`]): every reported layer with its own height's wind.
    pub fn cloud_drift_at(&self, point_m: DVec3) -> DVec2 {
        let s = &self.air.settings;
        let (weather, gust, qnh) =
            self.weather_here(point_m.truncate(), s.pressure.default_qnh_hpa);
        let surface = self.surface_air(point_m.truncate(), &weather, gust, qnh);
        let (aloft, lat_deg) = self.aloft_and_latitude(point_m.truncate());
        let wind = air_at_aloft(&surface, point_m.z, lat_deg, s, aloft.as_ref()).wind;
        let to = (wind.from_deg + 180.0).to_radians();
        DVec2::new(to.sin(), to.cos()) * wind.speed_kt * crate::weather::METRES_PER_KNOT
    }

    /// The surface air at ground point `point_m` from its weather, gust excess and QNH, with
    /// the regional surface wind around it the profile reaches at the top of the boundary
    /// layer (`[wind] regional_radius_m` of the air settings).
    fn surface_air(
        &self,
        point_m: DVec2,
        weather: &BlockWeather,
        gust: f64,
        qnh: f64,
    ) -> SurfaceAir {
        let radius = self.air.settings.wind.regional_radius_m;
        SurfaceAir::of(weather, gust, qnh)
            .with_regional_wind_kt(self.field().regional_wind_kt(point_m, radius))
    }

    /// The winds aloft's column over ground point `point_m` (an FB product's if one is in use,
    /// else the weather model's under the field, if any) and the point's latitude, degrees:
    /// what the air's profile needs besides the surface.
    fn aloft_and_latitude(&self, point_m: DVec2) -> (Option<AloftColumn>, f64) {
        let (lat, lon) = self.field().frame().to_lat_lon_deg(point_m);
        let aloft = match &self.air.aloft {
            Some(fb) => Some(fb.column_at(point_m)),
            None => self
                .field()
                .model()
                .map(|(model, _)| model.aloft_column_at(lat, lon)),
        };
        (aloft, lat)
    }

    /// The height the lowest drift band's living clouds drift at over ground point `point_m`
    /// ([`Self::band_drift_height_m`] of band 0: the middle of the lowest cloud layer there);
    /// `None` under a clear sky.
    pub fn drift_height_m(&self, point_m: DVec2) -> Option<f64> {
        let bands = self.clouds_config().field.drift_bands;
        self.band_drift_height_m(point_m, DriftBand::new(0, bands))
    }

    /// The height drift `band`'s living clouds drift at over ground point `point_m`, metres
    /// above mean sea level: the middle of the band's layer there
    /// ([`DriftBand::steering_layer`]: the layer of its rank, or the highest there is);
    /// `None` under a clear sky.
    pub fn band_drift_height_m(&self, point_m: DVec2, band: DriftBand) -> Option<f64> {
        let weather = self.field().weather_at(point_m);
        let ground = f64::from(weather.ground_elevation_m);
        band.steering_layer(&weather.layers).map(|l| {
            ground
                + f64::from(l.base_ft_agl + 0.5 * l.thickness_ft) * crate::weather::METRES_PER_FOOT
        })
    }

    /// Uses `air` and `fog` settings for the air data.
    pub fn set_air_settings(&mut self, air: AirSettings, fog: FogSettings) {
        self.air.settings = air;
        self.air.fog = fog;
    }

    /// The probe over every drift band's living field (`None` before they exist).
    fn probe(&self) -> Option<BandedProbe<'_>> {
        self.living_field()?;
        let bands = self.living_fields().zip(&self.air.caches);
        Some(BandedProbe::new(bands, &self.air.settings.in_cloud))
    }

    /// The clouds at a ground point (nothing before the living clouds exist).
    pub fn clouds_at(&self, point_m: DVec3) -> CloudsAtPoint {
        self.probe().map(|p| p.at(point_m)).unwrap_or_default()
    }

    /// Every cloud along the segment `from_m`..`to_m`: the first one met (where, its type, the
    /// optical depth through it), the optical depth through them all, and each stretch of
    /// cloud with its entry, exit and optical depth (`crossings`); `None` in clear air (and
    /// before the living clouds exist).
    pub fn line_of_sight(&self, from_m: DVec3, to_m: DVec3) -> Option<SightHit> {
        self.probe()?.line_of_sight(from_m, to_m)
    }

    /// The first cloud the segment `from_m`..`to_m` meets and the optical depth through it,
    /// the cheaper query for sensors casting many lines a frame: its walk stops at the first
    /// cloud (`total_optical_depth` counts only the clouds looked at, `crossings` is empty).
    pub fn first_cloud(&self, from_m: DVec3, to_m: DVec3) -> Option<SightHit> {
        self.probe()?.first_cloud(from_m, to_m)
    }

    /// How much of the sun (towards unit `sun_direction`) the clouds hide from `point_m`,
    /// 0..=1: `1 - exp(-optical depth)` through every cloud along 30 km towards it.
    pub fn sun_occlusion(&self, point_m: DVec3, sun_direction: DVec3) -> f32 {
        let to = point_m + sun_direction * SUN_SIGHT_M;
        self.probe().map_or(0.0, |p| {
            let depth = p.optical_depth_until(point_m, to, SUN_OPAQUE_DEPTH);
            (1.0 - (-depth).exp()) as f32
        })
    }

    /// The air data at `point_m` (local metres east, north, and up above mean sea level), with
    /// the sun towards `sun_direction`. See the module docs.
    pub fn air_at(&self, point_m: DVec3, sun_direction: DVec3) -> AirData {
        let s = &self.air.settings;
        let (weather, gust, qnh) =
            self.weather_here(point_m.truncate(), s.pressure.default_qnh_hpa);
        let clouds = self.clouds_at(point_m);
        // Towards the sun only as far as the highest cloud top over the point (plus a margin):
        // above it nothing hides the sun, and a low sun's 30 km ray would cross many blocks.
        let ground_m = f64::from(weather.ground_elevation_m);
        let top_m = weather
            .layers
            .iter()
            .map(|l| ground_m + f64::from(l.base_ft_agl + l.thickness_ft) * METRES_PER_FOOT)
            .fold(f64::MIN, f64::max);
        let ceiling_m = top_m + SUN_TOP_MARGIN_M;
        let sun_occlusion = if point_m.z >= ceiling_m {
            0.0
        } else if sun_direction.z <= 0.0 {
            self.sun_occlusion(point_m, sun_direction)
        } else {
            let climb_m = ((ceiling_m - point_m.z) / sun_direction.z).min(SUN_SIGHT_M);
            let to = point_m + sun_direction * climb_m;
            self.probe().map_or(0.0, |p| {
                let depth = p.optical_depth_until(point_m, to, SUN_OPAQUE_DEPTH);
                (1.0 - (-depth).exp()) as f32
            })
        };
        let surface = self.surface_air(point_m.truncate(), &weather, gust, qnh);
        let (aloft, lat_deg) = self.aloft_and_latitude(point_m.truncate());
        air_data(
            &weather,
            &surface,
            aloft.as_ref(),
            &clouds,
            point_m.z,
            lat_deg,
            sun_occlusion,
            &self.air.settings,
            &self.air.fog,
            self.field().settings().precipitation.light,
            self.field().settings().precipitation.moderate,
            self.field().settings().precipitation.heavy,
        )
    }

    /// The weather, gust excess and QNH at a ground point ([`WeatherField::weather_at`],
    /// [`WeatherField::gust_and_qnh_at`]), kept for the next question about the same point and
    /// field: a host asks the sky's update ([`Self::weather_over`]) and the air data about the
    /// aircraft every frame, and each is three natural-neighbour interpolations.
    ///
    /// [`WeatherField::weather_at`]: crate::weather::field::WeatherField::weather_at
    /// [`WeatherField::gust_and_qnh_at`]: crate::weather::field::WeatherField::gust_and_qnh_at
    pub(super) fn weather_here(&self, point_m: DVec2, default_qnh_hpa: f64) -> HereWeather {
        let key = (
            point_m.x.to_bits(),
            point_m.y.to_bits(),
            self.field_version(),
            default_qnh_hpa.to_bits(),
        );
        let mut kept = self
            .air
            .here
            .lock()
            .unwrap_or_else(|poison| poison.into_inner());
        if let Some((k, answer)) = kept.as_ref()
            && *k == key
        {
            return answer.clone();
        }
        let answer = self
            .field()
            .weather_gust_and_qnh_at(point_m, default_qnh_hpa);
        *kept = Some((key, answer.clone()));
        answer
    }
}

/// The key of [`AirState::here`]: the point's bits, the field's version, the default QNH's bits.
type HereKey = (u64, u64, u64, u64);

/// The weather, gust excess (knots) and QNH (hPa) at a point.
type HereWeather = (BlockWeather, f64, f64);

/// What the world keeps for the air data: settings and the clouds' boxes.
#[derive(Debug, Default)]
pub struct AirState {
    settings: AirSettings,
    fog: FogSettings,
    /// Each drift band's field's boxes, the lowest band's first.
    caches: [BoxCache; MAX_DRIFT_BANDS as usize],
    /// The last answer of [`World::weather_here`].
    here: Mutex<Option<(HereKey, HereWeather)>>,
    /// The FB product's winds and temperatures aloft, placed in the world's frame.
    aloft: Option<WindsAloftField>,
}

/// The air data of a point from its weather, surface air and clouds.
#[allow(clippy::too_many_arguments)]
fn air_data(
    weather: &BlockWeather,
    surface: &SurfaceAir,
    aloft: Option<&AloftColumn>,
    clouds: &CloudsAtPoint,
    alt_m_msl: f64,
    lat_deg: f64,
    sun_occlusion: f32,
    s: &AirSettings,
    fog: &FogSettings,
    light: f64,
    moderate: f64,
    heavy: f64,
) -> AirData {
    let column = air_at_aloft(surface, alt_m_msl, lat_deg, s, aloft);
    let ground = surface.ground_m_msl;
    let layer = |l: &crate::weather::BlockLayer| AirLayer {
        cloud_type: l.cloud_type,
        coverage_oktas: l.coverage_oktas,
        base_ft_msl: feet(ground) + f64::from(l.base_ft_agl),
        top_ft_msl: feet(ground) + f64::from(l.base_ft_agl + l.thickness_ft),
    };
    let alt_ft = feet(alt_m_msl);
    let layers: Vec<AirLayer> = weather.layers.iter().map(layer).collect();
    let layers_above: Vec<AirLayer> = layers
        .iter()
        .copied()
        .filter(|l| l.base_ft_msl > alt_ft)
        .collect();
    let layers_below: Vec<AirLayer> = layers
        .iter()
        .copied()
        .filter(|l| l.top_ft_msl < alt_ft)
        .collect();
    let layer_at = layers
        .iter()
        .copied()
        .find(|l| l.base_ft_msl <= alt_ft && alt_ft <= l.top_ft_msl);
    let clear: f32 = layers
        .iter()
        .filter(|l| l.top_ft_msl > alt_ft)
        .map(|l| 1.0 - (l.coverage_oktas / 8.0).clamp(0.0, 1.0))
        .product();
    // Visibility: the fog's, in rain, in cloud.
    let mut visibility_m = fog
        .in_rain(fog.fog(weather, glam::Vec3::ONE), clouds.in_rain)
        .distance_m;
    if clouds.in_cloud > 0.0 {
        visibility_m = visibility_m.min(s.in_cloud.visibility_m / clouds.in_cloud);
    }
    // Precipitation: under the highest top, or in a shaft.
    let highest_top = layers.iter().map(|l| l.top_ft_msl).fold(f64::MIN, f64::max);
    let p = f64::from(weather.precipitation);
    let falls = p > 0.0 && (alt_ft <= highest_top || clouds.in_rain > 0.0);
    let pr = &s.precipitation;
    let precipitation_mm_h = if falls {
        rate_mm_h(
            p,
            [light, moderate, heavy],
            [pr.light_mm_h, pr.moderate_mm_h, pr.heavy_mm_h],
        )
    } else {
        0.0
    };
    let precipitation = if precipitation_mm_h <= 0.0 {
        PrecipitationType::None
    } else if column.temperature_c <= f64::from(pr.snow_below_c) {
        PrecipitationType::Snow
    } else {
        PrecipitationType::Rain
    };
    let turbulence = turbulence(weather, surface, clouds, &column, alt_ft, s);
    let t = &s.turbulence;
    let turbulence_category = if turbulence >= t.severe {
        TurbulenceCategory::Severe
    } else if turbulence >= t.moderate {
        TurbulenceCategory::Moderate
    } else if turbulence >= t.light {
        TurbulenceCategory::Light
    } else {
        TurbulenceCategory::None
    };
    let moist = clouds.in_cloud >= s.icing.in_cloud_min || precipitation_mm_h > 0.0;
    let temp = column.temperature_c as f32;
    let icing = moist && (s.icing.coldest_c..=s.icing.warmest_c).contains(&temp);
    AirData {
        wind_from_deg: column.wind.from_deg,
        wind_kt: column.wind.speed_kt,
        gust_kt: column.wind.gust_kt,
        temperature_c: column.temperature_c,
        dewpoint_c: column.dewpoint_c,
        pressure_hpa: column.pressure_hpa,
        qnh_hpa: surface.qnh_hpa,
        pressure_altitude_ft: column.pressure_altitude_ft,
        density_altitude_ft: column.density_altitude_ft,
        height_agl_ft: feet(column.height_agl_m),
        visibility_m,
        precipitation,
        precipitation_mm_h,
        in_cloud: clouds.in_cloud,
        nearest_cloud_m: clouds.nearest_cloud_m,
        turbulence,
        turbulence_category,
        icing,
        layers_above,
        layers_below,
        layer_at,
        ceiling_ft_agl: ceiling_ft(&weather.layers, 5.0),
        sky_coverage: 1.0 - clear,
        sun_occlusion,
    }
}

/// The rate of a reported intensity `p`, linear through (0, 0) and the intensity levels.
pub(super) fn rate_mm_h(p: f64, levels: [f64; 3], rates: [f32; 3]) -> f32 {
    let mut prev = (0.0, 0.0f32);
    for (l, r) in levels.into_iter().zip(rates) {
        if p <= l {
            let t = ((p - prev.0) / (l - prev.0).max(1e-9)) as f32;
            return prev.1 + t * (r - prev.1);
        }
        prev = (l, r);
    }
    rates[2]
}

/// The turbulence intensity, 0..=1 (see the module docs).
fn turbulence(
    weather: &BlockWeather,
    surface: &SurfaceAir,
    clouds: &CloudsAtPoint,
    column: &crate::weather::air::AirColumnSample,
    alt_ft: f64,
    s: &AirSettings,
) -> f32 {
    let t = &s.turbulence;
    let mut out = 0.0f32;
    let inside = clouds.in_cloud > 0.0;
    if clouds.in_cb > 0.0 {
        out = out.max(t.cb_inside);
    }
    match clouds.cloud_type {
        Some(CloudType::CumulusCongestus) if inside => out = out.max(t.congestus),
        Some(CloudType::CumulusHumilis | CloudType::CumulusMediocris) if inside => {
            out = out.max(t.cumulus)
        }
        _ => {}
    }
    if clouds.nearest_cb_m.is_some_and(|d| d <= t.cb_near_m) {
        out = out.max(t.cb_near);
    }
    // A reported CB layer over the block: its height band is near one.
    let ground_ft = feet(surface.ground_m_msl);
    let in_cb_band = weather.layers.iter().any(|l| {
        l.cloud_type == CloudType::Cumulonimbus
            && alt_ft >= ground_ft
            && alt_ft <= ground_ft + f64::from(l.base_ft_agl + l.thickness_ft)
    });
    if in_cb_band {
        out = out.max(t.cb_near);
    }
    // Mechanical: surface wind and gusts, fading up through the boundary layer.
    let wind = surface.wind.speed_kt + surface.gust_excess_kt as f32;
    let strength = ((wind - t.mechanical_from_kt) / (t.mechanical_full_kt - t.mechanical_from_kt))
        .clamp(0.0, 1.0);
    let top_m = s.wind.boundary_layer_top_m;
    let low = (1.0 - column.height_agl_m / top_m).clamp(0.0, 1.0) as f32;
    out = out.max(t.mechanical_max * strength * low);
    out
}

/// Metres of a height in feet (for callers giving feet).
pub fn metres(ft: f64) -> f64 {
    ft * METRES_PER_FOOT
}

impl super::SkySystem {
    /// A host position in local metres (east, north, up MSL).
    pub fn local_m(&self, position: super::HostPosition) -> DVec3 {
        match position {
            super::HostPosition::Local(p) => p,
            super::HostPosition::LatLonAlt {
                lat_deg,
                lon_deg,
                alt_m,
            } => self.frame().to_local_m(lat_deg, lon_deg).extend(alt_m),
        }
    }

    /// The air data at a position (see [`crate::flight::air`]): cheap enough to ask every frame,
    /// after [`Self::update`] (the clouds and the sun of that frame).
    pub fn air_at(&self, position: super::HostPosition) -> AirData {
        let sun = self.lighting().sun_direction.as_dvec3();
        self.world().air_at(self.local_m(position), sun)
    }

    /// Every cloud between two positions ([`World::line_of_sight`]): the first one met, and
    /// each stretch of cloud with its entry, exit and optical depth; `None` in clear air.
    pub fn line_of_sight(
        &self,
        from: super::HostPosition,
        to: super::HostPosition,
    ) -> Option<SightHit> {
        self.world()
            .line_of_sight(self.local_m(from), self.local_m(to))
    }

    /// The first cloud met between two positions and the optical depth through it
    /// ([`World::first_cloud`]: cheaper, for many lines a frame); `None` in clear air.
    pub fn first_cloud(
        &self,
        from: super::HostPosition,
        to: super::HostPosition,
    ) -> Option<SightHit> {
        self.world()
            .first_cloud(self.local_m(from), self.local_m(to))
    }

    /// Uses the winds and temperatures aloft of an FB product ([`World::set_winds_aloft`]),
    /// its sites placed through the built-in station table; returns how many were placed and
    /// the ids of those that were not.
    pub fn set_winds_aloft(&mut self, fb: Option<&WindsAloft>) -> (usize, Vec<String>) {
        self.world_mut()
            .set_winds_aloft(fb, &StationTable::builtin())
    }

    /// How much of the sun's disc the clouds hide from a position, 0..=1.
    pub fn sun_occlusion(&self, position: super::HostPosition) -> f32 {
        let sun = self.lighting().sun_direction.as_dvec3();
        self.world().sun_occlusion(self.local_m(position), sun)
    }

    /// The precipitation map around a position out to `range_m`, cells of `cell_m`, for a
    /// weather-radar display ([`super::radar`]).
    pub fn precipitation_map(
        &self,
        position: super::HostPosition,
        range_m: f64,
        cell_m: f64,
    ) -> super::radar::PrecipitationMap {
        self.world()
            .precipitation_map(self.local_m(position), range_m, cell_m)
    }

    /// The share of the sky the layers above a position cover, 0..=1.
    pub fn sky_coverage(&self, position: super::HostPosition) -> f32 {
        self.air_at(position).sky_coverage
    }
}

#[cfg(test)]
#[path = "air_tests.rs"]
mod tests;

#[cfg(test)]
#[path = "instrument_tests.rs"]
mod instrument_tests;
