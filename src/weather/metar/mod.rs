//! METAR/SPECI decoding of the main body (WMO FM 15, ICAO Annex 3, and US practice):
//! station, time, AUTO/COR/NIL, wind, visibility, present weather, cloud groups, temperature,
//! dewpoint and altimeter. The body ends at RMK, TEMPO, BECMG, NOSIG or PROB; the remarks are kept
//! raw for the stages that read them. A malformed group becomes a warning on the report, never a
//! failure of the whole report.

mod report;

pub use report::{
    CloudGroup, ConvectiveKind, Cover, Intensity, PresentWeather, Report, ReportTime, SkyCode,
    WindGroup,
};
