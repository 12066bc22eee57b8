//! Static alignment: detection of a disturbed start, coarse analytic alignment from the mean
//! specific force (gravity reaction, "up") and the mean angular rate (Earth rate), latitude from
//! the angle between them, and fine alignment by the error-state Kalman filter (P13, closed loop)
//! with zero-velocity and known-position updates. NED/FRD, SI inside.

use crate::nav::attitude::dcm_from_euler;

use crate::estimate::filter::{self, AidingEpoch, FilterConfig, Mode};
use crate::io::imu::{ImuData, ImuSample};
use crate::model::Model;
use crate::nav::strapdown::{NavState, Vertical};
use nalgebra::{Rotation3, UnitQuaternion, Vector3};

/// Coarse alignment of one stretch of static data.
#[derive(Debug, Clone, Copy)]
pub struct Coarse {
    /// Roll, pitch, heading [rad].
    pub euler: Vector3<f64>,
    /// Latitude from the Earth-rate and gravity directions [rad].
    pub lat: f64,
    /// Mean specific force, FRD [m/s²].
    pub f_mean: Vector3<f64>,
    /// Mean angular rate, FRD [rad/s].
    pub w_mean: Vector3<f64>,
}

/// Analytic alignment from the mean specific force and rate of `samples`.
pub fn coarse(samples: &[ImuSample], dt: f64) -> Coarse {
    let n = samples.len() as f64;
    let f = samples.iter().map(|s| s.dv).sum::<Vector3<f64>>() / (n * dt);
    let w = samples.iter().map(|s| s.dtheta).sum::<Vector3<f64>>() / (n * dt);
    let roll = (-f.y).atan2(-f.z);
    let pitch = f.x.atan2((f.y * f.y + f.z * f.z).sqrt());
    // rate in the levelled body frame (yaw 0): its horizontal part is Ω cos L (cos ψ, −sin ψ)
    let level = dcm_from_euler(roll, pitch, 0.0);
    let wl = level * w;
    let heading = (-wl.y).atan2(wl.x);
    // latitude: "up" is along f; the Earth rate's up component is Ω sin L
    let up = f.normalize();
    let w_up = w.dot(&up);
    let lat = w_up.atan2((w - w_up * up).norm());
    Coarse {
        euler: Vector3::new(roll, pitch, heading),
        lat,
        f_mean: f,
        w_mean: w,
    }
}

/// Disturbed windows (of `win_s` seconds): a parked vehicle being rocked shows up in the mean
/// angular rate of a window, so a window is disturbed when its mean rate differs from the median
/// window's by more than 5 robust standard deviations (1.4826 × median absolute deviation).
/// Returns the window length in samples and one flag per whole window.
pub fn disturbed_windows(data: &ImuData, win_s: f64) -> (usize, Vec<bool>) {
    let dt = data.interval();
    let w = ((win_s / dt).round() as usize).max(2);
    let means: Vec<Vector3<f64>> = data
        .samples
        .chunks(w)
        .filter(|c| c.len() == w)
        .map(|c| c.iter().map(|s| s.dtheta).sum::<Vector3<f64>>() / (w as f64 * dt))
        .collect();
    let med = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(0.0)
    };
    let center = Vector3::new(
        med(&mut means.iter().map(|m| m.x).collect()),
        med(&mut means.iter().map(|m| m.y).collect()),
        med(&mut means.iter().map(|m| m.z).collect()),
    );
    let dev: Vec<f64> = means.iter().map(|m| (m - center).norm()).collect();
    let mad = med(&mut dev.clone());
    (w, dev.iter().map(|d| *d > 5.0 * 1.4826 * mad).collect())
}

/// Index of the first sample after the last disturbed window in the first half of the data.
pub fn quiet_start(data: &ImuData, win_s: f64) -> usize {
    let (w, flags) = disturbed_windows(data, win_s);
    let half = flags.len() / 2;
    flags[..half]
        .iter()
        .rposition(|f| *f)
        .map(|k| (k + 1) * w)
        .unwrap_or(0)
}

/// Result of a static alignment.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Alignment {
    /// Roll [deg] (NED/FRD).
    pub roll_deg: f64,
    /// Pitch [deg].
    pub pitch_deg: f64,
    /// Heading [deg], 0..360.
    pub heading_deg: f64,
    /// 1-σ of the heading from the fine alignment [deg].
    pub heading_sigma_deg: f64,
    /// Latitude: given, or estimated [deg].
    pub lat_deg: f64,
    /// 1-σ of the estimated latitude [deg] (0 when given).
    pub lat_sigma_deg: f64,
    /// Seconds skipped as disturbed at the start.
    pub skipped_s: f64,
    /// Coarse heading per window of the used data [deg] (evidence of stability).
    pub heading_windows_deg: Vec<f64>,
    /// Coarse latitude estimate [deg].
    pub coarse_lat_deg: f64,
    /// Estimated gyro biases after fine alignment [deg/h].
    pub gyro_bias_deg_h: [f64; 3],
}

/// Aligns static data: skips a disturbed start, uses at most `seconds` of the rest; latitude
/// given in radians or estimated; longitude/height only matter through gravity and radii.
/// `gyro_bias_sigma` [rad/s] is the prior 1-σ of the gyro biases in the fine alignment; it
/// bounds the heading accuracy (σ_ψ ≈ σ_ε / (Ω cos L)).
pub fn align(
    data: &ImuData,
    lat: Option<f64>,
    seconds: Option<f64>,
    lon: f64,
    h: f64,
    gyro_bias_sigma: f64,
) -> anyhow::Result<Alignment> {
    let dt = data.interval();
    // the quiet-window logic works on 10 s windows of samples: at least 1 Hz data
    if !(dt > 0.0 && dt <= 1.0) {
        anyhow::bail!(
            "the IMU interval is {dt} s: alignment needs data at 1 Hz or faster (10 s windows of samples)"
        );
    }
    let q0 = quiet_start(data, 10.0);
    let mut used: Vec<ImuSample> = data.samples[q0..].to_vec();
    if let Some(s) = seconds {
        let n = ((s / dt).round() as usize).min(used.len());
        used.truncate(n);
    }
    if used.len() < (60.0 / dt) as usize {
        anyhow::bail!("fewer than 60 s of quiet data to align on");
    }
    // coarse alignment on the quiet windows only (later disturbances excluded from the means)
    let used_data = ImuData {
        samples: used.clone(),
    };
    let (w10, flags) = disturbed_windows(&used_data, 10.0);
    let quiet: Vec<ImuSample> = used
        .chunks(w10)
        .zip(flags.iter().chain(std::iter::repeat(&false)))
        .filter(|(_, f)| !**f)
        .flat_map(|(c, _)| c.iter().copied())
        .collect();
    let c = coarse(&quiet, dt);
    // latitude σ from the scatter of per-window estimates (60 s windows)
    let w = (60.0 / dt) as usize;
    let windows: Vec<Coarse> = quiet
        .chunks(w)
        .filter(|x| x.len() == w)
        .map(|x| coarse(x, dt))
        .collect();
    let k = windows.len() as f64;
    let lat_mean_w = windows.iter().map(|x| x.lat).sum::<f64>() / k;
    let lat_sigma = (windows
        .iter()
        .map(|x| (x.lat - lat_mean_w).powi(2))
        .sum::<f64>()
        / (k - 1.0).max(1.0))
    .sqrt()
        / k.sqrt();
    let lat_used = lat.unwrap_or(c.lat);

    // fine alignment: P13, closed loop, zero velocity and known position at 1 Hz
    let model = Model::parse("P13")?;
    let mut cfg = FilterConfig::new(&model);
    cfg.mode = Mode::ClosedLoop;
    cfg.vertical = Vertical::Fixed;
    cfg.set_prior(&model, "phi_n", 1e-3);
    cfg.set_prior(&model, "phi_e", 1e-3);
    cfg.set_prior(&model, "phi_d", 0.1);
    for n in ["eps_x", "eps_y", "eps_z"] {
        cfg.set_prior(&model, n, gyro_bias_sigma);
    }
    cfg.set_prior(&model, "nabla_x", 1e-3);
    cfg.set_prior(&model, "nabla_y", 1e-3);
    cfg.set_prior(&model, "nabla_z", 1e-3);
    let t0 = used[0].t - dt;
    let start = NavState {
        t: t0,
        lat: lat_used,
        lon,
        h,
        v: Vector3::zeros(),
        q: UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(dcm_from_euler(
            c.euler.x, c.euler.y, c.euler.z,
        ))),
    };
    let t_end = used[used.len() - 1].t;
    let aid: Vec<AidingEpoch> = (1..)
        .map(|i| t0 + i as f64)
        .take_while(|t| *t <= t_end)
        .map(|t| AidingEpoch {
            t,
            vel: Some((Vector3::zeros(), 0.01)),
            pos: Some((lat_used, lon, h, [0.1, 0.1, 0.1])),
        })
        .collect();
    let imu = ImuData { samples: used };
    let run = filter::run(&model, &cfg, &imu, start, &aid, None, |_| {});
    let e = run.final_state.euler();
    let last = run
        .records
        .last()
        .ok_or_else(|| anyhow::anyhow!("no filter update"))?;
    let i_phid = model.index_of("phi_d").expect("P13 has phi_d");
    let deg = 180.0 / std::f64::consts::PI;
    let eps: Vec<f64> = ["eps_x", "eps_y", "eps_z"]
        .iter()
        .map(|n| last.x[model.index_of(n).expect("P13 eps")] * deg * 3600.0)
        .collect();
    Ok(Alignment {
        roll_deg: e.x * deg,
        pitch_deg: e.y * deg,
        heading_deg: (e.z * deg).rem_euclid(360.0),
        heading_sigma_deg: last.sigma[i_phid] * deg,
        lat_deg: lat_used * deg,
        lat_sigma_deg: if lat.is_some() { 0.0 } else { lat_sigma * deg },
        // rounded to the microsecond: q0·dt carries the interval's binary rounding
        skipped_s: (q0 as f64 * dt * 1e6).round() / 1e6,
        heading_windows_deg: windows
            .iter()
            .map(|x| (x.euler.z * deg).rem_euclid(360.0))
            .collect(),
        coarse_lat_deg: c.lat * deg,
        gyro_bias_deg_h: [eps[0], eps[1], eps[2]],
    })
}
