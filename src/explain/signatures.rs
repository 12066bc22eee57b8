//! Candidate signatures (Willsky–Jones GLR) riding along one filter pass.

use crate::estimate::filter::Observer;
use crate::model::catalog::StateRef;
use crate::model::generated::common;
use crate::model::{Model, RegressorAccumulator};
use crate::nav::nav_point::NavPoint;
use nalgebra::Vector3;

/// Candidate signatures riding along one filter pass.
pub(super) struct Signatures {
    pub(super) n: usize,
    /// Candidate term indices.
    pub(super) cands: Vec<usize>,
    /// Baseline instrument terms: (model index, term index).
    pub(super) base_terms: Vec<(usize, usize)>,
    /// Per candidate, the indices into `base_terms` of the terms on its sensor axis.
    same_axis: Vec<Vec<usize>>,
    /// Accumulator of the candidates' and baseline terms' regressors (ids below).
    pub(super) acc: RegressorAccumulator,
    pub(super) r_mean: Vec<f64>,
    /// D, state-major: D[i·m + c] is state i of candidate c's signature (the inner loops run
    /// over the candidates, so one A entry serves all of them).
    pub(super) d: Vec<f64>,
    pub(super) w: Vec<f64>,
    pub(super) aw: Vec<f64>,
    pub(super) g: Vec<f64>,
    /// Position in `r_mean` of each candidate's and each baseline term's regressor.
    pub(super) cand_r: Vec<usize>,
    pub(super) base_r_idx: Vec<usize>,
    /// Baseline terms' regressor means of the current step.
    pub(super) base_r: Vec<f64>,
    /// For each candidate, (model index, row of its term column) of the rows it reaches.
    pub(super) cand_rows: Vec<Vec<(usize, usize)>>,
    /// Mean NIS of the pass (the dispersion φ of the quasi-likelihood; 1 when consistent).
    pub(super) dispersion: f64,
    /// Information J (m × m) and score b (m) per group of each split of the updates (the first
    /// split is by time and covers every update: J is the sum of its groups').
    pub(super) splits: Vec<SplitAcc>,
    /// Speed of the last step [m/s].
    pub(super) speed: f64,
    /// Group of [`Split::Motion`] for the next update: 0 before any rotation, else 1 + the body
    /// axis of the most recent step that rotated faster than [`ROTATING`].
    pub(super) last_axis: usize,
    /// Group of [`Split::Manoeuvre`]: rotations begun so far (capped), and whether the last
    /// step rotated.
    pub(super) manoeuvre: usize,
    pub(super) rotating: bool,
    /// Σ over steps of each candidate's regressor mean, and steps counted.
    pub(super) reg_sum: Vec<f64>,
    pub(super) steps: usize,
    /// Σ r_c r_b, Σ r_c², Σ r_b² over steps for candidates vs same-axis baseline terms.
    pub(super) cross: Vec<f64>,
    pub(super) cand_sq: Vec<f64>,
    pub(super) base_sq: Vec<f64>,
    /// Excitation level per step: (t [s], rms of the specific force about its step mean [m/s²]).
    pub(super) level: Vec<(f64, f64)>,
    pub(super) f_sum: Vector3<f64>,
    pub(super) f2_sum: f64,
    pub(super) count: usize,
    /// Candidates that enter H instead of A (GNSS terms): (candidate index, term name).
    pub(super) gnss: Vec<(usize, &'static str)>,
    /// The navigation point of the last step (a GNSS candidate's H entry is evaluated there).
    pub(super) np: Option<NavPoint>,
    /// The current measurement's GNSS candidate entries: (component, candidate, H value).
    pub(super) gnss_h: Vec<(usize, usize, f64)>,
    /// The (measurement, time) `gnss_h` holds.
    pub(super) gnss_h_key: (&'static str, f64),
}

/// A body rate above which a step counts as rotating [rad/s] (0.5 deg/s; Earth's rate is
/// 0.004 deg/s).
pub(super) const ROTATING: f64 = 0.5 * std::f64::consts::PI / 180.0;

/// A partition of the updates into groups whose information and score are kept apart, so that
/// a finding can be checked to hold across the data (a constant of the sensor or the aiding
/// gives one value in every group; a term fitting some other effect follows that effect).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Split {
    /// Before and from the median aiding time [s].
    Time(f64),
    /// Below and from the median aided speed [m/s].
    Speed(f64),
    /// By the body axis of the most recent rotation: none yet, x, y, z (a turntable's
    /// positions, a vehicle's turns).
    Motion,
    /// By manoeuvre: the updates since each rotation began (before the first, then one group
    /// per rotation, the last of [`MAX_MANOEUVRES`] holding the rest).
    Manoeuvre,
    /// By the kind of fix: positions, velocities, attitudes (a timing, lever arm or mounting of
    /// the aiding moves each kind by its own H; one value must fit them all).
    Measurement,
}

/// The group of [`Split::Measurement`] of an update of measurement `meas`: 0 position,
/// 1 velocity (NED or body), 2 attitude or any other.
fn measurement_group(meas: &str) -> usize {
    if meas.starts_with("pos") {
        0
    } else if meas.starts_with("vel") {
        1
    } else {
        2
    }
}

/// Most groups of [`Split::Manoeuvre`].
pub(super) const MAX_MANOEUVRES: usize = 64;

impl Split {
    /// The split's name in the report and the JSON.
    pub(super) fn name(&self) -> &'static str {
        match self {
            Split::Time(_) => "time",
            Split::Speed(_) => "speed",
            Split::Motion => "motion",
            Split::Manoeuvre => "manoeuvre",
            Split::Measurement => "measurement",
        }
    }

    /// Its number of groups.
    pub(super) fn group_count(&self) -> usize {
        match self {
            Split::Time(_) | Split::Speed(_) => 2,
            Split::Motion => 4,
            Split::Manoeuvre => MAX_MANOEUVRES,
            Split::Measurement => 3,
        }
    }

    /// Group `k`, in words.
    pub(super) fn group_label(&self, k: usize) -> String {
        const MOTION: [&str; 4] = [
            "before any rotation",
            "after rotating about x",
            "after rotating about y",
            "after rotating about z",
        ];
        match (self, k) {
            (Split::Time(_), 0) => "first half".into(),
            (Split::Time(_), _) => "second half".into(),
            (Split::Speed(_), 0) => "slower half".into(),
            (Split::Speed(_), _) => "faster half".into(),
            (Split::Motion, k) => MOTION[k.min(3)].into(),
            (Split::Manoeuvre, 0) => "before any rotation".into(),
            (Split::Manoeuvre, k) if k + 1 == MAX_MANOEUVRES => format!("from rotation {k} on"),
            (Split::Manoeuvre, k) => format!("rotation {k}"),
            (Split::Measurement, 0) => "from the position fixes".into(),
            (Split::Measurement, 1) => "from the velocity fixes".into(),
            (Split::Measurement, _) => "from the attitude fixes".into(),
        }
    }
}

/// One split's information and score per group.
pub(super) struct SplitAcc {
    pub(super) split: Split,
    /// J per group (m × m, row-major).
    pub(super) info: Vec<Vec<f64>>,
    /// b per group (m).
    pub(super) score: Vec<Vec<f64>>,
}

pub(super) fn reg_id(t: usize) -> usize {
    common::TERMS[t].regressor
}

impl Signatures {
    /// Signatures of the candidates `cands` through `model`'s filter, the updates' information
    /// kept apart per group of each of `splits` (the first must be [`Split::Time`]).
    pub(super) fn new(model: &Model, cands: &[usize], splits: &[Split]) -> Signatures {
        let n = model.n();
        let base_terms: Vec<(usize, usize)> = model
            .states
            .iter()
            .enumerate()
            .filter_map(|(i, s)| match *s {
                StateRef::Term(t) => Some((i, t)),
                StateRef::Nav(_) => None,
            })
            .collect();
        let mut r_ids = Vec::new();
        for t in cands.iter().copied().chain(base_terms.iter().map(|b| b.1)) {
            if !r_ids.contains(&reg_id(t)) {
                r_ids.push(reg_id(t));
            }
        }
        let mut nav_pos = [None; common::NAV_COUNT];
        for (i, s) in model.states.iter().enumerate() {
            if let StateRef::Nav(k) = *s {
                nav_pos[k] = Some(i);
            }
        }
        let m = cands.len();
        let nb = base_terms.len();
        let pos = |t: usize| r_ids.iter().position(|&x| x == reg_id(t)).unwrap_or(0);
        let cand_r = cands.iter().map(|&t| pos(t)).collect();
        let base_r_idx = base_terms.iter().map(|b| pos(b.1)).collect();
        let cand_rows = cands
            .iter()
            .map(|&t| {
                common::TERM_ROWS[t]
                    .iter()
                    .filter_map(|&row| nav_pos[row].map(|i| (i, row)))
                    .collect()
            })
            .collect();
        // each candidate's baseline terms on its sensor axis, in the baseline's order
        let same_axis = cands
            .iter()
            .map(|&t| {
                let info = &common::TERMS[t];
                base_terms
                    .iter()
                    .enumerate()
                    .filter(|(_, &(_, bt))| {
                        let bi = &common::TERMS[bt];
                        bi.sensor == info.sensor && bi.axis == info.axis
                    })
                    .map(|(k, _)| k)
                    .collect()
            })
            .collect();
        Signatures {
            n,
            cands: cands.to_vec(),
            same_axis,
            base_terms,
            acc: RegressorAccumulator::new(r_ids.clone()),
            r_mean: vec![0.0; r_ids.len()],
            d: vec![0.0; m * n],
            w: vec![0.0; m * n],
            aw: vec![0.0; m * n],
            g: vec![0.0; m],
            cand_r,
            base_r_idx,
            base_r: vec![0.0; nb],
            cand_rows,
            dispersion: 1.0,
            splits: splits
                .iter()
                .map(|&split| {
                    let k = split.group_count();
                    SplitAcc {
                        split,
                        info: vec![vec![0.0; m * m]; k],
                        score: vec![vec![0.0; m]; k],
                    }
                })
                .collect(),
            speed: 0.0,
            last_axis: 0,
            manoeuvre: 0,
            rotating: false,
            reg_sum: vec![0.0; m],
            steps: 0,
            cross: vec![0.0; m * nb],
            cand_sq: vec![0.0; m],
            base_sq: vec![0.0; nb],
            level: Vec::new(),
            f_sum: Vector3::zeros(),
            f2_sum: 0.0,
            count: 0,
            gnss: cands
                .iter()
                .enumerate()
                .filter(|(_, &t)| common::TERMS[t].sensor.enters_h())
                .map(|(c, &t)| (c, common::TERMS[t].name))
                .collect(),
            np: None,
            gnss_h: Vec::new(),
            gnss_h_key: ("", f64::NAN),
        }
    }
}

/// A function whose loops run compiled for AVX-512F where the CPU has it, else as written: the
/// same operations in the same order on wider vectors (Rust never fuses a multiply and an add),
/// so the same bits.
macro_rules! wide_fn {
    ($(#[$doc:meta])* fn $name:ident($($arg:ident: $ty:ty),* $(,)?) $body:block) => {
        $(#[$doc])*
        fn $name($($arg: $ty),*) {
            #[inline(always)]
            fn body($($arg: $ty),*) $body
            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx512f")]
            unsafe fn avx512($($arg: $ty),*) {
                body($($arg),*)
            }
            #[cfg(target_arch = "x86_64")]
            if crate::model::covariance::has_avx512() && !scalar_only() {
                // SAFETY: the CPU has AVX-512F
                return unsafe { avx512($($arg),*) };
            }
            body($($arg),*)
        }
    };
}

#[cfg(test)]
thread_local! {
    /// Tests: run [`wide_fn!`]'s functions as written on this thread.
    static SCALAR_ONLY: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Whether [`wide_fn!`]'s functions must run as written (a test's scalar reference).
#[inline(always)]
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
fn scalar_only() -> bool {
    #[cfg(test)]
    {
        SCALAR_ONLY.with(|c| c.get())
    }
    #[cfg(not(test))]
    {
        false
    }
}

wide_fn! {
    /// W = A D over A's pattern for the m signatures (state-major), in place of `w`.
    fn mul_d(a: &[f64], n: usize, m: usize, pattern: &[(usize, usize)], d: &[f64], w: &mut [f64]) {
        sparse_mul_block(a, n, m, pattern, d, w)
    }
}

wide_fn! {
    /// D ← D + dt (W + dt/2 A W), with `aw` as scratch.
    #[allow(clippy::too_many_arguments)]
    fn advance_d(
        a: &[f64],
        n: usize,
        m: usize,
        pattern: &[(usize, usize)],
        w: &[f64],
        aw: &mut [f64],
        d: &mut [f64],
        dt: f64,
    ) {
        sparse_mul_block(a, n, m, pattern, w, aw);
        let h = 0.5 * dt;
        for ((di, wi), awi) in d.iter_mut().zip(w).zip(aw.iter()) {
            *di += dt * (wi + h * awi);
        }
    }
}

wide_fn! {
    /// G += H D for one scalar measurement row `h`, then D ← D − K G.
    fn update_d(h: &[f64], k: &[f64], n: usize, m: usize, g: &mut [f64], d: &mut [f64]) {
        for (j, &hj) in h.iter().enumerate().take(n) {
            if hj != 0.0 {
                for (g, d) in g.iter_mut().zip(&d[j * m..(j + 1) * m]) {
                    *g += hj * d;
                }
            }
        }
        for (i, &ki) in k.iter().enumerate().take(n) {
            if ki != 0.0 {
                for (d, g) in d[i * m..(i + 1) * m].iter_mut().zip(g.iter()) {
                    *d -= ki * g;
                }
            }
        }
    }
}

wide_fn! {
    /// J += g gᵀ / s and b += g ν / s for one scalar measurement (g: the m signatures' H D).
    fn accumulate_info(info: &mut [f64], score: &mut [f64], g: &[f64], m: usize, inv_s: f64, nu: f64) {
        for a in 0..m {
            let ga = g[a] * inv_s;
            if ga == 0.0 {
                continue;
            }
            score[a] += ga * nu;
            for (i, gb) in info[a * m..(a + 1) * m].iter_mut().zip(g) {
                *i += ga * gb;
            }
        }
    }
}

/// out = A · v for m column vectors stored state-major (v[j·m + c]), over A's pattern.
#[inline(always)]
pub(super) fn sparse_mul_block(
    a: &[f64],
    n: usize,
    m: usize,
    pattern: &[(usize, usize)],
    v: &[f64],
    out: &mut [f64],
) {
    out.iter_mut().for_each(|x| *x = 0.0);
    for &(i, j) in pattern {
        let aij = a[i * n + j];
        let (src, dst) = (&v[j * m..(j + 1) * m], &mut out[i * m..(i + 1) * m]);
        for (o, x) in dst.iter_mut().zip(src) {
            *o += aij * x;
        }
    }
}

impl Observer for Signatures {
    fn sample(&mut self, sig: &crate::model::ImuSignals) {
        self.acc.add(sig);
        self.f_sum += sig.f;
        self.f2_sum += sig.f.norm_squared();
        self.count += 1;
    }

    fn step_sums(&mut self, sums: &crate::estimate::nav_tape::StepSums<'_>) {
        self.acc.set_sums(sums.regressors, sums.count);
        self.f_sum = sums.f;
        self.f2_sum = sums.f2;
        self.count = sums.count as _;
    }

    fn step(&mut self, t: f64, dt: f64, np: &NavPoint, a: &[f64], pattern: &[(usize, usize)]) {
        let (n, m) = (self.n, self.cands.len());
        if !self.gnss.is_empty() {
            self.np = Some(*np);
        }
        self.speed = Vector3::from(np.v_ned).norm();
        let w = Vector3::from(np.w_b);
        if w.norm() > ROTATING {
            self.last_axis = 1 + w.iamax();
            if !self.rotating {
                self.manoeuvre = (self.manoeuvre + 1).min(MAX_MANOEUVRES - 1);
            }
            self.rotating = true;
        } else if w.norm() < 0.5 * ROTATING {
            self.rotating = false;
        }
        self.acc.mean_into(&mut self.r_mean);
        self.acc.reset();
        if self.count > 0 {
            let c = self.count as f64;
            let mean = self.f_sum / c;
            let var = (self.f2_sum / c - mean.norm_squared()).max(0.0);
            self.level.push((t, var.sqrt()));
        }
        self.f_sum = Vector3::zeros();
        self.f2_sum = 0.0;
        self.count = 0;
        self.steps += 1;
        let nb = self.base_terms.len();
        for k in 0..nb {
            let r = self.r_mean[self.base_r_idx[k]];
            self.base_r[k] = r;
            self.base_sq[k] += r * r;
        }
        if m == 0 {
            return;
        }
        // W = A D + [a_c], then D ← D + dt (W + dt/2 A W)
        mul_d(a, n, m, pattern, &self.d, &mut self.w);
        for c in 0..m {
            let t_c = self.cands[c];
            let rv = self.r_mean[self.cand_r[c]];
            self.reg_sum[c] += rv;
            self.cand_sq[c] += rv * rv;
            for &k in &self.same_axis[c] {
                self.cross[c * nb + k] += rv * self.base_r[k];
            }
            let mut col = [0.0; common::NAV_COUNT];
            common::term_column(t_c, np, rv, &mut col);
            for &(i, row) in &self.cand_rows[c] {
                self.w[i * m + c] += col[row];
            }
        }
        advance_d(a, n, m, pattern, &self.w, &mut self.aw, &mut self.d, dt);
    }

    fn scalar_update(
        &mut self,
        t: f64,
        meas: &'static str,
        component: usize,
        h: &[f64],
        k: &[f64],
        nu: f64,
        s: f64,
    ) {
        let (n, m) = (self.n, self.cands.len());
        if m == 0 {
            return;
        }
        // G = H D (per candidate), plus a GNSS candidate's own H entry, then D ← D − K G
        self.g.iter_mut().for_each(|x| *x = 0.0);
        if let (false, Some(np)) = (self.gnss.is_empty(), &self.np) {
            // the measurement's GNSS entries, evaluated once per epoch for all its components
            if self.gnss_h_key != (meas, t) {
                self.gnss_h_key = (meas, t);
                self.gnss_h.clear();
                if let Some(mi) = common::MEASUREMENTS.iter().position(|x| x.name == meas) {
                    let (out, gnss) = (&mut self.gnss_h, &self.gnss);
                    common::measurement_entries(mi, np, &mut |row, state, v| {
                        if let Some(&(c, _)) = gnss.iter().find(|x| x.1 == state) {
                            out.push((row, c, v));
                        }
                    });
                }
            }
            for &(row, c, v) in &self.gnss_h {
                if row == component {
                    self.g[c] += v;
                }
            }
        }
        update_d(h, k, n, m, &mut self.g, &mut self.d);
        let inv_s = 1.0 / s;
        let (speed, axis, manoeuvre) = (self.speed, self.last_axis, self.manoeuvre);
        let g = &self.g;
        for acc in &mut self.splits {
            let k = match acc.split {
                Split::Time(t_half) => usize::from(t >= t_half),
                Split::Speed(v_half) => usize::from(speed >= v_half),
                Split::Motion => axis,
                Split::Manoeuvre => manoeuvre,
                Split::Measurement => measurement_group(meas),
            };
            let (info, score) = (&mut acc.info[k], &mut acc.score[k]);
            accumulate_info(info, score, g, m, inv_s, nu);
        }
    }
}

impl Signatures {
    /// Information J (m × m, row-major) over the whole pass.
    pub(super) fn info(&self) -> Vec<f64> {
        sum_groups(&self.splits[0].info)
    }

    /// Score b (m) over the whole pass.
    pub(super) fn score(&self) -> Vec<f64> {
        sum_groups(&self.splits[0].score)
    }
}

/// Element-wise sum of a split's groups.
fn sum_groups(groups: &[Vec<f64>]) -> Vec<f64> {
    let mut out = vec![0.0; groups.first().map_or(0, Vec::len)];
    for g in groups {
        for (o, x) in out.iter_mut().zip(g) {
            *o += x;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The signature loops give the same bits compiled for AVX-512F as written (where the CPU
    /// has it; elsewhere both runs take the scalar path): W = A D, D's advance, its update by a
    /// scalar measurement and the information's accumulation, over m = 1 to 41 signatures.
    #[test]
    fn the_wide_loops_give_the_scalar_bits() {
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut rnd = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for m in [1, 3, 8, 17, 39, 41] {
            let n = 31;
            let pattern: Vec<(usize, usize)> = (0..n * n)
                .filter(|_| rnd() > 0.7)
                .map(|k| (k / n, k % n))
                .collect();
            let a: Vec<f64> = (0..n * n).map(|_| rnd() * 1e-3).collect();
            let d0: Vec<f64> = (0..n * m).map(|_| rnd()).collect();
            let h: Vec<f64> = (0..n)
                .map(|j| if j % 3 == 0 { rnd() } else { 0.0 })
                .collect();
            let k: Vec<f64> = (0..n)
                .map(|i| if i % 2 == 0 { rnd() } else { 0.0 })
                .collect();
            let run = |scalar: bool| {
                SCALAR_ONLY.with(|c| c.set(scalar));
                let (mut d, mut w, mut aw) = (d0.clone(), vec![0.0; n * m], vec![0.0; n * m]);
                mul_d(&a, n, m, &pattern, &d, &mut w);
                advance_d(&a, n, m, &pattern, &w, &mut aw, &mut d, 0.01);
                let mut g = vec![0.0; m];
                update_d(&h, &k, n, m, &mut g, &mut d);
                let (mut info, mut score) = (vec![0.0; m * m], vec![0.0; m]);
                accumulate_info(&mut info, &mut score, &g, m, 1.0 / 3.7, 0.25);
                SCALAR_ONLY.with(|c| c.set(false));
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<u64>>();
                [
                    bits(&w),
                    bits(&aw),
                    bits(&d),
                    bits(&g),
                    bits(&info),
                    bits(&score),
                ]
            };
            assert_eq!(run(true), run(false), "m = {m}");
        }
    }
}
