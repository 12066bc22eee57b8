//! Replays of an open-loop filter pass under other noise levels, without the navigator.
//!
//! In open loop the navigation solution, A(t), every H row and every residual z are the same
//! whatever the process noise q and the fixes' σ: only P, x and the innovations' variances
//! change. A [`Recorder`] watches one pass (it is an [`Observer`]) and keeps, for each interval
//! between updates, the transition Ψ = Π Φ over the interval's steps and, for each group of
//! states whose q is scaled together, the process noise the interval adds, G_k = Σ Ψ_j diag(q_k)
//! dt_j Ψ_jᵀ; and each scalar measurement (h, z, σ). [`Tape::innovations`] then runs
//! P ← Ψ P Ψᵀ + Σ_k s_k² G_k and the same scalar updates (gate included) for any configuration
//! that differs from the recorded one only by a scale of each group's q and of each
//! measurement's σ: the pass's innovations in well under 1 % of its time. The arithmetic is
//! regrouped (Ψ is formed before it meets P), so the results agree with a full pass to
//! round-off, not to the bit.

use super::filter::{gate_run, joseph_update, FilterConfig, Innovation, Mode, Observer, Scalar};
use crate::model::covariance::SparsePropagator;
use crate::nav::nav_point::NavPoint;
use crate::nav::strapdown::NavState;

/// A tape larger than this [bytes] is not kept (the passes then run in full).
const MAX_BYTES: usize = 64 << 20;

/// One recorded event.
enum Event {
    /// An interval's transition Ψ on the live rows (|L| × n) and each group's G on L × L.
    Propagate { psi: Vec<f64>, g: Vec<f64> },
    /// A scalar measurement: time [s], name, component, non-zeros of h, z and its 1-σ (SI).
    Measure {
        t: f64,
        meas: &'static str,
        comp: usize,
        h: Vec<(usize, f64)>,
        z: f64,
        sigma: f64,
    },
}

impl Event {
    /// Bytes the event holds (its matrices or its row, and the fixed fields).
    fn bytes(&self) -> usize {
        match self {
            Event::Propagate { psi, g } => 8 * (psi.len() + g.len()),
            Event::Measure { h, .. } => 16 * h.len() + 64,
        }
    }
}

/// Watches an open-loop pass and records what a replay needs (see the module's note).
pub struct Recorder {
    n: usize,
    /// States of each group (a partition of 0..n).
    groups: Vec<Vec<usize>>,
    /// Each group's q (zero off the group) [SI²/s].
    q_by_group: Vec<Vec<f64>>,
    cfg: FilterConfig,
    sp: Option<SparsePropagator>,
    /// Live rows L: those Φ − I can change or q drives (Ψ is the identity and G zero elsewhere).
    live: Vec<usize>,
    psi: Vec<f64>,
    g: Vec<Vec<f64>>,
    pending: bool,
    start: Option<(Vec<f64>, Vec<f64>)>,
    events: Vec<Event>,
    bytes: usize,
    too_large: bool,
}

impl Recorder {
    /// A recorder for a pass with configuration `cfg` over `n` states; `groups` lists the states
    /// whose q a replay may scale together (states in no group form one more group). None in
    /// closed loop, where the navigation depends on the noise.
    pub fn new(n: usize, cfg: &FilterConfig, groups: &[Vec<usize>]) -> Option<Recorder> {
        if cfg.mode != Mode::OpenLoop || cfg.q.len() != n || cfg.keep_covariance {
            return None;
        }
        let mut groups: Vec<Vec<usize>> = groups.to_vec();
        let rest: Vec<usize> = (0..n)
            .filter(|i| !groups.iter().any(|g| g.contains(i)))
            .collect();
        groups.push(rest);
        let q_by_group = groups
            .iter()
            .map(|g| {
                let mut q = vec![0.0; n];
                g.iter().for_each(|&i| q[i] = cfg.q[i]);
                q
            })
            .collect();
        let mut identity = vec![0.0; n * n];
        (0..n).for_each(|i| identity[i * n + i] = 1.0);
        Some(Recorder {
            n,
            g: vec![vec![0.0; n * n]; groups.len()],
            groups,
            q_by_group,
            cfg: cfg.clone(),
            sp: None,
            live: Vec::new(),
            psi: identity,
            pending: false,
            start: None,
            events: Vec::new(),
            bytes: 0,
            too_large: false,
        })
    }

    /// Closes the interval under way into a `Propagate` event.
    fn flush(&mut self) {
        let n = self.n;
        let nl = self.live.len();
        let mut psi = Vec::with_capacity(nl * n);
        for &i in &self.live {
            psi.extend_from_slice(&self.psi[i * n..(i + 1) * n]);
        }
        let mut g = Vec::with_capacity(self.g.len() * nl * nl);
        for gk in &mut self.g {
            for &i in &self.live {
                g.extend(self.live.iter().map(|&j| gk[i * n + j]));
            }
            gk.iter_mut().for_each(|v| *v = 0.0);
        }
        self.psi.iter_mut().for_each(|v| *v = 0.0);
        (0..n).for_each(|i| self.psi[i * n + i] = 1.0);
        self.pending = false;
        self.push(Event::Propagate { psi, g });
    }

    /// Keeps `e`, or drops the whole tape once it outgrows [`MAX_BYTES`].
    fn push(&mut self, e: Event) {
        self.bytes += e.bytes();
        self.events.push(e);
        if self.bytes > MAX_BYTES {
            self.too_large = true;
            self.events = Vec::new();
        }
    }

    /// The tape, or None when the pass recorded none (no step) or it outgrew [`MAX_BYTES`].
    pub fn finish(self) -> Option<Tape> {
        if self.too_large || self.sp.is_none() {
            return None;
        }
        let (x0, p0) = self.start?;
        Some(Tape {
            n: self.n,
            live: self.live,
            groups: self.groups,
            cfg: self.cfg,
            x0,
            p0,
            events: self.events,
        })
    }
}

impl Observer for Recorder {
    fn step(&mut self, _t: f64, dt: f64, _np: &NavPoint, a: &[f64], pattern: &[(usize, usize)]) {
        if self.too_large {
            return;
        }
        let n = self.n;
        if self.sp.is_none() {
            let sp = SparsePropagator::new(n, pattern);
            let mut live: Vec<usize> = sp.dyn_rows().to_vec();
            live.extend((0..n).filter(|&i| self.cfg.q[i] != 0.0));
            live.sort_unstable();
            live.dedup();
            self.live = live;
            self.sp = Some(sp);
        }
        let sp = self.sp.as_mut().expect("set above");
        sp.accumulate(a, dt, &self.q_by_group, &mut self.g, &mut self.psi);
        self.pending = true;
    }

    fn nav_sample(&mut self, _s: &NavState, x: &[f64], p: &[f64]) {
        if self.start.is_none() {
            self.start = Some((x.to_vec(), p.to_vec()));
        }
    }

    fn residual(&mut self, t: f64, meas: &'static str, comp: usize, h: &[f64], z: f64, sigma: f64) {
        if self.too_large {
            return;
        }
        if self.pending {
            self.flush();
        }
        let h: Vec<(usize, f64)> = h
            .iter()
            .enumerate()
            .filter(|(_, v)| **v != 0.0)
            .map(|(j, &v)| (j, v))
            .collect();
        self.push(Event::Measure {
            t,
            meas,
            comp,
            h,
            z,
            sigma,
        });
    }
}

/// A recorded open-loop pass (see the module's note).
pub struct Tape {
    n: usize,
    live: Vec<usize>,
    groups: Vec<Vec<usize>>,
    cfg: FilterConfig,
    x0: Vec<f64>,
    p0: Vec<f64>,
    events: Vec<Event>,
}

impl Tape {
    /// Each group's scale of q (as s², the ratio of `cfg.q` to the recorded q) when `cfg`
    /// differs from the recorded configuration only by such scales and by σ scales; else None.
    fn q_ratios(&self, cfg: &FilterConfig) -> Option<Vec<f64>> {
        let rec = &self.cfg;
        let same = cfg.step_s == rec.step_s
            && cfg.mode == rec.mode
            && cfg.prior_sigma == rec.prior_sigma
            && cfg.vertical == rec.vertical
            && cfg.keep_covariance == rec.keep_covariance
            && cfg.dense_reference == rec.dense_reference
            && cfg.known_gnss == rec.known_gnss
            && cfg.gate == rec.gate
            && cfg.q.len() == self.n;
        if !same {
            return None;
        }
        let mut ratios = Vec::with_capacity(self.groups.len());
        for g in &self.groups {
            let mut ratio = None::<f64>;
            for &i in g {
                let (new, old) = (cfg.q[i], rec.q[i]);
                if old == 0.0 {
                    if new != 0.0 {
                        return None;
                    }
                    continue;
                }
                let r = new / old;
                match ratio {
                    None => ratio = Some(r),
                    Some(x) if (x - r).abs() <= 1e-12 * x.abs() => {}
                    Some(_) => return None,
                }
            }
            let r = ratio.unwrap_or(1.0);
            if !(r.is_finite() && r >= 0.0) {
                return None;
            }
            ratios.push(r);
        }
        Some(ratios)
    }

    /// The scale of measurement `meas`'s σ in `cfg` against the recorded one.
    fn sigma_ratio(&self, cfg: &FilterConfig, meas: &str) -> f64 {
        let of = |c: &FilterConfig| {
            c.sigma_scale
                .iter()
                .find(|x| x.0 == meas)
                .map_or(1.0, |x| x.1)
        };
        of(cfg) / of(&self.cfg)
    }

    /// The applied innovations of the pass with configuration `cfg`, in the pass's order; None
    /// when `cfg` is not a rescaling of the recorded one, or when the replay meets what would
    /// end a pass (a variance negative or not finite, an update not finite): a full pass then
    /// says what went wrong.
    pub fn innovations(&self, cfg: &FilterConfig) -> Option<Vec<Innovation>> {
        let ratios = self.q_ratios(cfg)?;
        let sigma_ratios: Vec<(&'static str, f64)> = self
            .events
            .iter()
            .filter_map(|e| match e {
                Event::Measure { meas, .. } => Some(*meas),
                _ => None,
            })
            .fold(Vec::new(), |mut v, m| {
                if !v.iter().any(|x: &(&str, f64)| x.0 == m) {
                    v.push((m, self.sigma_ratio(cfg, m)));
                }
                v
            });
        let n = self.n;
        let (live, nl) = (&self.live, self.live.len());
        let mut off_live = vec![true; n];
        live.iter().for_each(|&i| off_live[i] = false);
        let mut x = self.x0.clone();
        let mut p = self.p0.clone();
        let (mut u, mut k) = (vec![0.0; n], vec![0.0; n]);
        let mut m = vec![0.0; nl * n];
        let mut xl = vec![0.0; nl];
        let mut h = vec![0.0; n];
        let mut gate_runs = Vec::new();
        let mut out = Vec::new();
        for e in &self.events {
            match e {
                Event::Propagate { psi, g } => {
                    // M = Ψ_L P (rows L); rows off L of Ψ P are P's own
                    for (r, mr) in m.chunks_exact_mut(n).enumerate() {
                        let pr = &psi[r * n..(r + 1) * n];
                        for (j, mj) in mr.iter_mut().enumerate() {
                            *mj = (0..n).map(|q| pr[q] * p[q * n + j]).sum();
                        }
                    }
                    for (r, &i) in live.iter().enumerate() {
                        // row i of Ψ P Ψᵀ: (Ψ P)_i · Ψ_j; off L, Ψ_j is e_j
                        let mr = &m[r * n..(r + 1) * n];
                        for j in 0..n {
                            p[i * n + j] = mr[j];
                        }
                    }
                    for (r, &i) in live.iter().enumerate() {
                        let mr = &m[r * n..(r + 1) * n];
                        for (s, &j) in live.iter().enumerate() {
                            let ps = &psi[s * n..(s + 1) * n];
                            let v: f64 = mr.iter().zip(ps).map(|(a, b)| a * b).sum();
                            p[i * n + j] = v;
                        }
                    }
                    // the columns off L mirror the rows
                    for &i in live {
                        for j in (0..n).filter(|&j| off_live[j]) {
                            p[j * n + i] = p[i * n + j];
                        }
                    }
                    for (kg, &s) in ratios.iter().enumerate() {
                        let gk = &g[kg * nl * nl..(kg + 1) * nl * nl];
                        for (r, &i) in live.iter().enumerate() {
                            for (c, &j) in live.iter().enumerate() {
                                p[i * n + j] += s * gk[r * nl + c];
                            }
                        }
                    }
                    for (r, xr) in xl.iter_mut().enumerate() {
                        *xr = psi[r * n..(r + 1) * n]
                            .iter()
                            .zip(&x)
                            .map(|(a, b)| a * b)
                            .sum();
                    }
                    for (r, &i) in live.iter().enumerate() {
                        x[i] = xl[r];
                    }
                    let bad = (0..n).any(|i| {
                        let v = p[i * n + i];
                        !x[i].is_finite()
                            || !v.is_finite()
                            || v < -1e-9 * self.cfg.prior_sigma[i].powi(2)
                    });
                    if bad {
                        return None;
                    }
                }
                Event::Measure {
                    t,
                    meas,
                    comp,
                    h: hs,
                    z,
                    sigma,
                } => {
                    let scale = sigma_ratios
                        .iter()
                        .find(|x| x.0 == *meas)
                        .map_or(1.0, |x| x.1);
                    let sc = sigma * scale;
                    if !(z.is_finite() && sc.is_finite()) {
                        return None;
                    }
                    hs.iter().for_each(|&(j, v)| h[j] = v);
                    let run = gate_run(&mut gate_runs, meas, *comp);
                    let gate = match cfg.gate {
                        Some(g) if gate_runs[run].2 < super::filter::GATE_RUN => g,
                        _ => f64::INFINITY,
                    };
                    let upd =
                        joseph_update(&mut x, &mut p, (&h, *z, sc * sc), gate, &mut u, &mut k);
                    hs.iter().for_each(|&(j, _)| h[j] = 0.0);
                    match upd {
                        Scalar::Applied(nu, s) => {
                            gate_runs[run].2 = 0;
                            out.push(Innovation {
                                t: *t,
                                meas,
                                component: *comp,
                                nu,
                                s,
                            });
                        }
                        Scalar::Gated(..) => gate_runs[run].2 += 1,
                        Scalar::NotFinite => return None,
                    }
                }
            }
        }
        if x.iter().chain(&p).any(|v| !v.is_finite()) {
            return None;
        }
        Some(out)
    }

    /// Bytes the tape holds (the events' matrices and rows).
    pub fn bytes(&self) -> usize {
        self.events.iter().map(Event::bytes).sum()
    }
}
