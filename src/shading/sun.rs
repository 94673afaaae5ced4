//! Solar position from a UTC instant and a latitude/longitude: the NOAA solar calculator's
//! algorithm (after Meeus, "Astronomical Algorithms", ch. 25), good to about 0.01 degree.
//!
//! In: Unix seconds (UTC), latitude and longitude in degrees (east positive). Out: elevation
//! (degrees above the horizon, geometric, no refraction) and azimuth (degrees clockwise from
//! true north), and the sun direction as an east-north-up unit vector.

use glam::DVec3;

/// Where the sun stands for an observer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SunPosition {
    /// Degrees above the horizon (negative at night), geometric.
    pub elevation_deg: f64,
    /// Degrees clockwise from true north, 0..360.
    pub azimuth_deg: f64,
    /// Solar declination, degrees.
    pub declination_deg: f64,
}

impl SunPosition {
    /// Unit vector towards the sun in the local east-north-up frame.
    pub fn direction_enu(&self) -> DVec3 {
        let el = self.elevation_deg.to_radians();
        let az = self.azimuth_deg.to_radians();
        DVec3::new(el.cos() * az.sin(), el.cos() * az.cos(), el.sin())
    }
}

/// The sun's position at `unix_s` (seconds since 1970-01-01 UTC) seen from `lat_deg`, `lon_deg`.
pub fn sun_position(unix_s: f64, lat_deg: f64, lon_deg: f64) -> SunPosition {
    let jd = unix_s / 86_400.0 + 2_440_587.5;
    let t = (jd - 2_451_545.0) / 36_525.0; // Julian centuries since J2000.0

    let l0 = (280.466_46 + t * (36_000.769_83 + t * 0.000_303_2)).rem_euclid(360.0);
    let m = 357.529_11 + t * (35_999.050_29 - 0.000_153_7 * t);
    let e = 0.016_708_634 - t * (0.000_042_037 + 0.000_000_126_7 * t);
    let mr = m.to_radians();
    let c = mr.sin() * (1.914_602 - t * (0.004_817 + 0.000_014 * t))
        + (2.0 * mr).sin() * (0.019_993 - 0.000_101 * t)
        + (3.0 * mr).sin() * 0.000_289;
    let true_long = l0 + c;
    let omega = 125.04 - 1_934.136 * t;
    let app_long = true_long - 0.005_69 - 0.004_78 * omega.to_radians().sin();
    let eps0 =
        23.0 + (26.0 + (21.448 - t * (46.815 + t * (0.000_59 - t * 0.001_813))) / 60.0) / 60.0;
    let eps = eps0 + 0.002_56 * omega.to_radians().cos();
    let er = eps.to_radians();
    let decl = (er.sin() * app_long.to_radians().sin()).asin();

    // Equation of time, minutes.
    let y = (er / 2.0).tan().powi(2);
    let l0r = l0.to_radians();
    let eot_min = 4.0
        * (y * (2.0 * l0r).sin() - 2.0 * e * mr.sin() + 4.0 * e * y * mr.sin() * (2.0 * l0r).cos()
            - 0.5 * y * y * (4.0 * l0r).sin()
            - 1.25 * e * e * (2.0 * mr).sin())
        .to_degrees();

    let minutes_utc = (unix_s / 60.0).rem_euclid(1_440.0);
    let true_solar_min = (minutes_utc + eot_min + 4.0 * lon_deg).rem_euclid(1_440.0);
    let hour_angle = (true_solar_min / 4.0 - 180.0).to_radians();

    let lat = lat_deg.to_radians();
    let cos_zen =
        (lat.sin() * decl.sin() + lat.cos() * decl.cos() * hour_angle.cos()).clamp(-1.0, 1.0);
    let zenith = cos_zen.acos();
    let elevation_deg = 90.0 - zenith.to_degrees();
    // Azimuth from north, clockwise: atan2 of the east and north components.
    let east = -decl.cos() * hour_angle.sin();
    let north = decl.sin() * lat.cos() - decl.cos() * lat.sin() * hour_angle.cos();
    let azimuth_deg = east.atan2(north).to_degrees().rem_euclid(360.0);
    SunPosition {
        elevation_deg,
        azimuth_deg,
        declination_deg: decl.to_degrees(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Unix seconds of a UTC date and time (tests only; the CLI parses RFC 3339 with jiff).
    fn utc(y: i64, mo: i64, d: i64, h: f64) -> f64 {
        // Days from civil (Howard Hinnant's algorithm).
        let y = if mo <= 2 { y - 1 } else { y };
        let era = y.div_euclid(400);
        let yoe = y - era * 400;
        let mp = (mo + 9) % 12;
        let doy = (153 * mp + 2) / 5 + d - 1;
        let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
        let days = era * 146_097 + doe - 719_468;
        days as f64 * 86_400.0 + h * 3_600.0
    }

    #[test]
    fn solstice_noon_at_greenwich_stands_at_62_degrees_due_south() {
        // Solar noon at Greenwich on 2024-06-21 is 12:01:42 UTC (NOAA calculator); elevation is
        // 90 - 51.4779 + 23.4384 = 61.96 degrees.
        let s = sun_position(utc(2024, 6, 21, 12.0 + 1.7 / 60.0), 51.4779, 0.0);
        assert!((s.elevation_deg - 61.96).abs() < 0.05, "{s:?}");
        assert!((s.azimuth_deg - 180.0).abs() < 0.5, "{s:?}");
        assert!((s.declination_deg - 23.438).abs() < 0.01, "{s:?}");
    }

    #[test]
    fn equinox_sun_rises_in_the_east_and_declination_is_near_zero() {
        // 2024-03-20, equator, lon 0: equation of time is -7.5 min, so the sun crosses the
        // horizon at about 06:07:30 UTC, due east.
        let s = sun_position(utc(2024, 3, 20, 6.0 + 7.5 / 60.0), 0.0, 0.0);
        assert!(s.elevation_deg.abs() < 0.3, "{s:?}");
        assert!((s.azimuth_deg - 90.0).abs() < 0.5, "{s:?}");
        assert!(s.declination_deg.abs() < 0.1, "{s:?}");
    }

    #[test]
    fn longitude_shifts_the_sun_four_minutes_a_degree() {
        // Denver (104.99 W) sees at 19:00 UTC roughly what Greenwich-longitude sees at 12:00.
        let denver = sun_position(utc(2026, 11, 22, 12.0 + 104.99 / 15.0), 39.74, -104.99);
        let same_lon0 = sun_position(utc(2026, 11, 22, 12.0), 39.74, 0.0);
        // Seven hours later the declination has moved about 0.1 degree.
        assert!((denver.elevation_deg - same_lon0.elevation_deg).abs() < 0.15);
        // Late November, noon at 39.74 N: 90 - 39.74 - 20.2 = about 30 degrees.
        assert!((denver.elevation_deg - 30.0).abs() < 1.0, "{denver:?}");
    }

    #[test]
    fn midnight_sun_in_the_arctic_summer_and_night_in_winter() {
        let summer = sun_position(utc(2024, 6, 21, 0.0), 80.0, 0.0);
        assert!(summer.elevation_deg > 2.0, "{summer:?}");
        assert!((summer.azimuth_deg - 0.0).abs() < 1.0 || summer.azimuth_deg > 359.0);
        let winter = sun_position(utc(2024, 12, 21, 12.0), 80.0, 0.0);
        assert!(winter.elevation_deg < -3.0, "{winter:?}");
    }

    #[test]
    fn direction_is_a_unit_vector_matching_elevation_and_azimuth() {
        let s = SunPosition {
            elevation_deg: 30.0,
            azimuth_deg: 90.0,
            declination_deg: 0.0,
        };
        let d = s.direction_enu();
        assert!((d.length() - 1.0).abs() < 1e-12);
        assert!((d.x - 30f64.to_radians().cos()).abs() < 1e-12 && d.y.abs() < 1e-12);
        assert!((d.z - 0.5).abs() < 1e-12);
    }
}
