//! The camera a frame is drawn from: a position in the local east-north-up frame (f64 metres,
//! z up, metres above mean sea level), heading and pitch in degrees, and the projection.
//!
//! Everything sent to the GPU is relative to the camera: [`Camera::view_proj_relative`] maps
//! `world - position_m` (as f32) to clip space, so nothing jitters far from the origin.
//! Depth is the standard WebGPU `[0, 1]` range, near plane at 0.

use glam::{DVec3, Mat4, Vec3, Vec4};

/// A camera in the local east-north-up frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Position, metres east, north and above mean sea level.
    pub position_m: DVec3,
    /// Heading, degrees clockwise from true north.
    pub heading_deg: f64,
    /// Pitch, degrees above the horizon (negative looks down).
    pub pitch_deg: f64,
    /// Vertical field of view, degrees.
    pub fov_y_deg: f32,
    /// Width / height of the image.
    pub aspect: f32,
    /// Near clip plane, metres.
    pub near_m: f32,
    /// Far clip plane, metres.
    pub far_m: f32,
}

impl Camera {
    /// Unit vector the camera looks along (east-north-up).
    pub fn forward(&self) -> DVec3 {
        let h = self.heading_deg.to_radians();
        let p = self.pitch_deg.clamp(-89.9, 89.9).to_radians();
        DVec3::new(h.sin() * p.cos(), h.cos() * p.cos(), p.sin())
    }

    /// View matrix with the camera at the origin (world axes east, north, up).
    pub fn view_relative(&self) -> Mat4 {
        glam::camera::rh::view::look_at_mat4(Vec3::ZERO, self.forward().as_vec3(), Vec3::Z)
    }

    /// Perspective projection, WebGPU depth `[0, 1]`.
    pub fn projection(&self) -> Mat4 {
        glam::camera::rh::proj::directx::perspective(
            self.fov_y_deg.to_radians(),
            self.aspect,
            self.near_m,
            self.far_m,
        )
    }

    /// Projection times view for camera-relative positions.
    pub fn view_proj_relative(&self) -> Mat4 {
        self.projection() * self.view_relative()
    }

    /// The view volume, camera-relative, for culling whole blocks before any of their sprites
    /// is built or drawn.
    pub fn frustum_relative(&self) -> Frustum {
        Frustum::from_view_proj(self.view_proj_relative())
    }
}

/// The four side planes of a view volume (camera-relative metres), each `n . p + d >= 0`
/// inside with `n` of unit length. The near and far planes are left out: whatever contains the
/// camera is in view, and a host's far plane may be at infinity (reversed Z).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frustum {
    planes: [Vec4; 4],
}

impl Frustum {
    /// The side planes of a projection-times-view matrix (Gribb and Hartmann's extraction from
    /// the matrix's rows).
    pub fn from_view_proj(m: Mat4) -> Self {
        let (r0, r1, r3) = (m.row(0), m.row(1), m.row(3));
        let unit = |p: Vec4| p / p.truncate().length().max(f32::MIN_POSITIVE);
        Self {
            planes: [unit(r3 + r0), unit(r3 - r0), unit(r3 + r1), unit(r3 - r1)],
        }
    }

    /// Whether any of the sphere at `centre` (camera-relative) of `radius` may be in view.
    pub fn sees_sphere(&self, centre: Vec3, radius: f32) -> bool {
        self.planes
            .iter()
            .all(|p| p.truncate().dot(centre) + p.w >= -radius)
    }

    /// Whether a sphere (`centre` relative to the eye, metres) lies wholly inside the frustum.
    pub fn holds_sphere(&self, centre: Vec3, radius: f32) -> bool {
        self.planes
            .iter()
            .all(|p| p.truncate().dot(centre) + p.w >= radius)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam() -> Camera {
        Camera {
            position_m: DVec3::new(1.0e6, -2.0e6, 1500.0),
            heading_deg: 90.0,
            pitch_deg: 0.0,
            fov_y_deg: 60.0,
            aspect: 16.0 / 9.0,
            near_m: 1.0,
            far_m: 10_000.0,
        }
    }

    #[test]
    fn heading_90_looks_east_and_a_point_ahead_projects_to_the_centre() {
        let c = cam();
        assert!((c.forward() - DVec3::X).length() < 1e-12);
        let ahead = c.view_proj_relative() * Vec3::new(100.0, 0.0, 0.0).extend(1.0);
        let ndc = ahead.truncate() / ahead.w;
        assert!(ndc.x.abs() < 1e-5 && ndc.y.abs() < 1e-5 && ndc.z > 0.0 && ndc.z < 1.0);
        // Up is up on screen, north (left of an east-looking camera) is left.
        let above = c.view_proj_relative() * Vec3::new(100.0, 0.0, 10.0).extend(1.0);
        let left = c.view_proj_relative() * Vec3::new(100.0, 10.0, 0.0).extend(1.0);
        assert!(above.y / above.w > 0.0 && left.x / left.w < 0.0);
        // clip.w is the view depth, which the shaders use as linear depth.
        assert!((ahead.w - 100.0).abs() < 1e-3);
    }

    #[test]
    fn the_frustum_sees_what_is_ahead_and_what_holds_the_camera_and_nothing_behind() {
        let f = cam().frustum_relative();
        // Ahead, and a sphere just off the edge of the view that still reaches into it.
        assert!(f.sees_sphere(Vec3::new(5000.0, 0.0, 0.0), 10.0));
        // 60 degrees up at 1 km is outside the 30-degree half-angle; its 1 m sphere too,
        // a sphere reaching back across the top plane is seen.
        let high = Vec3::new(500.0, 0.0, 866.0);
        assert!(!f.sees_sphere(high, 1.0));
        assert!(f.sees_sphere(high, 600.0));
        // Behind the camera.
        assert!(!f.sees_sphere(Vec3::new(-3000.0, 0.0, 0.0), 2000.0));
        // A block holding the camera is always seen, whatever its radius beyond zero.
        assert!(f.sees_sphere(Vec3::new(-1.0, 0.5, 0.0), 2.0));
    }
}
