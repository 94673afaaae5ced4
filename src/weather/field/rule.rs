//! The cloud-type rule, `config/cloud_type_rule.toml`: which [`CloudType`] an interpolated layer
//! is drawn as. A reported CB/TCU decides first; otherwise the first `[[rule]]` of the layer's
//! band whose conditions hold (coverage, precipitation, temperature-dewpoint spread). The shipped
//! file documents the conditions and the choices.

use std::path::Path;

use serde::Deserialize;
use toml::Spanned;

use crate::config::{ConfigError, ShippedFile, TomlSettings};
use crate::weather::cloud_type::CloudType;

/// The shipped rule file, built in.
const BUILTIN: &str = include_str!("../../../config/cloud_type_rule.toml");
const BUILTIN_PATH: &str = "config/cloud_type_rule.toml";

/// Altitude band of a layer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Band {
    /// Cloud on the ground: FG, or VV (sky obscured).
    Fog,
    /// Base below the low band top (6,500 ft AGL by default).
    Low,
    /// Between the low and the high band.
    Middle,
    /// Base above the high band base (20,000 ft AGL by default).
    High,
}

impl Band {
    /// Every band, lowest first.
    pub const ALL: [Band; 4] = [Band::Fog, Band::Low, Band::Middle, Band::High];

    /// The snake_case name.
    pub fn name(self) -> &'static str {
        match self {
            Band::Fog => "fog",
            Band::Low => "low",
            Band::Middle => "middle",
            Band::High => "high",
        }
    }
}

/// What the rule looks at for one layer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LayerFacts {
    /// The layer's band.
    pub band: Band,
    /// Coverage, oktas.
    pub coverage_oktas: f64,
    /// Precipitation intensity 0..=1 at the place.
    pub precipitation: f64,
    /// Temperature minus dewpoint at the place, degrees C.
    pub spread_c: f64,
}

/// Types given to reported convective clouds.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Reported {
    /// Type for a CB.
    pub cb: CloudType,
    /// Type for a TCU.
    pub tcu: CloudType,
}

/// One ordered rule.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Rule {
    /// The band it applies to.
    pub band: Spanned<Band>,
    /// Least coverage, oktas (inclusive).
    #[serde(default)]
    pub min_oktas: Option<f64>,
    /// Coverage below this, oktas (exclusive).
    #[serde(default)]
    pub max_oktas: Option<f64>,
    /// Least precipitation intensity 0..=1.
    #[serde(default)]
    pub min_precipitation: Option<f64>,
    /// Least temperature-dewpoint spread, degrees C (inclusive).
    #[serde(default)]
    pub min_spread_c: Option<f64>,
    /// Spread below this, degrees C (exclusive).
    #[serde(default)]
    pub max_spread_c: Option<f64>,
    /// The type it gives.
    pub cloud_type: CloudType,
}

impl Rule {
    fn has_conditions(&self) -> bool {
        self.min_oktas.is_some()
            || self.max_oktas.is_some()
            || self.min_precipitation.is_some()
            || self.min_spread_c.is_some()
            || self.max_spread_c.is_some()
    }

    fn matches(&self, f: &LayerFacts) -> bool {
        *self.band.get_ref() == f.band
            && self.min_oktas.is_none_or(|m| f.coverage_oktas >= m)
            && self.max_oktas.is_none_or(|m| f.coverage_oktas < m)
            && self.min_precipitation.is_none_or(|m| f.precipitation >= m)
            && self.min_spread_c.is_none_or(|m| f.spread_c >= m)
            && self.max_spread_c.is_none_or(|m| f.spread_c < m)
    }
}

/// The whole rule file.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CloudTypeRule {
    /// Types of reported CB/TCU.
    pub reported: Reported,
    /// Ordered rules; the first match of a layer's band wins.
    #[serde(rename = "rule")]
    pub rules: Vec<Rule>,
}

impl TomlSettings for CloudTypeRule {
    const SHIPPED: Option<ShippedFile> = ShippedFile::at(BUILTIN_PATH, BUILTIN);

    /// Every band has a rule without conditions.
    fn check(&self, path: &Path, text: &str) -> Result<(), ConfigError> {
        for band in Band::ALL {
            let of_band: Vec<&Rule> = self
                .rules
                .iter()
                .filter(|r| *r.band.get_ref() == band)
                .collect();
            if of_band.iter().any(|r| !r.has_conditions()) {
                continue;
            }
            let message = format!(
                "band `{}` has no rule without conditions, so some layers would get no type; \
                 end its rules with one that has only `band` and `cloud_type`",
                band.name()
            );
            return Err(match of_band.last() {
                Some(last) => ConfigError::at(path, text, last.band.span(), "rule.band", message),
                None => ConfigError {
                    path: path.to_path_buf(),
                    line: None,
                    field: Some("rule".to_string()),
                    message,
                },
            });
        }
        Ok(())
    }
}

impl CloudTypeRule {
    /// The type of a layer that carries no reported CB/TCU.
    pub fn height_rule_type(&self, facts: &LayerFacts) -> CloudType {
        self.rules
            .iter()
            .find(|r| r.matches(facts))
            .map(|r| r.cloud_type)
            // Unreachable after validation; fog is the safe, visible answer.
            .unwrap_or(CloudType::Fog)
    }
}

impl Default for CloudTypeRule {
    /// The shipped `config/cloud_type_rule.toml` (a test proves it parses).
    fn default() -> Self {
        Self::shipped()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn facts(band: Band, coverage_oktas: f64, precipitation: f64, spread_c: f64) -> LayerFacts {
        LayerFacts {
            band,
            coverage_oktas,
            precipitation,
            spread_c,
        }
    }

    #[test]
    fn the_shipped_rule_types_each_band() {
        let r = CloudTypeRule::default();
        let t = |f| r.height_rule_type(&f);
        assert_eq!(t(facts(Band::Fog, 8.0, 0.0, 0.0)), CloudType::Fog);
        assert_eq!(
            t(facts(Band::Low, 2.0, 0.0, 3.0)),
            CloudType::CumulusHumilis
        );
        assert_eq!(
            t(facts(Band::Low, 4.0, 0.0, 12.0)),
            CloudType::CumulusMediocris
        );
        assert_eq!(t(facts(Band::Low, 6.0, 0.0, 3.0)), CloudType::Stratocumulus);
        assert_eq!(t(facts(Band::Low, 8.0, 0.0, 1.0)), CloudType::Stratus);
        assert_eq!(t(facts(Band::Low, 8.0, 0.67, 1.0)), CloudType::Nimbostratus);
        assert_eq!(
            t(facts(Band::Middle, 4.0, 0.0, 5.0)),
            CloudType::Altocumulus
        );
        assert_eq!(
            t(facts(Band::Middle, 6.0, 0.0, 5.0)),
            CloudType::Altostratus
        );
        assert_eq!(t(facts(Band::High, 2.0, 0.0, 5.0)), CloudType::Cirrus);
        assert_eq!(t(facts(Band::High, 6.0, 0.0, 5.0)), CloudType::Cirrocumulus);
        assert_eq!(t(facts(Band::High, 8.0, 0.0, 5.0)), CloudType::Cirrostratus);
        assert_eq!(r.reported.cb, CloudType::Cumulonimbus);
        assert_eq!(r.reported.tcu, CloudType::CumulusCongestus);
    }

    #[test]
    fn an_unknown_cloud_type_names_line_and_field() {
        let text = BUILTIN.replace("cloud_type = \"stratocumulus\"", "cloud_type = \"cumulus\"");
        let err = CloudTypeRule::parse(&text, Path::new("rule.toml")).unwrap_err();
        let line = text
            .lines()
            .position(|l| l == "cloud_type = \"cumulus\"")
            .unwrap()
            + 1;
        assert_eq!(err.line, Some(line), "{err}");
        assert_eq!(err.field.as_deref(), Some("cloud_type"), "{err}");
        assert!(err.to_string().starts_with("rule.toml:"), "{err}");
        assert!(err.message.contains("unknown variant"), "{err}");
    }

    #[test]
    fn unknown_fields_and_bands_are_errors() {
        let text = BUILTIN.replace("min_spread_c = 8.0", "min_sprad_c = 8.0");
        let err = CloudTypeRule::parse(&text, Path::new("rule.toml")).unwrap_err();
        assert_eq!(err.field.as_deref(), Some("min_sprad_c"), "{err}");
        let text = BUILTIN.replace("band = \"middle\"", "band = \"mid\"");
        let err = CloudTypeRule::parse(&text, Path::new("rule.toml")).unwrap_err();
        assert_eq!(err.field.as_deref(), Some("band"), "{err}");
        assert!(err.line.is_some());
    }

    #[test]
    fn a_band_without_a_catch_all_is_an_error_at_its_last_rule() {
        let text = "[reported]\ncb = \"cumulonimbus\"\ntcu = \"cumulus_congestus\"\n\
[[rule]]\nband = \"fog\"\ncloud_type = \"fog\"\n\
[[rule]]\nband = \"low\"\nmin_oktas = 5.0\ncloud_type = \"stratus\"\n";
        let err = CloudTypeRule::parse(text, Path::new("rule.toml")).unwrap_err();
        assert_eq!(err.line, Some(8), "{err}");
        assert_eq!(err.field.as_deref(), Some("rule.band"));
        assert!(err.message.contains("band `low`"), "{err}");
        // A band with no rule at all has no line to point at.
        let text = text.replace("min_oktas = 5.0\n", "");
        let err = CloudTypeRule::parse(&text, Path::new("rule.toml")).unwrap_err();
        assert_eq!(err.line, None);
        assert!(err.message.contains("band `middle`"), "{err}");
    }
}
