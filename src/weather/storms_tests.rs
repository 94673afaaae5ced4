use std::path::Path;

use super::*;
use crate::weather::air::AirSettings;
use crate::weather::field::{CloudTypeRule, FieldSettings, WeatherField};
use crate::weather::frame::LocalFrame;
use crate::weather::{BlockIndex, files, stations::StationTable, theme};

const SEED: u64 = 0x5eed;

/// The shipped 2025 bulk file as a weather field framed at `lat`, `lon` (also the far cells'
/// tests, `flight::far_cells`).
pub(crate) fn real_field(lat: f64, lon: f64) -> WeatherField {
    let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/weather"));
    let stations = StationTable::load(&dir.join("nsd_cccc.txt")).unwrap();
    let file = files::load(
        &dir.join("awc-metars-2025-01-27T22Z.cache.csv"),
        Some(&stations),
    )
    .unwrap();
    WeatherField::build(
        LocalFrame::new(lat, lon),
        &file.reports,
        &FieldSettings::default(),
        &CloudTypeRule::default(),
    )
}

fn theme_field() -> WeatherField {
    let path = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/weather/themes/thunderstorm_cells.toml"
    ));
    let t = theme::load_theme(path).unwrap();
    WeatherField::from_theme(
        LocalFrame::new(27.0, -81.0),
        &t,
        &FieldSettings::default(),
        &CloudTypeRule::default(),
    )
}

fn ctx(lat_deg: f64) -> StormContext {
    StormContext {
        lat_deg,
        ..StormContext::default()
    }
}

/// The cells over the `half_m` square around the frame origin, the field sampled per block as
/// the cloud field does.
fn cells_around(field: &WeatherField, half_m: f64, ctx: &StormContext) -> Vec<StormCell> {
    cells_over(
        DVec2::splat(-half_m),
        DVec2::splat(half_m),
        &mut |p| field.block_weather(BlockIndex::containing(p)),
        ctx,
        SEED,
    )
}

/// Done means 1: bases 5-15 km, anvils at least 2.5 times the base, the anvil's centre downwind
/// (the wind aloft at the anvil, from the air data's profile) by at least 0.3 of its width.
fn assert_geometry(field: &WeatherField, cells: &[StormCell], ctx: &StormContext, what: &str) {
    assert!(!cells.is_empty(), "{what}: no cells");
    for c in cells {
        assert!(
            (5_000.0..=15_000.0).contains(&c.base_width_m),
            "{what}: base {} m",
            c.base_width_m
        );
        assert!(
            c.anvil_width_m >= 2.5 * c.base_width_m,
            "{what}: anvil {} m over base {} m",
            c.anvil_width_m,
            c.base_width_m
        );
        // The wind at the anvil, worked out here from the surface weather under the cell.
        let w = field.block_weather(BlockIndex::containing(c.centre()));
        let anvil_m = c.top_m_msl() - 0.5 * c.anvil_thickness_m;
        let wind = crate::weather::air::wind_at(
            &SurfaceAir::of(&w, 0.0, 1013.25),
            anvil_m - w.ground_elevation_m as f64,
            anvil_m,
            ctx.lat_deg,
            &ctx.wind,
        );
        assert!(wind.speed_kt > 1.0, "{what}: a wind to be downwind of");
        let to = (wind.from_deg + 180.0).to_radians();
        let downwind = DVec2::new(to.sin(), to.cos());
        let along = c.anvil_offset().dot(downwind);
        assert!(
            along >= 0.3 * c.anvil_width_m,
            "{what}: anvil {along:.0} m downwind, width {:.0} m",
            c.anvil_width_m
        );
        // Within 17 degrees of the wind under the cell's centre (the cell takes the wind at its
        // grid square's centre, a few km off).
        assert!(c.anvil_offset().perp_dot(downwind).abs() < 0.3 * c.anvil_offset().length());
        eprintln!(
            "{what}: base {:.1} km, anvil {:.1} km ({:.2}x), {:.2} of it downwind",
            c.base_width_m / 1000.0,
            c.anvil_width_m / 1000.0,
            c.anvil_width_m / c.base_width_m,
            along / c.anvil_width_m
        );
    }
}

#[test]
fn the_shipped_settings_parse_and_a_bad_range_names_its_field() {
    let s = StormSettings::default();
    assert!(s.cells.base_width_m[0] >= 5_000.0 && s.cells.widest_base_m <= 15_000.0);
    let text = BUILTIN.replace(
        "anvil_over_base = [2.6, 3.4]",
        "anvil_over_base = [3.4, 2.6]",
    );
    let err = StormSettings::parse(&text, Path::new("config/storms.toml")).unwrap_err();
    assert_eq!(err.field.as_deref(), Some("cells.anvil_over_base"));
    assert!(err.line.is_some(), "{err}");
}

#[test]
fn thunderstorm_cells_theme_cells_are_5_to_15_km_with_anvils_downwind() {
    let field = theme_field();
    let ctx = ctx(27.0);
    let cells = cells_around(&field, 30_000.0, &ctx);
    assert_geometry(&field, &cells, &ctx, "thunderstorm_cells");
    // The theme's wind is from 250 degrees: the anvils spread to the east-north-east.
    for c in &cells {
        assert!(c.anvil_offset_m[0] > 0.0, "{:?}", c.anvil_offset_m);
        assert_eq!(c.thunder, 2, "the theme's TS");
    }
}

#[test]
fn sbbh_bkn045cb_cells_are_5_to_15_km_with_anvils_downwind() {
    let field = real_field(-19.851, -43.951);
    let here = field.block_weather(BlockIndex::containing(DVec2::ZERO));
    let cb = here
        .layers
        .iter()
        .find(|l| l.cloud_type == CloudType::Cumulonimbus)
        .expect("SBBH's BKN045CB");
    assert!((cb.base_ft_agl - 4500.0).abs() < 1.0 && cb.coverage_oktas >= 5.0);
    let ctx = ctx(-19.851);
    let cells = cells_around(&field, 30_000.0, &ctx);
    assert_geometry(&field, &cells, &ctx, "SBBH");
    // TSRA: the cells over the station flash.
    let near: Vec<_> = cells
        .iter()
        .filter(|c| c.centre().length() < 15_000.0)
        .collect();
    assert!(!near.is_empty() && near.iter().all(|c| c.thunder == 2));
}

#[test]
fn over_60_km_around_wayy_the_few_cb_bases_cover_1_to_2_5_oktas() {
    // WAYY 272200Z 35005KT 4000 -RA FEW012CB BKN013: a FEW CB beside a broken deck.
    let field = real_field(-4.528, 136.887);
    let ctx = ctx(-4.528);
    let (lo, hi) = (DVec2::splat(-30_000.0), DVec2::splat(30_000.0));
    let cells = cells_over(
        lo,
        hi,
        &mut |p| field.block_weather(BlockIndex::containing(p)),
        &ctx,
        SEED,
    );
    let oktas = base_cover_oktas(&cells, lo, hi, 200.0);
    eprintln!("WAYY: {} cells, {oktas:.2} oktas", cells.len());
    assert!(
        (1.0..=2.5).contains(&oktas),
        "{oktas:.2} oktas of {} cells",
        cells.len()
    );
    // No TS in the report: no cell flashes.
    assert!(cells.iter().all(|c| c.thunder == 0));
    assert!(flashes_between(&cells, 0.0, 600.0, &ctx.settings.lightning, SEED).is_empty());
}

#[test]
fn cells_are_the_same_whichever_area_asks_for_them() {
    let field = theme_field();
    let ctx = StormContext::default();
    let mut weather = |p: DVec2| field.block_weather(BlockIndex::containing(p));
    let a = cells_over(
        DVec2::new(0.0, 0.0),
        DVec2::new(4_000.0, 4_000.0),
        &mut weather,
        &ctx,
        SEED,
    );
    let b = cells_over(
        DVec2::new(4_000.0, 0.0),
        DVec2::new(8_000.0, 4_000.0),
        &mut weather,
        &ctx,
        SEED,
    );
    let shared: Vec<_> = a.iter().filter(|c| b.contains(c)).collect();
    assert!(!shared.is_empty(), "neighbouring blocks share cells");
    for c in a.iter().filter(|c| b.iter().any(|d| d.key == c.key)) {
        assert!(b.contains(c), "one cell, one shape, for both blocks");
    }
    // Another seed, other cells.
    let other = cells_over(
        DVec2::ZERO,
        DVec2::splat(4_000.0),
        &mut weather,
        &ctx,
        SEED + 1,
    );
    assert_ne!(a, other);
}

#[test]
fn a_ts_cell_flashes_at_least_once_a_minute_and_pieces_add_up() {
    let field = theme_field();
    let ctx = StormContext::default();
    let cells = cells_around(&field, 30_000.0, &ctx);
    let l = ctx.settings.lightning;
    let all = flashes_between(&cells, 0.0, 600.0, &l, SEED);
    for c in &cells {
        for minute in 0..10 {
            let t = minute as f64 * 60.0;
            let n = all
                .iter()
                .filter(|f| f.cell_key == c.key && f.time_s >= t && f.time_s < t + 60.0)
                .count();
            assert!(n >= 1, "cell {:x} minute {minute}: {n} flashes", c.key);
        }
    }
    let mut pieces = Vec::new();
    for k in 0..60 {
        pieces.extend(flashes_between(
            &cells,
            k as f64 * 10.0,
            (k + 1) as f64 * 10.0,
            &l,
            SEED,
        ));
    }
    assert_eq!(pieces, all);
    assert!(all.iter().any(|f| f.kind == FlashKind::CloudToGround));
    assert!(all.iter().any(|f| f.kind == FlashKind::InCloud));
    // The same cells without thunder: not one flash.
    let quiet: Vec<_> = cells
        .iter()
        .map(|c| StormCell { thunder: 0, ..*c })
        .collect();
    assert!(flashes_between(&quiet, 0.0, 600.0, &l, SEED).is_empty());
    let _ = AirSettings::default();
}
