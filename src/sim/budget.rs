//! What a simulation costs before it runs (memory, text written, vibration-term evaluations,
//! against the limits above which `simulate` asks for `--force`), and whether what it produced
//! is data the readers accept.

use crate::sim::scenario::Scenario;
use crate::sim::simulator::SimOutput;

/// Bytes of memory per IMU sample while simulating (measured: ~55 B).
pub const MEM_PER_SAMPLE: f64 = 60.0;
/// Bytes of text per sample in imu.txt (measured: ~150 B).
pub const TEXT_PER_SAMPLE: f64 = 160.0;
/// Above this many bytes of memory or output, `--force` is needed.
pub const LIMIT_BYTES: f64 = 4e9;
/// Vibration-term evaluations per second on one core (measured here: 4.7e8/s for 2000 random
/// components at 100 Hz with 320 sub-steps).
pub const EVALUATIONS_PER_S: f64 = 4e8;
/// Above this many vibration-term evaluations (about 10 min), `--force` is needed.
pub const LIMIT_EVALUATIONS: f64 = 2.4e11;

/// The cost of simulating a scenario.
#[derive(Debug, Clone, Copy)]
pub struct Budget {
    /// IMU samples.
    pub samples: f64,
    /// Memory while simulating [bytes].
    pub memory_bytes: f64,
    /// Text of imu.txt [bytes].
    pub text_bytes: f64,
    /// Vibration terms.
    pub terms: f64,
    /// Sub-steps per IMU sample.
    pub sub_steps: f64,
    /// Vibration-term evaluations: at every quadrature node (3) of every sub-step.
    pub evaluations: f64,
}

impl Budget {
    /// The cost of simulating `sc`.
    pub fn of(sc: &Scenario) -> Budget {
        let samples = sc.duration() * sc.imu_rate_hz;
        let (terms, sub) = sc.vibration_work();
        Budget {
            samples,
            memory_bytes: samples * MEM_PER_SAMPLE,
            text_bytes: samples * TEXT_PER_SAMPLE,
            terms,
            sub_steps: sub,
            evaluations: samples * sub * 3.0 * terms.max(1.0),
        }
    }

    /// True when the memory or the text exceeds [`LIMIT_BYTES`].
    pub fn too_large(&self) -> bool {
        self.memory_bytes > LIMIT_BYTES || self.text_bytes > LIMIT_BYTES
    }

    /// True when the vibration-term evaluations exceed [`LIMIT_EVALUATIONS`].
    pub fn too_long(&self) -> bool {
        self.evaluations > LIMIT_EVALUATIONS
    }

    /// Roughly how long the vibration terms take on one core [min].
    pub fn minutes(&self) -> f64 {
        self.evaluations / EVALUATIONS_PER_S / 60.0
    }
}

/// What makes a simulation's output unreadable, with the time (None when the readers accept
/// it): a trajectory that runs past a pole or beyond 1e4 m/s, or increments beyond what any IMU
/// measures (a scenario can ask for them within each of its own bounds).
pub fn unreadable(sim: &SimOutput) -> Option<String> {
    use crate::io::bounds;
    use crate::io::imu_stream::{MAX_FORCE, MAX_RATE};
    for r in &sim.truth {
        let d = 180.0 / std::f64::consts::PI;
        let problem = bounds::lat_deg(r.lat * d)
            .or_else(|| bounds::height_m(r.h))
            .or_else(|| {
                (r.v.norm() > 1e4).then(|| format!("speed {:.0} m/s beyond 1e4 m/s", r.v.norm()))
            });
        if let Some(p) = problem {
            return Some(format!("the simulated trajectory is not one the readers accept at t = {:.3} s: {p} (a path across a pole, or an acceleration or vibration too large for its duration)", r.t));
        }
    }
    let mut prev = sim.start.t;
    for s in &sim.imu.samples {
        let dt = s.t - prev;
        prev = s.t;
        let (w, f) = (s.dtheta.norm() / dt, s.dv.norm() / dt);
        if !(w.is_finite() && f.is_finite()) || w > MAX_RATE || f > MAX_FORCE {
            return Some(format!(
                "at t = {:.3} s the simulated IMU measures {w:.3e} rad/s and {f:.3e} m/s^2, beyond any IMU (<= {MAX_RATE} rad/s, <= 2000 g): an injected error or a motion too large",
                s.t
            ));
        }
    }
    None
}
