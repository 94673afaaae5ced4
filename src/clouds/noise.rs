//! Small deterministic 2-D value noise and fractal Brownian motion (fBm) for the texture sheet.
//!
//! Lattice values come from an integer hash ([`super::rng::mix64`]); interpolation is the quintic
//! fade of Perlin 2002. Plain f32 arithmetic only, so the sheet is the same on every machine.

use super::rng::mix64;

/// Value noise at `(x, y)`, in [0, 1); `seed` picks an independent field.
pub fn value(x: f32, y: f32, seed: u64) -> f32 {
    let xf = x.floor();
    let yf = y.floor();
    let (xi, yi) = (xf as i64, yf as i64);
    let (tx, ty) = (fade(x - xf), fade(y - yf));
    let v00 = lattice(xi, yi, seed);
    let v10 = lattice(xi + 1, yi, seed);
    let v01 = lattice(xi, yi + 1, seed);
    let v11 = lattice(xi + 1, yi + 1, seed);
    let a = v00 + (v10 - v00) * tx;
    let b = v01 + (v11 - v01) * tx;
    a + (b - a) * ty
}

/// fBm: `octaves` octaves of [`value`], each twice the frequency and `gain` times the amplitude
/// of the last, normalised to [0, 1).
pub fn fbm(x: f32, y: f32, seed: u64, octaves: u32, gain: f32) -> f32 {
    let (mut sum, mut amp, mut norm, mut freq) = (0.0, 1.0, 0.0, 1.0);
    for o in 0..octaves {
        sum += amp * value(x * freq, y * freq, seed.wrapping_add(o as u64 * 0x9E37));
        norm += amp;
        amp *= gain;
        freq *= 2.0;
    }
    sum / norm
}

/// Ridged fBm: sharp creases where the noise crosses its middle, in [0, 1].
pub fn ridged(x: f32, y: f32, seed: u64, octaves: u32) -> f32 {
    let (mut sum, mut amp, mut norm, mut freq) = (0.0, 1.0, 0.0, 1.0);
    for o in 0..octaves {
        let n = value(x * freq, y * freq, seed.wrapping_add(o as u64 * 0x51ED));
        sum += amp * (1.0 - (2.0 * n - 1.0).abs());
        norm += amp;
        amp *= 0.5;
        freq *= 2.0;
    }
    sum / norm
}

fn fade(t: f32) -> f32 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

fn lattice(x: i64, y: i64, seed: u64) -> f32 {
    let h = mix64(seed ^ mix64((x as u64).wrapping_mul(0x8CB9_2BA7_2F3D_8DD7) ^ (y as u64)));
    (h >> 40) as f32 * (1.0 / (1u32 << 24) as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_is_bounded_continuous_and_seeded() {
        let mut max_step: f32 = 0.0;
        for k in 0..2000 {
            let x = k as f32 * 0.01 - 7.0;
            let a = fbm(x, 0.3 * x, 5, 5, 0.5);
            let b = fbm(x + 0.001, 0.3 * x, 5, 5, 0.5);
            assert!((0.0..1.0).contains(&a));
            max_step = max_step.max((a - b).abs());
        }
        assert!(max_step < 0.05, "fbm jumps by {max_step}");
        assert_ne!(value(0.5, 0.5, 1), value(0.5, 0.5, 2));
        assert_eq!(value(3.0, 4.0, 9), value(3.0, 4.0, 9));
    }
}
