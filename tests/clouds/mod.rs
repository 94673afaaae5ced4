//! The clouds stage from outside: `scenarios` runs the paper's three overdraw scenarios from real
//! METARs through the weather and clouds stages; `cli` runs `skycast sheet`, `preview` and
//! `block`.

mod borders;
mod cli;
mod scenarios;
