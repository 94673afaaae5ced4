//! The rows of the screen where the ring pass can show anything, no GPU. The ring's far clouds
//! lie in a narrow band of elevations seen from its centre (clouds 20 km and more away, within
//! a few kilometres of the camera's height): outside it every lookup of the impostors finds
//! nothing, and the full-screen pass blended zero there. The pass keeps its full-screen
//! triangle (the same rays to the bit, so the same pixels) under a scissor of the rows that band
//! crosses. Units: metres, radians above the level plane.

use glam::{DVec2, DVec3, Mat4, Vec4};

use super::layout::IMPOSTOR_FOV_Y_DEG;

/// Radians the band is widened by on each side, besides two impostor texels (the bilinear
/// lookup's reach).
const MARGIN_RAD: f64 = 0.005;

/// The screen is searched for the band on a grid of this many cells down and across.
const GRID: (u32, u32) = (48, 16);

/// Metres added to a cloud's radius: the drift of its block while its impostor waits to be
/// rendered, and a sprite's corner past its sphere.
const CLOUD_MARGIN_M: f64 = 200.0;

/// An Earth radius below the smallest the sky flies over: the curvature's drop of a far cloud
/// in the impostor renders taken as larger than it is.
const DROP_RADIUS_M: f64 = 6.0e6;

/// The elevations from the ring centre (lowest first) of a cloud whose sprites lie within
/// `radius_m` of `rel_m` (its centre relative to the ring centre), drawn on the round Earth.
pub fn cloud_elevations_rad(rel_m: DVec3, radius_m: f64) -> (f64, f64) {
    let r = widened_m(radius_m);
    let d = rel_m.truncate().length();
    let (near, far) = ((d - r).max(0.0), d + r);
    let top = rel_m.z + r;
    let bottom = rel_m.z - r - far * far / (2.0 * DROP_RADIUS_M);
    (
        bottom.atan2(if bottom >= 0.0 { far } else { near }),
        top.atan2(if top >= 0.0 { near } else { far }),
    )
}

/// The radius [`cloud_elevations_rad`] takes a cloud of radius `radius_m` to reach: a turned
/// sprite's corner reaches past the sphere of its half side, and the margin.
pub fn widened_m(radius_m: f64) -> f64 {
    radius_m * std::f64::consts::SQRT_2 + CLOUD_MARGIN_M
}

/// Elevations no cloud inside a box reaches beyond (lowest first): for every cloud whose
/// sphere widened by [`widened_m`] lies within `lo_m..=hi_m` (relative to the ring centre), its
/// [`cloud_elevations_rad`] lie within them. The box's top over its nearest reach across the
/// ground, its bottom less the drop at its farthest reach over its nearest or its farthest (as
/// the cloud's own are taken), each the extreme of every sphere inside it.
pub fn box_elevations_rad(lo_m: DVec3, hi_m: DVec3) -> (f64, f64) {
    let nearest = |lo: f64, hi: f64| {
        if lo > 0.0 {
            lo
        } else if hi < 0.0 {
            -hi
        } else {
            0.0
        }
    };
    let near = DVec2::new(nearest(lo_m.x, hi_m.x), nearest(lo_m.y, hi_m.y)).length();
    let far = DVec2::new(
        lo_m.x.abs().max(hi_m.x.abs()),
        lo_m.y.abs().max(hi_m.y.abs()),
    )
    .length();
    let top = hi_m.z;
    let bottom = lo_m.z - far * far / (2.0 * DROP_RADIUS_M);
    (
        bottom.atan2(if bottom >= 0.0 { far } else { near }),
        top.atan2(if top >= 0.0 { near } else { far }),
    )
}

/// The band of elevations above the camera's level plane (lowest first) where the ring pass
/// can show a cloud this frame. `content_rad`: the elevations of the ring's clouds from its
/// centre ([`cloud_elevations_rad`] over them); `offset_m`: the camera relative to the centre;
/// the pass looks the impostors up at `radius_m` or more from the centre along each ray;
/// `size_px`: an impostor's side.
pub fn ring_band_rad(
    content_rad: (f64, f64),
    offset_m: DVec3,
    radius_m: f64,
    size_px: u32,
) -> (f64, f64) {
    let texel_rad = IMPOSTOR_FOV_Y_DEG.to_radians() / f64::from(size_px.max(1));
    let margin = MARGIN_RAD + 2.0 * texel_rad;
    let (lo, hi) = (content_rad.0 - margin, content_rad.1 + margin);
    let across = offset_m.truncate().length();
    // A point `s` from the centre at elevation `e` from it, seen from the camera: the
    // elevation grows with `e` (the camera is inside the sphere) and moves one way with `s`,
    // so its extremes are at the ends of both, with the camera at either end of its
    // horizontal offset.
    let seen = |e: f64, s: f64, side: f64| {
        let (sin, cos) = e.sin_cos();
        (s * sin - offset_m.z).atan2((s * cos + side * across).max(0.0))
    };
    let ends = |e: f64| [e, seen(e, radius_m, -1.0), seen(e, radius_m, 1.0)];
    let low = ends(lo).into_iter().fold(f64::MAX, f64::min);
    let high = ends(hi).into_iter().fold(f64::MIN, f64::max);
    (low, high.max(low))
}

/// [`ScreenGrid::rows_ndc`] on a grid made for `inv_view_proj` alone (a ring keeps its grid
/// from frame to frame).
#[cfg(test)]
pub fn screen_rows_ndc(band_rad: (f64, f64), inv_view_proj: Mat4) -> Option<(f32, f32)> {
    let mut grid = ScreenGrid::default();
    grid.aim(inv_view_proj);
    grid.rows_ndc(band_rad)
}

/// The grid the rows of the screen a band crosses are searched on, for one camera-relative
/// clip-to-world matrix: its rays, their elevations as cells ask for them, and what each row's
/// shortcut reads. A camera that moves without turning keeps its matrix (it is relative to the
/// eye), and a frame then only compares the band with each row's reach (the grid's 833 rays and
/// their rows' chords took more of the ring's prepare than its sorting on the approach's
/// profile).
#[derive(Debug, Clone, Default)]
pub struct ScreenGrid {
    /// The matrix's bits (none yet: empty).
    key: Option<[u32; 16]>,
    /// Each grid point's ray, row after row.
    rays: Vec<DVec3>,
    /// Each grid point's ray's elevation, once a cell asked for it.
    elevations: Vec<Option<f64>>,
    /// Per row of cells: the elevations no cell of it can reach below and above
    /// ([`row_reach`]); `None` where that shortcut does not hold.
    reach: Vec<Option<(f64, f64)>>,
}

impl ScreenGrid {
    /// Points the grid along `inv_view_proj`: made again only if it differs from the last to
    /// the bit.
    pub fn aim(&mut self, inv_view_proj: Mat4) {
        let key = inv_view_proj.to_cols_array().map(f32::to_bits);
        if self.key == Some(key) {
            return;
        }
        self.key = Some(key);
        let (rows, cols) = GRID;
        let ray = |x: f32, y: f32| {
            let far = inv_view_proj * Vec4::new(x, y, 0.5, 1.0);
            (far.truncate() / far.w).as_dvec3().normalize_or_zero()
        };
        let side = cols as usize + 1;
        self.rays.clear();
        self.rays.extend(
            (0..=rows).flat_map(|j| (0..=cols).map(move |i| ray(ndc(i, cols), ndc(j, rows)))),
        );
        self.elevations.clear();
        self.elevations.resize(self.rays.len(), None);
        self.reach.clear();
        let rays = &self.rays;
        (self.reach)
            .extend((0..rows as usize).map(|j| row_reach(&rays[j * side..(j + 2) * side], side)));
    }

    /// The rows of the screen the band of elevations `band_rad` crosses, as normalised device
    /// y (lowest first), under the matrix last aimed at; `None` when it crosses none. A cell is
    /// kept when the elevations of its corners, widened by half its diagonal (no ray in it is
    /// farther from a corner), meet the band. A grid never aimed crosses no row.
    pub fn rows_ndc(&mut self, band_rad: (f64, f64)) -> Option<(f32, f32)> {
        self.key?;
        let (rows, cols) = GRID;
        let side = cols as usize + 1;
        let mut found: Option<(f32, f32)> = None;
        for j in 0..rows as usize {
            if let Some(Some((low, high))) = self.reach.get(j)
                && (*low > band_rad.1 || *high < band_rad.0)
            {
                continue;
            }
            let (rays, elevations) = (&self.rays, &mut self.elevations);
            let mut corner = |k: usize| -> Corner {
                let r = rays[k];
                (r, *elevations[k].get_or_insert_with(|| elevation(r.z)))
            };
            // One cell of a row that meets the band is enough: the row is in.
            let meets = (0..side - 1).any(|i| {
                let at = j * side + i;
                let c = [
                    corner(at),
                    corner(at + 1),
                    corner(at + side),
                    corner(at + side + 1),
                ];
                cell_meets(band_rad, c)
            });
            if meets {
                let (y0, y1) = (ndc(j as u32, rows), ndc(j as u32 + 1, rows));
                found = Some(found.map_or((y0, y1), |(a, b)| (a.min(y0), b.max(y1))));
            }
        }
        found
    }
}

/// Grid line `k` of `n` as normalised device coordinates.
fn ndc(k: u32, n: u32) -> f32 {
    -1.0 + 2.0 * k as f32 / n as f32
}

/// The elevation of a unit ray whose up component is `z`, radians.
fn elevation(z: f64) -> f64 {
    z.clamp(-1.0, 1.0).asin()
}

/// The elevations below and above which no cell of a row of [`ScreenGrid`]'s grid can
/// meet a band, told from the row's lowest and highest ray and its longest diagonal chord alone
/// (two arc sines a row, not one a point): a band wholly outside them fails [`cell_meets`] for
/// each of the row's cells, each of which lies within those elevations and has a diagonal within
/// that bound (a billionth of a radian more against the arc sine's rounding). `None` where a
/// ray is not of unit length (no shortcut). `points`: the row's two lines of `side` unit rays.
fn row_reach(points: &[DVec3], side: usize) -> Option<(f64, f64)> {
    let unit = |r: &DVec3| r.is_finite() && (r.length_squared() - 1.0).abs() < 1e-12;
    if !points.iter().all(unit) {
        return None;
    }
    let lowest = elevation(points.iter().map(|r| r.z).fold(f64::MAX, f64::min));
    let highest = elevation(points.iter().map(|r| r.z).fold(f64::MIN, f64::max));
    let chord = (0..side - 1)
        .map(|i| {
            let (sw, se, nw, ne) = (
                points[i],
                points[i + 1],
                points[side + i],
                points[side + i + 1],
            );
            (sw - ne).length().max((se - nw).length())
        })
        .fold(0.0, f64::max);
    let half = 0.5 * diagonal_bound(chord) + 1e-9;
    Some((lowest - half, highest + half))
}

/// At least the angle between two unit rays `chord` apart (pi/2 times the chord), with a margin
/// for the arc cosine's rounding near 0.
fn diagonal_bound(chord: f64) -> f64 {
    chord * std::f64::consts::FRAC_PI_2 * (1.0 + 1e-9) + 1e-6
}

/// A grid point of a [`ScreenGrid`]: its ray (unit, or zero) and the ray's elevation.
type Corner = (DVec3, f64);

/// Whether a cell of [`ScreenGrid`]'s grid, corners (south-west, south-east, north-west,
/// north-east) `c`, meets the band: the elevations of its corners widened by half its diagonal
/// (the larger angle between opposite corners) reach it. The diagonal (two arc cosines, most of
/// the search's time) is asked only where the answer depends on it: the corners' elevations
/// alone reaching the band meet it (the diagonal only widens them), and where even a bound on
/// the diagonal leaves them short they do not (between unit rays it is at most pi/2 times
/// their chord, plus a margin for the arc cosine's rounding near 0). The same answer as
/// widening every cell by its diagonal.
fn cell_meets(band_rad: (f64, f64), c: [Corner; 4]) -> bool {
    let lowest = c.iter().map(|c| c.1).fold(f64::MAX, f64::min);
    let highest = c.iter().map(|c| c.1).fold(f64::MIN, f64::max);
    let widened = |half_diagonal: f64| {
        lowest - half_diagonal <= band_rad.1 && highest + half_diagonal >= band_rad.0
    };
    let exact = || {
        widened(
            0.5 * c[0]
                .0
                .angle_between(c[3].0)
                .max(c[1].0.angle_between(c[2].0)),
        )
    };
    // The shortcuts hold for unit rays (a zero ray's diagonal is not a number: no shortcut).
    let unit = c
        .iter()
        .all(|c| c.0.is_finite() && (c.0.length_squared() - 1.0).abs() < 1e-12);
    if !unit {
        return exact();
    }
    if widened(0.0) {
        return true;
    }
    let chord = (c[0].0 - c[3].0).length().max((c[1].0 - c[2].0).length());
    if !widened(0.5 * diagonal_bound(chord)) {
        return false;
    }
    exact()
}

/// The band that holds both `a` and `b`.
pub fn union(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    (a.0.min(b.0), a.1.max(b.1))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Elevation of `p` seen from `from`.
    fn elevation(p: DVec3, from: DVec3) -> f64 {
        let v = p - from;
        v.z.atan2(v.truncate().length())
    }

    #[test]
    fn every_lookup_that_can_find_a_cloud_is_inside_the_band() {
        let radius_m = 20_000.0;
        // A deck 1.3 km below the centre and a heap 2 km above it, 21 to 60 km off.
        let clouds = [
            (DVec3::new(21_000.0, 3_000.0, -1_300.0), 800.0),
            (DVec3::new(-40_000.0, 45_000.0, 2_000.0), 1_500.0),
        ];
        let content = clouds
            .iter()
            .map(|&(c, r)| cloud_elevations_rad(c, r))
            .reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)))
            .unwrap();
        for offset in [
            DVec3::ZERO,
            DVec3::new(2_900.0, 0.0, 390.0),
            DVec3::new(-2_000.0, 2_000.0, -390.0),
        ] {
            let (lo, hi) = ring_band_rad(content, offset, radius_m, 256);
            // Points at the cloud's elevations from the centre, at the ring radius and beyond,
            // seen from the camera.
            for &(c, r) in &clouds {
                let (a, b) = cloud_elevations_rad(c, r);
                for e in [a, b] {
                    for s in [radius_m, 30_000.0, 100_000.0, 1.0e7] {
                        for az in 0..32 {
                            let az = f64::from(az) * std::f64::consts::TAU / 32.0;
                            let p = DVec3::new(az.cos() * e.cos(), az.sin() * e.cos(), e.sin());
                            let seen = elevation(p * s, offset);
                            assert!(lo <= seen && seen <= hi, "{seen} not in {lo}..{hi}");
                        }
                    }
                }
            }
            assert!(hi - lo < 0.5, "a narrow band: {lo}..{hi}");
        }
    }

    #[test]
    fn a_cloud_is_within_its_elevations() {
        let c = DVec3::new(25_000.0, 0.0, -1_000.0);
        let (lo, hi) = cloud_elevations_rad(c, 500.0);
        for p in [
            c,
            c + DVec3::Z * 500.0,
            c - DVec3::Z * 500.0,
            c + DVec3::X * 500.0,
        ] {
            let e = elevation(p, DVec3::ZERO);
            assert!(lo < e && e < hi);
        }
    }

    #[test]
    fn the_rows_hold_every_pixel_of_the_band() {
        // 60 degrees high, 16:9, pitched down 3 degrees, heading east.
        let camera = crate::render::camera::Camera {
            position_m: DVec3::ZERO,
            heading_deg: 90.0,
            pitch_deg: -3.0,
            fov_y_deg: 60.0,
            aspect: 16.0 / 9.0,
            near_m: 2.0,
            far_m: 160_000.0,
        };
        let inv = camera.view_proj_relative().inverse();
        let band = (-0.06, 0.04);
        let (y0, y1) = screen_rows_ndc(band, inv).unwrap();
        assert!(y1 - y0 < 0.6, "a strip: {y0}..{y1}");
        for j in 0..=360 {
            for i in 0..=64 {
                let (x, y) = (-1.0 + i as f32 / 32.0, -1.0 + j as f32 / 180.0);
                let far = inv * Vec4::new(x, y, 0.5, 1.0);
                let dir = (far.truncate() / far.w).as_dvec3().normalize();
                let e = dir.z.asin();
                if band.0 <= e && e <= band.1 {
                    assert!(
                        y0 <= y && y <= y1,
                        "{y} of elevation {e} outside {y0}..{y1}"
                    );
                }
            }
        }
        // Straight up: no row.
        assert_eq!(screen_rows_ndc((1.2, 1.3), inv), None);
        assert_eq!(union((0.0, 0.1), (-0.2, 0.05)), (-0.2, 0.1));
    }

    /// [`screen_rows_ndc`] as it was written first: every cell widened by its diagonal.
    fn rows_every_cell(band_rad: (f64, f64), inv_view_proj: Mat4) -> Option<(f32, f32)> {
        let (rows, cols) = GRID;
        let ray = |x: f32, y: f32| {
            let far = inv_view_proj * Vec4::new(x, y, 0.5, 1.0);
            (far.truncate() / far.w).as_dvec3().normalize_or_zero()
        };
        let ndc = |k: u32, n: u32| -1.0 + 2.0 * k as f32 / n as f32;
        let grid: Vec<Vec<DVec3>> = (0..=rows)
            .map(|j| {
                (0..=cols)
                    .map(|i| ray(ndc(i, cols), ndc(j, rows)))
                    .collect()
            })
            .collect();
        let mut found: Option<(f32, f32)> = None;
        for j in 0..rows as usize {
            for i in 0..cols as usize {
                let corners = [
                    grid[j][i],
                    grid[j][i + 1],
                    grid[j + 1][i],
                    grid[j + 1][i + 1],
                ];
                let diagonal = corners[0]
                    .angle_between(corners[3])
                    .max(corners[1].angle_between(corners[2]));
                let elevations = corners.map(|c| c.z.clamp(-1.0, 1.0).asin());
                let low = elevations.iter().copied().fold(f64::MAX, f64::min) - 0.5 * diagonal;
                let high = elevations.iter().copied().fold(f64::MIN, f64::max) + 0.5 * diagonal;
                if low <= band_rad.1 && high >= band_rad.0 {
                    let (y0, y1) = (ndc(j as u32, rows), ndc(j as u32 + 1, rows));
                    found = Some(found.map_or((y0, y1), |(a, b)| (a.min(y0), b.max(y1))));
                }
            }
        }
        found
    }

    /// The search that asks a cell's diagonal only where the answer depends on it finds the
    /// rows of widening every cell, to the bit, over pitches, headings, fields of view and
    /// bands (narrow, wide, at a cell's edge, out of view).
    #[test]
    fn the_rows_are_those_of_widening_every_cell() {
        let mut checked = 0;
        // One grid aimed at each camera in turn, as a ring keeps it: the same rows.
        let mut kept = ScreenGrid::default();
        assert_eq!(kept.rows_ndc((-0.1, 0.1)), None, "a grid never aimed");
        for pitch in [-89.0, -30.0, -3.0, 0.0, 2.5, 12.0, 45.0, 89.0] {
            for heading in [0.0, 37.0, 90.0, 211.0] {
                for (fov, aspect) in [(60.0, 16.0 / 9.0), (30.0, 1.0), (90.0, 2.4)] {
                    let camera = crate::render::camera::Camera {
                        position_m: DVec3::ZERO,
                        heading_deg: heading,
                        pitch_deg: pitch,
                        fov_y_deg: fov,
                        aspect,
                        near_m: 2.0,
                        far_m: 160_000.0,
                    };
                    let inv = camera.view_proj_relative().inverse();
                    kept.aim(inv);
                    for k in 0..40 {
                        let lo = -0.8 + 0.04 * f64::from(k) + 0.0013 * f64::from(k % 7);
                        for width in [0.0, 0.001, 0.02, 0.1, 0.5] {
                            let band = (lo, lo + width);
                            let expected = rows_every_cell(band, inv);
                            assert_eq!(
                                screen_rows_ndc(band, inv),
                                expected,
                                "pitch {pitch} heading {heading} fov {fov} band {band:?}"
                            );
                            assert_eq!(kept.rows_ndc(band), expected, "kept grid");
                            checked += 1;
                        }
                    }
                }
            }
        }
        assert_eq!(checked, 8 * 4 * 3 * 40 * 5);
    }
}
