//! The MEMS drive end to end: mounting found from the data (as `--init auto` finds it), the filter with RTK positions and
//! the vertical channel, with the spec's default noise and with the noise identified by Allan
//! deviation on the static start.

use nalgebra::Vector3;
use sinsmodel::estimate::allan::{fit, oadev, uniform_rates};
use sinsmodel::estimate::filter::{self, AidingEpoch, FilterConfig, Mode};
use sinsmodel::io::readers::{gnss_imu, rtklib};
use sinsmodel::model::Model;
use sinsmodel::nav::strapdown::Vertical;
use std::path::PathBuf;

#[test]
fn mems_drive_mounting_and_noise_identification() {
    let d = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data/gnss-imu-drive");
    let log = gnss_imu::read(&d.join("imu_1934.csv")).unwrap();
    let pos = rtklib::read(&d.join("gnss_1934_sf.pos")).unwrap();
    // the mounting, as `--init auto` finds it: level at rest, heading from the drive-off
    use sinsmodel::estimate::init::{self, Blocks, Fix, Found, Priors};
    let mut blocks = Blocks::default();
    for s in &log.imu.samples {
        blocks.push(s, log.imu.interval());
    }
    let fixes: Vec<Fix> = pos
        .iter()
        .map(|p| Fix {
            t: p.t,
            pos: [p.lat_deg.to_radians(), p.lon_deg.to_radians(), p.h],
            sigma_pos: p.sigma_neu[0].max(p.sigma_neu[1]).max(0.02),
            v: p.v_ned.map(Vector3::from),
            sigma_v: p.sigma_v_ne.map(|s| s[0].max(s[1])).unwrap_or(0.1),
            derived: false,
        })
        .collect();
    let priors = Priors {
        gyro_bias: 0.5f64.to_radians(),
        accel_bias: 0.5,
        speed: init::DEFAULT_SPEED,
        gyro_scale: 0.01,
    };
    let Found::Done(m) = init::find(&blocks.blocks, &fixes, None, priors, true).unwrap() else {
        panic!("no start found")
    };
    let e = m.state.euler().map(f64::to_degrees);
    // sensor z points up (roll near 180°) and the car drives off along sensor -x
    assert!(e.x.abs() > 170.0, "{e:?}");
    let travel = m.travel_from_x.unwrap().to_degrees();
    assert!(
        travel.abs() > 150.0,
        "travel {travel} deg from the sensor x axis"
    );
    eprintln!("mounting: euler {e:?} deg, travel {travel:.1} deg from the sensor x axis");

    // Allan on the static start: white-noise densities for q
    let t0 = log.imu.samples[0].t;
    let stat: Vec<_> = log.imu.samples.iter().filter(|s| s.t < t0 + 30.0).collect();
    // the clock jitters (8–11 ms): increments resampled in time, as `sinsmodel allan` does
    let times: Vec<f64> = stat.iter().map(|s| s.t).collect();
    let dens = |c: usize| {
        let inc: Vec<f64> = stat
            .iter()
            .map(|s| if c < 3 { s.dtheta[c] } else { s.dv[c - 3] })
            .collect();
        let (y, t) = uniform_rates(&times, &inc);
        fit(&oadev(&y, t)).white
    };
    let arw = ((0..3).map(|c| dens(c).powi(2)).sum::<f64>() / 3.0).sqrt();
    let vrw = ((3..6).map(|c| dens(c).powi(2)).sum::<f64>() / 3.0).sqrt();

    let model = Model::parse("P13+vertical").unwrap();
    let start = m.state;
    let aid: Vec<AidingEpoch> = pos
        .iter()
        .filter(|p| p.t > start.t)
        .map(|p| AidingEpoch {
            t: p.t,
            vel: None,
            pos: Some((
                p.lat_deg.to_radians(),
                p.lon_deg.to_radians(),
                p.h,
                [
                    p.sigma_neu[0].max(0.02),
                    p.sigma_neu[1].max(0.02),
                    p.sigma_neu[2].max(0.05),
                ],
            )),
            body_vel: None,
            att: None,
        })
        .collect();
    let base = || {
        let mut cfg = FilterConfig::new(&model);
        cfg.mode = Mode::ClosedLoop;
        cfg.vertical = Vertical::Free;
        let d2r = std::f64::consts::PI / 180.0;
        for (n, s) in [
            ("eps_", 0.5 * d2r),
            ("nabla_", 0.5),
            ("phi_n", 2.0 * d2r),
            ("phi_e", 2.0 * d2r),
            ("phi_d", 10.0 * d2r),
        ] {
            for i in 0..model.n() {
                if model.names[i].starts_with(n) {
                    cfg.prior_sigma[i] = s;
                }
            }
        }
        cfg
    };
    let nis = |cfg: &FilterConfig| {
        let run = filter::run(&model, cfg, &log.imu, start, &aid, None, |_| {});
        let i = model.index_of("nabla_z").unwrap();
        let nz = run.records.last().unwrap().x[i];
        (
            run.innovations
                .iter()
                .map(|x| x.nu * x.nu / x.s)
                .sum::<f64>()
                / run.innovations.len() as f64,
            nz,
        )
    };
    let (nis_default, _) = nis(&base());
    let (nis_allan, nabla_z) = nis(&base().with_sensor_noise(&model, arw, vrw));
    eprintln!("MEMS drive, P13+vertical: mean NIS {nis_default:.1} with the spec's noise, {nis_allan:.2} with Allan noise (ARW {arw:.2e}, VRW {vrw:.2e}); nabla_z {nabla_z:.3} m/s^2");
    assert!(
        nis_default > 100.0,
        "navigation-grade default noise is far too optimistic for a MEMS IMU"
    );
    assert!(
        nis_allan < 10.0,
        "identified noise brings the innovations near their predicted size"
    );
    // the static |f| is ~1.3 % above gravity: along sensor z (up) the accelerometer reads high
    assert!(nabla_z > 0.05 && nabla_z < 0.3, "{nabla_z}");
}
