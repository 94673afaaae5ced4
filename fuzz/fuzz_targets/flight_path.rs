//! Any bytes as a flight path (`config/flights/*.toml`): no panic; a plan that loads can be
//! placed and sampled anywhere along it, giving finite poses; a rejected one's error names the
//! file.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use skycast::flight::FlightPlan;
use skycast::weather::LocalFrame;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let plan = match FlightPlan::parse(&text, Path::new("fuzz.toml")) {
        Ok(plan) => plan,
        Err(e) => {
            assert!(e.to_string().contains("fuzz.toml"), "{e}");
            return;
        }
    };
    let (lat, lon) = plan.origin_lat_lon_deg;
    let path = plan.place(&LocalFrame::new(lat, lon));
    let (start, duration) = (path.start_s(), path.duration_s());
    for k in 0..=8 {
        let pose = path.pose_at(start + duration * k as f64 / 8.0);
        assert!(pose.position_m.is_finite(), "{pose:?}");
        assert!(pose.heading_deg.is_finite() && pose.pitch_deg.is_finite(), "{pose:?}");
    }
});
