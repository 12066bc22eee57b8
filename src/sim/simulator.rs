//! IMU simulator: exact true increments of a scenario's trajectory (Gauss–Legendre quadrature of
//! the instantaneous specific force and body rate inside every IMU interval), error injection for
//! any spec term by name (applied to the instantaneous signals, then integrated), white noise,
//! bias random walk and quantisation. Seeded and bit-reproducible.

use crate::io::aiding::{PositionFix, VelocityFix};
use crate::io::imu::{ImuData, ImuSample};
use crate::io::truth::TruthRow;
use crate::model::catalog::Sensor;
use crate::model::generated::common;
use crate::nav::earth;
use crate::nav::strapdown::NavState;
use crate::sim::rng::Rng;
use crate::sim::scenario::{NoiseSi, Scenario};
use crate::sim::trajectory::Trajectory;
use nalgebra::{UnitQuaternion, Vector3};

/// Everything a simulation produces.
#[derive(Debug, Clone)]
pub struct SimOutput {
    /// The (error-corrupted) IMU increments.
    pub imu: ImuData,
    /// Truth at the truth rate, starting at t = 0.
    pub truth: Vec<TruthRow>,
    /// The truth as the GNSS receiver reports it at each truth row: `truth` moved by the
    /// scenario's GNSS terms (antenna lever arm, time offset; through their H entries), equal
    /// to `truth` without them. Aiding formed from truth uses it.
    pub gnss_truth: Vec<TruthRow>,
    /// GNSS fixes.
    pub gnss: Vec<PositionFix>,
    /// GNSS velocities, one per fix, when the scenario's `[gnss]` gives `sigma_v`.
    pub gnss_velocity: Option<Vec<crate::io::aiding::VelocityFix>>,
    /// Body-frame velocities of the scenario's `[reference]`, turned by its mounting terms.
    pub body_velocity: Option<Vec<crate::io::aiding::BodyVelocityFix>>,
    /// Attitudes of the scenario's `[attitude_reference]`, turned by its mounting terms.
    pub attitude: Option<Vec<crate::io::aiding::AttitudeFix>>,
    /// True navigation state at t = 0 (to start a navigator).
    pub start: NavState,
}

const GL_NODES: [f64; 3] = [-0.774_596_669_241_483_4, 0.0, 0.774_596_669_241_483_4];
const GL_WEIGHTS: [f64; 3] = [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0];

struct Injected {
    sensor: Sensor,
    axis: usize,
    regressor: usize,
    value: f64,
}

/// (f^b [m/s²], ω_ib^b [rad/s], d(lat, lon, h)/dt) for the kinematic state `k` at position `e`.
fn body_signals(
    e: &earth::LocalEarth,
    k: &crate::sim::trajectory::Kinematics,
) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
    let v = &k.v;
    let w_en = e.omega_en(v);
    let f_n = k.a + (2.0 * e.w_ie + w_en).cross(v) - e.g;
    let ct = k.c.transpose();
    let rate = Vector3::new(v.x / e.rm, v.y / (e.rn * e.cos), -v.z);
    (ct * f_n, ct * (e.w_ie + w_en) + k.w_nb, rate)
}

/// Half-step [s] of the central difference that gives the true signal derivatives.
const DW_STEP: f64 = 1e-5;

/// How far before a fix the kinematics that move it through the GNSS terms' H are taken [s]:
/// the acceleration of the IMU step that ends at the fix, as the filter sees it (a scenario's
/// segment accelerations jump at segment boundaries, which fall on fix times; the left limit
/// is also the physical one for a negative time offset).
const KINEMATICS_BEFORE: f64 = 1e-6;

/// The truth row `row` as a GNSS receiver with the GNSS terms `terms` ((term, value SI)) reports
/// it: each measurement row's value moves by Σ H θ (the terms' H entries of the spec at the true
/// point), z = computed − aided read back into the aided position and velocity. `row` itself
/// without terms.
fn gnss_shift(
    row: &TruthRow,
    e: &earth::LocalEarth,
    traj: &Trajectory,
    terms: &[(usize, f64)],
) -> TruthRow {
    if terms.is_empty() {
        return *row;
    }
    let t = row.t - KINEMATICS_BEFORE;
    let np = true_point(e, traj, &traj.at(t), t, row.lat, row.h, row.v);
    let mut out = *row;
    for (m, info) in common::MEASUREMENTS.iter().enumerate() {
        common::measurement_entries(m, &np, &mut |comp, state, value| {
            let Some(&(_, theta)) = terms.iter().find(|(t, _)| common::TERMS[*t].name == state)
            else {
                return;
            };
            let shift = value * theta;
            match info.rows[comp].name {
                "dp_n" => out.lat -= shift / np.rm,
                "dp_e" => out.lon -= shift / (np.rn * row.lat.cos()),
                "dp_u" => out.h -= shift,
                "dv_n" => out.v.x -= shift,
                "dv_e" => out.v.y -= shift,
                other => panic!("the simulator does not know how measurement row `{other}` reads back into a fix"),
            }
        });
    }
    out
}

/// The navigation point at `t` [s] of the true kinematics `k` (at latitude `lat` [rad], height
/// `h` [m], NED velocity `v` [m/s]) as the filter forms it from its solution, for the H entries
/// of the aiding terms: the body rate, dv/dt over the last second and the instantaneous one.
fn true_point(
    e: &earth::LocalEarth,
    traj: &Trajectory,
    k: &crate::sim::trajectory::Kinematics,
    t: f64,
    lat: f64,
    h: f64,
    v: Vector3<f64>,
) -> crate::nav::nav_point::NavPoint {
    let (f_b, w_b, _) = body_signals(e, k);
    let mut np = crate::nav::nav_point::NavPoint::new(lat, h, v, &k.c, &f_b);
    np.set_rate(&w_b);
    let t0 = (t - crate::nav::nav_point::AccelWindow::SECONDS).max(0.0);
    if t > t0 {
        np.set_acceleration(&((k.v - traj.at(t0).v) / (t - t0)));
    }
    np.set_step_acceleration(&k.a);
    np
}

/// The true body velocity at `t` [s] as a reference mounted with the terms `terms` ((term, value
/// SI)) reads it: each `vel_body` row moves by Σ H θ (the terms' H entries of the spec at the
/// true point; z = computed − aided, so the aided value is the true one less H θ).
fn reference_reading(
    traj: &Trajectory,
    e: &earth::LocalEarth,
    t: f64,
    lat: f64,
    h: f64,
    terms: &[(usize, f64)],
) -> Vector3<f64> {
    let k = traj.at(t);
    let mut v_b = k.c.transpose() * k.v;
    if terms.is_empty() {
        return v_b;
    }
    let np = true_point(e, traj, &k, t, lat, h, k.v);
    let m = common::MEASUREMENTS
        .iter()
        .position(|m| m.name == "vel_body")
        .expect("the spec declares vel_body");
    common::measurement_entries(m, &np, &mut |comp, state, value| {
        if let Some(&(_, theta)) = terms.iter().find(|(t, _)| common::TERMS[*t].name == state) {
            v_b[comp] -= value * theta;
        }
    });
    v_b
}

/// The true attitude at `t` [s] as a reference with the terms `terms` ((term, value SI)) reads
/// it: C_r^n = C_b^n(t + dt_att) exp([m×]), as roll, pitch, yaw [rad].
fn attitude_reading(traj: &Trajectory, t: f64, terms: &[(usize, f64)]) -> Vector3<f64> {
    let (mut m, mut dt) = (Vector3::zeros(), 0.0);
    for &(k, v) in terms {
        match common::TERMS[k].name {
            "att_mount_x" => m[0] = v,
            "att_mount_y" => m[1] = v,
            "att_mount_z" => m[2] = v,
            "dt_att" => dt = v,
            other => unreachable!("{other} is no attitude reference term the simulator knows"),
        }
    }
    let c_r = traj.at(t + dt).c * *nalgebra::Rotation3::from_scaled_axis(m).matrix();
    crate::nav::attitude::euler_from_dcm(&c_r)
}

/// What stays fixed through a simulation: the trajectory, the step, the injected errors.
struct Run<'a> {
    /// The scenario.
    sc: &'a Scenario,
    /// Its trajectory.
    traj: Trajectory,
    /// IMU period [s].
    dt: f64,
    /// Gauss–Legendre sub-intervals per IMU period.
    sub: usize,
    /// The injected IMU (and GNSS) terms.
    injected: Vec<Injected>,
    /// An injected regressor reads the true derivatives of the rate and specific force.
    needs_rates: bool,
    /// The scenario's GNSS terms: (term index in `common::TERMS`, SI value).
    gnss_terms: Vec<(usize, f64)>,
    /// The scenario's velocity-reference terms (mounting): (term index, SI value).
    reference_terms: Vec<(usize, f64)>,
    /// The scenario's attitude-reference terms (mounting): (term index, rad).
    attitude_terms: Vec<(usize, f64)>,
}

impl<'a> Run<'a> {
    /// The trajectory, step, sub-steps and injected terms of scenario `sc`.
    fn new(sc: &'a Scenario) -> Self {
        let traj = Trajectory::new(sc);
        let dt = 1.0 / sc.imu_rate_hz;
        let sub = ((16.0 * traj.max_freq_hz / sc.imu_rate_hz).ceil() as usize).max(1);
        let injected: Vec<Injected> = sc
            .errors
            .iter()
            .map(|&(k, value)| Injected {
                sensor: common::TERMS[k].sensor,
                axis: common::TERMS[k].axis,
                regressor: common::TERMS[k].regressor,
                value,
            })
            .collect();
        // the true derivatives are formed only when an injected regressor reads them
        let needs_rates = injected
            .iter()
            .any(|inj| crate::model::regressor_reads(inj.regressor, &["dw", "df"]));
        let gnss_terms: Vec<(usize, f64)> = sc
            .errors
            .iter()
            .copied()
            .filter(|&(k, _)| common::TERMS[k].sensor == Sensor::Gnss)
            .collect();
        let reference_terms: Vec<(usize, f64)> = sc
            .errors
            .iter()
            .copied()
            .filter(|&(k, _)| common::TERMS[k].sensor == Sensor::Reference)
            .collect();
        let attitude_terms: Vec<(usize, f64)> = sc
            .errors
            .iter()
            .copied()
            .filter(|&(k, _)| common::TERMS[k].sensor == Sensor::Attitude)
            .collect();
        Run {
            sc,
            traj,
            dt,
            sub,
            injected,
            needs_rates,
            gnss_terms,
            reference_terms,
            attitude_terms,
        }
    }

    /// The error-injected increments over the IMU interval from `t0` [s]: Δθ [rad], Δv [m/s],
    /// and the change of (lat [rad], lon [rad], h [m]), by Gauss–Legendre on `sub` sub-intervals.
    fn increments(
        &self,
        e: &earth::LocalEarth,
        t0: f64,
    ) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
        let (traj, dt, sub) = (&self.traj, self.dt, self.sub);
        let mut dth = Vector3::zeros();
        let mut dvel = Vector3::zeros();
        let mut dpos = Vector3::zeros();
        let hsub = dt / sub as f64;
        for s in 0..sub {
            let a = t0 + s as f64 * hsub;
            for (x, w) in GL_NODES.iter().zip(GL_WEIGHTS) {
                let tn = a + 0.5 * hsub * (x + 1.0);
                let k = traj.at(tn);
                let (f, mut om, rate) = body_signals(e, &k);
                let mut sig = crate::model::ImuSignals::new(f, om);
                if self.needs_rates {
                    // d(ω_ib^b)/dt and d(f^b)/dt of the analytic motion, by a central difference
                    let (f_p, om_p, _) = body_signals(e, &traj.at(tn + DW_STEP));
                    let (f_m, om_m, _) = body_signals(e, &traj.at(tn - DW_STEP));
                    sig.dw = (om_p - om_m) / (2.0 * DW_STEP);
                    sig.df = (f_p - f_m) / (2.0 * DW_STEP);
                }
                let mut fm = f;
                for inj in &self.injected {
                    let r = common::regressor_value(inj.regressor, &sig);
                    match inj.sensor {
                        Sensor::Gyro => om[inj.axis] += inj.value * r,
                        Sensor::Accel => fm[inj.axis] += inj.value * r,
                        // in the aiding (`gnss_shift`), not in the IMU
                        Sensor::Gnss | Sensor::Reference | Sensor::Attitude => {}
                    }
                }
                let wt = 0.5 * hsub * w;
                dth += wt * om;
                dvel += wt * fm;
                dpos += wt * rate;
            }
        }
        (dth, dvel, dpos)
    }

    /// The truth row at `t1` [s] at position `pos` (lat, lon [rad], h [m]).
    fn truth_row(&self, t1: f64, pos: [f64; 3]) -> TruthRow {
        let k1 = self.traj.at(t1);
        TruthRow {
            t: t1,
            lat: pos[0],
            lon: pos[1],
            h: pos[2],
            v: k1.v,
            euler: k1.euler,
        }
    }

    /// The GNSS fix at `t1` [s] at true position `pos` (lat, lon [rad], h [m]): moved by the
    /// GNSS terms, with noise of 1-σ `sne`, `sd` [m] when `noisy` (`rng`), and its velocity when
    /// the scenario gives `sigma_v` (noise from `rng_v`).
    fn gnss_fix(
        &self,
        e: &earth::LocalEarth,
        t1: f64,
        pos: [f64; 3],
        (sne, sd, noisy): (f64, f64, bool),
        rng: &mut Rng,
        rng_v: &mut Rng,
    ) -> (PositionFix, Option<VelocityFix>) {
        let (lat, h) = (pos[0], pos[2]);
        let seen = gnss_shift(&self.truth_row(t1, pos), e, &self.traj, &self.gnss_terms);
        let (mut glat, mut glon, mut gh) = (seen.lat, seen.lon, seen.h);
        if noisy {
            glat += sne * rng.normal() / (earth::radius_meridian(lat) + h);
            glon += sne * rng.normal() / ((earth::radius_transverse(lat) + h) * lat.cos());
            gh += sd * rng.normal();
        }
        let fix = PositionFix {
            t: t1,
            lat: glat,
            lon: glon,
            h: gh,
            sigma: [sne, sne, sd],
        };
        let velocity = self.sc.gnss_sigma_v.map(|sv| {
            let mut v = seen.v;
            if noisy {
                for j in 0..3 {
                    v[j] += sv * rng_v.normal();
                }
            }
            VelocityFix {
                v_ned: [v.x, v.y, v.z],
                sigma: sv,
            }
        });
        (fix, velocity)
    }
}

/// The sensor errors carried from sample to sample: bias random walks and quantisation
/// remainders.
struct SensorState {
    /// Gyro bias [rad/s].
    gyro_bias: Vector3<f64>,
    /// Accelerometer bias [m/s²].
    accel_bias: Vector3<f64>,
    /// Angle not yet output by the gyro quantiser [rad].
    carry_th: Vector3<f64>,
    /// Velocity not yet output by the accelerometer quantiser [m/s].
    carry_dv: Vector3<f64>,
}

impl SensorState {
    /// No bias, nothing carried.
    fn new() -> Self {
        SensorState {
            gyro_bias: Vector3::zeros(),
            accel_bias: Vector3::zeros(),
            carry_th: Vector3::zeros(),
            carry_dv: Vector3::zeros(),
        }
    }

    /// Adds white noise, bias random walk and quantisation to one sample's increments `dth`
    /// [rad] and `dvel` [m/s] over `dt` [s] (`sqdt` = √dt [√s]).
    fn corrupt(
        &mut self,
        noise: &NoiseSi,
        dt: f64,
        sqdt: f64,
        rng: &mut Rng,
        dth: &mut Vector3<f64>,
        dvel: &mut Vector3<f64>,
    ) {
        if noise.arw > 0.0 || noise.vrw > 0.0 {
            for j in 0..3 {
                dth[j] += noise.arw * sqdt * rng.normal();
                dvel[j] += noise.vrw * sqdt * rng.normal();
            }
        }
        if noise.gyro_bias_rw > 0.0 || noise.accel_bias_rw > 0.0 {
            for j in 0..3 {
                self.gyro_bias[j] += noise.gyro_bias_rw * sqdt * rng.normal();
                self.accel_bias[j] += noise.accel_bias_rw * sqdt * rng.normal();
            }
            *dth += self.gyro_bias * dt;
            *dvel += self.accel_bias * dt;
        }
        if noise.gyro_quantum > 0.0 {
            let total = *dth + self.carry_th;
            *dth = total.map(|x| (x / noise.gyro_quantum).round() * noise.gyro_quantum);
            self.carry_th = total - *dth;
        }
        if noise.accel_quantum > 0.0 {
            let total = *dvel + self.carry_dv;
            *dvel = total.map(|x| (x / noise.accel_quantum).round() * noise.accel_quantum);
            self.carry_dv = total - *dvel;
        }
    }
}

/// Runs a scenario. `progress` is called with the fraction done (for a progress bar).
pub fn simulate(sc: &Scenario, mut progress: impl FnMut(f64)) -> SimOutput {
    let run = Run::new(sc);
    let (traj, dt) = (&run.traj, run.dt);
    let n = (traj.duration * sc.imu_rate_hz).round() as usize;
    let mut rng = Rng::new(sc.seed);
    // GNSS velocity noise on a stream of its own: adding velocities changes no other draw
    let mut rng_v = Rng::new(sc.seed ^ 0xbb67_ae85_84ca_a73b);
    // and the reference's noise on another
    let mut rng_r = Rng::new(sc.seed ^ 0x3c6e_f372_fe94_f82b);
    let reference_every = sc
        .reference
        .map(|r| (sc.imu_rate_hz / r.0).round().max(1.0) as usize);
    let mut body_velocity = Vec::new();
    // and the attitude reference's on another
    let mut rng_a = Rng::new(sc.seed ^ 0xa54f_f53a_5f1d_36f1);
    let attitude_every = sc
        .attitude_reference
        .map(|r| (sc.imu_rate_hz / r.0).round().max(1.0) as usize);
    let mut attitude = Vec::new();
    let d = std::f64::consts::PI / 180.0;
    let (mut lat, mut lon, mut h) = (sc.start.lat_deg * d, sc.start.lon_deg * d, sc.start.h_m);
    let k0 = traj.at(0.0);
    let start = NavState {
        t: 0.0,
        lat,
        lon,
        h,
        v: k0.v,
        q: UnitQuaternion::from_rotation_matrix(&nalgebra::Rotation3::from_matrix_unchecked(k0.c)),
    };
    let truth_every = (sc.imu_rate_hz / sc.truth_rate_hz).round().max(1.0) as usize;
    let gnss_every = sc
        .gnss
        .map(|g| (sc.imu_rate_hz / g.0).round().max(1.0) as usize);
    let mut truth = vec![TruthRow {
        t: 0.0,
        lat,
        lon,
        h,
        v: k0.v,
        euler: k0.euler,
    }];
    let mut gnss_truth = vec![gnss_shift(
        &truth[0],
        &earth::LocalEarth::new(lat, h),
        traj,
        &run.gnss_terms,
    )];
    let mut gnss = Vec::new();
    let mut gnss_velocity = Vec::new();
    let mut samples = Vec::with_capacity(n);
    let mut sensor = SensorState::new();
    let noise = sc.noise;
    let sqdt = dt.sqrt();
    let report_every = (n / 200).max(1);
    let mut e = earth::LocalEarth::new(lat, h);
    for i in 0..n {
        let t0 = i as f64 * dt;
        let t1 = (i + 1) as f64 * dt;
        // increments and position: Gauss–Legendre on `sub` sub-intervals
        e.follow(lat, h);
        let (mut dth, mut dvel, dpos) = run.increments(&e, t0);
        let (lat1, lon1, h1) = (lat + dpos.x, lon + dpos.y, h + dpos.z);
        // noise, bias random walk, quantisation
        sensor.corrupt(&noise, dt, sqdt, &mut rng, &mut dth, &mut dvel);
        samples.push(ImuSample {
            t: t1,
            dtheta: dth,
            dv: dvel,
        });
        lat = lat1;
        lon = lon1;
        h = h1;
        if (i + 1) % truth_every == 0 {
            let row = run.truth_row(t1, [lat, lon, h]);
            truth.push(row);
            gnss_truth.push(gnss_shift(&row, &e, traj, &run.gnss_terms));
        }
        if let (Some(every), Some((_, sne, sd, noisy))) = (gnss_every, sc.gnss) {
            if (i + 1) % every == 0 {
                let (fix, velocity) = run.gnss_fix(
                    &e,
                    t1,
                    [lat, lon, h],
                    (sne, sd, noisy),
                    &mut rng,
                    &mut rng_v,
                );
                gnss.push(fix);
                gnss_velocity.extend(velocity);
            }
        }
        if let (Some(every), Some((_, sigma, noisy))) = (reference_every, sc.reference) {
            if (i + 1) % every == 0 {
                let mut v = reference_reading(traj, &e, t1, lat, h, &run.reference_terms);
                if noisy {
                    for j in 0..3 {
                        v[j] += sigma * rng_r.normal();
                    }
                }
                body_velocity.push(crate::io::aiding::BodyVelocityFix {
                    t: t1,
                    v_frd: [v.x, v.y, v.z],
                    sigma,
                });
            }
        }
        if let (Some(every), Some((_, s_tilt, s_yaw, noisy))) =
            (attitude_every, sc.attitude_reference)
        {
            if (i + 1) % every == 0 {
                let mut rpy = attitude_reading(traj, t1, &run.attitude_terms);
                if noisy {
                    rpy[0] += s_tilt * rng_a.normal();
                    rpy[1] += s_tilt * rng_a.normal();
                    rpy[2] += s_yaw * rng_a.normal();
                }
                attitude.push(crate::io::aiding::AttitudeFix {
                    t: t1,
                    rpy: [rpy.x, rpy.y, rpy.z],
                    sigma_tilt: s_tilt,
                    sigma_yaw: s_yaw,
                });
            }
        }
        if i % report_every == 0 {
            progress(i as f64 / n as f64);
        }
    }
    progress(1.0);
    if sc.clock_jitter_periods > 1 {
        samples = jitter_clock(samples, sc.clock_jitter_periods, sc.seed);
    }
    SimOutput {
        imu: ImuData { samples },
        truth,
        gnss_truth,
        gnss,
        gnss_velocity: sc.gnss_sigma_v.map(|_| gnss_velocity),
        body_velocity: sc.reference.map(|_| body_velocity),
        attitude: sc.attitude_reference.map(|_| attitude),
        start,
    }
}

/// A jittered IMU clock: consecutive samples merged so that each output sample spans 1 to
/// `max_periods` base periods at random (its increments the sums over its real interval, as an
/// IMU whose output timing jitters delivers them). Its own random stream, so the base samples,
/// truth and GNSS are those of the uniform clock.
fn jitter_clock(samples: Vec<ImuSample>, max_periods: u32, seed: u64) -> Vec<ImuSample> {
    let mut rng = Rng::new(seed ^ 0x6a09_e667_f3bc_c908);
    let mut out = Vec::with_capacity(samples.len());
    let mut it = samples.into_iter();
    'outer: loop {
        let k = 1
            + (rng.uniform() * max_periods as f64)
                .floor()
                .min(max_periods as f64 - 1.0) as u32;
        let Some(mut s) = it.next() else { break };
        for _ in 1..k {
            match it.next() {
                Some(n) => {
                    s.t = n.t;
                    s.dtheta += n.dtheta;
                    s.dv += n.dv;
                }
                None => {
                    out.push(s);
                    break 'outer;
                }
            }
        }
        out.push(s);
    }
    out
}
