//! Writing read-back frames: PNG (sRGB, 8 bits) for looking at, EXR (linear RGBA half floats and
//! the depth as a `Z` channel in metres from the camera plane) for compositing.

use std::path::Path;

use super::headless::Frame;
use crate::render::RenderError;

/// The sRGB transfer function of a linear value, 0..=1.
pub fn linear_to_srgb(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

impl Frame {
    /// 8-bit sRGB RGBA pixels, opaque.
    pub fn to_srgb8(&self) -> Vec<u8> {
        self.rgba
            .iter()
            .flat_map(|p| {
                let c = |x: f32| (linear_to_srgb(x) * 255.0).round() as u8;
                [c(p[0]), c(p[1]), c(p[2]), 255]
            })
            .collect()
    }

    /// Metres from the camera plane at every pixel for a `[0, 1]` perspective with these
    /// planes; pixels with nothing drawn get `far_m`.
    pub fn linear_depth_m(&self, near_m: f32, far_m: f32) -> Vec<f32> {
        self.depth
            .iter()
            .map(|&d| {
                if d >= 1.0 {
                    far_m
                } else {
                    near_m * far_m / (far_m - d * (far_m - near_m))
                }
            })
            .collect()
    }

    /// Writes an 8-bit sRGB PNG.
    pub fn write_png(&self, path: &Path) -> Result<(), RenderError> {
        image::RgbaImage::from_raw(self.width, self.height, self.to_srgb8())
            .ok_or_else(|| RenderError::Output {
                path: path.display().to_string(),
                message: "frame size mismatch".into(),
            })?
            .save(path)
            .map_err(|e| RenderError::Output {
                path: path.display().to_string(),
                message: e.to_string(),
            })
    }

    /// Writes an EXR with linear R, G, B, A as half floats and `Z` (metres) as f32.
    pub fn write_exr(&self, path: &Path, near_m: f32, far_m: f32) -> Result<(), RenderError> {
        self.write_exr_with(path, near_m, far_m, None)
    }

    /// [`Self::write_exr`] plus a `cloud_distance` channel (f32 metres from the camera plane of
    /// the clouds each pixel shows, weighted by their alpha; 0 where there are none), one value a
    /// pixel, when given.
    pub fn write_exr_with(
        &self,
        path: &Path,
        near_m: f32,
        far_m: f32,
        cloud_distance_m: Option<&[f32]>,
    ) -> Result<(), RenderError> {
        use exr::prelude::*;
        let channel =
            |i: usize| -> Vec<f16> { self.rgba.iter().map(|p| f16::from_f32(p[i])).collect() };
        let mut list = vec![
            AnyChannel::new("R", FlatSamples::F16(channel(0))),
            AnyChannel::new("G", FlatSamples::F16(channel(1))),
            AnyChannel::new("B", FlatSamples::F16(channel(2))),
            AnyChannel::new("A", FlatSamples::F16(channel(3))),
            AnyChannel::new("Z", FlatSamples::F32(self.linear_depth_m(near_m, far_m))),
        ];
        if let Some(d) = cloud_distance_m.filter(|d| d.len() == self.rgba.len()) {
            list.push(AnyChannel::new(
                "cloud_distance",
                FlatSamples::F32(d.to_vec()),
            ));
        }
        let channels = SmallVec::from_vec(list);
        let image = Image::from_channels(
            (self.width as usize, self.height as usize),
            AnyChannels::sort(channels),
        );
        image
            .write()
            .to_file(path)
            .map_err(|e| RenderError::Output {
                path: path.display().to_string(),
                message: e.to_string(),
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame() -> Frame {
        Frame {
            width: 2,
            height: 1,
            rgba: vec![[0.0, 0.5, 1.0, 1.0], [0.2, 0.2, 0.2, 0.5]],
            depth: vec![1.0, 0.5],
        }
    }

    #[test]
    fn srgb_encoding_matches_the_standard() {
        assert_eq!(
            frame().to_srgb8(),
            vec![0, 188, 255, 255, 124, 124, 124, 255]
        );
    }

    #[test]
    fn exr_round_trips_colour_and_depth() {
        use exr::prelude::*;
        let dir = std::env::temp_dir().join(format!("skycast-exr-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("f.exr");
        frame().write_exr(&path, 1.0, 100.0).unwrap();
        let img = read_all_flat_layers_from_file(&path).unwrap();
        let chans = &img.layer_data[0].channel_data.list;
        let names: Vec<String> = chans.iter().map(|c| c.name.to_string()).collect();
        assert_eq!(names, ["A", "B", "G", "R", "Z"]);
        let z: Vec<f32> = chans[4].sample_data.values_as_f32().collect();
        // d = 0.5 with near 1, far 100: 100 / (100 - 49.5) = 1.98 m.
        assert_eq!(z[0], 100.0);
        assert!((z[1] - 1.980_198).abs() < 1e-4, "{z:?}");
        let g: Vec<f32> = chans[2].sample_data.values_as_f32().collect();
        assert_eq!(g, [0.5, 0.2].map(|x: f32| half::f16::from_f32(x).to_f32()));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
