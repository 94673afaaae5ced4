//! The weather stage from outside: `metar_bulk` decodes every report of the real bulk file and
//! compares its cloud layers with the service's own decode; `metar_cli` runs `skycast metar`.

mod metar_bulk;
mod metar_cli;
