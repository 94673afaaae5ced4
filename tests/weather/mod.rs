//! The weather stage from outside: `field_bulk` asks the weather field at every cloudy station
//! of the real bulk file and compares with the service's decode; `metar_bulk` decodes every report of the real bulk file and
//! compares its cloud layers with the service's own decode; `metar_cli` runs `skycast metar`;
//! `weather_cli` runs `skycast weather` on bulk, plain and cycle files and on bad input;
//! `fuzz_seeds` replays every fuzz target's seed corpus through the target's checks.

mod field_bulk;
mod fuzz_seeds;
mod metar_bulk;
mod metar_cli;
mod model_blend;
mod model_cli;
mod weather_cli;
