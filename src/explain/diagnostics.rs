//! What one filter pass's innovations say: per channel NIS, whiteness, segments, truth.

use super::{ARCSEC, G0};
use crate::estimate::filter::{self, channel_name, FilterRun};
use crate::estimate::stats;
use crate::io::truth::TruthRow;
use crate::model::Model;
use crate::nav::earth;
use serde::Serialize;

/// One segment of the run and what the innovations of one channel did in it.
#[derive(Debug, Clone, Serialize)]
pub struct SegmentStats {
    /// Start and end [s].
    pub t0: f64,
    /// End [s].
    pub t1: f64,
    /// Excitation level (rms specific force about its mean) [g].
    pub level_g: f64,
    /// Innovations in the segment.
    pub count: usize,
    /// Mean NIS.
    pub nis_mean: f64,
    /// Mean normalised innovation ν/√S (bias in σ units).
    pub bias_sigma: f64,
}

/// What the innovations of one channel say.
#[derive(Debug, Clone, Serialize)]
pub struct ChannelStats {
    /// `vel_n`, `vel_e`, `pos_n`, `pos_e`, `pos_h`.
    pub channel: String,
    /// Number of innovations.
    pub count: usize,
    /// Mean NIS (1 for a consistent filter).
    pub nis_mean: f64,
    /// 95 % band of the mean NIS for this count.
    pub nis_band: [f64; 2],
    /// Fraction of innovations outside the single-epoch 95 % band (0.05 expected).
    pub fraction_outside_95: f64,
    /// Ljung–Box Q and its p-value (whiteness of the normalised innovations), when computable.
    pub ljung_box_q: Option<f64>,
    /// Ljung–Box p-value.
    pub whiteness_p: Option<f64>,
    /// Per-segment statistics.
    pub segments: Vec<SegmentStats>,
}

/// With truth: the filter's predicted σ against its actual estimation error.
#[derive(Debug, Clone, Serialize)]
pub struct TruthCheck {
    /// State (`phi_n`, `phi_e`, `dlat`, `dlon`, …).
    pub state: String,
    /// RMS of the predicted 1-σ (display unit).
    pub predicted_sigma_rms: f64,
    /// RMS of the actual error of the estimate (display unit).
    pub actual_error_rms: f64,
    /// Display unit.
    pub unit: String,
}

/// What one filter pass says about its model.
#[derive(Debug, Clone, Serialize)]
pub struct PassStats {
    /// Model as a string.
    pub model: String,
    /// Time of the first innovation [s] (data time; the words count from here).
    pub t_start: f64,
    /// Total log-likelihood of the innovations, Σ −½(ν²/S + ln 2πS).
    pub loglik: f64,
    /// Mean NIS over all scalar innovations.
    pub nis_mean: f64,
    /// Smallest per-channel whiteness p, Bonferroni-corrected over the channels (capped at 1).
    pub whiteness_p: f64,
    /// Per channel.
    pub channels: Vec<ChannelStats>,
    /// Model error e = φ̂ − φ RMS north, east [arcsec] over the second half (with truth).
    pub model_error_rms_arcsec: Option<[f64; 2]>,
    /// Predicted σ against actual error (with truth).
    pub truth_check: Vec<TruthCheck>,
}

/// Bonferroni-corrected whiteness p at or below which a channel's innovations are called
/// correlated in time.
pub const STRUCTURE_WHITENESS_P: f64 = 0.01;
/// |mean normalised innovation| × √count over a segment at or beyond which the segment is
/// called biased (≈ a two-sided 6e-5 level: fifty segment-channel tests at 0.3 %).
pub const STRUCTURE_SEGMENT_Z: f64 = 4.0;

/// Structure left in one channel's innovations: time correlation, or a segment whose mean
/// normalised innovation is far from zero for its count.
#[derive(Debug, Clone, Serialize)]
pub struct ResidualStructure {
    /// Channel (`vel_n`, …).
    pub channel: String,
    /// Ljung–Box p, Bonferroni-corrected over the pass's channels (capped at 1).
    pub whiteness_p: Option<f64>,
    /// True when `whiteness_p` ≤ [`STRUCTURE_WHITENESS_P`].
    pub correlated: bool,
    /// The segment with the largest |mean ν/√S| × √count: start, end [s, data time].
    pub segment: Option<[f64; 2]>,
    /// That segment's mean normalised innovation × √count (a z-score; 0 expected).
    pub segment_z: f64,
    /// True when |`segment_z`| ≥ [`STRUCTURE_SEGMENT_Z`].
    pub biased: bool,
}

impl PassStats {
    /// The channels whose innovations show structure (correlated in time or biased over a
    /// segment); empty for a pass whose innovations look white and unbiased. Channels whose
    /// mean NIS lies below half its band's lower end are left out (their stated σ dominates).
    pub fn structure(&self) -> Vec<ResidualStructure> {
        let k = self.channels.len().max(1) as f64;
        self.channels
            .iter()
            // innovations far below their stated σ (a noise-free static aid at a stated 1 m)
            // are the filter's own smooth error: correlated by construction, no sign of a
            // missing effect
            .filter(|c| c.nis_mean >= 0.5 * c.nis_band[0])
            .filter_map(|c| {
                let whiteness_p = c.whiteness_p.map(|p| (p * k).min(1.0));
                let worst = c
                    .segments
                    .iter()
                    .map(|s| (s, s.bias_sigma * (s.count as f64).sqrt()))
                    .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()));
                let segment_z = worst.map(|w| w.1).unwrap_or(0.0);
                let r = ResidualStructure {
                    channel: c.channel.clone(),
                    whiteness_p,
                    correlated: whiteness_p.is_some_and(|p| p <= STRUCTURE_WHITENESS_P),
                    segment: worst.map(|(s, _)| [s.t0, s.t1]),
                    segment_z,
                    biased: segment_z.abs() >= STRUCTURE_SEGMENT_Z,
                };
                (r.correlated || r.biased).then_some(r)
            })
            .collect()
    }
}

/// Segments of constant excitation: 1-s bins of the level merged while within 30 % (and
/// 0.05 g); runs shorter than 10 s join their neighbour; with one segment, ten fixed windows.
pub(super) fn segments(level: &[(f64, f64)], t_start: f64, t_end: f64) -> Vec<(f64, f64, f64)> {
    let mut bins: Vec<(f64, f64, f64)> = Vec::new(); // (t0, t1, level)
    let mut k = 0;
    while k < level.len() {
        let t0 = level[k].0;
        let (mut s, mut c) = (0.0, 0usize);
        while k < level.len() && level[k].0 < t0 + 1.0 {
            s += level[k].1;
            c += 1;
            k += 1;
        }
        let t1 = level.get(k).map(|l| l.0).unwrap_or(t_end);
        bins.push((t0, t1, s / c.max(1) as f64));
    }
    let mut segs: Vec<(f64, f64, f64, usize)> = Vec::new(); // t0 t1 sum count
    for (t0, t1, l) in bins {
        if let Some(last) = segs.last_mut() {
            let mean = last.2 / last.3 as f64;
            if (l - mean).abs() <= (0.3 * mean).max(0.05 * G0) {
                last.1 = t1;
                last.2 += l;
                last.3 += 1;
                continue;
            }
        }
        segs.push((t0, t1, l, 1));
    }
    let mut merged: Vec<(f64, f64, f64, usize)> = Vec::new();
    for s in segs {
        match merged.last_mut() {
            Some(last) if s.1 - s.0 < 10.0 => {
                last.1 = s.1;
                last.2 += s.2;
                last.3 += s.3;
            }
            _ => merged.push(s),
        }
    }
    let mut out: Vec<(f64, f64, f64)> = merged
        .into_iter()
        .map(|(t0, t1, s, c)| (t0, t1, s / c as f64))
        .collect();
    if let Some(first) = out.first_mut() {
        first.0 = t_start;
    }
    if out.len() <= 1 && t_end - t_start > 60.0 {
        let lvl = out.first().map(|s| s.2).unwrap_or(0.0);
        let w = (t_end - t_start) / 10.0;
        out = (0..10)
            .map(|i| (t_start + i as f64 * w, t_start + (i + 1) as f64 * w, lvl))
            .collect();
    }
    out
}

/// Total log-likelihood of a run's innovations, Σ −½(ν²/S + ln 2πS).
pub fn innovation_loglik(run: &FilterRun) -> f64 {
    loglik_sum(&run.innovations)
}

/// Total log-likelihood of scalar innovations, Σ −½(ν²/S + ln 2πS).
pub(super) fn loglik_sum(innovations: &[crate::estimate::filter::Innovation]) -> f64 {
    innovations.iter().map(loglik_of).sum()
}

/// One scalar innovation's log-likelihood −½(ν²/S + ln 2πS).
pub(super) fn loglik_of(i: &crate::estimate::filter::Innovation) -> f64 {
    -0.5 * (i.nu * i.nu / i.s + (2.0 * std::f64::consts::PI * i.s).ln())
}

pub(super) fn pass_stats(
    model: &Model,
    run: &FilterRun,
    level: &[(f64, f64)],
    truth: Option<&[TruthRow]>,
) -> PassStats {
    let t_start = run.innovations.first().map(|i| i.t).unwrap_or(0.0);
    let t_end = run.innovations.last().map(|i| i.t).unwrap_or(0.0);
    let segs = segments(level, t_start, t_end + 1e-9);
    let mut names: Vec<String> = Vec::new();
    for i in &run.innovations {
        let c = channel_name(i.meas, i.component);
        if !names.contains(&c) {
            names.push(c);
        }
    }
    let single = [
        stats::chi2_quantile(1.0, -1.959_964).max(0.0),
        3.841_458_820_694_124,
    ];
    let mut channels = Vec::new();
    let loglik = innovation_loglik(run);
    let (mut nis_all, mut n_all) = (0.0, 0usize);
    for i in &run.innovations {
        nis_all += i.nu * i.nu / i.s;
        n_all += 1;
    }
    let mut min_p: f64 = 1.0;
    for name in &names {
        let inn: Vec<_> = run
            .innovations
            .iter()
            .filter(|i| &channel_name(i.meas, i.component) == name)
            .collect();
        let normed: Vec<f64> = inn.iter().map(|i| i.nu / i.s.sqrt()).collect();
        let nis: Vec<f64> = normed.iter().map(|v| v * v).collect();
        let count = nis.len();
        let nis_mean = nis.iter().sum::<f64>() / count.max(1) as f64;
        let outside = nis.iter().filter(|&&v| v > single[1]).count() as f64 / count.max(1) as f64;
        let lags = (count / 5).clamp(1, 20);
        let lb = stats::ljung_box(&normed, lags);
        if let Some((_, p)) = lb {
            min_p = min_p.min(p);
        }
        let segments = segs
            .iter()
            .map(|&(t0, t1, lvl)| {
                let vals: Vec<f64> = inn
                    .iter()
                    .zip(&normed)
                    .filter(|(i, _)| i.t >= t0 && i.t < t1)
                    .map(|(_, v)| *v)
                    .collect();
                let c = vals.len().max(1) as f64;
                SegmentStats {
                    t0,
                    t1,
                    level_g: lvl / G0,
                    count: vals.len(),
                    nis_mean: vals.iter().map(|v| v * v).sum::<f64>() / c,
                    bias_sigma: vals.iter().sum::<f64>() / c,
                }
            })
            .filter(|s| s.count > 0)
            .collect();
        channels.push(ChannelStats {
            channel: name.clone(),
            count,
            nis_mean,
            nis_band: stats::mean_chi2_band(1.0, count.max(1), 1.959_964),
            fraction_outside_95: outside,
            ljung_box_q: lb.map(|x| x.0),
            whiteness_p: lb.map(|x| x.1),
            segments,
        });
    }
    let whiteness_p = (min_p * names.len().max(1) as f64).min(1.0);
    let half = 0.5 * (t_start + t_end);
    let model_error_rms_arcsec = filter::model_error_rms_arcsec(run, half, t_end + 1.0);
    let truth_check = truth.map(|_| truth_check(model, run)).unwrap_or_default();
    PassStats {
        model: model.name.clone(),
        t_start,
        loglik,
        nis_mean: nis_all / n_all.max(1) as f64,
        whiteness_p,
        channels,
        model_error_rms_arcsec,
        truth_check,
    }
}

pub(super) fn truth_check(model: &Model, run: &FilterRun) -> Vec<TruthCheck> {
    let mut out = Vec::new();
    for (c, name) in ["phi_n", "phi_e"].iter().enumerate() {
        let Some(i) = model.index_of(name) else {
            continue;
        };
        let (mut se, mut ss, mut k) = (0.0, 0.0, 0usize);
        for r in &run.records {
            if let Some(pt) = r.phi_true {
                se += (r.phi_est[c] - pt[c]).powi(2);
                ss += r.sigma[i].powi(2);
                k += 1;
            }
        }
        if k > 0 {
            out.push(TruthCheck {
                state: name.to_string(),
                predicted_sigma_rms: (ss / k as f64).sqrt() * ARCSEC,
                actual_error_rms: (se / k as f64).sqrt() * ARCSEC,
                unit: "arcsec".into(),
            });
        }
    }
    for (c, name) in ["dlat", "dlon"].iter().enumerate() {
        let Some(i) = model.index_of(name) else {
            continue;
        };
        let (mut se, mut ss, mut k) = (0.0, 0.0, 0usize);
        for r in &run.records {
            if let Some(pe) = r.pos_err_ne {
                let scale = if c == 0 {
                    earth::radius_meridian(r.nav.lat) + r.nav.h
                } else {
                    (earth::radius_transverse(r.nav.lat) + r.nav.h) * r.nav.lat.cos()
                };
                se += (r.x[i] * scale - pe[c]).powi(2);
                ss += (r.sigma[i] * scale).powi(2);
                k += 1;
            }
        }
        if k > 0 {
            out.push(TruthCheck {
                state: ["pos_n", "pos_e"][c].to_string(),
                predicted_sigma_rms: (ss / k as f64).sqrt(),
                actual_error_rms: (se / k as f64).sqrt(),
                unit: "m".into(),
            });
        }
    }
    out
}
