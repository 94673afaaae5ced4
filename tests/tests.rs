//! Integration tests, one module per stage, each run against the library or the built binary:
//! - `weather`: the METAR decoder on the real bulk file, the `skycast metar` and
//!   `skycast weather` commands.
//! - `bench`: the `skycast bench` command at a tiny size.
//! - `clouds`: the paper's overdraw scenarios from real METARs, and the `skycast sheet`,
//!   `preview` and `block` commands.
//! - `product`: the command line from any directory, `--config-dir`, the OpenGL backend.

mod bench;
mod clouds;
mod product;
mod weather;
