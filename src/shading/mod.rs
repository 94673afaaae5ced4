//! The shading stage: where the sun is and how bright and what colour a cloud vertex is.
//!
//! In: a UTC instant, latitude/longitude (degrees), a cloud's five ambient colour levels, its
//! shading groups and a vertex position. Out: the sun direction (east-north-up unit vector,
//! elevation and azimuth in degrees) and the Wang 2003 section 5 vertex colour
//! `C_vertex = (C_amb + C_dir) * C_texture * alpha_morph` (the texture factor is applied by the
//! renderer's fragment shader; this stage returns `C_amb + C_dir` with the alpha).
//!
//! - [`sun`]: NOAA / Meeus solar position (accurate to about 0.01 degree for 1900-2100).
//! - [`time_of_day`]: the artist tables of Wang 5.1/5.2, indexed by sun elevation instead of clock
//!   time so one table serves every latitude and season (`config/time_of_day.toml`): ambient
//!   percentage, maximum directional colour, sky colours; more samples around dawn and dusk.
//! - [`ambient`]: Wang 5.1, equation (1): five RGBA colour levels by height.
//! - [`directional`]: Wang 5.2, equation (2): shading groups and the biased mapping
//!   `[-1, 0] -> [Cmin, Cmedian]`, `[0, 1] -> [Cmedian, Cmax]`.
//! - [`scatter`]: beyond Wang, light scattered forward towards the eye (Harris and Lastra
//!   2001): the silver lining of a cloud between the camera and the sun.
//! - [`harris_lastra`]: a second, switchable model (Harris and Lastra 2001): the light each
//!   particle gets through the others (multiple forward scattering), a phase function towards
//!   the eye, skylight as a second light.
//! - [`cover`]: beyond Wang, the daylight under the clouds: how much of the sky the layers above
//!   a point hide, and the grey, sunless light below a thick deck.
//! - [`fog`]: the weather's visibility and obscuration as the fog a host draws (distance and
//!   colour, Koschmieder's law) and the clouds' haze distance.
//!
//! Plain data only: no wgpu here. Units: metres, degrees, linear RGB in 0..=1.

pub mod ambient;
pub mod cover;
pub mod directional;
pub mod fog;
pub mod harris_lastra;
pub mod scatter;
pub mod sun;
pub mod time_of_day;

pub use ambient::{ColourLevel, ColourLevels};
pub use cover::{OvercastLight, hidden_above};
pub use directional::{DirectionalMapping, directional_percent};
pub use fog::{AltitudeHaze, Fog, FogSettings};
pub use harris_lastra::{
    HarrisLastra, LightScratch, Particle, ParticleLight, RelightTrigger, ShadingModel,
    ShadingSettings,
};
pub use scatter::ForwardScattering;
pub use sun::{SunPosition, sun_position};
pub use time_of_day::{TimeOfDay, TimeOfDaySample, TimeOfDayTable};

use glam::{Vec3, Vec4};

/// Errors of the shading stage.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ShadingError {
    /// A time-of-day file could not be read or parsed; names file, line and field.
    #[error(transparent)]
    Config(#[from] crate::config::ConfigError),
}

/// Wang 2003 equation (3) without the texture factor: `(C_amb + C_dir) * alpha_morph`.
///
/// `ambient` is the level colour already multiplied by the time-of-day percentage (RGBA),
/// `directional_rgb` the mapped percentage times the time-of-day directional colour. The alpha
/// of the result is the ambient alpha times `alpha_morph`; colours are not premultiplied.
pub fn vertex_colour(ambient: Vec4, directional_rgb: Vec3, alpha_morph: f32) -> Vec4 {
    let rgb = ambient.truncate() + directional_rgb;
    rgb.extend(ambient.w * alpha_morph)
}

/// The luminance of a linear RGB colour (Rec. 709 weights).
pub fn luminance(rgb: Vec3) -> f32 {
    rgb.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vertex_colour_adds_light_and_multiplies_morph_into_alpha() {
        let c = vertex_colour(Vec4::new(0.5, 0.5, 0.6, 0.8), Vec3::new(0.3, 0.2, 0.1), 0.5);
        assert!((c - Vec4::new(0.8, 0.7, 0.7, 0.4)).abs().max_element() < 1e-6);
    }
}
