//! Catmull-Rom interpolation through timed points: C1-continuous, passes through every point.

use glam::DVec3;

/// A point of the curve at a time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Key {
    /// Seconds from the start.
    pub time_s: f64,
    /// Position, metres.
    pub position_m: DVec3,
}

/// Position and velocity (metres per second) at `time_s` on the Catmull-Rom curve through `keys`
/// (sorted by strictly increasing time, at least two). Before the first key or after the last,
/// the curve holds the end position.
pub fn sample(keys: &[Key], time_s: f64) -> (DVec3, DVec3) {
    let last = keys.len() - 1;
    if time_s <= keys[0].time_s {
        return (keys[0].position_m, tangent(keys, 0));
    }
    if time_s >= keys[last].time_s {
        return (keys[last].position_m, tangent(keys, last));
    }
    let i = keys.partition_point(|k| k.time_s <= time_s) - 1;
    let (k0, k1) = (keys[i], keys[i + 1]);
    let dt = k1.time_s - k0.time_s;
    let u = (time_s - k0.time_s) / dt;
    // Cubic Hermite with Catmull-Rom tangents scaled to the segment's duration.
    let (m0, m1) = (tangent(keys, i) * dt, tangent(keys, i + 1) * dt);
    let (u2, u3) = (u * u, u * u * u);
    let p = k0.position_m * (2.0 * u3 - 3.0 * u2 + 1.0)
        + m0 * (u3 - 2.0 * u2 + u)
        + k1.position_m * (-2.0 * u3 + 3.0 * u2)
        + m1 * (u3 - u2);
    let v = (k0.position_m * (6.0 * u2 - 6.0 * u)
        + m0 * (3.0 * u2 - 4.0 * u + 1.0)
        + k1.position_m * (-6.0 * u2 + 6.0 * u)
        + m1 * (3.0 * u2 - 2.0 * u))
        / dt;
    (p, v)
}

/// Velocity at key `i`: the central difference of its neighbours (one-sided at the ends).
fn tangent(keys: &[Key], i: usize) -> DVec3 {
    let (a, b) = (keys[i.saturating_sub(1)], keys[(i + 1).min(keys.len() - 1)]);
    (b.position_m - a.position_m) / (b.time_s - a.time_s)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(time_s: f64, x: f64, y: f64) -> Key {
        Key {
            time_s,
            position_m: DVec3::new(x, y, 0.0),
        }
    }

    #[test]
    fn passes_through_keys_and_holds_at_ends() {
        let keys = [
            key(0.0, 0.0, 0.0),
            key(10.0, 100.0, 0.0),
            key(30.0, 100.0, 200.0),
        ];
        for k in keys {
            assert!(sample(&keys, k.time_s).0.distance(k.position_m) < 1e-9);
        }
        assert_eq!(sample(&keys, -5.0).0, keys[0].position_m);
        assert_eq!(sample(&keys, 99.0).0, keys[2].position_m);
    }

    #[test]
    fn straight_uniform_motion_is_reproduced_exactly() {
        let keys = [
            key(0.0, 0.0, 0.0),
            key(10.0, 100.0, 0.0),
            key(20.0, 200.0, 0.0),
        ];
        let (p, v) = sample(&keys, 13.0);
        assert!(p.distance(DVec3::new(130.0, 0.0, 0.0)) < 1e-9);
        assert!(v.distance(DVec3::new(10.0, 0.0, 0.0)) < 1e-9);
    }

    #[test]
    fn velocity_is_continuous_across_a_key() {
        let keys = [
            key(0.0, 0.0, 0.0),
            key(10.0, 100.0, 0.0),
            key(30.0, 100.0, 200.0),
            key(40.0, 0.0, 250.0),
        ];
        let before = sample(&keys, 10.0 - 1e-6).1;
        let after = sample(&keys, 10.0 + 1e-6).1;
        assert!(before.distance(after) < 1e-3, "{before} vs {after}");
    }
}
