//! The cloud types skycast knows. The weather stage chooses one per layer (from a reported CB/TCU,
//! a remark, a theme or the height rule of `config/cloud_type_rule.toml`); the clouds stage reads
//! each type's shape from `config/cloud_types.toml`. Names are the snake_case WMO genus/species.

use serde::{Deserialize, Serialize};

/// A cloud type: the WMO genera a pilot would name, split into species where they look different.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CloudType {
    /// Fair-weather cumulus, wider than tall.
    CumulusHumilis,
    /// Cumulus about as tall as wide.
    CumulusMediocris,
    /// Towering cumulus (TCU).
    CumulusCongestus,
    /// Thunderstorm tower with an anvil (CB).
    Cumulonimbus,
    /// Lumpy low layer in rolls or patches.
    Stratocumulus,
    /// Grey, featureless low deck.
    Stratus,
    /// Thick dark deck with continuous precipitation.
    Nimbostratus,
    /// Mid-level heaped patches.
    Altocumulus,
    /// Mid-level grey sheet.
    Altostratus,
    /// High wispy filaments.
    Cirrus,
    /// High rippled small puffs.
    Cirrocumulus,
    /// High thin veil.
    Cirrostratus,
    /// Cloud on the ground.
    Fog,
}

impl CloudType {
    /// Every type, in declaration order.
    pub const ALL: [CloudType; 13] = [
        CloudType::CumulusHumilis,
        CloudType::CumulusMediocris,
        CloudType::CumulusCongestus,
        CloudType::Cumulonimbus,
        CloudType::Stratocumulus,
        CloudType::Stratus,
        CloudType::Nimbostratus,
        CloudType::Altocumulus,
        CloudType::Altostratus,
        CloudType::Cirrus,
        CloudType::Cirrocumulus,
        CloudType::Cirrostratus,
        CloudType::Fog,
    ];

    /// The snake_case name used in TOML, JSON and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            CloudType::CumulusHumilis => "cumulus_humilis",
            CloudType::CumulusMediocris => "cumulus_mediocris",
            CloudType::CumulusCongestus => "cumulus_congestus",
            CloudType::Cumulonimbus => "cumulonimbus",
            CloudType::Stratocumulus => "stratocumulus",
            CloudType::Stratus => "stratus",
            CloudType::Nimbostratus => "nimbostratus",
            CloudType::Altocumulus => "altocumulus",
            CloudType::Altostratus => "altostratus",
            CloudType::Cirrus => "cirrus",
            CloudType::Cirrocumulus => "cirrocumulus",
            CloudType::Cirrostratus => "cirrostratus",
            CloudType::Fog => "fog",
        }
    }

    /// The type with this snake_case name, if any.
    pub fn from_name(name: &str) -> Option<CloudType> {
        CloudType::ALL.into_iter().find(|t| t.name() == name)
    }
}

impl std::fmt::Display for CloudType {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_match_serde() {
        for t in CloudType::ALL {
            assert_eq!(CloudType::from_name(t.name()), Some(t));
            assert_eq!(
                serde_json::to_string(&t).unwrap(),
                format!("\"{}\"", t.name())
            );
        }
        assert_eq!(CloudType::from_name("cumulus"), None);
    }
}
