//! The local frame: latitude/longitude (degrees, f64) to metres east/north around a reference
//! point, and back.
//!
//! Projection: azimuthal equidistant on a sphere of the WGS84 mean radius (R1 = 6,371,008.8 m),
//! centred on the reference. At the reference it is the east-north-up tangent plane; distances
//! and bearings from the reference are exact on the sphere at any range, and distortion grows
//! slowly away from it (1% scale error across the direction of travel at about 1,600 km). Every
//! point except the reference's antipode maps to a unique point inside a disc of radius pi R, so
//! stations worldwide can be triangulated in one frame. Blocks ([`BlockIndex`]) are 4,000 m
//! squares of this plane.

use glam::DVec2;

use super::block::BlockIndex;

/// WGS84 mean radius R1 = (2a + b) / 3, metres.
pub const EARTH_MEAN_RADIUS_M: f64 = 6_371_008.8;

/// An east-north-up frame around a reference latitude/longitude.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalFrame {
    /// Reference latitude, degrees north.
    pub reference_lat_deg: f64,
    /// Reference longitude, degrees east.
    pub reference_lon_deg: f64,
    sin_lat0: f64,
    cos_lat0: f64,
}

impl LocalFrame {
    /// The frame around this reference point (latitude clamped to +-90, longitude wrapped).
    pub fn new(reference_lat_deg: f64, reference_lon_deg: f64) -> Self {
        let lat = reference_lat_deg.clamp(-90.0, 90.0);
        let (sin_lat0, cos_lat0) = lat.to_radians().sin_cos();
        Self {
            reference_lat_deg: lat,
            reference_lon_deg: wrap_lon_deg(reference_lon_deg),
            sin_lat0,
            cos_lat0,
        }
    }

    /// Metres east (x) and north (y) of the reference.
    pub fn to_local_m(&self, lat_deg: f64, lon_deg: f64) -> DVec2 {
        let (sin_lat, cos_lat) = lat_deg.to_radians().sin_cos();
        let (sin_dlon, cos_dlon) = (lon_deg - self.reference_lon_deg).to_radians().sin_cos();
        // Direction of the great circle from the reference (unnormalised east/north) and the
        // cosine of the angular distance.
        let east = cos_lat * sin_dlon;
        let north = self.cos_lat0 * sin_lat - self.sin_lat0 * cos_lat * cos_dlon;
        let cos_c = self.sin_lat0 * sin_lat + self.cos_lat0 * cos_lat * cos_dlon;
        let sin_c = east.hypot(north);
        if sin_c == 0.0 {
            // The reference itself, or its antipode (every direction at once: put it due south).
            return if cos_c > 0.0 {
                DVec2::ZERO
            } else {
                DVec2::new(0.0, -std::f64::consts::PI * EARTH_MEAN_RADIUS_M)
            };
        }
        let c = sin_c.atan2(cos_c);
        DVec2::new(east, north) * (EARTH_MEAN_RADIUS_M * c / sin_c)
    }

    /// Latitude and longitude, degrees, of a local point (metres east, north).
    pub fn to_lat_lon_deg(&self, point_m: DVec2) -> (f64, f64) {
        let rho = point_m.length();
        if rho == 0.0 {
            return (self.reference_lat_deg, self.reference_lon_deg);
        }
        let c = rho / EARTH_MEAN_RADIUS_M;
        let (sin_c, cos_c) = c.sin_cos();
        let sin_lat =
            (cos_c * self.sin_lat0 + point_m.y * sin_c * self.cos_lat0 / rho).clamp(-1.0, 1.0);
        let lon = (point_m.x * sin_c)
            .atan2(rho * self.cos_lat0 * cos_c - point_m.y * self.sin_lat0 * sin_c);
        (
            sin_lat.asin().to_degrees(),
            wrap_lon_deg(self.reference_lon_deg + lon.to_degrees()),
        )
    }

    /// The block containing a latitude/longitude.
    pub fn block_of(&self, lat_deg: f64, lon_deg: f64) -> BlockIndex {
        BlockIndex::containing(self.to_local_m(lat_deg, lon_deg))
    }
}

/// Longitude wrapped into [-180, 180).
fn wrap_lon_deg(lon_deg: f64) -> f64 {
    if (-180.0..180.0).contains(&lon_deg) {
        return lon_deg;
    }
    (lon_deg + 180.0).rem_euclid(360.0) - 180.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Great-circle distance on the same sphere (haversine), metres.
    fn haversine_m(a: (f64, f64), b: (f64, f64)) -> f64 {
        let (la1, lo1) = (a.0.to_radians(), a.1.to_radians());
        let (la2, lo2) = (b.0.to_radians(), b.1.to_radians());
        let h = ((la2 - la1) / 2.0).sin().powi(2)
            + la1.cos() * la2.cos() * ((lo2 - lo1) / 2.0).sin().powi(2);
        2.0 * EARTH_MEAN_RADIUS_M * h.sqrt().asin()
    }

    #[test]
    fn one_minute_of_latitude_north_is_one_nautical_mile_ish() {
        let f = LocalFrame::new(51.4775, -0.4614);
        let p = f.to_local_m(51.4775 + 1.0 / 60.0, -0.4614);
        assert!(p.x.abs() < 1e-6);
        // R * pi / 10800 = 1853.25 m on the mean sphere.
        assert!((p.y - 1853.25).abs() < 0.01, "{p}");
    }

    #[test]
    fn distance_from_the_reference_is_the_great_circle_distance() {
        // Heathrow to JFK: 5,539 km on the mean sphere.
        let egll = (51.4775, -0.4614);
        let kjfk = (40.6398, -73.7789);
        let f = LocalFrame::new(egll.0, egll.1);
        let p = f.to_local_m(kjfk.0, kjfk.1);
        let d = haversine_m(egll, kjfk);
        assert!((p.length() - d).abs() < 1e-3, "{} vs {d}", p.length());
        assert!((d - 5_539_000.0).abs() < 2_000.0, "{d}");
        // JFK lies west and a little south-ish of Heathrow on the initial bearing (about 288 deg).
        let bearing = p.x.atan2(p.y).to_degrees().rem_euclid(360.0);
        assert!((bearing - 288.3).abs() < 1.0, "{bearing}");
    }

    #[test]
    fn round_trip_near_and_far_and_across_the_date_line() {
        let f = LocalFrame::new(47.0, 179.5);
        for &(lat, lon) in &[
            (47.0, 179.5),
            (47.01, 179.49),
            (46.0, -179.0),
            (-33.9, 151.2),
            (89.9, 10.0),
            (-60.0, -60.0),
        ] {
            let p = f.to_local_m(lat, lon);
            let (lat2, lon2) = f.to_lat_lon_deg(p);
            assert!((lat - lat2).abs() < 1e-9, "{lat} {lat2}");
            assert!((wrap_lon_deg(lon - lon2)).abs() < 1e-9, "{lon} {lon2}");
        }
        // The antipode is pi R away, not at the origin.
        let antipode = LocalFrame::new(10.0, 20.0).to_local_m(-10.0, -160.0);
        assert!((antipode.length() - std::f64::consts::PI * EARTH_MEAN_RADIUS_M).abs() < 1.0);
        // Across the date line 1 degree of longitude east is about 76 km east, not 40,000 km west.
        let p = f.to_local_m(47.0, -179.5);
        assert!(p.x > 75_000.0 && p.x < 77_000.0, "{p}");
    }

    #[test]
    fn near_the_reference_it_is_the_tangent_plane() {
        let f = LocalFrame::new(40.0, -100.0);
        // 0.01 degree east at 40 N: R cos(40) * 0.01 * pi / 180.
        let p = f.to_local_m(40.0, -99.99);
        let expect = EARTH_MEAN_RADIUS_M * 40f64.to_radians().cos() * 0.01f64.to_radians();
        assert!(
            (p.x - expect).abs() < 0.01 && p.y.abs() < 0.1,
            "{p} {expect}"
        );
        assert_eq!(f.block_of(40.0, -100.0), BlockIndex::new(0, 0));
        assert_eq!(f.block_of(40.0, -99.99), BlockIndex::new(0, 0));
        assert_eq!(f.block_of(39.99, -100.01), BlockIndex::new(-1, -1));
    }
}
