//! Whole reports, most of them from the real bulk file in `weather/`.

use super::*;

fn ok(text: &str) -> Report {
    decode(text).unwrap_or_else(|e| panic!("{text}: {e}"))
}

fn layer(cover: Option<Cover>, base_ft: Option<u32>, kind: Option<ConvectiveKind>) -> CloudGroup {
    CloudGroup {
        cover,
        base_ft,
        kind,
    }
}

#[test]
fn station_time_and_main_body() {
    let r = ok("OPLA 272225Z 33006KT 4000 FU NSC 11/06 Q1011 NOSIG RMK QFE986 A29.88");
    assert_eq!(r.station, "OPLA");
    assert_eq!(
        r.time,
        Some(ReportTime {
            day: 27,
            hour: 22,
            minute: 25
        })
    );
    assert_eq!(r.time.map(|t| t.to_string()).as_deref(), Some("272225Z"));
    assert!(!r.auto && !r.corrected && !r.cavok);
    let wind = r.wind.unwrap_or_default();
    assert_eq!((wind.dir_deg, wind.speed_kt), (Some(330), Some(6.0)));
    assert_eq!(r.visibility_m, Some(4000.0));
    assert_eq!(r.weather.len(), 1);
    assert_eq!(r.weather[0].to_string(), "FU");
    assert_eq!(r.sky, Some(SkyCode::Nsc));
    assert!(r.clouds.is_empty());
    assert_eq!((r.temperature_c, r.dewpoint_c), (Some(11.0), Some(6.0)));
    assert_eq!(r.altimeter_hpa, Some(1011.0));
    assert_eq!(r.remarks, "QFE986 A29.88");
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
}

#[test]
fn us_automatic_report_with_layers() {
    let r = ok("KIKT 272225Z AUTO VRB04KT 10SM SCT028 BKN033 OVC050 22/12 A3011 RMK A01");
    assert!(r.auto);
    let wind = r.wind.unwrap_or_default();
    assert!(wind.variable);
    assert_eq!((wind.dir_deg, wind.speed_kt), (None, Some(4.0)));
    assert_eq!(r.visibility_m, Some(16_093.44));
    assert_eq!(
        r.clouds,
        [
            layer(Some(Cover::Sct), Some(2_800), None),
            layer(Some(Cover::Bkn), Some(3_300), None),
            layer(Some(Cover::Ovc), Some(5_000), None),
        ]
    );
    assert_eq!(r.remarks, "A01");
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
}

#[test]
fn runway_groups_vertical_visibility_and_trend() {
    let r = ok(
        "UWOO 272223Z 15002MPS 0200 0150E R26/0550N FZFG VV001 M03/M03 Q1025 R26/950140 NOSIG RMK QBB050",
    );
    assert_eq!(r.visibility_m, Some(200.0));
    assert_eq!(r.weather[0].to_string(), "FZFG");
    assert_eq!(r.clouds, [layer(Some(Cover::Vv), Some(100), None)]);
    assert_eq!((r.temperature_c, r.dewpoint_c), (Some(-3.0), Some(-3.0)));
    assert_eq!(r.remarks, "QBB050");
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
    // Groups after TEMPO belong to the trend, not the observation.
    let r = ok("URMN 272221Z 24001MPS 2000 BR OVC005 00/M00 Q1024 R24/////// TEMPO 0500 FG OVC001");
    assert_eq!(r.clouds, [layer(Some(Cover::Ovc), Some(500), None)]);
    assert_eq!(r.visibility_m, Some(2000.0));
    assert_eq!(r.weather.len(), 1);
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
}

#[test]
fn missing_cloud_parts_and_cover_less_cb() {
    let r = ok("EGAC 272220Z AUTO VRB02KT 4200 RA FEW007/// OVC042/// //////CB 08/07 Q0969");
    assert_eq!(
        r.clouds,
        [
            layer(Some(Cover::Few), Some(700), None),
            layer(Some(Cover::Ovc), Some(4_200), None),
            layer(None, None, Some(ConvectiveKind::Cb)),
        ]
    );
    let r = ok("LSGS 272220Z AUTO VRB02KT 4700 RA BR BKN/// 05/04 Q1004");
    assert_eq!(r.clouds, [layer(Some(Cover::Bkn), None, None)]);
    assert_eq!(r.weather.len(), 2);
    // Everything missing: no group, no warning.
    let r = ok("EKVD 272220Z AUTO 16007KT //// ///////// 05/04 Q0991");
    assert!(r.clouds.is_empty() && r.visibility_m.is_none());
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
}

#[test]
fn fractions_of_a_mile_and_missing_temperature_halves() {
    let r = ok("CYEK 272213Z 33020KT 1 1/2SM IC BLSN SKC M30/M33 A2962 RMK SLP032");
    assert_eq!(r.visibility_m, Some(2_414.016));
    assert_eq!(r.sky, Some(SkyCode::Skc));
    let texts: Vec<String> = r.weather.iter().map(ToString::to_string).collect();
    assert_eq!(texts, ["IC", "BLSN"]);
    let r = ok("KHTL 272216Z AUTO 25019G31KT M1/4SM -SN BR M02/ A2939");
    assert_eq!(r.visibility_m, Some(402.336));
    assert_eq!((r.temperature_c, r.dewpoint_c), (Some(-2.0), None));
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
}

#[test]
fn cavok_and_variable_range() {
    let r = ok("LIRF 272220Z 18010KT 140V220 CAVOK 12/08 Q1015 NOSIG");
    assert!(r.cavok);
    assert_eq!(r.visibility_m, Some(10_000.0));
    let wind = r.wind.unwrap_or_default();
    assert_eq!(
        (wind.var_from, wind.var_to, wind.variable),
        (Some(140), Some(220), true)
    );
    assert_eq!(wind.dir_deg, Some(180));
}

#[test]
fn nil_report() {
    let r = ok("SVVL 272203Z AUTO NIL");
    assert_eq!(r.sky, Some(SkyCode::Nil));
    assert!(r.auto && r.wind.is_none() && r.clouds.is_empty());
    assert!(r.warnings.is_empty());
}

#[test]
fn prefix_correction_and_end_marker() {
    let r = ok("METAR COR EGLL 272220Z 24012KT 9999 SCT030 09/04 Q0990=");
    assert_eq!(r.station, "EGLL");
    assert!(r.corrected);
    assert_eq!(r.altimeter_hpa, Some(990.0));
    let r = ok("SPECI KJFK 272220Z 24012KT 10SM BKN030 09/04 A2990 RMK AO2 =");
    assert_eq!(r.remarks, "AO2");
}

#[test]
fn malformed_groups_become_warnings() {
    let r = ok("SGES 272200Z 12006KT 9999 SCT030 FEW040TCUBKN070 27/25 Q1009");
    assert_eq!(r.clouds, [layer(Some(Cover::Sct), Some(3_000), None)]);
    assert_eq!(
        r.warnings,
        ["`FEW040TCUBKN070`: cloud type is not CB, TCU or ///"]
    );
    assert_eq!(r.temperature_c, Some(27.0));
    let r = ok("RKSW 2210Z 30007KT 2400 -SN BR FEW000 M04/M04 A2997");
    assert_eq!(r.time, None);
    assert_eq!(r.warnings, ["`2210Z`: time is not DDHHMMZ"]);
    assert_eq!(r.clouds, [layer(Some(Cover::Few), Some(0), None)]);
    let r = ok("VRMG 272200Z 31008KT 9000 FEW018CB BKN110 27/25 Q1006 CB NW NOSIG");
    assert_eq!(r.warnings.len(), 2, "{:?}", r.warnings);
    assert_eq!(r.clouds.len(), 2);
}

#[test]
fn not_a_report() {
    assert_eq!(decode(""), Err(MetarError::Empty));
    assert_eq!(decode("  \n "), Err(MetarError::Empty));
    assert_eq!(decode("METAR"), Err(MetarError::Empty));
    assert_eq!(
        decode("272225Z 33006KT"),
        Err(MetarError::NoStation("272225Z".into()))
    );
    assert!(matches!(
        decode("hello world"),
        Err(MetarError::NoStation(_))
    ));
}

#[test]
fn groups_skipped_quietly() {
    let quiet = [
        "EHJR 272155Z AUTO 19030KT //// // ///////// 09/06 Q0985 RE// W07/H26",
        "EDAC 272150Z AUTO /////KT ///V/// 9999 // OVC180/// 10/04 Q0999",
        "KVGN 272155Z AUTO 32010KT 10SM M 16/05 A3012 RMK AO2",
        "SKBG 272200Z 32005KT 9999 SCT015 SCT070 26/21 Q1011 RESH WS R35",
        "KXXX 272155Z AUTO 32010KT ////SM CLR 16/05 A3012",
        "LFXX 272155Z 32010KT 9999 FEW030 16/05 Q1012 W/////",
        "EGXX 272155Z 32010KT 9999 FEW030 16/05 Q1012 BLU",
        "ESDF 272220Z AUTO 16004KT 0750 0600// R01/1700D R19/1400VP2000N FG FEW005/// 04/04 Q0996",
    ];
    for text in quiet {
        let r = ok(text);
        assert!(r.warnings.is_empty(), "{text}: {:?}", r.warnings);
    }
    let r = ok(quiet[1]);
    assert_eq!(r.wind, None);
    assert_eq!(r.clouds, [layer(Some(Cover::Ovc), Some(18_000), None)]);
    assert_eq!(ok(quiet[7]).visibility_m, Some(750.0));
}

/// Bytes past the third that are not a character boundary (a `€` in a group) make a token that is
/// not a sky group, or a malformed one, never a panic (the split at byte 3 needs both checks).
#[test]
fn a_multibyte_character_in_a_sky_group_is_no_panic() {
    assert!(matches!(sky::parse_sky("F€"), sky::SkyToken::No));
    assert!(matches!(
        sky::parse_sky("FEW0€"),
        sky::SkyToken::Malformed(_)
    ));
    let r = ok("KXYZ 271700Z F€ FEW0€ SCT030 10/05 A2992");
    assert_eq!(r.clouds, [layer(Some(Cover::Sct), Some(3000), None)]);
    assert!(!r.warnings.is_empty());
}
