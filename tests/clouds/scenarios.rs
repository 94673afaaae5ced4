//! Wang 2003 §6.3's three scenarios from real METARs (`weather/scenarios/`): the weather stage
//! turns each into block weather, the clouds stage into blocks; the mean cloud block overdraw
//! must come out near the paper's figures (sparse 170 %, scattered 200 %, overcast 475 %).

use std::path::Path;

use skycast::clouds::{CloudBlock, CloudTypes, CloudsConfig, generate_block};
use skycast::weather::{
    BlockIndex, BlockWeather, CloudType, CloudTypeRule, FieldSettings, LocalFrame, StationTable,
    WeatherInput,
};

/// The block weather of block (0, 0) of a frame centred on the scenario's one station.
pub fn scenario_weather(name: &str) -> BlockWeather {
    let stations = StationTable::load(Path::new("weather/nsd_cccc.txt")).unwrap();
    let path = format!("weather/scenarios/{name}.metar");
    let input = WeatherInput::load(Path::new(&path), Some(&stations)).unwrap();
    let WeatherInput::Reports(file) = &input else {
        panic!("{path} is a report file");
    };
    assert_eq!(file.reports.len(), 1, "{path}: one report");
    let p = file.reports[0].position;
    let frame = LocalFrame::new(p.latitude_deg, p.longitude_deg);
    let field = input.field(frame, &FieldSettings::default(), &CloudTypeRule::default());
    field.block_weather(BlockIndex::new(0, 0))
}

/// Mean overdraw of a 5 x 5 patch of blocks under one weather.
pub fn mean_overdraw(weather: &BlockWeather) -> f64 {
    let types = CloudTypes::builtin();
    let seed = CloudsConfig::builtin().field.seed;
    let blocks: Vec<CloudBlock> = (-2..=2)
        .flat_map(|j| (-2..=2).map(move |i| BlockIndex::new(i, j)))
        .map(|index| generate_block(index, weather, seed, &types))
        .collect();
    blocks.iter().map(CloudBlock::overdraw).sum::<f64>() / blocks.len() as f64
}

#[test]
fn the_three_scenarios_come_out_near_the_papers_overdraw() {
    let mut report = Vec::new();
    for (name, cloud_type, oktas, paper) in [
        ("sparse", CloudType::CumulusHumilis, 2.0, 1.70),
        ("scattered", CloudType::CumulusHumilis, 3.5, 2.00),
        ("overcast", CloudType::Stratus, 8.0, 4.75),
    ] {
        let weather = scenario_weather(name);
        assert_eq!(weather.layers.len(), 1, "{name}: {weather:?}");
        assert_eq!(weather.layers[0].cloud_type, cloud_type, "{name}");
        assert_eq!(weather.layers[0].coverage_oktas, oktas, "{name}");
        let overdraw = mean_overdraw(&weather);
        report.push((name, overdraw, paper));
    }
    let text: Vec<String> = report
        .iter()
        .map(|(n, o, p)| format!("{n} {:.0}% (paper {:.0}%)", o * 100.0, p * 100.0))
        .collect();
    for (_, overdraw, paper) in &report {
        assert!(
            (overdraw / paper - 1.0).abs() <= 0.15,
            "{}",
            text.join(", ")
        );
    }
    eprintln!("overdraw: {}", text.join(", "));
}
