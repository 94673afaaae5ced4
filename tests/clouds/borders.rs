//! The cloud cover across block borders, on the real bulk file
//! (`weather/awc-metars-2025-01-27T22Z.cache.csv`): issue 31, "no visible edge".
//!
//! A patch of blocks is generated from the weather field (each with its own block weather, as
//! the cloud field asks for it), and the 100 m cells of the world under a sprite's dense core
//! (within 0.35 of its width of its centre, an ellipse for a flat sprite: what the clouds stage
//! counts as cover) are marked, clouds of every block together, so a cloud overhanging a border
//! counts on both sides. For every border two blocks of the patch share, the covered fractions of
//! the 400 m strips either side are compared, with each block generated with [`SEEDS`] seeds:
//! the *step* is the difference the weather makes there, the mean over the seeds less what their
//! scatter alone gives ([`systematic_step`]), root-mean-square over the borders. The same across
//! each block's two middle lines, where no border is, is the *control*: about 0 where the cover
//! is smooth, and a measure of what is left of the seeds' scatter.
//!
//! Three places: the FL350 Los Angeles track (issue 31), and Dublin and London (chosen
//! before measuring, not tuned on). Run alone with
//! `cargo test --test tests borders -- --nocapture` to print the figures.

use std::collections::HashSet;
use std::path::Path;

use skycast::clouds::{Cloud, CloudTypes, CloudsConfig, generate_block};
use skycast::weather::{
    BLOCK_SIZE_M, BlockIndex, CloudType, CloudTypeRule, FieldSettings, LocalFrame, StationTable,
    WeatherField, files,
};

const BULK_FILE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/weather/awc-metars-2025-01-27T22Z.cache.csv"
);

/// Side of a cover cell, metres (the clouds stage's coverage grid).
const CELL_M: f64 = 100.0;
/// Cells per block side.
const CELLS: i64 = (BLOCK_SIZE_M / CELL_M) as i64;
/// Depth of a strip beside a border, cells (400 m).
const STRIP: i64 = 4;
/// The greatest root-mean-square step the weather may make at the borders, oktas.
const MAX_STEP_OKTAS: f64 = 0.3;
/// Seeds each block is generated with: the strips' shares are averaged over them, so that what
/// is left is the cover the weather asks for there, not where one seed put its clouds.
const SEEDS: usize = 16;

/// The 100 m world cells (east, north indices) under the dense cores of the clouds' sprites
/// (`skycast::clouds::core`, the geometry every probe asks).
fn covered_cells<'a>(clouds: impl Iterator<Item = &'a Cloud>) -> HashSet<(i64, i64)> {
    let mut out = HashSet::new();
    for cloud in clouds {
        for core in skycast::clouds::core::cores(cloud) {
            let c = cloud.centre_m + core.centre_m;
            let r = core.box_half_m().x;
            let (x0, x1) = (
                ((c.x - r) / CELL_M).floor() as i64,
                ((c.x + r) / CELL_M) as i64,
            );
            let (y0, y1) = (
                ((c.y - r) / CELL_M).floor() as i64,
                ((c.y + r) / CELL_M) as i64,
            );
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let q = glam::DVec2::new((x as f64 + 0.5) * CELL_M, (y as f64 + 0.5) * CELL_M);
                    // The core's horizontal section through its centre.
                    let at = core.centre_m + (q - c.truncate()).extend(0.0);
                    if core.radius(at) <= 1.0 {
                        out.insert((x, y));
                    }
                }
            }
        }
    }
    out
}

/// Covered share of the cells `x0..x1` x `y0..y1`.
fn share(cells: &HashSet<(i64, i64)>, x: (i64, i64), y: (i64, i64)) -> f64 {
    let n = (x.1 - x.0) * (y.1 - y.0);
    let hit = (y.0..y.1)
        .flat_map(|j| (x.0..x.1).map(move |i| (i, j)))
        .filter(|c| cells.contains(c))
        .count();
    hit as f64 / n as f64
}

/// The covered shares of the strips either side of each border the blocks of `inner` share
/// (west or south first), then of each block's two middle lines (the control).
fn strips(cells: &HashSet<(i64, i64)>, inner: &[BlockIndex]) -> (Vec<[f64; 2]>, Vec<[f64; 2]>) {
    let has = |b: BlockIndex| inner.contains(&b);
    let (mut border, mut control) = (Vec::new(), Vec::new());
    for &b in inner {
        let (x0, y0) = (b.i as i64 * CELLS, b.j as i64 * CELLS);
        let rows = (y0, y0 + CELLS);
        let cols = (x0, x0 + CELLS);
        let across_x = |x: i64| {
            [
                share(cells, (x - STRIP, x), rows),
                share(cells, (x, x + STRIP), rows),
            ]
        };
        let across_y = |y: i64| {
            [
                share(cells, cols, (y - STRIP, y)),
                share(cells, cols, (y, y + STRIP)),
            ]
        };
        if has(BlockIndex::new(b.i + 1, b.j)) {
            border.push(across_x(x0 + CELLS));
        }
        if has(BlockIndex::new(b.i, b.j + 1)) {
            border.push(across_y(y0 + CELLS));
        }
        control.push(across_x(x0 + CELLS / 2));
        control.push(across_y(y0 + CELLS / 2));
    }
    (border, control)
}

/// The root-mean-square step the weather makes, without the clouds' randomness: over the
/// seeds each border's difference `d` of its two sides has a mean `m` and a sample variance
/// `v`, and `m^2 - v / seeds` is an unbiased estimate of the square of the difference the seeds
/// scatter around; the root of its mean over the borders (0 where that is negative).
fn systematic_step(diffs: &[Vec<f64>]) -> f64 {
    let squares = diffs.iter().map(|d| {
        let n = d.len() as f64;
        let m = d.iter().sum::<f64>() / n;
        let v = d.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0);
        m * m - v / n
    });
    (squares.sum::<f64>() / diffs.len().max(1) as f64)
        .max(0.0)
        .sqrt()
}

/// One place: the blocks measured (their borders and middle lines) and, around them, the ring
/// of blocks whose clouds overhang into them.
struct Place {
    name: &'static str,
    frame: LocalFrame,
    inner: Vec<BlockIndex>,
}

impl Place {
    /// The blocks within `half` blocks of the blocks under a straight track from `from` to `to`
    /// (latitude, longitude, degrees).
    fn track(name: &'static str, from: (f64, f64), to: (f64, f64), half: i32) -> Self {
        let frame = LocalFrame::new(from.0, from.1);
        let mut inner = Vec::new();
        for k in 0..=200 {
            let t = k as f64 / 200.0;
            let b = frame.block_of(from.0 + t * (to.0 - from.0), from.1 + t * (to.1 - from.1));
            for dj in -half..=half {
                let n = BlockIndex::new(b.i, b.j + dj);
                if !inner.contains(&n) {
                    inner.push(n);
                }
            }
        }
        Self { name, frame, inner }
    }
}

/// A band of clouds: its name and which types are in it.
type Band = (&'static str, fn(CloudType) -> bool);

/// Per border (or middle line), the difference of its two sides per seed.
type Diffs = Vec<Vec<f64>>;

/// The family of a cloud type: 0 low (cumulus, stratocumulus, stratus, fog), 1 middle (alto-,
/// nimbostratus), 2 high (cirro-).
fn family(t: CloudType) -> u8 {
    match t {
        CloudType::Altocumulus | CloudType::Altostratus | CloudType::Nimbostratus => 1,
        CloudType::Cirrus | CloudType::Cirrocumulus | CloudType::Cirrostratus => 2,
        _ => 0,
    }
}

/// (band, border step, control) of a place: all clouds, then the low, middle and high clouds
/// apart ([`family`]).
fn measure(place: &Place, reports: &[files::PlacedReport]) -> Vec<(&'static str, f64, f64)> {
    let field = WeatherField::build(
        place.frame,
        reports,
        &FieldSettings::default(),
        &CloudTypeRule::default(),
    );
    let types = CloudTypes::builtin();
    let mut all = place.inner.clone();
    for b in &place.inner {
        for (di, dj) in [
            (-1, 0),
            (1, 0),
            (0, -1),
            (0, 1),
            (-1, -1),
            (1, 1),
            (-1, 1),
            (1, -1),
        ] {
            let n = BlockIndex::new(b.i + di, b.j + dj);
            if !all.contains(&n) {
                all.push(n);
            }
        }
    }
    let weathers: Vec<_> = all.iter().map(|&b| (b, field.block_weather(b))).collect();
    let bands: [Band; 4] = [
        ("all", |_| true),
        ("low", |t| family(t) == 0),
        ("middle", |t| family(t) == 1),
        ("high", |t| family(t) == 2),
    ];
    // Per band, each border's and each middle line's difference of its two sides, per seed.
    let mut diffs: Vec<(Diffs, Diffs)> = Vec::new();
    let first = CloudsConfig::builtin().field.seed;
    for seed in first..first + SEEDS as u64 {
        let clouds: Vec<Cloud> = weathers
            .iter()
            .flat_map(|(b, w)| generate_block(*b, w, seed, &types).clouds)
            .collect();
        for (k, (_, of_band)) in bands.iter().enumerate() {
            let cells = covered_cells(clouds.iter().filter(|c| of_band(c.cloud_type)));
            let (border, control) = strips(&cells, &place.inner);
            if diffs.len() <= k {
                diffs.push((
                    vec![Vec::new(); border.len()],
                    vec![Vec::new(); control.len()],
                ));
            }
            let (border_diffs, control_diffs) = &mut diffs[k];
            let pairs = border_diffs.iter_mut().zip(&border);
            for (d, [a, b]) in pairs.chain(control_diffs.iter_mut().zip(&control)) {
                d.push(a - b);
            }
        }
    }
    let mut out = Vec::new();
    for ((band, _), (border, control)) in bands.iter().zip(&diffs) {
        let (step, ctrl) = (systematic_step(border), systematic_step(control));
        // Borders whose mean step over the seeds is an okta or more.
        let mean = |d: &Vec<f64>| d.iter().sum::<f64>() / d.len() as f64;
        let okta = border.iter().filter(|d| mean(d).abs() >= 1.0 / 8.0).count();
        eprintln!(
            "{}: {band}: {} borders, step {:.2} oktas, control {:.2} oktas, {okta} borders \
             of an okta or more",
            place.name,
            border.len(),
            8.0 * step,
            8.0 * ctrl,
        );
        out.push((*band, step, ctrl));
    }
    out
}

#[test]
fn cloud_cover_does_not_step_at_block_borders() {
    let stations =
        StationTable::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("weather/nsd_cccc.txt"))
            .expect("the station table");
    let file = files::load(Path::new(BULK_FILE), Some(&stations)).expect("the bulk file reads");
    let places = [
        // The FL350 cruise's track (config/flights/cruise_fl350_los_angeles_east.toml), five
        // rows of blocks wide (Chino, KCNO, about 8 km north of it, at the patch's edge).
        Place::track("los angeles", (33.94, -118.41), (33.90, -117.48), 2),
        Place::track("dublin", (53.35, -6.45), (53.35, -6.05), 2),
        Place::track("london", (51.47, -0.65), (51.47, -0.05), 2),
    ];
    let mut worst: Vec<String> = Vec::new();
    for place in &places {
        for (band, step, _) in measure(place, &file.reports) {
            // A block's cover the same all over it (before issue 31): Los Angeles 0.38 oktas
            // (0.48 in the middle clouds), London 0.34, Dublin 0.00; blended: 0.07 (0.09), 0.22
            // and 0.00; with the lattice's overhang allowed for: 0.00 (0.00), 0.22 and 0.00.
            if 8.0 * step > MAX_STEP_OKTAS {
                worst.push(format!("{} {band}: {:.2} oktas", place.name, 8.0 * step));
            }
        }
    }
    assert!(worst.is_empty(), "cover steps at block borders: {worst:?}");
}
