//! The data a run reads, opened by the library: the options that name it ([`DataOptions`],
//! [`ImuSource`]), the aiding plan and outages ([`aid`]), the initial state ([`start`]), the
//! opened data set ([`Dataset`]) and the filter set-up the options give ([`setup`]). What
//! `filter` and `explain` do with files, a library caller can do with the same calls.

pub mod aid;
pub mod dataset;
pub mod options;
pub mod setup;
mod start;
pub use start::init_numbers;

pub use aid::{AidPlan, Outage};
pub use dataset::{check_inside, Dataset, PassInputs, DEFAULT_STEP_S};
pub use options::{open_imu, DataOptions, ImuSource};
pub use setup::{apply_opened, noise_given, NoiseGiven};

#[cfg(test)]
mod tests {
    use super::*;

    /// Options with nothing given (the command line's defaults).
    fn none() -> DataOptions {
        DataOptions {
            imu: None,
            imu_format: None,
            clock_offset: None,
            aid: None,
            aid_use: None,
            static_aid: None,
            prior: Vec::new(),
            noise: None,
            truth: None,
            init: None,
            init_speed: None,
            mode: "open".into(),
            step: None,
            zupt: None,
            force: false,
            grade: None,
            outage: Vec::new(),
            gnss_delay: None,
            lever_arm: None,
        }
    }

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
        let mut o = none();
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
        let mut o = none();
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
        let mut o = none();
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

    #[test]
    fn the_distance_check_uses_the_ellipsoid() {
        let lat = 40f64.to_radians();
        // one arcminute of latitude at 40° is about 1.85 km
        let d = dataset::tests_distance(lat, 0.0, 0.0, lat + (1.0f64 / 60.0).to_radians(), 0.0);
        assert!((d - 1850.0).abs() < 5.0, "{d}");
    }
}
