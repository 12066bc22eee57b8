//! The data a run reads, opened by the library: the options that name it ([`DataOptions`],
//! [`ImuSource`]), the aiding plan and outages ([`aid`]), the initial state ([`start`]), the
//! opened data set ([`Dataset`]) and the filter set-up the options give ([`setup`]). What
//! `filter` and `explain` do with files, a library caller can do with the same calls.

pub mod aid;
pub mod dataset;
pub mod options;
pub mod setup;
mod start;
pub use start::{init_numbers, init_value_problem};

pub use aid::{AidPlan, Outage};
pub use dataset::{check_inside, Dataset, PassInputs, DEFAULT_STEP_S};
pub use options::{open_imu, DataOptions, ImuSource};
pub use setup::{apply_opened, noise_given, NoiseGiven};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_states_a_bias_random_walk_inline_with_units_checked() {
        let p = std::path::Path::new(
            "arw=0.3 deg/sqrt(h), vrw=150 ug/sqrt(Hz), gyro_bias_rw=10 deg/h/sqrt(h)",
        );
        let n = noise_given(p).unwrap();
        let want = 10.0f64.to_radians() / 3600.0 / 60.0;
        assert!(
            (n.gyro_bias_rw / want - 1.0).abs() < 1e-12,
            "{n:?} vs {want}"
        );
        assert_eq!(n.accel_bias_rw, 0.0);
        assert_eq!(n.arw, 0.3f64.to_radians() / 60.0);
        // 10 rad/s/√s is a unit slip (deg/h read as rad/s): refused, naming the option
        let bad = std::path::Path::new(
            "arw=0.3 deg/sqrt(h), vrw=150 ug/sqrt(Hz), gyro_bias_rw=10 rad/s/sqrt(s)",
        );
        let e = noise_given(bad).unwrap_err().to_string();
        assert!(e.contains("--noise gyro_bias_rw"), "{e}");
        let e = noise_given(std::path::Path::new(
            "arw=1 deg/sqrt(h), vrw=1 ug/sqrt(Hz), accel_bias_rw=3 deg",
        ))
        .unwrap_err()
        .to_string();
        assert!(e.contains("accel_bias_rw"), "{e}");
        // a key given twice is refused, not the last one taken
        let twice =
            std::path::Path::new("arw=0.3 deg/sqrt(h), arw=3 deg/sqrt(h), vrw=1 ug/sqrt(Hz)");
        let e = noise_given(twice).unwrap_err().to_string();
        assert!(e.contains("`arw` given twice"), "{e}");
    }

    #[test]
    fn outages_are_sorted_from_the_first_sample_and_overlaps_refused() {
        let mut o = DataOptions::none();
        o.outage = vec!["100,20".into(), "10,5".into()];
        let w = o.outages(1000.0).unwrap();
        assert_eq!(w.len(), 2);
        assert_eq!((w[0].start_s, w[0].end_s), (1010.0, 1015.0));
        assert_eq!((w[1].start_s, w[1].end_s), (1100.0, 1120.0));
        assert!(w[0].contains(1010.0) && !w[0].contains(1015.0));
        o.outage = vec!["10,20".into(), "25,5".into()];
        let e = o.outages(0.0).unwrap_err().to_string();
        assert!(e.contains("overlap"), "{e}");
        o.outage = vec!["-1,5".into()];
        assert!(o
            .outages(0.0)
            .unwrap_err()
            .to_string()
            .contains("START >= 0"));
    }

    #[test]
    fn a_static_aid_is_checked_and_starts_at_the_next_whole_second() {
        let mut o = DataOptions::none();
        o.static_aid = Some(vec![40.0, -105.0, 1600.0]);
        match o.aid_plan(12.3).unwrap() {
            AidPlan::Static { first_s, zupt, fix } => {
                assert_eq!(first_s, 13.0);
                assert!(zupt.is_some(), "a static vehicle gets ZUPTs");
                assert!((fix.lat - 40f64.to_radians()).abs() < 1e-15);
            }
            _ => panic!("expected a static plan"),
        }
        o.static_aid = Some(vec![95.0, 0.0, 0.0]);
        assert!(o
            .aid_plan(0.0)
            .unwrap_err()
            .to_string()
            .starts_with("--static-aid"));
        o.static_aid = None;
        let e = o.aid_plan(0.0).unwrap_err().to_string();
        assert!(e.contains("no aiding"), "{e}");
        o.zupt = Some(-1.0);
        assert!(o
            .aid_plan(0.0)
            .unwrap_err()
            .to_string()
            .starts_with("--zupt"));
    }

    #[test]
    fn priors_by_pattern_override_the_grade_and_are_checked() {
        let model = crate::model::Model::parse("P28").unwrap();
        let mut o = DataOptions::none();
        let nav = o.config(&model, false).unwrap();
        o.grade = Some("mems".into());
        let mems = o.config(&model, false).unwrap();
        let eps = model.index_of("eps_x").unwrap();
        assert!(
            mems.prior_sigma[eps] > 100.0 * nav.prior_sigma[eps],
            "MEMS gyro bias prior"
        );
        o.prior = vec!["eps_*=0.5 deg/s".into()];
        let c = o.config(&model, false).unwrap();
        for n in ["eps_x", "eps_y", "eps_z"] {
            let i = model.index_of(n).unwrap();
            assert!((c.prior_sigma[i] - 0.5f64.to_radians()).abs() < 1e-15);
        }
        o.prior = vec!["nope_*=1".into()];
        assert!(o.config(&model, false).is_err());
        assert!(
            o.config(&model, true).is_ok(),
            "lenient: a prior for another model"
        );
        o.prior = vec!["eps_x=-1 deg/h".into()];
        assert!(o
            .config(&model, false)
            .unwrap_err()
            .to_string()
            .contains("positive"));
    }

    /// "Nothing lost, nothing silent": a specific `--prior` wins over a wildcard whatever the
    /// order, a name given twice is refused naming both values, and an attitude prior of 90° or
    /// more (beyond the small-angle model) is refused with the reason.
    #[test]
    fn the_most_specific_prior_wins_and_conflicts_are_refused() {
        let model = crate::model::Model::parse("P28").unwrap();
        let (x, y) = (
            model.index_of("eps_x").unwrap(),
            model.index_of("eps_y").unwrap(),
        );
        let deg_h = 1f64.to_radians() / 3600.0;
        let mut o = DataOptions::none();
        for order in [
            ["eps_x=1 deg/h", "eps_*=10 deg/h"],
            ["eps_*=10 deg/h", "eps_x=1 deg/h"],
        ] {
            o.prior = order.iter().map(|s| s.to_string()).collect();
            let c = o.config(&model, false).unwrap();
            assert!((c.prior_sigma[x] / deg_h - 1.0).abs() < 1e-9, "{order:?}");
            assert!((c.prior_sigma[y] / deg_h - 10.0).abs() < 1e-9, "{order:?}");
        }
        // a longer prefix is more specific than a shorter one
        o.prior = vec!["eps_x*=2 deg/h".into(), "eps*=20 deg/h".into()];
        let c = o.config(&model, false).unwrap();
        assert!((c.prior_sigma[x] / deg_h - 2.0).abs() < 1e-9);
        assert!((c.prior_sigma[y] / deg_h - 20.0).abs() < 1e-9);
        // explain's term priors follow the same rule
        o.prior = vec!["eps_x=1 deg/h".into(), "eps_*=10 deg/h".into()];
        let terms = o.term_priors().unwrap();
        let t = crate::model::generated::common::TERMS
            .iter()
            .position(|t| t.name == "eps_x")
            .unwrap();
        let (_, si) = terms.iter().find(|(k, _)| *k == t).unwrap();
        assert!((si / deg_h - 1.0).abs() < 1e-9);
        for p in [
            vec!["eps_x=1 deg/h", "eps_x=2 deg/h"],
            vec!["eps_*=1 deg/h", " eps_* = 2 deg/h"],
        ] {
            o.prior = p.iter().map(|s| s.to_string()).collect();
            for e in [
                o.config(&model, false).unwrap_err().to_string(),
                o.term_priors().unwrap_err().to_string(),
            ] {
                assert!(
                    e.contains("given twice") && e.contains("`1 deg/h`") && e.contains("`2 deg/h`"),
                    "{e}"
                );
            }
        }
        o.prior = vec!["phi_d=180 deg".into()];
        let e = o.config(&model, false).unwrap_err().to_string();
        assert!(e.contains("phi_d") && e.contains("small"), "{e}");
        o.prior = vec!["phi_*=1.6 rad".into()];
        assert!(o.config(&model, false).is_err(), "91.7 deg by a wildcard");
        o.prior = vec!["phi_d=60 deg".into()];
        let c = o.config(&model, false).unwrap();
        let d = model.index_of("phi_d").unwrap();
        assert!((c.prior_sigma[d] - 60f64.to_radians()).abs() < 1e-12);
    }

    /// An allan JSON's declared units are honoured (deg/√h is not read as rad/√s), a unit of
    /// the wrong kind or a missing entry beside others refused naming the key, and a key twice
    /// refused naming it (serde_json would keep the last).
    #[test]
    fn a_noise_file_is_read_in_its_declared_units_and_with_unique_keys() {
        let dir = tempfile::tempdir().unwrap();
        let file = |name: &str, white_g: f64, gyro_unit: &str, extra: &str| {
            let ch = |n: &str, w: f64| format!("\"{n}\": {{\"white\": {w}}}");
            let fit = ["x", "y", "z"]
                .iter()
                .map(|a| {
                    format!(
                        "{}, {}",
                        ch(&format!("gyro_{a}"), white_g),
                        ch(&format!("accel_{a}"), 1e-4)
                    )
                })
                .collect::<Vec<_>>()
                .join(", ");
            let units = ["x", "y", "z"]
                .iter()
                .filter(|a| !(extra == "no gyro_z unit" && **a == "z"))
                .map(|a| format!("\"gyro_{a}\": \"{gyro_unit}\", \"accel_{a}\": \"m/s^2 (fit: white m/s/sqrt(s), random_walk m/s^2/sqrt(s))\""))
                .collect::<Vec<_>>()
                .join(", ");
            let dup = if extra == "dup" { "\"fit\": {}, " } else { "" };
            let p = dir.path().join(name);
            std::fs::write(
                &p,
                format!("{{{dup}\"fit\": {{{fit}}},\n\"units\": {{{units}}}}}"),
            )
            .unwrap();
            p
        };
        let deg = file(
            "deg.json",
            0.01,
            "deg/h (fit: white deg/sqrt(h), random_walk deg/h/sqrt(h))",
            "",
        );
        let n = noise_given(&deg).unwrap();
        let want = 0.01f64.to_radians() / 60.0;
        assert!((n.arw / want - 1.0).abs() < 1e-12, "{} vs {want}", n.arw);
        assert!((n.vrw - 1e-4).abs() < 1e-16);
        let si = file(
            "si.json",
            want,
            "rad/s (fit: white rad/sqrt(s), random_walk rad/s/sqrt(s))",
            "",
        );
        assert!((noise_given(&si).unwrap().arw / want - 1.0).abs() < 1e-12);
        let alone = file("alone.json", 0.01, "deg/sqrt(h)", "");
        assert!((noise_given(&alone).unwrap().arw / want - 1.0).abs() < 1e-12);
        let wrong = file("wrong.json", 0.01, "deg/h", "");
        let e = noise_given(&wrong).unwrap_err().to_string();
        assert!(
            e.contains("wrong.json") && e.contains("units.gyro_x"),
            "{e}"
        );
        let partial = file("partial.json", 0.01, "deg/sqrt(h)", "no gyro_z unit");
        let e = noise_given(&partial).unwrap_err().to_string();
        assert!(e.contains("partial.json") && e.contains("gyro_z"), "{e}");
        let dup = file("dup.json", 0.01, "deg/sqrt(h)", "dup");
        let e = noise_given(&dup).unwrap_err().to_string();
        assert!(
            e.contains("dup.json") && e.contains("key `fit` given twice"),
            "{e}"
        );
        // a file without `units` is read in SI, and the run says so
        let bare = dir.path().join("bare.json");
        let fit = ["gyro", "accel"]
            .iter()
            .flat_map(|k| ["x", "y", "z"].map(|a| format!("\"{k}_{a}\": {{\"white\": 1e-4}}")))
            .collect::<Vec<_>>()
            .join(", ");
        std::fs::write(&bare, format!("{{\"fit\": {{{fit}}}}}")).unwrap();
        let said = |path: &std::path::Path| {
            let mut o = DataOptions::none();
            o.noise = Some(path.to_path_buf());
            o.noise_lines().unwrap().join("\n")
        };
        let lines = said(&bare);
        assert!(
            lines.contains("warning: --noise") && lines.contains("no `units` entry"),
            "{lines}"
        );
        assert!(!said(&si).contains("warning"), "{}", said(&si));
    }

    #[test]
    fn the_distance_check_uses_the_ellipsoid() {
        let lat = 40f64.to_radians();
        // one arcminute of latitude at 40° is about 1.85 km
        let d = dataset::tests_distance(lat, 0.0, 0.0, lat + (1.0f64 / 60.0).to_radians(), 0.0);
        assert!((d - 1850.0).abs() < 5.0, "{d}");
    }
}
