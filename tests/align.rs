//! Static alignment on simulated data of known attitude and on the real RLG log.

use sinsmodel::estimate::align::align;
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
    let (hd, hs) = (a.heading_deg.unwrap(), a.heading_sigma_deg.unwrap());
    assert!(
        (hd - 30.0).abs() < 3.0 * hs.max(0.01),
        "heading {hd} ± {hs}"
    );
    assert!(
        (a.lat_deg.unwrap() - 45.0).abs() < 3.0 * a.lat_sigma_deg.unwrap().max(0.01),
        "lat {:?} ± {:?}",
        a.lat_deg,
        a.lat_sigma_deg
    );
    assert_eq!(a.skipped_s, 0.0, "nothing disturbed");
}

#[test]
fn lasergyro_alignment_finds_latitude_and_the_disturbed_start() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/psins-lasergyro/lasergyro.imu");
    let log = sinsmodel::io::imu_stream::read_psins(&path).unwrap();
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
        "lasergyro: lat {:?} ± {:?} deg, heading {:?} ± {:?} deg (header {:.1}), skipped {} s",
        a.lat_deg,
        a.lat_sigma_deg,
        a.heading_deg,
        a.heading_sigma_deg,
        log.euler_deg[2],
        a.skipped_s
    );
    assert!(
        (a.lat_deg.unwrap() - 34.246048).abs() < 0.5,
        "latitude {}",
        a.lat_deg.unwrap()
    );
    assert!(a.skipped_s >= 100.0, "the disturbed start is detected");
    let (hd, hs) = (a.heading_deg.unwrap(), a.heading_sigma_deg.unwrap());
    assert!(
        (hd - log.euler_deg[2]).abs() < 3.0 * hs,
        "heading {hd} vs header {}",
        log.euler_deg[2]
    );
}

fn sim(text: &str) -> sinsmodel::io::imu::ImuData {
    simulate(&Scenario::parse(text, "align").unwrap(), |_| {}).imu
}

/// A start that moves: alignment refuses, naming the evidence, instead of printing a heading.
/// (Its windows look alike, so judging them against the median window would call them quiet.)
#[test]
fn a_moving_start_is_refused_with_its_evidence() {
    // a car weaving and changing speed every few seconds, from 20 s on
    let weave: String = (0..40)
        .map(|k| {
            format!(
                "[[segment]]\nkind = \"turn\"\nduration_s = 4.0\nyaw_rate_deg_s = {}\n[[segment]]\nkind = \"accelerate\"\nduration_s = 2.0\naccel_mps2 = {}\n",
                if k % 2 == 0 { 6.0 } else { -6.0 },
                if k % 4 < 2 { 0.8 } else { -0.8 }
            )
        })
        .collect();
    let imu = sim(&format!(
        "name = \"m\"\nimu_rate_hz = 100.0\nseed = 4\n[start]\nlat_deg = 40.0\nlon_deg = 7.0\neuler_deg = [0.0, 0.0, 30.0]\n\
         [[segment]]\nkind = \"rest\"\nduration_s = 20.0\n\
         [[segment]]\nkind = \"accelerate\"\nduration_s = 5.0\naccel_mps2 = 1.5\n{}\
         [[vibration]]\nkind = \"random\"\naxis = \"z\"\npsd = \"1e-4 g^2/Hz\"\nband_hz = [5.0, 40.0]\n\
         [noise]\narw = \"0.3 deg/sqrt(h)\"\nvrw = \"100 ug/sqrt(Hz)\"\n",
        weave
    ));
    let e = align(&imu, None, None, 7.0 * D, 0.0, 0.2 * D / 3600.0)
        .expect_err("a moving start must be refused")
        .to_string();
    assert!(
        e.contains("not at rest long enough") && e.contains("angular-rate spread"),
        "{e}"
    );
}

/// A MEMS gyro (bias 0.15 deg/s, 36x Earth rate): roll and pitch come out, the heading does
/// not, and the note says why; a prior that says the same (--gyro-bias-sigma) does too.
#[test]
fn a_mems_gyro_gives_no_heading_and_says_why() {
    let imu = sim(
        "name = \"mems\"\nimu_rate_hz = 100.0\nseed = 5\n[start]\nlat_deg = 30.0\nlon_deg = 7.0\neuler_deg = [2.0, -1.0, 60.0]\n\
         [[segment]]\nkind = \"rest\"\nduration_s = 300.0\n\
         [errors]\neps_x = \"0.15 deg/s\"\neps_y = \"-0.1 deg/s\"\nnabla_x = \"5 mg\"\n\
         [noise]\narw = \"0.3 deg/sqrt(h)\"\nvrw = \"100 ug/sqrt(Hz)\"\n",
    );
    let a = align(&imu, Some(30.0 * D), None, 7.0 * D, 0.0, 0.2 * D / 3600.0).unwrap();
    assert!(
        a.heading_deg.is_none() && a.heading_sigma_deg.is_none(),
        "{a:?}"
    );
    let note = a.heading_note.clone().unwrap();
    assert!(
        note.contains("no heading") && note.contains("seen in the data"),
        "{note}"
    );
    assert!(a.gyro_bias_sigma_used_deg_h > 360.0, "{a:?}"); // > 0.1 deg/s
                                                            // roll and pitch from gravity (the 5 mg accelerometer bias tilts them by ~0.3 deg)
    assert!(
        (a.roll_deg - 2.0).abs() < 0.5 && (a.pitch_deg + 1.0).abs() < 0.5,
        "{a:?}"
    );
    // a navigation-grade gyro whose prior says MEMS gives no heading either
    let nav = sim(
        "name = \"nav\"\nimu_rate_hz = 100.0\nseed = 6\n[start]\nlat_deg = 30.0\nlon_deg = 7.0\neuler_deg = [0.0, 0.0, 60.0]\n\
         [[segment]]\nkind = \"rest\"\nduration_s = 300.0\n[noise]\narw = \"0.003 deg/sqrt(h)\"\nvrw = \"10 ug/sqrt(Hz)\"\n",
    );
    let a = align(&nav, Some(30.0 * D), None, 7.0 * D, 0.0, 0.1 * D).unwrap();
    assert!(a.heading_deg.is_none(), "{a:?}");
    assert!(a.heading_note.unwrap().contains("--gyro-bias-sigma prior"));
    // and with a navigation-grade prior it finds north within its sigma
    let a = align(&nav, Some(30.0 * D), None, 7.0 * D, 0.0, 0.01 * D / 3600.0).unwrap();
    let (hd, hs) = (a.heading_deg.unwrap(), a.heading_sigma_deg.unwrap());
    assert!((hd - 60.0).abs() < 3.0 * hs.max(0.01), "{hd} ± {hs}");
}

/// A jittered clock (intervals of one or two base periods): each increment over its own
/// interval gives the uniform clock's mean rates, where dividing by the median interval is off
/// by the mean-to-median ratio.
#[test]
fn a_jittered_clock_gives_the_uniform_mean_rates() {
    use sinsmodel::io::imu::{ImuData, ImuSample};
    let uniform = sim(
        "name = \"j\"\nimu_rate_hz = 100.0\nseed = 8\n[start]\nlat_deg = 30.0\nlon_deg = 7.0\neuler_deg = [1.0, 2.0, 40.0]\n\
         [[segment]]\nkind = \"rest\"\nduration_s = 120.0\n[noise]\narw = \"0.01 deg/sqrt(h)\"\nvrw = \"20 ug/sqrt(Hz)\"\n",
    );
    // merge every second and third sample of each group of three into one: intervals 10, 20 ms
    let mut jittered = Vec::new();
    let mut k = 0;
    while k + 2 < uniform.samples.len() {
        let (a, b, c) = (
            uniform.samples[k],
            uniform.samples[k + 1],
            uniform.samples[k + 2],
        );
        jittered.push(a);
        jittered.push(ImuSample {
            t: c.t,
            dtheta: b.dtheta + c.dtheta,
            dv: b.dv + c.dv,
        });
        k += 3;
    }
    let jittered = ImuData { samples: jittered };
    let (fu, wu) = uniform.mean_rates();
    let (fj, wj) = jittered.mean_rates();
    assert!((fj - fu).norm() < 1e-3 * fu.norm(), "{fj} vs {fu}");
    assert!((wj - wu).norm() < 1e-2 * wu.norm() + 1e-9, "{wj} vs {wu}");
    // the old division by n x median interval (20 ms here, the mean is 15 ms): 25 % low
    let n = jittered.samples.len() as f64;
    let old = jittered
        .samples
        .iter()
        .map(|s| s.dv)
        .sum::<nalgebra::Vector3<f64>>()
        / (n * jittered.interval());
    assert!(
        (old.norm() / fu.norm() - 0.75).abs() < 0.01,
        "{}",
        old.norm() / fu.norm()
    );
    let au = align(
        &uniform,
        Some(30.0 * D),
        None,
        7.0 * D,
        0.0,
        0.01 * D / 3600.0,
    )
    .unwrap();
    let aj = align(
        &jittered,
        Some(30.0 * D),
        None,
        7.0 * D,
        0.0,
        0.01 * D / 3600.0,
    )
    .unwrap();
    assert!((au.roll_deg - aj.roll_deg).abs() < 0.01 && (au.pitch_deg - aj.pitch_deg).abs() < 0.01);
}

/// A latitude the data at rest contradict is refused (radians given as degrees, a lost
/// hemisphere sign); the true one and one a degree off are accepted.
#[test]
fn a_given_latitude_the_data_contradict_is_refused() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/psins-lasergyro/lasergyro.imu");
    let log = sinsmodel::io::imu_stream::read_psins(&path).unwrap();
    let run = |lat_deg: f64| {
        align(
            &log.imu,
            Some(lat_deg * D),
            None,
            log.lon_deg * D,
            log.h_m,
            0.2 * D / 3600.0,
        )
    };
    assert!(run(34.246).is_ok());
    assert!(run(33.3).is_ok());
    for wrong in [34.246f64.to_radians(), -34.246] {
        let e = run(wrong).unwrap_err().to_string();
        assert!(e.contains("--lat") && e.contains("σ away"), "{e}");
    }
}

/// A drive-off (60 s at rest, then 30 s at a constant 0.8 m/s², which passes every test inside
/// a 10-s window) is not taken as rest: on the whole log the alignment uses the first 60 s
/// and finds the heading and zero gyro biases within their σ; from 10 s on, too little rest is
/// left and the refusal says the mean specific force moved between windows.
#[test]
fn a_drive_off_is_not_taken_as_rest() {
    let sc = Scenario::parse(
        "name = \"off\"\nimu_rate_hz = 100.0\nseed = 3\n[start]\nlat_deg = 28.22\nlon_deg = 112.99\nh_m = 50.0\n\
         euler_deg = [0.5, -0.3, 30.0]\n[[segment]]\nkind = \"rest\"\nduration_s = 60.0\n[[segment]]\n\
         kind = \"accelerate\"\nduration_s = 30.0\naccel_mps2 = 0.8\n[noise]\narw = \"0.005 deg/sqrt(h)\"\n\
         vrw = \"10 ug/sqrt(Hz)\"\n",
        "align",
    )
    .unwrap();
    let sim = simulate(&sc, |_| {});
    let a = align(
        &sim.imu,
        Some(28.22 * D),
        None,
        112.99 * D,
        50.0,
        0.01 * D / 3600.0,
    )
    .unwrap();
    let (hd, hs) = (a.heading_deg.unwrap(), a.heading_sigma_deg.unwrap());
    assert!((hd - 30.0).abs() < 3.0 * hs, "heading {hd} ± {hs}");
    assert!(
        (a.roll_deg - 0.5).abs() < 0.02 && (a.pitch_deg + 0.3).abs() < 0.02,
        "{a:?}"
    );
    for k in 0..3 {
        let (b, s) = (a.gyro_bias_deg_h[k], a.gyro_bias_sigma_deg_h[k]);
        assert!(
            s > 0.0 && b.abs() < 3.0 * s,
            "gyro bias {k}: {b} ± {s} deg/h"
        );
    }
    let late = sinsmodel::io::imu::ImuData {
        samples: sim
            .imu
            .samples
            .iter()
            .filter(|s| s.t > 10.0)
            .copied()
            .collect(),
    };
    let e = align(
        &late,
        Some(28.22 * D),
        None,
        112.99 * D,
        50.0,
        0.01 * D / 3600.0,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("not at rest long enough") && e.contains("moved by up to 0.8"),
        "{e}"
    );
}
