//! Tests of `config`: the shipped cloud types load, and every wrong value is named.

use super::*;

const FILE: &str = "cloud_types.toml";

/// The shipped file with the first occurrence of `from` (after `[section]`) replaced.
fn edited(section: &str, from: &str, to: &str) -> String {
    let text = BUILTIN_CLOUD_TYPES;
    let start = text.find(&format!("[{section}]")).expect("section exists");
    let at = start + text[start..].find(from).expect("text exists in section");
    format!("{}{}{}", &text[..at], to, &text[at + from.len()..])
}

fn error_of(text: &str) -> (usize, String, String) {
    match CloudTypes::parse(text, Path::new(FILE)) {
        Err(CloudsError::Parse {
            line,
            field,
            message,
            ..
        })
        | Err(CloudsError::Invalid {
            line,
            field,
            message,
            ..
        }) => (line, field, message),
        other => panic!("expected a parse or invalid error, got {other:?}"),
    }
}

fn line_containing(text: &str, section: &str, needle: &str) -> usize {
    let start = text.find(&format!("[{section}]")).unwrap();
    let at = start + text[start..].find(needle).unwrap();
    text[..at].matches('\n').count() + 1
}

#[test]
fn the_shipped_files_are_valid_and_cover_every_type() {
    let types = CloudTypes::builtin();
    for t in CloudType::ALL {
        assert!(!types.get(t).texture_bands.is_empty());
    }
    assert!(types.get(CloudType::Cirrus).flat);
    assert!(types.get(CloudType::Stratus).continuous);
    assert!(types.get(CloudType::Cumulonimbus).anvil.is_some());
    let c = CloudsConfig::builtin();
    assert_eq!(c.lifecycle.inner_radius_fraction, 0.5);
}

/// Every deck's top seen from above is a thick cloud's, white in the sun whatever the type
/// (its greys are in its body below): the top colour level of each type laid as a deck on
/// the lattice is at least 0.85 grey. A nimbostratus top of 0.74 read from FL350 as a grey
/// patch in a stratus overcast.
#[test]
fn every_decks_top_is_a_thick_clouds() {
    let types = CloudTypes::builtin();
    for t in CloudType::ALL {
        let c = types.get(t);
        if c.sunlit_depth_m.is_none() {
            continue;
        }
        let top = c.colour_levels.last().map_or([0.0; 4], |l| l.rgba);
        let grey = 0.2126 * top[0] + 0.7152 * top[1] + 0.0722 * top[2];
        assert!(grey >= 0.85, "{t:?}: its deck's top is {grey} grey");
    }
}

#[test]
fn every_out_of_range_field_is_named_with_its_line() {
    // (section, text to replace, replacement, field named in the error)
    let cases = [
        (
            "stratus",
            "thickness_m = [150.0, 600.0]",
            "thickness_m = [600.0, 150.0]",
            "thickness_m",
        ),
        (
            "stratus",
            "cloud_size_m = [1500.0, 1800.0]",
            "cloud_size_m = [0.0, 1800.0]",
            "cloud_size_m",
        ),
        (
            "stratus",
            "lattice_spacing_m = 1000.0",
            "lattice_spacing_m = 5.0",
            "lattice_spacing_m",
        ),
        (
            "cumulus_humilis",
            "boxes_per_cloud = [2, 3]",
            "boxes_per_cloud = [0, 3]",
            "boxes_per_cloud",
        ),
        ("cumulus_humilis", "taper = 0.3", "taper = 1.5", "taper"),
        (
            "cumulus_congestus",
            "max_height_over_size = 2.0",
            "max_height_over_size = 0.0",
            "max_height_over_size",
        ),
        (
            "cumulonimbus",
            "anvil = { from = 0.8,",
            "anvil = { from = 1.2,",
            "anvil",
        ),
        (
            "cirrus",
            "streak_length_over_width = 5.0",
            "streak_length_over_width = 0.5",
            "streak_length_over_width",
        ),
        ("cumulus_humilis", "few = 40", "few = 10", "boxes_per_block"),
        (
            "cumulus_humilis",
            "ovc = 200",
            "ovc = 201",
            "boxes_per_block",
        ),
        (
            "cumulus_humilis",
            "sprites_per_box = [10, 18]",
            "sprites_per_box = [10, 101]",
            "sprites_per_box",
        ),
        (
            "cumulus_humilis",
            "sprite_width_m = [160.0, 300.0]",
            "sprite_width_m = [300.0, 160.0]",
            "sprite_width_m",
        ),
        (
            "stratus",
            "sprite_height_ratio = [0.45, 0.7]",
            "sprite_height_ratio = [0.45, 1.6]",
            "sprite_height_ratio",
        ),
        (
            "cumulus_humilis",
            "cull_radius_fraction = 0.333",
            "cull_radius_fraction = -0.1",
            "cull_radius_fraction",
        ),
        (
            "cumulus_humilis",
            "shading_group_size = [3, 10]",
            "shading_group_size = [3, 31]",
            "shading_group_size",
        ),
        (
            "cumulus_humilis",
            "{ up_to = 0.2,",
            "{ up_to = 1.2,",
            "texture_bands",
        ),
        (
            "cumulus_humilis",
            "{ up_to = 1.0, textures = [\"puffy\"]",
            "{ up_to = 0.9, textures = [\"puffy\"]",
            "texture_bands",
        ),
        (
            "cumulus_humilis",
            "textures = [\"flat_bottom\", \"foggy\"]",
            "textures = []",
            "texture_bands",
        ),
        (
            "cumulus_humilis",
            "rotation_deg = [-5.0, 5.0]",
            "rotation_deg = [5.0, -5.0]",
            "texture_bands",
        ),
        (
            "cumulus_humilis",
            "{ height = 0.25,",
            "{ height = 1.25,",
            "colour_levels",
        ),
        (
            "cumulus_humilis",
            "rgba = [0.86, 0.87, 0.90, 1.0]",
            "rgba = [0.86, 0.87, 0.90, 2.0]",
            "colour_levels",
        ),
    ];
    for (section, from, to, field) in cases {
        let text = edited(section, from, to);
        let (line, named, message) = error_of(&text);
        let key = from.split([' ', '=']).next().unwrap();
        let expected_line = if key == "density_by_cover" {
            line_containing(&text, section, key)
        } else if named.ends_with("colour_levels") {
            line_containing(&text, section, "colour_levels")
        } else if ["few", "ovc"].contains(&key) {
            line_containing(&text, section, "boxes_per_block")
        } else if key == "{" || key == "textures" || key == "rotation_deg" {
            line_containing(&text, section, "texture_bands")
        } else {
            line_containing(&text, section, key)
        };
        assert_eq!(
            named,
            format!("{section}.{field}"),
            "{from} -> {to}: {message}"
        );
        assert_eq!(line, expected_line, "{from} -> {to}: {message}");
        let shown = CloudTypes::parse(&text, Path::new(FILE))
            .unwrap_err()
            .to_string();
        assert!(
            shown.starts_with(&format!("{FILE}:{line}: field `{section}.{field}`")),
            "{shown}"
        );
    }
}

#[test]
fn a_type_without_texture_bands_is_refused() {
    let start = BUILTIN_CLOUD_TYPES.find("[fog]").unwrap();
    let at = start
        + BUILTIN_CLOUD_TYPES[start..]
            .find("texture_bands = [")
            .unwrap();
    let end = at + BUILTIN_CLOUD_TYPES[at..].find("\n]\n").unwrap() + 3;
    let text = format!(
        "{}texture_bands = []\n{}",
        &BUILTIN_CLOUD_TYPES[..at],
        &BUILTIN_CLOUD_TYPES[end..]
    );
    let (line, field, message) = error_of(&text);
    assert_eq!(field, "fog.texture_bands", "{message}");
    assert_eq!(line, line_containing(&text, "fog", "texture_bands"));
}

#[test]
fn toml_faults_name_line_and_field() {
    // Missing field: the error points at the section and names the field.
    let text = edited("fog", "taper = 0.0\n", "");
    let (line, field, message) = error_of(&text);
    assert!(
        field.ends_with("taper") && message.contains("missing"),
        "{field}: {message}"
    );
    assert!(
        line >= line_containing(&text, "fog", "[fog]"),
        "line {line}"
    );
    // Unknown field.
    let text = edited("fog", "taper = 0.0", "taper = 0.0\nwobble = 1");
    let (line, field, message) = error_of(&text);
    assert_eq!(
        (line, field.as_str()),
        (line_containing(&text, "fog", "wobble"), "fog.wobble"),
        "{message}"
    );
    // Wrong type.
    let text = edited("fog", "taper = 0.0", "taper = \"steep\"");
    let (line, field, _) = error_of(&text);
    assert_eq!(
        (line, field.as_str()),
        (line_containing(&text, "fog", "taper"), "fog.taper")
    );
    // Wrong number of colour levels.
    let text = edited(
        "fog",
        "  { height = 1.0, rgba = [0.88, 0.89, 0.91, 0.4] },\n",
        "",
    );
    let (line, field, _) = error_of(&text);
    assert_eq!(
        (line, field.as_str()),
        (
            line_containing(&text, "fog", "colour_levels"),
            "fog.colour_levels"
        )
    );
    // Unknown texture category.
    let text = edited("fog", "textures = [\"foggy\"]", "textures = [\"smoky\"]");
    let (line, _, message) = error_of(&text);
    assert_eq!(line, line_containing(&text, "fog", "smoky"), "{message}");
    // Not TOML at all.
    let (line, _, _) = error_of("[fog]\ncontinuous = = true\n");
    assert_eq!(line, 2);
    // A section for a type that does not exist.
    let text = format!("{BUILTIN_CLOUD_TYPES}\n[cumulus_giganticus]\n");
    let (line, field, _) = error_of(&text);
    assert_eq!(field, "cumulus_giganticus");
    assert_eq!(line, text.lines().count());
}

#[test]
fn a_missing_type_section_or_file_is_an_error() {
    let start = BUILTIN_CLOUD_TYPES.find("[fog]").unwrap();
    let text = &BUILTIN_CLOUD_TYPES[..start];
    match CloudTypes::parse(text, Path::new(FILE)) {
        Err(e @ CloudsError::MissingType { .. }) => {
            assert_eq!(
                e.to_string(),
                "cloud_types.toml: no section `[fog]`: every cloud type needs one"
            )
        }
        other => panic!("{other:?}"),
    }
    let missing = Path::new("/nonexistent/cloud_types.toml");
    assert!(matches!(
        CloudTypes::load(missing),
        Err(CloudsError::Read { .. })
    ));
    assert!(matches!(
        CloudsConfig::load(missing),
        Err(CloudsError::Read { .. })
    ));
}

#[test]
fn clouds_toml_faults_name_line_and_field() {
    let cases = [
        (
            "formation_s = 600.0",
            "formation_s = 0.0",
            "lifecycle.formation_s",
        ),
        (
            "dissipation_s = 480.0",
            "dissipation_s = -1.0",
            "lifecycle.dissipation_s",
        ),
        (
            "inner_radius_fraction = 0.5",
            "inner_radius_fraction = 1.0",
            "lifecycle.inner_radius_fraction",
        ),
        (
            "outer_start_opacity = 0.6",
            "outer_start_opacity = 0.0",
            "lifecycle.outer_start_opacity",
        ),
        ("radius_m = 100000.0", "radius_m = 0.0", "field.radius_m"),
        (
            "wind_factor = 1.5",
            "wind_factor = -2.0",
            "field.wind_factor",
        ),
        ("seed = 2003", "seed = \"x\"", "field.seed"),
        (
            "wind_factor = 1.5",
            "wind_factor = 1.5\ngust = 3",
            "field.gust",
        ),
    ];
    for (from, to, field) in cases {
        let text = BUILTIN_CLOUDS.replacen(from, to, 1);
        let key = field.split('.').nth(1).unwrap();
        let expected = text[..text.find(&format!("{key} =")).unwrap()]
            .matches('\n')
            .count()
            + 1;
        match CloudsConfig::parse(&text, Path::new("clouds.toml")) {
            Err(CloudsError::Invalid { line, field: f, .. })
            | Err(CloudsError::Parse { line, field: f, .. }) => {
                assert_eq!((line, f.as_str()), (expected, field), "{to}");
            }
            other => panic!("{to}: {other:?}"),
        }
    }
}
