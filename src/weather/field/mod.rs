//! The weather field: placed reports in, the weather at any point (and so of any 4 km block) out.
//!
//! The stations are projected into a [`LocalFrame`] and triangulated (spade's Delaunay
//! triangulation; stations at identical positions are merged, the latest report wins). Values are
//! interpolated by Sibson's natural-neighbour interpolation (spade's `natural_neighbor`), which is
//! exact at the stations and smooth between them; a point outside the convex hull of the stations
//! takes its nearest station's values.
//!
//! Two triangulations: the cloud field holds the stations that say something about the sky
//! (layers, CAVOK/NSC/NCD/SKC/CLR as a clear sky, VV); the surface field holds every station
//! (visibility, obscuration, wind as a vector, temperature, dewpoint, precipitation, ground
//! elevation). A value some neighbours do not report is interpolated over the neighbours that do
//! (weights renormalised); with none, the configured default.
//!
//! Cloud layers: every reported layer is kept; the neighbours' layers are matched by height and
//! blended by their weights, and the covers follow the summation principle (`layers`). A block
//! that holds a station is sampled at the station, not at its centre, so it is that station's
//! report. Layer types come from [`CloudTypeRule`], vertical extents from the settings.
//! The block also carries its layers' cover at its rim ([`crate::weather::BlockCover`], `rim`),
//! so that its clouds blend into the neighbours'. Settings: `config/weather_field.toml`.

mod blend;
mod layers;
mod regional;
mod rim;
mod rule;
mod sample;
mod settings;
#[cfg(test)]
mod tests;

pub use rule::{Band, CloudTypeRule, LayerFacts, Reported, Rule};
pub use sample::{LayerKind, StationLayer, StationSample};
pub use settings::{FieldSettings, PerCover, StationHold};

use std::collections::HashMap;
use std::sync::Arc;

use glam::DVec2;
use spade::{DelaunayTriangulation, HasPosition, Point2, Triangulation};

use super::block::{BlockIndex, BlockLayer, BlockWeather, Obscuration, Wind};
use super::block_cover::RIM_POINTS_M;
use super::files::PlacedReport;
use super::frame::LocalFrame;
use super::model::{ModelField, ModelSettings};
use super::theme::Theme;

/// A triangulation vertex: a station's local position and its index in the sample list.
#[derive(Debug, Clone, Copy)]
struct Site {
    position: Point2<f64>,
    index: usize,
}

impl HasPosition for Site {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.position
    }
}

type Tri = DelaunayTriangulation<Site>;

/// The weather everywhere, from placed reports (and a model under them,
/// [`Self::with_model`]).
#[derive(Debug, Clone)]
pub struct WeatherField {
    frame: LocalFrame,
    settings: FieldSettings,
    rule: CloudTypeRule,
    samples: Vec<StationSample>,
    surface: Tri,
    clouds: Tri,
    /// Where each block that holds a station is sampled: at that station (a sky station first,
    /// the one nearest the block centre).
    station_in_block: HashMap<BlockIndex, DVec2>,
    /// A numerical weather model under the reports ([`Self::with_model`]).
    model: Option<(Arc<ModelField>, ModelSettings)>,
    /// Each sample's report age, hours behind the file's time (empty: all fresh).
    report_ages_h: Vec<f64>,
    /// The stations' surface winds binned for [`Self::regional_wind_kt`].
    regional: regional::RegionalWinds,
}

/// Natural-neighbour weights of a point: (sample index, weight), weights summing to 1.
type Weights = Vec<(usize, f64)>;

impl WeatherField {
    /// Builds the field of `reports` in `frame`.
    pub fn build(
        frame: LocalFrame,
        reports: &[PlacedReport],
        settings: &FieldSettings,
        rule: &CloudTypeRule,
    ) -> Self {
        // Latest report per position (bit-identical latitude/longitude): by report time, then by
        // file order.
        let mut latest: HashMap<(u64, u64), &PlacedReport> = HashMap::new();
        for p in reports {
            let key = (
                p.position.latitude_deg.to_bits(),
                p.position.longitude_deg.to_bits(),
            );
            let time = |p: &PlacedReport| p.report.time.map(|t| (t.day, t.hour, t.minute));
            latest
                .entry(key)
                .and_modify(|old| {
                    if (time(p), p.line) >= (time(old), old.line) {
                        *old = p;
                    }
                })
                .or_insert(p);
        }
        let mut kept: Vec<&PlacedReport> = latest.into_values().collect();
        kept.sort_by_key(|p| p.line);
        // Each report's age, hours behind the file's time (what a model under the reports fades
        // them by, `model::BlendSettings`): the time 95 % of its reports are at or before, so
        // that one station's clock running ahead does not age all the others.
        let minutes = |p: &PlacedReport| {
            p.report
                .time
                .map(|t| (i64::from(t.day) * 24 + i64::from(t.hour)) * 60 + i64::from(t.minute))
        };
        let mut times: Vec<i64> = kept.iter().filter_map(|p| minutes(p)).collect();
        times.sort_unstable();
        let newest = (!times.is_empty()).then(|| times[((times.len() - 1) * 95).div_ceil(100)]);
        let mut ages_h = Vec::with_capacity(kept.len());
        let placed: Vec<(DVec2, StationSample)> = kept
            .into_iter()
            .filter_map(|p| {
                let sample = StationSample::of(p, settings)?;
                let local = frame.to_local_m(p.position.latitude_deg, p.position.longitude_deg);
                if !local.is_finite() {
                    return None;
                }
                // A report of the month before (day 31 behind day 1) is a month's days back;
                // one a little ahead of the file's time is fresh.
                let age_min = match (newest, minutes(p)) {
                    (Some(n), Some(m)) if m > n + 24 * 60 => n + 31 * 24 * 60 - m,
                    (Some(n), Some(m)) => (n - m).max(0),
                    _ => 0,
                };
                ages_h.push(age_min as f64 / 60.0);
                Some((local, sample))
            })
            .collect();
        let mut field = Self::from_samples(frame, placed, settings, rule);
        field.report_ages_h = ages_h;
        field
    }

    /// Builds the field of a weather theme in `frame`: its points, or, for a theme without
    /// points, one place at the frame origin (so the same weather everywhere).
    pub fn from_theme(
        frame: LocalFrame,
        theme: &Theme,
        settings: &FieldSettings,
        rule: &CloudTypeRule,
    ) -> Self {
        let places: Vec<(DVec2, StationSample)> = if theme.points.is_empty() {
            vec![(
                DVec2::ZERO,
                StationSample::of_theme(&theme.everywhere, settings),
            )]
        } else {
            theme
                .points
                .iter()
                .map(|p| {
                    let local = frame.to_local_m(p.lat_deg, p.lon_deg);
                    (local, StationSample::of_theme(&p.weather, settings))
                })
                .collect()
        };
        Self::from_samples(frame, places, settings, rule)
    }

    /// Triangulates station samples at local positions (non-finite positions are left out).
    fn from_samples(
        frame: LocalFrame,
        places: impl IntoIterator<Item = (DVec2, StationSample)>,
        settings: &FieldSettings,
        rule: &CloudTypeRule,
    ) -> Self {
        let places = places.into_iter();
        let mut samples = Vec::with_capacity(places.size_hint().0);
        let mut surface_sites = Vec::with_capacity(places.size_hint().0);
        let mut cloud_sites = Vec::new();
        for (local, sample) in places {
            if !local.is_finite() {
                continue;
            }
            let site = Site {
                position: Point2::new(local.x, local.y),
                index: samples.len(),
            };
            if sample.sky.is_some() {
                cloud_sites.push(site);
            }
            surface_sites.push(site);
            samples.push(sample);
        }
        // The two triangulations are independent: build them side by side.
        let station_in_block = stations_in_blocks(&cloud_sites, &surface_sites);
        let regional = regional::RegionalWinds::new(surface_sites.iter().map(|s| {
            (
                DVec2::new(s.position.x, s.position.y),
                samples[s.index].wind_kt,
            )
        }));
        let (surface, clouds) =
            rayon::join(|| triangulate(surface_sites), || triangulate(cloud_sites));
        Self {
            frame,
            settings: settings.clone(),
            rule: rule.clone(),
            samples,
            surface,
            clouds,
            station_in_block,
            model: None,
            report_ages_h: Vec::new(),
            regional,
        }
    }

    /// The field with a numerical weather model under its reports: near a station the report
    /// rules, its weight fading with the distance to the nearest station
    /// ([`super::model::BlendSettings::report_weight`]: the sky's stations for the layers, all
    /// stations for the surface values) and with the reports' age
    /// ([`super::model::BlendSettings::age_weight`]), and the model carries the rest; with no
    /// reports, the model alone.
    pub fn with_model(mut self, model: Arc<ModelField>, settings: ModelSettings) -> Self {
        self.model = Some((model, settings));
        self
    }

    /// Puts a model under the reports, or takes it away (`None`): [`Self::with_model`] on a
    /// field already built.
    pub fn set_model(&mut self, model: Option<(Arc<ModelField>, ModelSettings)>) {
        self.model = model;
    }

    /// The model under the reports, if any, and its settings.
    pub fn model(&self) -> Option<(&Arc<ModelField>, &ModelSettings)> {
        self.model.as_ref().map(|(m, s)| (m, s))
    }

    /// The reports' weight at `point_m` against the model, 0..=1, over the stations of `tri`
    /// whose natural-neighbour weights there are `w`: by the distance to the nearest station,
    /// times the stations' age weights averaged by `w` (1 without a model, 0 with a model and
    /// no station).
    fn report_weight(&self, tri: &Tri, point_m: DVec2, w: &Weights) -> f64 {
        let Some((_, settings)) = &self.model else {
            return 1.0;
        };
        let p = Point2::new(point_m.x, point_m.y);
        let by_distance = tri.nearest_neighbor(p).map_or(0.0, |v| {
            let q = v.position();
            let km = (q.x - p.x).hypot(q.y - p.y) / 1000.0;
            settings.blend.report_weight(km)
        });
        let (mut by_age, mut total) = (0.0, 0.0);
        for &(index, weight) in w {
            let age_h = self.report_ages_h.get(index).copied().unwrap_or(0.0);
            by_age += weight * settings.blend.age_weight(age_h);
            total += weight;
        }
        if total > 0.0 {
            by_distance * by_age / total
        } else {
            0.0
        }
    }

    /// The settings the field was built with.
    pub fn settings(&self) -> &FieldSettings {
        &self.settings
    }

    /// The frame the field lives in.
    pub fn frame(&self) -> &LocalFrame {
        &self.frame
    }

    /// Stations in the field (after merging identical positions, NIL reports left out).
    pub fn station_count(&self) -> usize {
        self.surface.num_vertices()
    }

    /// Stations that say something about the sky.
    pub fn cloud_station_count(&self) -> usize {
        self.clouds.num_vertices()
    }

    /// The weather of a block: queried at the station it holds (so the block is that station's
    /// report), else at its centre; with its layers' cover at the block's rim
    /// ([`BlockWeather::cover`]), which the blocks sharing a side share.
    pub fn block_weather(&self, block: BlockIndex) -> BlockWeather {
        let sample = self.block_sample_point_m(block);
        let mut weather = self.weather_at(sample);
        let corner = block.min_corner_m();
        let rim = RIM_POINTS_M.map(|p| self.layers_only_at(corner + p));
        let sample_m = (sample - corner).as_vec2().to_array();
        weather.cover = Some(rim::block_cover(
            &weather.layers,
            &rim,
            sample_m,
            &self.settings,
        ));
        weather
    }

    /// [`Self::block_weather`] without the cover at the block's rim (`cover` is `None`): for
    /// what reads only a block's layers (the storm cells beyond the cloud field, searched a few
    /// rows a frame on the frame thread), at a tenth of the cost.
    pub fn block_layers_weather(&self, block: BlockIndex) -> BlockWeather {
        self.weather_at(self.block_sample_point_m(block))
    }

    /// Where [`Self::block_weather`] samples a block, local metres: the station in it (a sky
    /// station first, then the one nearest the centre), else its centre.
    pub fn block_sample_point_m(&self, block: BlockIndex) -> DVec2 {
        self.station_in_block
            .get(&block)
            .copied()
            .unwrap_or_else(|| block.centre_m())
    }

    /// The weather at a latitude/longitude.
    pub fn weather_at_lat_lon(&self, lat_deg: f64, lon_deg: f64) -> BlockWeather {
        self.weather_at(self.frame.to_local_m(lat_deg, lon_deg))
    }

    /// The weather at a local point (metres east/north).
    pub fn weather_at(&self, point_m: DVec2) -> BlockWeather {
        self.weather_with(
            point_m,
            &weights(&self.surface, point_m, &self.settings.stations),
        )
    }

    /// [`Self::weather_at`] and [`Self::gust_and_qnh_at`] at once: the stations' weights at the
    /// point are worked out once for both (what the air data asks every frame).
    pub fn weather_gust_and_qnh_at(
        &self,
        point_m: DVec2,
        default_qnh_hpa: f64,
    ) -> (BlockWeather, f64, f64) {
        let w = weights(&self.surface, point_m, &self.settings.stations);
        let (gust, qnh) = self.gust_and_qnh_with(point_m, &w, default_qnh_hpa);
        (self.weather_with(point_m, &w), gust, qnh)
    }

    /// The cloud layers at a local point: the layers of [`Self::weather_at`] alone.
    fn layers_only_at(&self, point_m: DVec2) -> Vec<BlockLayer> {
        let (surface, _) =
            self.surface_with(&weights(&self.surface, point_m, &self.settings.stations));
        self.layers_at(point_m, surface)
    }

    /// The surface facts the layers depend on, and the dewpoint, from the surface stations'
    /// weights `w`.
    fn surface_with(&self, w: &Weights) -> (layers::Surface, f64) {
        let d = &self.settings.defaults;
        let value = |f: &dyn Fn(&StationSample) -> Option<f64>, default: f64| {
            weighted(w, &self.samples, f).unwrap_or(default)
        };
        let temperature_c = value(&|s| s.temperature_c, d.temperature_c);
        let dewpoint_c = value(&|s| s.dewpoint_c, d.dewpoint_c);
        let precipitation = value(&|s| Some(s.precipitation), 0.0);
        let surface = layers::Surface {
            precipitation,
            temperature_c,
            spread_c: temperature_c - dewpoint_c,
        };
        (surface, dewpoint_c)
    }

    /// The weather at `point_m` from the surface stations' weights `w` there.
    fn weather_with(&self, point_m: DVec2, w: &Weights) -> BlockWeather {
        let d = &self.settings.defaults;
        let value = |f: &dyn Fn(&StationSample) -> Option<f64>, default: f64| {
            weighted(w, &self.samples, f).unwrap_or(default)
        };
        let (surface, dewpoint_c) = self.surface_with(w);
        let (temperature_c, precipitation) = (surface.temperature_c, surface.precipitation);
        let thunder = value(&|s| Some(s.thunder), 0.0);
        let east = value(&|s| s.wind_kt.map(|v| v[0]), 0.0);
        let north = value(&|s| s.wind_kt.map(|v| v[1]), 0.0);
        let wind = wind_from_velocity_kt(east, north);
        let reported = BlockWeather {
            layers: self.layers_at(point_m, surface),
            visibility_m: value(&|s| s.visibility_m, d.visibility_m) as f32,
            obscuration: self.obscuration_at(w),
            wind,
            temperature_c: temperature_c as f32,
            dewpoint_c: dewpoint_c as f32,
            precipitation: precipitation as f32,
            thunder: thunder as f32,
            ground_elevation_m: value(&|s| s.elevation_m, d.ground_elevation_m) as f32,
            cover: None,
        };
        match self.model_surface_at(point_m, w) {
            Some((model, s)) => blend::surface(reported, s, &model),
            None => reported,
        }
    }

    /// The model's weather at `point_m` and the surface stations' weight against it there, if
    /// the field has a model and the stations do not rule alone.
    fn model_surface_at(&self, point_m: DVec2, w: &Weights) -> Option<(BlockWeather, f64)> {
        let (model, settings) = self.model.as_ref()?;
        let s = self.report_weight(&self.surface, point_m, w);
        let (lat, lon) = self.frame.to_lat_lon_deg(point_m);
        (s < 1.0).then(|| (model.weather_at(lat, lon, settings), s))
    }

    /// The regional surface wind at a local point: the reported surface winds within
    /// `radius_m` averaged as vectors (knots east, north; `regional`); `None` where no station
    /// within the radius reports a wind. What the air's profile reaches at the top of the
    /// boundary layer ([`crate::weather::air::SurfaceAir::regional_wind_kt`]).
    pub fn regional_wind_kt(&self, point_m: DVec2, radius_m: f64) -> Option<DVec2> {
        self.regional.at(point_m, radius_m)
    }

    /// The gust excess (knots above the mean wind, interpolated over the stations that report a
    /// wind) and the QNH (hPa, over those that report one; `default_qnh_hpa` where none does) at
    /// a local point: what [`crate::weather::air::SurfaceAir`] needs beyond the block weather.
    pub fn gust_and_qnh_at(&self, point_m: DVec2, default_qnh_hpa: f64) -> (f64, f64) {
        self.gust_and_qnh_with(
            point_m,
            &weights(&self.surface, point_m, &self.settings.stations),
            default_qnh_hpa,
        )
    }

    fn gust_and_qnh_with(&self, point_m: DVec2, w: &Weights, default_qnh_hpa: f64) -> (f64, f64) {
        let gust = weighted(w, &self.samples, &|s| s.gust_excess_kt).unwrap_or(0.0);
        let qnh = weighted(w, &self.samples, &|s| s.qnh_hpa).unwrap_or(default_qnh_hpa);
        // Under a model: its sea-level pressure where the reports' weight fades.
        let Some((model, _)) = &self.model else {
            return (gust, qnh);
        };
        let s = self.report_weight(&self.surface, point_m, w);
        let (lat, lon) = self.frame.to_lat_lon_deg(point_m);
        // Gusts fade with the reports' weight (the model gives none here).
        match model.qnh_hpa_at(lat, lon) {
            Some(model_qnh) if s < 1.0 => (gust * s, qnh * s + model_qnh * (1.0 - s)),
            _ => (gust, qnh),
        }
    }

    fn layers_at(&self, point_m: DVec2, surface: layers::Surface) -> Vec<BlockLayer> {
        let w = weights(&self.clouds, point_m, &self.settings.stations);
        let reported = layers::blend(&w, &self.samples, &self.settings, &self.rule, surface);
        let Some((model, settings)) = &self.model else {
            return reported;
        };
        let s = self.report_weight(&self.clouds, point_m, &w);
        let (lat, lon) = self.frame.to_lat_lon_deg(point_m);
        let modelled = if s < 1.0 {
            model.layers_at(lat, lon, &settings.layers)
        } else {
            Vec::new()
        };
        blend::layers(reported, s, modelled)
    }

    /// The obscuration the neighbours reporting one carry the most weight for, if that weight
    /// reaches `convective.weight_min` (as a reported CB must).
    fn obscuration_at(&self, w: &Weights) -> Option<Obscuration> {
        let mut tally: Vec<(Obscuration, f64)> = Vec::new();
        for &(index, weight) in w {
            if let Some(o) = self.samples[index].obscuration {
                match tally.iter_mut().find(|(t, _)| *t == o) {
                    Some((_, total)) => *total += weight,
                    None => tally.push((o, weight)),
                }
            }
        }
        tally
            .into_iter()
            .max_by(|a, b| a.1.total_cmp(&b.1).then(a.0.rank().cmp(&b.0.rank())))
            .filter(|(_, weight)| *weight > 0.0 && *weight >= self.settings.convective.weight_min)
            .map(|(o, _)| o)
    }
}

/// The sample point of every block that holds a station: sky stations first, then any; of
/// several, the one nearest the block centre.
fn stations_in_blocks(cloud_sites: &[Site], surface_sites: &[Site]) -> HashMap<BlockIndex, DVec2> {
    let mut out: HashMap<BlockIndex, DVec2> = HashMap::new();
    for sites in [cloud_sites, surface_sites] {
        let mut these: HashMap<BlockIndex, DVec2> = HashMap::new();
        for site in sites {
            let p = DVec2::new(site.position.x, site.position.y);
            let block = BlockIndex::containing(p);
            if out.contains_key(&block) {
                continue;
            }
            let centre = block.centre_m();
            these
                .entry(block)
                .and_modify(|q| {
                    if p.distance_squared(centre) < q.distance_squared(centre) {
                        *q = p;
                    }
                })
                .or_insert(p);
        }
        out.extend(these);
    }
    out
}

/// The triangulation of the sites (bulk loaded; a site spade rejects is left out).
fn triangulate(sites: Vec<Site>) -> Tri {
    match Tri::bulk_load(sites.clone()) {
        Ok(tri) => tri,
        Err(_) => {
            let mut tri = Tri::new();
            for site in sites {
                let _ = tri.insert(site);
            }
            tri
        }
    }
}

/// Natural-neighbour weights at a point, each station's raised by its hold ([`StationHold`]:
/// near a station its report rules); the nearest station alone outside the hull.
fn weights(tri: &Tri, point_m: DVec2, hold: &StationHold) -> Weights {
    let p = Point2::new(point_m.x, point_m.y);
    let mut out = Vec::new();
    if tri.num_inner_faces() > 0 {
        let mut raw = Vec::new();
        tri.natural_neighbor().get_weights(p, &mut raw);
        let mut total = 0.0;
        for (h, w) in raw {
            let vertex = tri.vertex(h);
            let at = vertex.position();
            let raised = w * hold.raise_at((at.x - p.x).hypot(at.y - p.y));
            total += raised;
            out.push((vertex.data().index, raised));
        }
        if total > 0.0 {
            for (_, w) in &mut out {
                *w /= total;
            }
        }
    }
    if out.is_empty()
        && let Some(v) = tri.nearest_neighbor(p)
    {
        out.push((v.data().index, 1.0));
    }
    out
}

/// Weighted mean over the neighbours that report a value; `None` when none does.
fn weighted(
    w: &Weights,
    samples: &[StationSample],
    f: &dyn Fn(&StationSample) -> Option<f64>,
) -> Option<f64> {
    let (mut sum, mut total) = (0.0, 0.0);
    for &(index, weight) in w {
        if let Some(v) = f(&samples[index]) {
            sum += weight * v;
            total += weight;
        }
    }
    (total > 0.0).then(|| sum / total)
}

/// The wind blowing with this velocity (knots east/north).
fn wind_from_velocity_kt(east: f64, north: f64) -> Wind {
    let speed_kt = east.hypot(north);
    if speed_kt < 1e-9 {
        return Wind::default();
    }
    let from_deg = (east.atan2(north).to_degrees() + 180.0).rem_euclid(360.0);
    Wind {
        from_deg: from_deg as f32,
        speed_kt: speed_kt as f32,
    }
}
