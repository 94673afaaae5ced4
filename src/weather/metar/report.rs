//! The decoded report: plain data, one field per METAR group. Units are in the field names.

use serde::Serialize;

/// Day of month and UTC time of the observation (`DDHHMMZ`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct ReportTime {
    /// Day of the month, 1..=31.
    pub day: u8,
    /// Hour, UTC.
    pub hour: u8,
    /// Minute.
    pub minute: u8,
}

/// The wind group.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct WindGroup {
    /// Direction the wind blows from, degrees true; `None` when variable (VRB) or not reported.
    pub dir_deg: Option<u16>,
    /// VRB, or a variable range was given.
    pub variable: bool,
    /// Mean speed, knots (converted from MPS/KMH); 0 when calm.
    pub speed_kt: Option<f32>,
    /// Gust speed, knots.
    pub gust_kt: Option<f32>,
    /// Start of the variable range `dddVddd`, degrees.
    pub var_from: Option<u16>,
    /// End of the variable range, degrees.
    pub var_to: Option<u16>,
}

/// Sky cover of a cloud group.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum Cover {
    /// Few, 1-2 oktas.
    #[serde(rename = "FEW")]
    Few,
    /// Scattered, 3-4 oktas.
    #[serde(rename = "SCT")]
    Sct,
    /// Broken, 5-7 oktas.
    #[serde(rename = "BKN")]
    Bkn,
    /// Overcast, 8 oktas.
    #[serde(rename = "OVC")]
    Ovc,
    /// Vertical visibility (sky obscured), `base_ft` is the vertical visibility.
    #[serde(rename = "VV")]
    Vv,
}

/// Convective cloud named in a cloud group.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum ConvectiveKind {
    /// Cumulonimbus.
    #[serde(rename = "CB")]
    Cb,
    /// Towering cumulus.
    #[serde(rename = "TCU")]
    Tcu,
}

/// One cloud group (`BKN030CB`, `FEW///`, `//////CB`, `VV002`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CloudGroup {
    /// Cover, `None` when the station wrote `///`.
    pub cover: Option<Cover>,
    /// Base (or vertical visibility), feet above ground; `None` for `///`.
    pub base_ft: Option<u32>,
    /// CB or TCU; `None` when absent or `///`.
    pub kind: Option<ConvectiveKind>,
}

/// A report's statement that there is no cloud to report.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum SkyCode {
    /// Clear below 12,000 ft (automatic, US).
    #[serde(rename = "CLR")]
    Clr,
    /// Sky clear.
    #[serde(rename = "SKC")]
    Skc,
    /// No significant cloud.
    #[serde(rename = "NSC")]
    Nsc,
    /// No cloud detected (automatic).
    #[serde(rename = "NCD")]
    Ncd,
    /// The report is NIL (missing).
    #[serde(rename = "NIL")]
    Nil,
}

/// Intensity or proximity of present weather.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Intensity {
    /// `-`
    Light,
    /// no sign
    Moderate,
    /// `+`
    Heavy,
    /// `VC`: in the vicinity, not at the station.
    Vicinity,
}

/// One present-weather group (`-SHRA`, `+TSRAGR`, `BR`, `VCFG`).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct PresentWeather {
    /// Intensity or proximity.
    pub intensity: Intensity,
    /// Descriptor: MI BC PR DR BL SH TS FZ.
    pub descriptor: Option<String>,
    /// Phenomena in order: DZ RA SN SG IC PL GR GS UP BR FG FU VA DU SA HZ PY PO SQ FC SS DS.
    pub phenomena: Vec<String>,
}

/// A decoded METAR/SPECI.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct Report {
    /// ICAO station identifier.
    pub station: String,
    /// Observation time.
    pub time: Option<ReportTime>,
    /// Fully automatic observation (AUTO).
    pub auto: bool,
    /// Corrected report (COR).
    pub corrected: bool,
    /// Wind group.
    pub wind: Option<WindGroup>,
    /// Prevailing visibility, metres (`9999` is 10,000; `P6SM` is 6 statute miles and more).
    pub visibility_m: Option<f32>,
    /// CAVOK: visibility 10 km or more, no cloud below 5,000 ft or the highest minimum sector
    /// altitude, no CB/TCU, no significant weather.
    pub cavok: bool,
    /// No-cloud code (CLR, SKC, NSC, NCD, NIL) when the report gave one.
    pub sky: Option<SkyCode>,
    /// Cloud groups in report order (lowest first, as reported).
    pub clouds: Vec<CloudGroup>,
    /// Present weather groups.
    pub weather: Vec<PresentWeather>,
    /// Air temperature, degrees Celsius.
    pub temperature_c: Option<f32>,
    /// Dewpoint, degrees Celsius.
    pub dewpoint_c: Option<f32>,
    /// Altimeter setting, hectopascals (converted from inches of mercury for `A` groups).
    pub altimeter_hpa: Option<f32>,
    /// Everything after `RMK`, raw; empty when there is none.
    pub remarks: String,
    /// Groups that could not be decoded, each with the group and why.
    pub warnings: Vec<String>,
}

impl std::fmt::Display for ReportTime {
    /// `DDHHMMZ`, as the report writes it.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:02}{:02}{:02}Z", self.day, self.hour, self.minute)
    }
}

impl std::fmt::Display for PresentWeather {
    /// The group as the report writes it (`-SHRA`, `VCTS`, `+TSRAGR`).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let prefix = match self.intensity {
            Intensity::Light => "-",
            Intensity::Moderate => "",
            Intensity::Heavy => "+",
            Intensity::Vicinity => "VC",
        };
        f.write_str(prefix)?;
        if let Some(descriptor) = &self.descriptor {
            f.write_str(descriptor)?;
        }
        for phenomenon in &self.phenomena {
            f.write_str(phenomenon)?;
        }
        Ok(())
    }
}

impl Cover {
    /// The code as the report writes it: FEW, SCT, BKN, OVC, VV.
    pub fn code(self) -> &'static str {
        match self {
            Cover::Few => "FEW",
            Cover::Sct => "SCT",
            Cover::Bkn => "BKN",
            Cover::Ovc => "OVC",
            Cover::Vv => "VV",
        }
    }
}

impl ConvectiveKind {
    /// The code as the report writes it: CB, TCU.
    pub fn code(self) -> &'static str {
        match self {
            ConvectiveKind::Cb => "CB",
            ConvectiveKind::Tcu => "TCU",
        }
    }
}

impl SkyCode {
    /// The code as the report writes it: CLR, SKC, NSC, NCD, NIL.
    pub fn code(self) -> &'static str {
        match self {
            SkyCode::Clr => "CLR",
            SkyCode::Skc => "SKC",
            SkyCode::Nsc => "NSC",
            SkyCode::Ncd => "NCD",
            SkyCode::Nil => "NIL",
        }
    }
}
