//! True motion of a scenario as analytic functions of time: base motion (speed and heading by
//! segments, level attitude), linear vibration (NED or body axes; sine, or random as a seeded sum
//! of sinusoids with a flat PSD) and angular vibration (sinusoidal Euler angles). Velocity,
//! acceleration, attitude and body rate are exact derivatives of each other; position is
//! integrated from the velocity (see `simulator`).

use crate::io::units;
use crate::nav::attitude::dcm_from_euler;
use crate::sim::rng::Rng;
use crate::sim::scenario::Scenario;
use nalgebra::{Matrix3, Vector3};
use std::f64::consts::PI;

/// Frame of a linear vibration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Frame {
    Ned,
    Body,
}

/// A linear vibration along one axis: Σ A_i cos(ω_i t + φ_i), switched by windows.
#[derive(Debug, Clone)]
struct Linear {
    frame: Frame,
    axis: usize,
    comps: Vec<(f64, f64, f64)>,
    windows: Vec<[f64; 3]>,
    /// Per window and component (window-major): sin(ω t_start + φ) of a window that starts
    /// after t = 0 (else 0), the velocity's base.
    base: Vec<f64>,
    /// Per window and component: (sin, cos)(ω t_end + φ) of a window that ends (else 0): the
    /// frozen velocity after it.
    end: Vec<(f64, f64)>,
    phasor: std::cell::RefCell<Phasor>,
}

/// Sums of many sinusoids evaluated at increasing times by rotating each component's
/// (sin, cos) from the last time instead of calling sin_cos; rotations for the few distinct
/// steps the simulator uses are cached, and every 4096 evaluations the phasors are recomputed
/// exactly so rounding cannot accumulate.
#[derive(Debug, Clone, Default)]
struct Phasor {
    t: f64,
    sc: Vec<(f64, f64)>,
    steps: Vec<(u64, Vec<(f64, f64)>)>,
    uses: u32,
}

impl Linear {
    /// The source Σ A_i cos(ω_i t + φ_i) (`comps`: (A_i, ω_i, φ_i)) along `axis` of `frame`,
    /// switched by `windows`, with each window's constant phases computed once.
    fn new(frame: Frame, axis: usize, comps: Vec<(f64, f64, f64)>, windows: Vec<[f64; 3]>) -> Self {
        let mut base = Vec::with_capacity(windows.len() * comps.len());
        let mut end = Vec::with_capacity(windows.len() * comps.len());
        for w in &windows {
            for &(_, om, ph) in &comps {
                base.push(if w[0] <= 0.0 {
                    0.0
                } else {
                    (om * w[0] + ph).sin()
                });
                end.push(if w[1].is_finite() {
                    (om * w[1] + ph).sin_cos()
                } else {
                    (0.0, 0.0)
                });
            }
        }
        Linear {
            frame,
            axis,
            comps,
            windows,
            base,
            end,
            phasor: Default::default(),
        }
    }

    /// Fast path for a source that is always on (one window from t = 0 to ∞): (v, a).
    fn eval_always_on(&self, t: f64) -> (f64, f64) {
        let mut ph = self.phasor.borrow_mut();
        let delta = t - ph.t;
        let exact = ph.sc.is_empty() || ph.uses >= 4096 || delta < 0.0;
        if exact {
            ph.sc = self
                .comps
                .iter()
                .map(|&(_, om, p)| (om * t + p).sin_cos())
                .collect();
            ph.uses = 0;
        } else if delta != 0.0 {
            let key = delta.to_bits();
            let k = match ph.steps.iter().position(|(b, _)| *b == key) {
                Some(k) => k,
                None => {
                    if ph.steps.len() >= 16 {
                        ph.steps.remove(0);
                    }
                    let rot = self
                        .comps
                        .iter()
                        .map(|&(_, om, _)| (om * delta).sin_cos())
                        .collect();
                    ph.steps.push((key, rot));
                    ph.steps.len() - 1
                }
            };
            let Phasor { sc, steps, .. } = &mut *ph;
            for ((s, c), (rs, rc)) in sc.iter_mut().zip(&steps[k].1) {
                let (s0, c0) = (*s, *c);
                *s = s0 * rc + c0 * rs;
                *c = c0 * rc - s0 * rs;
            }
            ph.uses += 1;
        }
        ph.t = t;
        let w = self.windows[0][2];
        let (mut v, mut a) = (0.0, 0.0);
        for (&(amp, om, _), &(s, c)) in self.comps.iter().zip(&ph.sc) {
            v += w * amp / om * s;
            a += w * amp * c;
        }
        (v, a)
    }

    /// (velocity, acceleration) along the axis. In a window starting at t = 0 the velocity is the
    /// zero-mean (A/ω) sin(ωt + φ) (the start state moves with it); a later window integrates the
    /// acceleration from its start, so velocity is continuous. After a window it stays frozen.
    fn eval(&self, t: f64) -> (f64, f64) {
        if self.comps.len() > 4
            && self.windows.len() == 1
            && self.windows[0][0] == 0.0
            && self.windows[0][1] == f64::INFINITY
            && t >= 0.0
        {
            return self.eval_always_on(t);
        }
        let (mut v, mut a) = (0.0, 0.0);
        let nc = self.comps.len();
        for (k, w) in self.windows.iter().enumerate() {
            if t < w[0] {
                continue;
            }
            let inside = t <= w[1];
            for (i, &(amp, om, ph)) in self.comps.iter().enumerate() {
                let base = self.base[k * nc + i];
                // (at t = t_end, t itself; after the window, its end's)
                let (s, c) = if inside {
                    (om * t + ph).sin_cos()
                } else {
                    self.end[k * nc + i]
                };
                v += w[2] * amp / om * (s - base);
                if inside {
                    a += w[2] * amp * c;
                }
            }
        }
        (v, a)
    }
}

/// Angular vibration of one Euler angle: Θ sin(ω (t − t0) + φ) − Θ sin φ inside each window.
#[derive(Debug, Clone)]
struct Angular {
    axis: usize,
    amp: f64,
    om: f64,
    ph: f64,
    /// sin φ (computed once).
    sin_ph: f64,
    windows: Vec<[f64; 3]>,
}

impl Angular {
    fn eval(&self, t: f64) -> (f64, f64) {
        let (mut ang, mut rate) = (0.0, 0.0);
        for w in &self.windows {
            if t < w[0] || t > w[1] {
                continue;
            }
            let x = self.om * (t - w[0]) + self.ph;
            ang += w[2] * self.amp * (x.sin() - self.sin_ph);
            rate += w[2] * self.amp * self.om * x.cos();
        }
        (ang, rate)
    }
}

/// Kinematic state at one instant.
#[derive(Debug, Clone, Copy)]
pub struct Kinematics {
    /// NED velocity [m/s].
    pub v: Vector3<f64>,
    /// NED acceleration dv/dt [m/s²].
    pub a: Vector3<f64>,
    /// C_b^n.
    pub c: Matrix3<f64>,
    /// Body rate relative to NED, ω_nb^b [rad/s].
    pub w_nb: Vector3<f64>,
    /// Roll, pitch, yaw [rad].
    pub euler: Vector3<f64>,
}

/// The analytic motion of a scenario.
#[derive(Debug, Clone)]
pub struct Trajectory {
    seg_start: Vec<f64>,
    seg_speed0: Vec<f64>,
    seg_yaw0: Vec<f64>,
    seg_accel: Vec<f64>,
    seg_yaw_rate: Vec<f64>,
    seg_dcm: Vec<Matrix3<f64>>,
    /// Turntable scenarios (`rotate` segments): per segment (body axis, angle [rad], duration
    /// [s]) of its rotation, `None` at rest; empty otherwise.
    seg_rotation: Vec<Option<(usize, f64, f64)>>,
    roll0: f64,
    pitch0: f64,
    linear: Vec<Linear>,
    angular: Vec<Angular>,
    /// Highest vibration frequency [Hz] (0 without vibration).
    pub max_freq_hz: f64,
    /// Total duration [s].
    pub duration: f64,
}

fn windows(s: &Option<Vec<[f64; 3]>>) -> Vec<[f64; 3]> {
    s.clone().unwrap_or_else(|| vec![[0.0, f64::INFINITY, 1.0]])
}

impl Trajectory {
    /// Builds the motion of a validated scenario (random vibration draws from its seed).
    pub fn new(sc: &Scenario) -> Trajectory {
        let d = PI / 180.0;
        let (mut t, mut speed, mut yaw) = (0.0, sc.start.speed_mps, sc.start.euler_deg[2] * d);
        let (mut seg_start, mut seg_speed0, mut seg_yaw0, mut seg_accel, mut seg_yaw_rate) =
            (vec![], vec![], vec![], vec![], vec![]);
        for s in &sc.segments {
            let (acc, yr) = match s.kind.as_str() {
                "accelerate" => (s.accel_mps2, 0.0),
                "turn" => (0.0, s.yaw_rate_deg_s * d),
                _ => (0.0, 0.0),
            };
            seg_start.push(t);
            seg_speed0.push(speed);
            seg_yaw0.push(yaw);
            seg_accel.push(acc);
            seg_yaw_rate.push(yr);
            speed += acc * s.duration_s;
            yaw += yr * s.duration_s;
            t += s.duration_s;
        }
        let mut rng = Rng::new(sc.seed ^ 0x05ee_d0f7_ab1e);
        let mut linear = Vec::new();
        let mut angular = Vec::new();
        let mut max_freq: f64 = 0.0;
        for v in &sc.vibration {
            let axis_idx = |a: &str| {
                ["n", "e", "d", "x", "y", "z", "roll", "pitch", "yaw"]
                    .iter()
                    .position(|x| *x == a)
                    .unwrap_or(0)
            };
            let k = axis_idx(&v.axis);
            match v.kind.as_str() {
                "sine" => {
                    let amp =
                        units::parse_quantity_as(v.amplitude.as_deref().unwrap_or("0"), "m/s^2")
                            .unwrap_or(0.0);
                    max_freq = max_freq.max(v.freq_hz);
                    linear.push(Linear::new(
                        if k < 3 { Frame::Ned } else { Frame::Body },
                        k % 3,
                        vec![(amp, 2.0 * PI * v.freq_hz, v.phase_deg * d)],
                        windows(&v.schedule),
                    ));
                }
                "random" => {
                    let psd =
                        units::parse_quantity_as(v.psd.as_deref().unwrap_or("0"), "m^2/s^4/Hz")
                            .unwrap_or(0.0);
                    let [lo, hi] = v.band_hz.unwrap_or([1.0, 2.0]);
                    let n = v.components.unwrap_or(200).max(1);
                    let df = (hi - lo) / n as f64;
                    let amp = (2.0 * psd * df).sqrt();
                    let comps = (0..n)
                        .map(|i| {
                            let f = lo + (i as f64 + rng.uniform()) * df;
                            (amp, 2.0 * PI * f, 2.0 * PI * rng.uniform())
                        })
                        .collect();
                    max_freq = max_freq.max(hi);
                    linear.push(Linear::new(
                        if k < 3 { Frame::Ned } else { Frame::Body },
                        k % 3,
                        comps,
                        windows(&v.schedule),
                    ));
                }
                _ => {
                    let amp =
                        units::parse_quantity_as(v.amplitude.as_deref().unwrap_or("0"), "rad")
                            .unwrap_or(0.0);
                    max_freq = max_freq.max(v.freq_hz);
                    angular.push(Angular {
                        axis: k - 6,
                        amp,
                        om: 2.0 * PI * v.freq_hz,
                        ph: v.phase_deg * d,
                        sin_ph: (v.phase_deg * d).sin(),
                        windows: windows(&v.schedule),
                    });
                }
            }
        }
        let mut seg_dcm: Vec<Matrix3<f64>> = seg_yaw0
            .iter()
            .map(|&y| dcm_from_euler(sc.start.euler_deg[0] * d, sc.start.euler_deg[1] * d, y))
            .collect();
        let mut seg_rotation = Vec::new();
        if sc.segments.iter().any(|s| s.kind == "rotate") {
            // a turntable: each segment starts at the attitude the rotations before it left
            let mut c = seg_dcm[0];
            for (k, s) in sc.segments.iter().enumerate() {
                seg_dcm[k] = c;
                let rot = (s.kind == "rotate").then(|| {
                    let axis = match s.axis.as_deref() {
                        Some("y") => 1,
                        Some("z") => 2,
                        _ => 0,
                    };
                    (axis, s.angle_deg.unwrap_or(0.0) * d, s.duration_s)
                });
                if let Some((axis, angle, _)) = rot {
                    c *= axis_rotation(axis, angle);
                }
                seg_rotation.push(rot);
            }
        }
        Trajectory {
            seg_dcm,
            seg_rotation,
            seg_start,
            seg_speed0,
            seg_yaw0,
            seg_accel,
            seg_yaw_rate,
            roll0: sc.start.euler_deg[0] * d,
            pitch0: sc.start.euler_deg[1] * d,
            linear,
            angular,
            max_freq_hz: max_freq,
            duration: t,
        }
    }

    /// The kinematic state at time `t` [s].
    pub fn at(&self, t: f64) -> Kinematics {
        let i = self
            .seg_start
            .iter()
            .rposition(|&s| s <= t)
            .unwrap_or_default();
        let tau = t - self.seg_start[i];
        let speed = self.seg_speed0[i] + self.seg_accel[i] * tau;
        let yaw_rate = self.seg_yaw_rate[i];
        let yaw_base = self.seg_yaw0[i] + yaw_rate * tau;
        let (mut v, mut a) = (Vector3::zeros(), Vector3::zeros());
        if speed != 0.0 || self.seg_accel[i] != 0.0 {
            let (sy, cy) = yaw_base.sin_cos();
            v = Vector3::new(speed * cy, speed * sy, 0.0);
            a = Vector3::new(
                self.seg_accel[i] * cy - speed * yaw_rate * sy,
                self.seg_accel[i] * sy + speed * yaw_rate * cy,
                0.0,
            );
        }
        let mut euler = Vector3::new(self.roll0, self.pitch0, yaw_base);
        let (c, w_nb) = if !self.seg_rotation.is_empty() {
            // turntable: C = C_start R_axis(θ(τ)), ω_nb^b = e_axis θ'(τ)
            match self.seg_rotation[i] {
                Some((axis, angle, duration)) => {
                    let (th, rate) = rotation_profile(angle, duration, tau);
                    let c = self.seg_dcm[i] * axis_rotation(axis, th);
                    euler = crate::nav::attitude::euler_from_dcm(&c);
                    let mut w = Vector3::zeros();
                    w[axis] = rate;
                    (c, w)
                }
                None => {
                    euler = crate::nav::attitude::euler_from_dcm(&self.seg_dcm[i]);
                    (self.seg_dcm[i], Vector3::zeros())
                }
            }
        } else if self.angular.is_empty() && yaw_rate == 0.0 {
            (self.seg_dcm[i], Vector3::zeros())
        } else {
            let mut euler_rate = Vector3::new(0.0, 0.0, yaw_rate);
            for ang in &self.angular {
                let (x, r) = ang.eval(t);
                euler[ang.axis] += x;
                euler_rate[ang.axis] += r;
            }
            let (sr, cr) = euler.x.sin_cos();
            let (sp, cp) = euler.y.sin_cos();
            let w_nb = Vector3::new(
                euler_rate.x - euler_rate.z * sp,
                euler_rate.y * cr + euler_rate.z * sr * cp,
                -euler_rate.y * sr + euler_rate.z * cr * cp,
            );
            (dcm_from_euler(euler.x, euler.y, euler.z), w_nb)
        };
        let mut vb = Vector3::zeros();
        let mut ab = Vector3::zeros();
        for l in &self.linear {
            let (lv, la) = l.eval(t);
            match l.frame {
                Frame::Ned => {
                    v[l.axis] += lv;
                    a[l.axis] += la;
                }
                Frame::Body => {
                    vb[l.axis] += lv;
                    ab[l.axis] += la;
                }
            }
        }
        if vb != Vector3::zeros() || ab != Vector3::zeros() {
            // v^n = C v^b  →  dv^n/dt = C (a^b + ω_nb^b × v^b)
            v += c * vb;
            a += c * (ab + w_nb.cross(&vb));
        }
        Kinematics {
            v,
            a,
            c,
            w_nb,
            euler,
        }
    }
}

/// The rotation matrix of a body turned by `angle` [rad] about its own axis `axis` (0 = x):
/// C_b^n after = C_b^n before · this.
fn axis_rotation(axis: usize, angle: f64) -> Matrix3<f64> {
    let (s, c) = angle.sin_cos();
    match axis {
        0 => Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c),
        1 => Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c),
        _ => Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0),
    }
}

/// Angle [rad] and rate [rad/s] at `tau` [s] into a turntable rotation of `angle` [rad] over
/// `duration` [s]: raised-cosine rate ramps of [`crate::sim::scenario::rotate_ramp`] at each end,
/// a constant rate between (the ramps average half the rate, so the rate is angle / (T − ramp)).
fn rotation_profile(angle: f64, duration: f64, tau: f64) -> (f64, f64) {
    let ramp = crate::sim::scenario::rotate_ramp(duration);
    let rate = angle / (duration - ramp);
    let up = |t: f64| {
        let x = PI * t / ramp;
        (
            0.5 * rate * (t - ramp / PI * x.sin()),
            0.5 * rate * (1.0 - x.cos()),
        )
    };
    let tau = tau.clamp(0.0, duration);
    if tau < ramp {
        up(tau)
    } else if tau <= duration - ramp {
        (0.5 * rate * ramp + rate * (tau - ramp), rate)
    } else {
        let (th, r) = up(duration - tau);
        (angle - th, r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::scenario::Scenario;

    fn turntable() -> Trajectory {
        let text = "name = \"t\"\nseed = 1\nimu_rate_hz = 100.0\n[start]\nlat_deg = 40.0\nlon_deg = 116.0\nh_m = 50.0\neuler_deg = [0.0, 0.0, 30.0]\nspeed_mps = 0.0\n\
            [[segment]]\nkind = \"rest\"\nduration_s = 2.0\n\
            [[segment]]\nkind = \"rotate\"\naxis = \"x\"\nangle_deg = 90.0\nduration_s = 9.0\n\
            [[segment]]\nkind = \"rotate\"\naxis = \"z\"\nangle_deg = -90.0\nduration_s = 9.0\n\
            [[segment]]\nkind = \"rest\"\nduration_s = 2.0\n";
        Trajectory::new(&Scenario::parse(text, "test").unwrap())
    }

    #[test]
    fn turntable_rotations_end_where_they_should_and_rates_match_attitude() {
        let tr = turntable();
        let d = PI / 180.0;
        // after +90° about x then −90° about z: C = Rz(30°) Rx(90°) Rz(−90°)
        let want = dcm_from_euler(0.0, 0.0, 30.0 * d)
            * axis_rotation(0, 90.0 * d)
            * axis_rotation(2, -90.0 * d);
        assert!((tr.at(21.5).c - want).abs().max() < 1e-12);
        assert_eq!(tr.at(21.5).w_nb, Vector3::zeros());
        // dC/dt = C [ω_nb]× at points on the ramps and between
        for t in [2.1, 2.4, 5.0, 10.8, 11.3, 15.0, 19.9] {
            let h = 1e-6;
            let dc = (tr.at(t + h).c - tr.at(t - h).c) / (2.0 * h);
            let k = tr.at(t);
            let want = k.c * crate::nav::attitude::skew(&k.w_nb);
            assert!((dc - want).abs().max() < 1e-6, "t = {t}: {dc} vs {want}");
        }
        // the ramps: zero rate at the ends, the full rate in the middle (90° / (9 − 0.5) s)
        assert!(tr.at(2.0 + 1e-9).w_nb.norm() < 1e-6);
        assert!((tr.at(6.5).w_nb.x - 90.0 * d / 8.5).abs() < 1e-12);
    }

    #[test]
    fn rotate_segments_are_checked() {
        let base = "name = \"t\"\nseed = 1\nimu_rate_hz = 100.0\n[start]\nlat_deg = 40.0\nlon_deg = 116.0\nh_m = 50.0\neuler_deg = [0.0, 0.0, 0.0]\n";
        let bad = [
            ("[[segment]]\nkind = \"rotate\"\nangle_deg = 90.0\nduration_s = 9.0\n", "needs `axis`"),
            ("[[segment]]\nkind = \"rotate\"\naxis = \"roll\"\nangle_deg = 90.0\nduration_s = 9.0\n", "body axis"),
            ("[[segment]]\nkind = \"rotate\"\naxis = \"x\"\nangle_deg = 9e5\nduration_s = 9.0\n", "±3600"),
            ("[[segment]]\nkind = \"rotate\"\naxis = \"x\"\nangle_deg = 3000.0\nduration_s = 0.2\n", "peak rate"),
            ("[[segment]]\nkind = \"rotate\"\naxis = \"x\"\nangle_deg = 1.0\nduration_s = 0.001\n", "IMU periods"),
            ("[[segment]]\nkind = \"rotate\"\naxis = \"x\"\nduration_s = 9.0\n", "needs `angle_deg`"),
            ("[[segment]]\nkind = \"rotate\"\naxis = \"x\"\nangle_deg = 0.0\nduration_s = 9.0\n", "rotation of nothing"),
            ("[[segment]]\nkind = \"rotate\"\naxis = \"x\"\nangle_deg = 90.0\nduration_s = 9.0\nyaw_rate_deg_s = 5.0\n", "do not apply"),
            ("[[segment]]\nkind = \"rest\"\nangle_deg = 0.0\nduration_s = 9.0\n", "belong to `rotate`"),
            ("[[segment]]\nkind = \"rest\"\naxis = \"x\"\nduration_s = 9.0\n", "belong to `rotate`"),
            ("[[segment]]\nkind = \"rotate\"\naxis = \"x\"\nangle_deg = 90.0\nduration_s = 9.0\n[[segment]]\nkind = \"cruise\"\nduration_s = 9.0\n", "turntable"),
        ];
        for (seg, want) in bad {
            let e = Scenario::parse(&format!("{base}{seg}"), "sc.toml").unwrap_err();
            assert!(format!("{e:#}").contains(want), "{seg}: {e:#}");
        }
        // π/2 written as degrees: run, with a warning
        let sc = Scenario::parse(
            &format!("{base}[[segment]]\nkind = \"rotate\"\naxis = \"x\"\nangle_deg = 1.5708\nduration_s = 9.0\n"),
            "sc.toml",
        )
        .unwrap();
        assert!(
            sc.warnings.iter().any(|w| w.contains("radians")),
            "{:?}",
            sc.warnings
        );
    }

    #[test]
    fn injected_values_beyond_the_spec_limit_are_refused() {
        let base = "name = \"t\"\nseed = 1\nimu_rate_hz = 100.0\n[start]\nlat_deg = 40.0\nlon_deg = 116.0\nh_m = 50.0\neuler_deg = [0.0, 0.0, 0.0]\n[[segment]]\nkind = \"rest\"\nduration_s = 9.0\n[errors]\n";
        for (line, want) in [
            ("tau_x = \"2 s\"\n", "2000 ms is beyond the 100 ms"),
            ("size_x_y = \"40 m\"\n", "40000 mm is beyond the 1000 mm"),
        ] {
            let e = Scenario::parse(&format!("{base}{line}"), "sc.toml").unwrap_err();
            let e = format!("{e:#}");
            assert!(e.contains(want) && e.contains("sc.toml:"), "{line}: {e}");
        }
        for line in ["tau_x = \"2 ms\"\n", "size_x_y = \"40 mm\"\n"] {
            Scenario::parse(&format!("{base}{line}"), "sc.toml").unwrap();
        }
    }
}
