//! Static alignment on simulated data of known attitude and on the real RLG log.

use sinsmodel::estimate::align::align;
use sinsmodel::io::readers::psins;
use sinsmodel::sim::scenario::Scenario;
use sinsmodel::sim::simulator::simulate;
use std::path::PathBuf;

const D: f64 = std::f64::consts::PI / 180.0;

#[test]
fn simulated_static_alignment_recovers_attitude_and_latitude() {
    let sc = Scenario::parse(
        "name = \"al\"\nimu_rate_hz = 100.0\nseed = 2\n[start]\nlat_deg = 45.0\nlon_deg = 7.0\neuler_deg = [1.0, -2.0, 30.0]\n\
         [[segment]]\nkind = \"rest\"\nduration_s = 1200.0\n[errors]\neps_x = \"0.005 deg/h\"\nnabla_x = \"20 ug\"\n\
         [noise]\narw = \"0.003 deg/sqrt(h)\"\nvrw = \"10 ug/sqrt(Hz)\"\n",
        "align",
    )
    .unwrap();
    let sim = simulate(&sc, |_| {});
    let a = align(&sim.imu, None, None, 7.0 * D, 0.0, 0.01 * D / 3600.0).unwrap();
    eprintln!("{a:?}");
    assert!((a.roll_deg - 1.0).abs() < 0.01 && (a.pitch_deg + 2.0).abs() < 0.01);
    assert!(
        (a.heading_deg - 30.0).abs() < 3.0 * a.heading_sigma_deg.max(0.01),
        "heading {} ± {}",
        a.heading_deg,
        a.heading_sigma_deg
    );
    assert!(
        (a.lat_deg - 45.0).abs() < 3.0 * a.lat_sigma_deg.max(0.01),
        "lat {} ± {}",
        a.lat_deg,
        a.lat_sigma_deg
    );
    assert_eq!(a.skipped_s, 0.0, "nothing disturbed");
}

#[test]
fn lasergyro_alignment_finds_latitude_and_the_disturbed_start() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/psins-lasergyro/lasergyro.imu");
    let log = psins::read(&path).unwrap();
    let a = align(
        &log.imu,
        None,
        None,
        log.lon_deg * D,
        log.h_m,
        0.2 * D / 3600.0,
    )
    .unwrap();
    eprintln!(
        "lasergyro: lat {:.4} ± {:.4} deg, heading {:.3} ± {:.3} deg (header {:.1}), skipped {} s",
        a.lat_deg,
        a.lat_sigma_deg,
        a.heading_deg,
        a.heading_sigma_deg,
        log.euler_deg[2],
        a.skipped_s
    );
    assert!(
        (a.lat_deg - 34.246048).abs() < 0.5,
        "latitude {}",
        a.lat_deg
    );
    assert!(a.skipped_s >= 100.0, "the disturbed start is detected");
    assert!(
        (a.heading_deg - log.euler_deg[2]).abs() < 3.0 * a.heading_sigma_deg,
        "heading {} vs header {}",
        a.heading_deg,
        log.euler_deg[2]
    );
}
