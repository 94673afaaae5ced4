//! The air at any height over a point, from the surface weather there: the wind through the
//! boundary layer and above it, temperature and dewpoint, pressure, pressure altitude and density
//! altitude. Plain functions of a [`SurfaceAir`] (what the reports give at the ground) and the
//! settings of `config/air.toml` ([`AirSettings`]); the clouds, turbulence and icing come on top
//! in `clouds::probe` and `flight::air`.
//!
//! The wind (documented with its sources in `config/air.toml` and `docs/src/air-data.md`): the
//! report's at and under the anemometer height (10 m); through the boundary layer the speed grows
//! as the power law `v(z) = v10 (z / 10 m)^a` (a = 1/7 over land) and the direction turns with
//! `ln(z / 10 m)` by `turn_deg` at its top (veering in the northern hemisphere, backing in the
//! southern); the gust excess shrinks linearly to none at the top. The surface wind it grows
//! from goes over, with the same `ln(z / 10 m)`, from the point's own to the regional surface
//! wind ([`SurfaceAir::regional_wind_kt`]: a report's wind is local, the gradient wind
//! large-scale). Above it, the gradient wind at the top holds, or goes over linearly (as a
//! vector) to a wind aloft from the settings.
//!
//! Temperature: the ICAO standard lapse (6.5 C/km) from the surface report to the tropopause
//! (ICAO Doc 7488). Pressure: the ISA pressure at the altitude for the reported QNH,
//! `p = QNH (1 - 0.0065 h / 288.15)^5.25588`. Pressure altitude (NWS,
//! <https://www.weather.gov/media/epz/wxcalc/pressureAltitude.pdf>):
//! `PA ft = 145,366.45 (1 - (p / 1013.25)^0.190284)`; density altitude (NWS,
//! `densityAltitude.pdf`, dry air): `DA ft = 145,442.16 (1 - ((p / 1013.25) (288.15 / T))^0.234969)`.
//!
//! Units are in every field name: metres (`_m`, heights above ground `_agl`, above sea level
//! `_msl`), knots (`_kt`), degrees true the wind blows from (`from_deg`), Celsius (`_c`),
//! hectopascals (`_hpa`), feet (`_ft`).

use std::path::Path;

use glam::DVec2;
use serde::{Deserialize, Serialize};

use super::block::{BlockWeather, Wind};
use super::winds_aloft::AloftColumn;
use crate::config::{ConfigError, ShippedFile, TomlSettings};

/// The shipped settings file, built in.
const BUILTIN: &str = include_str!("../../config/air.toml");

/// Metres in a foot.
const M_PER_FT: f64 = 0.3048;

/// Settings of the air (`config/air.toml`).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AirSettings {
    /// The wind profile.
    pub wind: WindSettings,
    /// Temperature and dewpoint aloft.
    pub temperature: TemperatureSettings,
    /// Pressure.
    pub pressure: PressureSettings,
    /// The in-cloud measure and the line of sight.
    pub in_cloud: InCloudAirSettings,
    /// Precipitation rate and type.
    pub precipitation: PrecipitationAirSettings,
    /// Turbulence.
    pub turbulence: TurbulenceSettings,
    /// Icing risk.
    pub icing: IcingSettings,
}

/// The wind profile (`[wind]`).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WindSettings {
    /// Height the report's wind is measured at, metres AGL.
    pub reference_height_m: f64,
    /// Exponent of the power law through the boundary layer.
    pub power_law_exponent: f64,
    /// Top of the boundary (friction) layer, metres AGL.
    pub boundary_layer_top_m: f64,
    /// Turn of the wind from the surface to the top of the boundary layer, degrees (veering in
    /// the northern hemisphere, backing in the southern).
    pub turn_deg: f64,
    /// A wind aloft the profile goes over to above the boundary layer.
    #[serde(default)]
    pub aloft: Option<WindAloft>,
    /// Radius of the regional surface wind the profile reaches at the top of the boundary
    /// layer, metres (the surface winds within it averaged, `WeatherField::regional_wind_kt`);
    /// 0: each point's own surface wind all the way up.
    #[serde(default = "default_regional_radius_m")]
    pub regional_radius_m: f64,
    /// The least gradient wind at the top of the boundary layer, knots, where the regional
    /// wind is weaker (a region of calm surface winds under a moving sky): its direction the
    /// regional wind's, or the latitude's prevailing one where that is calm too
    /// ([`prevailing_from_deg`]). Only with the regional wind; 0: none.
    #[serde(default = "default_calm_gradient_kt")]
    pub calm_gradient_kt: f64,
}

/// [`WindSettings::calm_gradient_kt`] where a settings file does not set it.
fn default_calm_gradient_kt() -> f64 {
    10.0
}

/// [`WindSettings::regional_radius_m`] where a settings file does not set it.
fn default_regional_radius_m() -> f64 {
    150_000.0
}

/// A wind aloft from the settings (`[wind.aloft]`).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WindAloft {
    /// Direction it blows from, degrees true.
    pub from_deg: f64,
    /// Speed, knots.
    pub speed_kt: f64,
    /// Altitude it is reached at, metres above mean sea level.
    pub level_m_msl: f64,
}

/// Temperature and dewpoint aloft (`[temperature]`).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TemperatureSettings {
    /// Fall of the temperature with height, C per km.
    pub lapse_c_per_km: f64,
    /// Altitude above which the temperature holds, metres MSL.
    pub tropopause_m_msl: f64,
    /// Fall of the dewpoint with height, C per km.
    pub dewpoint_lapse_c_per_km: f64,
}

/// Pressure (`[pressure]`).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PressureSettings {
    /// QNH where no report gives one, hPa.
    pub default_qnh_hpa: f64,
}

/// The in-cloud measure at a point and the line of sight (`[in_cloud]`).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InCloudAirSettings {
    /// Fraction of a cloud's half-extent inside its core box over which in-cloud reaches 1.
    pub ramp_fraction: f32,
    /// Visibility inside a cloud, metres.
    pub visibility_m: f32,
    /// How far the nearest cloud is looked for, metres.
    pub search_radius_m: f64,
    /// Cell size of the grid a line of sight walks through the field's cloud boxes, metres.
    pub grid_cell_m: f64,
}

/// Precipitation rate and type (`[precipitation]`).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PrecipitationAirSettings {
    /// Rate of light precipitation, mm/h.
    pub light_mm_h: f32,
    /// Rate of moderate precipitation, mm/h.
    pub moderate_mm_h: f32,
    /// Rate of heavy precipitation, mm/h.
    pub heavy_mm_h: f32,
    /// At or below this temperature, C, it is snow.
    pub snow_below_c: f32,
}

/// Turbulence (`[turbulence]`).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TurbulenceSettings {
    /// Distance from a cumulonimbus within which it is moderate at least, metres.
    pub cb_near_m: f64,
    /// Intensity light starts at.
    pub light: f32,
    /// Intensity moderate starts at.
    pub moderate: f32,
    /// Intensity severe starts at.
    pub severe: f32,
    /// Intensity inside a cumulonimbus.
    pub cb_inside: f32,
    /// Intensity near one.
    pub cb_near: f32,
    /// Intensity inside towering cumulus.
    pub congestus: f32,
    /// Intensity inside other cumulus.
    pub cumulus: f32,
    /// Surface wind, kt, mechanical turbulence starts at.
    pub mechanical_from_kt: f32,
    /// Wind plus gust excess, kt, at which it is `mechanical_max`.
    pub mechanical_full_kt: f32,
    /// The most mechanical turbulence.
    pub mechanical_max: f32,
}

/// Icing risk (`[icing]`).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IcingSettings {
    /// Warmest temperature of the risk, C.
    pub warmest_c: f32,
    /// Coldest temperature of the risk, C.
    pub coldest_c: f32,
    /// In-cloud measure from which a point is in visible moisture.
    pub in_cloud_min: f32,
}

impl Default for AirSettings {
    /// The shipped `config/air.toml` (a test proves it parses).
    fn default() -> Self {
        Self::shipped()
    }
}

impl TomlSettings for AirSettings {
    const SHIPPED: Option<ShippedFile> = ShippedFile::at("config/air.toml", BUILTIN);

    fn check(&self, path: &Path, text: &str) -> Result<(), ConfigError> {
        let bad = |field: &str, message: &str| ConfigError::at_key(path, text, field, message);
        let positive = |v: f64| v > 0.0 && v.is_finite();
        let w = &self.wind;
        if !positive(w.reference_height_m) {
            return Err(bad("wind.reference_height_m", "must be above 0"));
        }
        if !(0.0..=1.0).contains(&w.power_law_exponent) {
            return Err(bad("wind.power_law_exponent", "must be within 0..=1"));
        }
        if !(w.boundary_layer_top_m > w.reference_height_m && w.boundary_layer_top_m.is_finite()) {
            return Err(bad(
                "wind.boundary_layer_top_m",
                "must be above wind.reference_height_m",
            ));
        }
        if !(-90.0..=90.0).contains(&w.turn_deg) {
            return Err(bad("wind.turn_deg", "must be within -90..=90"));
        }
        if !(w.regional_radius_m >= 0.0 && w.regional_radius_m <= 2_000_000.0) {
            return Err(bad(
                "wind.regional_radius_m",
                "must be within 0..=2000000 (metres; 0 switches the regional wind off)",
            ));
        }
        if !(0.0..=100.0).contains(&w.calm_gradient_kt) {
            return Err(bad(
                "wind.calm_gradient_kt",
                "must be within 0..=100 (knots; 0 leaves a calm region's gradient wind calm)",
            ));
        }
        if let Some(a) = w.aloft {
            if !(0.0..=360.0).contains(&a.from_deg) {
                return Err(bad("wind.aloft.from_deg", "must be within 0..=360"));
            }
            if !(0.0..=400.0).contains(&a.speed_kt) {
                return Err(bad("wind.aloft.speed_kt", "must be within 0..=400"));
            }
            if !a.level_m_msl.is_finite() {
                return Err(bad("wind.aloft.level_m_msl", "must be a number"));
            }
        }
        let t = &self.temperature;
        if !(0.0..=20.0).contains(&t.lapse_c_per_km) {
            return Err(bad("temperature.lapse_c_per_km", "must be within 0..=20"));
        }
        if !positive(t.tropopause_m_msl) {
            return Err(bad("temperature.tropopause_m_msl", "must be above 0"));
        }
        if !(0.0..=20.0).contains(&t.dewpoint_lapse_c_per_km) {
            return Err(bad(
                "temperature.dewpoint_lapse_c_per_km",
                "must be within 0..=20",
            ));
        }
        if !(800.0..=1100.0).contains(&self.pressure.default_qnh_hpa) {
            return Err(bad("pressure.default_qnh_hpa", "must be within 800..=1100"));
        }
        let c = &self.in_cloud;
        if !(c.ramp_fraction > 0.0 && c.ramp_fraction <= 1.0) {
            return Err(bad("in_cloud.ramp_fraction", "must be within (0, 1]"));
        }
        if !positive(f64::from(c.visibility_m)) {
            return Err(bad("in_cloud.visibility_m", "must be above 0"));
        }
        if !positive(c.search_radius_m) {
            return Err(bad("in_cloud.search_radius_m", "must be above 0"));
        }
        if !(c.grid_cell_m >= 50.0 && c.grid_cell_m <= 10_000.0) {
            return Err(bad("in_cloud.grid_cell_m", "must be within 50..=10000"));
        }
        let p = &self.precipitation;
        if !(0.0 <= p.light_mm_h
            && p.light_mm_h <= p.moderate_mm_h
            && p.moderate_mm_h <= p.heavy_mm_h
            && p.heavy_mm_h.is_finite())
        {
            return Err(bad(
                "precipitation.heavy_mm_h",
                "rates must grow: 0 <= light_mm_h <= moderate_mm_h <= heavy_mm_h",
            ));
        }
        let u = &self.turbulence;
        if !(positive(u.cb_near_m) && u.cb_near_m <= c.search_radius_m) {
            return Err(bad(
                "turbulence.cb_near_m",
                "must be above 0 and at most in_cloud.search_radius_m",
            ));
        }
        if !(0.0 < u.light && u.light < u.moderate && u.moderate < u.severe && u.severe <= 1.0) {
            return Err(bad(
                "turbulence.severe",
                "thresholds must grow: 0 < light < moderate < severe <= 1",
            ));
        }
        for (name, v) in [
            ("turbulence.cb_inside", u.cb_inside),
            ("turbulence.cb_near", u.cb_near),
            ("turbulence.congestus", u.congestus),
            ("turbulence.cumulus", u.cumulus),
            ("turbulence.mechanical_max", u.mechanical_max),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return Err(bad(name, "must be within 0..=1"));
            }
        }
        if !(0.0 <= u.mechanical_from_kt && u.mechanical_from_kt < u.mechanical_full_kt) {
            return Err(bad(
                "turbulence.mechanical_full_kt",
                "must be above mechanical_from_kt, which must be at least 0",
            ));
        }
        let i = &self.icing;
        if !(i.coldest_c < i.warmest_c && i.warmest_c.is_finite() && i.coldest_c.is_finite()) {
            return Err(bad("icing.coldest_c", "must be below icing.warmest_c"));
        }
        if !(0.0..=1.0).contains(&i.in_cloud_min) {
            return Err(bad("icing.in_cloud_min", "must be within 0..=1"));
        }
        Ok(())
    }
}

/// What the reports give at the ground under a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceAir {
    /// The surface wind (the report's, interpolated as a vector).
    pub wind: Wind,
    /// Gusts above the mean wind, knots (0 without gusts).
    pub gust_excess_kt: f64,
    /// Temperature at the ground, C.
    pub temperature_c: f64,
    /// Dewpoint at the ground, C.
    pub dewpoint_c: f64,
    /// Altimeter setting, hPa.
    pub qnh_hpa: f64,
    /// Ground elevation, metres MSL.
    pub ground_m_msl: f64,
    /// The regional surface wind around the point (knots east, north;
    /// [`crate::weather::WeatherField::regional_wind_kt`]): the wind goes over from
    /// [`Self::wind`] at the anemometer to this one's gradient wind at the top of the boundary
    /// layer. `None`: the point's own wind all the way up.
    pub regional_wind_kt: Option<DVec2>,
}

impl SurfaceAir {
    /// The surface air of a block weather, with the gust excess and QNH the field interpolates
    /// separately ([`super::WeatherField::gust_and_qnh_at`]).
    pub fn of(weather: &BlockWeather, gust_excess_kt: f64, qnh_hpa: f64) -> Self {
        Self {
            wind: weather.wind,
            gust_excess_kt: gust_excess_kt.max(0.0),
            temperature_c: f64::from(weather.temperature_c),
            dewpoint_c: f64::from(weather.dewpoint_c),
            qnh_hpa,
            ground_m_msl: f64::from(weather.ground_elevation_m),
            regional_wind_kt: None,
        }
    }

    /// This surface air with the regional surface wind around it
    /// ([`Self::regional_wind_kt`]).
    pub fn with_regional_wind_kt(self, regional_wind_kt: Option<DVec2>) -> Self {
        Self {
            regional_wind_kt,
            ..self
        }
    }
}

/// The wind at a height.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct WindSample {
    /// Direction it blows from, degrees true, 0..360 (0 when calm).
    pub from_deg: f64,
    /// Mean speed, knots.
    pub speed_kt: f64,
    /// Gust speed, knots (the mean speed without gusts).
    pub gust_kt: f64,
}

/// The air at a height over a point, from the weather stage alone (no clouds).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct AirColumnSample {
    /// The wind.
    pub wind: WindSample,
    /// Temperature, C.
    pub temperature_c: f64,
    /// Dewpoint, C.
    pub dewpoint_c: f64,
    /// Static pressure, hPa.
    pub pressure_hpa: f64,
    /// Pressure altitude, feet.
    pub pressure_altitude_ft: f64,
    /// Density altitude, feet.
    pub density_altitude_ft: f64,
    /// Height above the ground, metres.
    pub height_agl_m: f64,
}

/// The air at `alt_m_msl` over a point with `surface` air, at latitude `lat_deg` (its sign picks
/// veering or backing).
pub fn air_at(
    surface: &SurfaceAir,
    alt_m_msl: f64,
    lat_deg: f64,
    settings: &AirSettings,
) -> AirColumnSample {
    air_at_aloft(surface, alt_m_msl, lat_deg, settings, None)
}

/// [`air_at`] with the winds and temperatures aloft of an FB product over the point
/// ([`super::winds_aloft`]): above the boundary layer the wind goes over linearly (as a vector)
/// from the gradient wind at its top to the FB wind at the lowest FB level above it, follows
/// the FB levels linearly in altitude above that and holds the highest one's above it (the
/// `[wind.aloft]` setting then unused); the temperature likewise from the lapse's at the top of
/// the boundary layer to the FB temperatures. Inside the boundary layer and without FB: the
/// documented profile.
pub fn air_at_aloft(
    surface: &SurfaceAir,
    alt_m_msl: f64,
    lat_deg: f64,
    settings: &AirSettings,
    aloft: Option<&AloftColumn>,
) -> AirColumnSample {
    let height_agl_m = (alt_m_msl - surface.ground_m_msl).max(0.0);
    let t = &settings.temperature;
    let top_m = settings.wind.boundary_layer_top_m;
    let top_msl = surface.ground_m_msl + top_m;
    let mut temperature = temperature_c(surface, alt_m_msl, t);
    let mut wind = wind_at(surface, height_agl_m, alt_m_msl, lat_deg, &settings.wind);
    if let Some(column) = aloft
        && height_agl_m > top_m
    {
        let gradient = wind_at(
            surface,
            top_m,
            top_msl,
            lat_deg,
            &WindSettings {
                aloft: None,
                ..settings.wind
            },
        );
        let winds: Vec<(f64, DVec2)> = column
            .levels
            .iter()
            .filter(|l| l.alt_m_msl >= top_msl)
            .filter_map(|l| l.velocity_kt.map(|v| (l.alt_m_msl, v)))
            .collect();
        let base = velocity_kt(gradient.from_deg, gradient.speed_kt);
        if let Some(v) = through_levels(&winds, top_msl, base, alt_m_msl) {
            let (from, speed) = from_velocity_kt(v);
            wind = sample(from, speed, 0.0);
        }
        let temperatures: Vec<(f64, f64)> = column
            .levels
            .iter()
            .filter(|l| l.alt_m_msl >= top_msl)
            .filter_map(|l| l.temperature_c.map(|c| (l.alt_m_msl, c)))
            .collect();
        let at_top = temperature_c(surface, top_msl, t);
        if let Some(c) = through_levels(&temperatures, top_msl, at_top, alt_m_msl) {
            temperature = c;
        }
    }
    let temperature_c = temperature;
    let dewpoint_c =
        (surface.dewpoint_c - t.dewpoint_lapse_c_per_km * height_agl_m / 1000.0).min(temperature_c);
    let pressure_hpa = pressure_hpa(surface.qnh_hpa, alt_m_msl);
    AirColumnSample {
        wind,
        temperature_c,
        dewpoint_c,
        pressure_hpa,
        pressure_altitude_ft: pressure_altitude_ft(pressure_hpa),
        density_altitude_ft: density_altitude_ft(pressure_hpa, temperature_c),
        height_agl_m,
    }
}

/// A value through `levels` (altitude, value; lowest first) at `alt`: linear from `base` at
/// `base_alt` to the lowest level, between levels, the highest's above; `None` without levels.
fn through_levels<T>(levels: &[(f64, T)], base_alt: f64, base: T, alt: f64) -> Option<T>
where
    T: Copy + std::ops::Mul<f64, Output = T> + std::ops::Add<Output = T>,
{
    let mut below = (base_alt, base);
    for &(level_alt, value) in levels {
        if alt <= level_alt {
            let span = level_alt - below.0;
            let f = if span > 0.0 {
                ((alt - below.0) / span).clamp(0.0, 1.0)
            } else {
                1.0
            };
            return Some(below.1 * (1.0 - f) + value * f);
        }
        below = (level_alt, value);
    }
    levels.last().map(|l| l.1)
}

/// The temperature at `alt_m_msl`: the surface's, less the lapse up to the tropopause.
fn temperature_c(surface: &SurfaceAir, alt_m_msl: f64, t: &TemperatureSettings) -> f64 {
    let top = t.tropopause_m_msl.max(surface.ground_m_msl);
    let climb_m = alt_m_msl.clamp(surface.ground_m_msl, top) - surface.ground_m_msl;
    surface.temperature_c - t.lapse_c_per_km * climb_m / 1000.0
}

/// The wind at `height_agl_m` (`alt_m_msl`) over a point with `surface` air.
pub fn wind_at(
    surface: &SurfaceAir,
    height_agl_m: f64,
    alt_m_msl: f64,
    lat_deg: f64,
    w: &WindSettings,
) -> WindSample {
    let (zr, top) = (w.reference_height_m, w.boundary_layer_top_m);
    let z = height_agl_m.clamp(zr, top);
    let growth = (z / zr).powf(w.power_law_exponent);
    let share = (z / zr).ln() / (top / zr).ln();
    let hemisphere = if lat_deg < 0.0 { -1.0 } else { 1.0 };
    let turn = hemisphere * w.turn_deg * share;
    // The surface wind the profile grows from: the point's own at the anemometer, the
    // regional one's at the top of the boundary layer (over evenly in the logarithm of
    // height, as the turn).
    let own = velocity_kt(
        f64::from(surface.wind.from_deg),
        f64::from(surface.wind.speed_kt),
    );
    let base = match surface.regional_wind_kt {
        Some(regional) => {
            let top_growth = (top / zr).powf(w.power_law_exponent);
            own.lerp(
                at_least(regional, w.calm_gradient_kt / top_growth, lat_deg),
                share,
            )
        }
        None => own,
    };
    let (base_from, base_speed) = if surface.regional_wind_kt.is_some() {
        from_velocity_kt(base)
    } else {
        (
            f64::from(surface.wind.from_deg),
            f64::from(surface.wind.speed_kt),
        )
    };
    let speed = base_speed * growth;
    let from = base_from + turn;
    let gust_excess = surface.gust_excess_kt * (1.0 - height_agl_m / top).max(0.0);
    if height_agl_m <= top {
        return sample(from, speed, gust_excess);
    }
    let Some(aloft) = w.aloft else {
        return sample(from, speed, 0.0);
    };
    // Over linearly, as vectors, from the gradient wind at the top to the wind aloft.
    let top_msl = surface.ground_m_msl + top;
    let t = if aloft.level_m_msl <= top_msl {
        1.0
    } else {
        ((alt_m_msl - top_msl) / (aloft.level_m_msl - top_msl)).clamp(0.0, 1.0)
    };
    let v = velocity_kt(from, speed).lerp(velocity_kt(aloft.from_deg, aloft.speed_kt), t);
    let (from, speed) = from_velocity_kt(v);
    sample(from, speed, 0.0)
}

/// The regional surface wind `regional_kt` (knots east, north) made at least `least_kt`: along
/// itself, or from the prevailing direction at `lat_deg` where it is under half a knot.
fn at_least(regional_kt: DVec2, least_kt: f64, lat_deg: f64) -> DVec2 {
    let speed = regional_kt.length();
    if speed >= least_kt {
        regional_kt
    } else if speed >= 0.5 {
        regional_kt * (least_kt / speed)
    } else {
        velocity_kt(prevailing_from_deg(lat_deg), least_kt)
    }
}

/// The direction the prevailing wind blows from at `lat_deg`, degrees: the trade winds'
/// easterlies within 30 degrees of the equator, the westerlies to 60 degrees, the polar
/// easterlies beyond (the three cells of the general circulation).
pub fn prevailing_from_deg(lat_deg: f64) -> f64 {
    if (30.0..60.0).contains(&lat_deg.abs()) {
        270.0
    } else {
        90.0
    }
}

fn sample(from_deg: f64, speed_kt: f64, gust_excess_kt: f64) -> WindSample {
    WindSample {
        from_deg: if speed_kt > 0.0 {
            from_deg.rem_euclid(360.0)
        } else {
            0.0
        },
        speed_kt,
        gust_kt: speed_kt + gust_excess_kt,
    }
}

/// The velocity (knots east, north) of a wind from `from_deg`.
fn velocity_kt(from_deg: f64, speed_kt: f64) -> DVec2 {
    let to = (from_deg + 180.0).to_radians();
    DVec2::new(to.sin(), to.cos()) * speed_kt
}

/// Direction from and speed of a velocity.
fn from_velocity_kt(v: DVec2) -> (f64, f64) {
    let speed = v.length();
    if speed < 1e-9 {
        return (0.0, 0.0);
    }
    (
        (v.x.atan2(v.y).to_degrees() + 180.0).rem_euclid(360.0),
        speed,
    )
}

/// Static pressure at `alt_m_msl` in the ISA of this QNH, hPa.
pub fn pressure_hpa(qnh_hpa: f64, alt_m_msl: f64) -> f64 {
    qnh_hpa * (1.0 - 0.0065 * alt_m_msl / 288.15).max(1e-6).powf(5.25588)
}

/// Pressure altitude of a static pressure, feet (NWS).
pub fn pressure_altitude_ft(pressure_hpa: f64) -> f64 {
    145_366.45 * (1.0 - (pressure_hpa / 1013.25).powf(0.190_284))
}

/// Density altitude of a pressure and temperature, feet (NWS, dry air).
pub fn density_altitude_ft(pressure_hpa: f64, temperature_c: f64) -> f64 {
    let density_ratio = (pressure_hpa / 1013.25) * (288.15 / (temperature_c + 273.15));
    145_442.16 * (1.0 - density_ratio.max(1e-9).powf(0.234_969))
}

/// Feet of a height in metres.
pub fn feet(m: f64) -> f64 {
    m / M_PER_FT
}

#[cfg(test)]
mod tests {
    use super::*;

    fn surface(from_deg: f32, speed_kt: f32, gust_excess_kt: f64) -> SurfaceAir {
        SurfaceAir {
            wind: Wind { from_deg, speed_kt },
            gust_excess_kt,
            temperature_c: 15.0,
            dewpoint_c: 5.0,
            qnh_hpa: 1013.25,
            ground_m_msl: 200.0,
            regional_wind_kt: None,
        }
    }

    #[test]
    fn a_calm_surface_under_a_regional_wind_reaches_its_gradient_wind() {
        let s = AirSettings::default().wind;
        let calm = surface(0.0, 0.0, 0.0).with_regional_wind_kt(Some(velocity_kt(270.0, 10.0)));
        let at = |h: f64| wind_at(&calm, h, 200.0 + h, 45.0, &s);
        // The anemometer reads the station's calm...
        assert_eq!(at(10.0).speed_kt, 0.0);
        // ...the top of the boundary layer the region's gradient wind: 1.8 times its 10 kt,
        // veered 30 degrees.
        let top = at(s.boundary_layer_top_m);
        let growth = (s.boundary_layer_top_m / s.reference_height_m).powf(s.power_law_exponent);
        assert!((top.speed_kt - 10.0 * growth).abs() < 1e-9, "{top:?}");
        assert!((top.from_deg - 300.0).abs() < 1e-9, "{top:?}");
        // Between, the wind grows steadily, and above it holds.
        let speeds: Vec<f64> = [10.0, 50.0, 150.0, 400.0, 610.0, 2000.0]
            .map(|h| at(h).speed_kt)
            .to_vec();
        assert!(speeds.windows(2).all(|p| p[1] >= p[0]), "{speeds:?}");
        assert_eq!(at(2000.0), top);
        // Where the region's wind is the station's, the profile is the station's alone.
        let windy = surface(200.0, 12.0, 0.0);
        let same = windy.with_regional_wind_kt(Some(velocity_kt(200.0, 12.0)));
        for h in [10.0, 100.0, 610.0, 3000.0] {
            let (a, b) = (
                wind_at(&windy, h, 200.0 + h, 45.0, &s),
                wind_at(&same, h, 200.0 + h, 45.0, &s),
            );
            assert!(
                (a.speed_kt - b.speed_kt).abs() < 1e-9 && (a.from_deg - b.from_deg).abs() < 1e-6
            );
        }
    }

    #[test]
    fn a_calm_region_still_has_a_gradient_wind_above_its_calm_stations() {
        let s = AirSettings::default().wind;
        let top_of = |regional: DVec2, lat_deg: f64, s: &WindSettings| {
            let calm = surface(0.0, 0.0, 0.0).with_regional_wind_kt(Some(regional));
            let top = s.boundary_layer_top_m;
            // Above the boundary layer it holds.
            assert_eq!(
                wind_at(&calm, top, 200.0 + top, lat_deg, s),
                wind_at(&calm, 3000.0, 3200.0, lat_deg, s)
            );
            // The anemometer still reads the station's calm.
            assert_eq!(wind_at(&calm, 10.0, 210.0, lat_deg, s).speed_kt, 0.0);
            wind_at(&calm, top, 200.0 + top, lat_deg, s)
        };
        assert_eq!(s.calm_gradient_kt, 10.0);
        // A light regional wind is grown to the least gradient wind along itself (from 180,
        // veered 30 degrees)...
        let light = top_of(velocity_kt(180.0, 2.0), 45.0, &s);
        assert!((light.speed_kt - 10.0).abs() < 1e-9, "{light:?}");
        assert!((light.from_deg - 210.0).abs() < 1e-6, "{light:?}");
        // ...a calm one blows from the latitude's prevailing direction, turned as the
        // hemisphere turns it: westerlies at 45 N, trade easterlies at 15 N, westerlies at 45 S.
        for (lat, from) in [(45.0, 300.0), (15.0, 120.0), (-45.0, 240.0), (70.0, 120.0)] {
            let w = top_of(DVec2::ZERO, lat, &s);
            assert!((w.speed_kt - 10.0).abs() < 1e-9, "{lat}: {w:?}");
            assert!((w.from_deg - from).abs() < 1e-6, "{lat}: {w:?}");
        }
        // A regional wind strong enough is left as it is; none asked, a calm region stays calm.
        let growth = (s.boundary_layer_top_m / s.reference_height_m).powf(s.power_law_exponent);
        let strong = top_of(velocity_kt(180.0, 8.0), 45.0, &s);
        assert!((strong.speed_kt - 8.0 * growth).abs() < 1e-9, "{strong:?}");
        let off = WindSettings {
            calm_gradient_kt: 0.0,
            ..s
        };
        assert_eq!(top_of(DVec2::ZERO, 45.0, &off).speed_kt, 0.0);
        // A negative floor is an error naming its field and line.
        let bad = BUILTIN.replace("calm_gradient_kt = 10.0", "calm_gradient_kt = -1.0");
        let err = AirSettings::parse(&bad, Path::new("air.toml")).unwrap_err();
        assert_eq!(err.field.as_deref(), Some("wind.calm_gradient_kt"));
        assert!(err.line.is_some(), "{err}");
    }

    #[test]
    fn the_shipped_settings_parse_and_a_bad_one_names_its_field() {
        let s = AirSettings::default();
        assert_eq!(s.wind.power_law_exponent, 0.143);
        let bad = BUILTIN.replace("turn_deg = 30.0", "turn_deg = 120.0");
        let err = AirSettings::parse(&bad, Path::new("air.toml")).unwrap_err();
        assert_eq!(err.field.as_deref(), Some("wind.turn_deg"));
        assert!(err.line.is_some(), "{err}");
    }

    #[test]
    fn at_the_ground_the_air_is_the_report() {
        let s = AirSettings::default();
        let sfc = surface(250.0, 12.0, 8.0);
        let a = air_at(&sfc, 200.0, 45.0, &s);
        assert_eq!(a.wind.from_deg, 250.0);
        assert_eq!(a.wind.speed_kt, 12.0);
        assert_eq!(a.wind.gust_kt, 20.0);
        assert_eq!(a.temperature_c, 15.0);
        assert_eq!(a.dewpoint_c, 5.0);
    }

    #[test]
    fn the_boundary_layer_grows_and_veers_north_and_backs_south() {
        let s = AirSettings::default();
        let sfc = surface(250.0, 10.0, 8.0);
        let top = s.wind.boundary_layer_top_m;
        let north = air_at(&sfc, 200.0 + top, 45.0, &s).wind;
        let south = air_at(&sfc, 200.0 + top, -45.0, &s).wind;
        let growth = (top / 10.0).powf(0.143);
        assert!((north.speed_kt - 10.0 * growth).abs() < 1e-9, "{north:?}");
        assert!((north.from_deg - 280.0).abs() < 1e-9, "{north:?}");
        assert!((south.from_deg - 220.0).abs() < 1e-9, "{south:?}");
        // The gusts are gone at the top.
        assert_eq!(north.gust_kt, north.speed_kt);
        // Halfway up in log height, half the turn.
        let mid = (10.0 * top).sqrt();
        let half = air_at(&sfc, 200.0 + mid, 45.0, &s).wind;
        assert!((half.from_deg - 265.0).abs() < 1e-6, "{half:?}");
        // Above it, without a wind aloft, the gradient wind holds.
        let high = air_at(&sfc, 6000.0, 45.0, &s).wind;
        assert!((high.speed_kt - north.speed_kt).abs() < 1e-9);
    }

    #[test]
    fn above_the_boundary_layer_the_wind_goes_over_to_the_wind_aloft() {
        let mut s = AirSettings::default();
        s.wind.aloft = Some(WindAloft {
            from_deg: 300.0,
            speed_kt: 50.0,
            level_m_msl: 5000.0,
        });
        let sfc = surface(250.0, 10.0, 0.0);
        let at = |alt| air_at(&sfc, alt, 45.0, &s).wind;
        let aloft = at(5000.0);
        assert!((aloft.from_deg - 300.0).abs() < 1e-9 && (aloft.speed_kt - 50.0).abs() < 1e-9);
        assert_eq!(at(9000.0), aloft);
        let top = at(200.0 + s.wind.boundary_layer_top_m);
        let mid = at((200.0 + s.wind.boundary_layer_top_m + 5000.0) / 2.0);
        let v = (velocity_kt(top.from_deg, top.speed_kt) + velocity_kt(300.0, 50.0)) / 2.0;
        let (from, speed) = from_velocity_kt(v);
        assert!((mid.from_deg - from).abs() < 1e-6 && (mid.speed_kt - speed).abs() < 1e-6);
    }

    #[test]
    fn temperature_lapses_to_the_tropopause_and_pressure_altitude_follows_the_qnh() {
        let s = AirSettings::default();
        let mut sfc = surface(0.0, 0.0, 0.0);
        let a = air_at(&sfc, 1200.0, 45.0, &s);
        assert!((a.temperature_c - 8.5).abs() < 1e-9);
        assert!(a.dewpoint_c <= a.temperature_c);
        let high = air_at(&sfc, 15_000.0, 45.0, &s);
        assert!((high.temperature_c - (15.0 - 6.5 * 10.8)).abs() < 1e-9);
        // Standard day at sea level: PA 0 and DA 0; 1000 ft of ISA pressure altitude is 1000.
        sfc.ground_m_msl = 0.0;
        let sl = air_at(&sfc, 0.0, 45.0, &s);
        assert!(sl.pressure_altitude_ft.abs() < 1.0 && sl.density_altitude_ft.abs() < 1.0);
        let k = air_at(&sfc, 304.8, 45.0, &s);
        assert!((k.pressure_altitude_ft - 1000.0).abs() < 5.0, "{k:?}");
        // Low QNH reads higher: about 27-30 ft per hPa near sea level.
        sfc.qnh_hpa = 1003.25;
        let low = air_at(&sfc, 0.0, 45.0, &s);
        assert!((low.pressure_altitude_ft - 275.0).abs() < 10.0, "{low:?}");
        // Hot air: density altitude above pressure altitude (about 120 ft per C).
        sfc.qnh_hpa = 1013.25;
        sfc.temperature_c = 35.0;
        let hot = air_at(&sfc, 0.0, 45.0, &s);
        assert!((hot.density_altitude_ft - 2400.0).abs() < 200.0, "{hot:?}");
    }
}
