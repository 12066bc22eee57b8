//! What a filter run measures, computed once: the model error e = φ̂ − φ against truth (RMS in
//! arcsec), the mean NIS per innovation channel against its band, the drift at the end of each
//! GNSS outage; and the unit constant they share.

use super::filter::FilterRun;
use crate::io::aiding::Outage;
use anyhow::{bail, Result};

/// Arcseconds per radian.
pub const ARCSEC_PER_RAD: f64 = 180.0 / std::f64::consts::PI * 3600.0;

/// Root-mean-square of the model error e = φ̂ − φ (north, east) over records with t in [t0, t1],
/// in arcseconds (the paper's metric, DESIGN §5).
pub fn model_error_rms_arcsec(run: &FilterRun, t0: f64, t1: f64) -> Option<[f64; 2]> {
    let mut sum = [0.0; 2];
    let mut k = 0usize;
    for r in run.records.iter().filter(|r| r.t >= t0 && r.t <= t1) {
        let pt = r.phi_true?;
        for c in 0..2 {
            sum[c] += (r.phi_est[c] - pt[c]).powi(2);
        }
        k += 1;
    }
    if k == 0 {
        return None;
    }
    let arcsec = ARCSEC_PER_RAD;
    Some([
        (sum[0] / k as f64).sqrt() * arcsec,
        (sum[1] / k as f64).sqrt() * arcsec,
    ])
}

/// Where the truth contradicts the filter itself, in words (None when it does not), from each
/// axis's (north tilt, east tilt, heading) |e| [rad] and |e| / σ over the epochs with truth: on
/// an axis where the median |e| exceeds 5° and the median |e| / σ 10, the truth is not of this
/// run's attitude (yaw in radians or with the opposite sign, another body frame) or not of its
/// time; `measured` names what measures against it (e.g. `model_error.txt measures`).
pub fn truth_disagreement(disagreement: &[Vec<(f64, f64)>; 3], measured: &str) -> Option<String> {
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(0.0)
    };
    let mut said = Vec::new();
    for (k, axis) in ["north tilt", "east tilt", "heading"].iter().enumerate() {
        let d = &disagreement[k];
        if d.len() < 10 {
            continue;
        }
        let e = median(d.iter().map(|x| x.0).collect());
        let z = median(d.iter().map(|x| x.1).collect());
        if e > 5f64.to_radians() && z > 10.0 {
            said.push(format!(
                "{axis} by a median {:.1}° ({z:.0} σ)",
                e.to_degrees()
            ));
        }
    }
    (!said.is_empty()).then(|| {
        format!(
            "--truth: the truth's attitude differs from the filter's estimate in {} over the epochs with truth: \
             is the truth's yaw in radians, counted the other way (PSINS: counter-clockwise), or of another body \
             frame, its roll and pitch in radians? Or the estimate is off: an aiding clock off the IMU's or a model that misses \
             an error (see the warnings and the NIS above). {measured} against it",
            said.join(", ")
        )
    })
}

/// The per-axis (north tilt, east tilt, heading) |e| [rad] and |e| / σ of `run`'s records with
/// truth, for [`truth_disagreement`]; `phi` the model's indices of phi_n, phi_e, phi_d.
pub fn attitude_disagreement(run: &FilterRun, phi: [Option<usize>; 3]) -> [Vec<(f64, f64)>; 3] {
    let mut out: [Vec<(f64, f64)>; 3] = Default::default();
    for r in &run.records {
        add_attitude_disagreement(&mut out, r, phi);
    }
    out
}

/// Adds record `r`'s |e| [rad] and |e| / σ per axis to `acc` when it has truth (a streamed run
/// collects them record by record); `phi` the model's indices of phi_n, phi_e, phi_d.
pub fn add_attitude_disagreement(
    acc: &mut [Vec<(f64, f64)>; 3],
    r: &super::filter::Record,
    phi: [Option<usize>; 3],
) {
    let Some(p) = r.phi_true else { return };
    let e = r.phi_est - p;
    for (k, i) in phi.iter().enumerate() {
        if let Some(i) = *i {
            acc[k].push((e[k].abs(), e[k].abs() / r.sigma[i]));
        }
    }
}

/// Name of one scalar channel of a measurement: `vel_n`, `vel_e`, `pos_n`, `pos_e`, `pos_h`,
/// a body-frame reference's `vel_bx`, `vel_by`, `vel_bz` and an attitude reference's `att_n`,
/// `att_e`, `att_d`.
pub fn channel_name(meas: &str, component: usize) -> String {
    if meas == "att_ref" {
        return format!("att_{}", ["n", "e", "d"].get(component).unwrap_or(&"?"));
    }
    if let Some(prefix) = meas.strip_suffix("_ne") {
        format!("{prefix}_{}", ["n", "e"].get(component).unwrap_or(&"?"))
    } else if let Some(prefix) = meas.strip_suffix("_body") {
        format!(
            "{prefix}_b{}",
            ["x", "y", "z"].get(component).unwrap_or(&"?")
        )
    } else {
        meas.to_string()
    }
}

/// The measurement has one channel per component (named by [`channel_name`]), not one in all.
fn per_component(meas: &str) -> bool {
    meas.ends_with("_ne") || meas.ends_with("_body") || meas == "att_ref"
}

/// [`channel_name`] as a static string (what explain keeps per innovation: no allocation each),
/// from a table of the spec's measurements built once; `?` for a component no measurement has.
pub fn channel_str(meas: &'static str, component: usize) -> &'static str {
    static TABLE: std::sync::OnceLock<Vec<(&'static str, usize, &'static str)>> =
        std::sync::OnceLock::new();
    if !per_component(meas) {
        return meas;
    }
    TABLE
        .get_or_init(|| {
            crate::model::generated::common::MEASUREMENTS
                .iter()
                .filter(|m| per_component(m.name))
                .flat_map(|m| {
                    (0..m.rows.len()).map(move |c| {
                        let name: &'static str =
                            Box::leak(channel_name(m.name, c).into_boxed_str());
                        (m.name, c, name)
                    })
                })
                .collect()
        })
        .iter()
        .find(|x| x.0 == meas && x.1 == component)
        .map_or("?", |x| x.2)
}

/// Every channel of the spec's measurements ([`channel_str`] of each component), in spec order:
/// an innovation kept for a plot holds its index here, not its name.
pub fn channels() -> &'static [&'static str] {
    static LIST: std::sync::OnceLock<Vec<&'static str>> = std::sync::OnceLock::new();
    LIST.get_or_init(|| {
        let mut out: Vec<&'static str> = Vec::new();
        for m in crate::model::generated::common::MEASUREMENTS.iter() {
            for c in 0..m.rows.len() {
                let name = channel_str(m.name, c);
                if !out.contains(&name) {
                    out.push(name);
                }
            }
        }
        out
    })
}

/// The index in [`channels`] of measurement `meas`'s component `component`.
pub fn channel_id(meas: &'static str, component: usize) -> u16 {
    let name = channel_str(meas, component);
    channels().iter().position(|c| *c == name).unwrap_or(0) as u16
}

/// Mean normalised innovation squared (NIS) of one scalar channel against what a consistent
/// filter gives (1, with the 95 % band of the mean of `count` χ²₁ values).
#[derive(Debug, Clone, serde::Serialize)]
pub struct ChannelNis {
    /// `vel_n`, `vel_e`, `pos_n`, `pos_e`, `pos_h`.
    pub channel: String,
    /// Number of scalar innovations.
    pub count: usize,
    /// Mean of ν²/S (dimensionless; 1 expected).
    pub mean: f64,
    /// 95 % band of the mean for a consistent filter with this count.
    pub band: [f64; 2],
}

impl ChannelNis {
    /// One word on the channel: `consistent`, `too large` (the model misses something or the
    /// noise is too small) or `too small` (noise or priors pessimistic).
    pub fn verdict(&self) -> &'static str {
        if self.mean > self.band[1] {
            "too large"
        } else if self.mean < self.band[0] {
            "too small"
        } else {
            "consistent"
        }
    }
}

/// Mean NIS per channel, in the order the channels first appear.
pub fn nis_by_channel(run: &FilterRun) -> Vec<ChannelNis> {
    let mut out: Vec<(String, f64, usize)> = Vec::new();
    for i in &run.innovations {
        let name = channel_name(i.meas, i.component);
        let v = i.nu * i.nu / i.s;
        match out.iter_mut().find(|c| c.0 == name) {
            Some(c) => {
                c.1 += v;
                c.2 += 1;
            }
            None => out.push((name, v, 1)),
        }
    }
    out.into_iter()
        .map(|(channel, sum, count)| ChannelNis {
            channel,
            count,
            mean: sum / count as f64,
            band: crate::estimate::stats::mean_chi2_band(1.0, count, 1.96),
        })
        .collect()
}

/// The model error RMS over the second half of the update epochs, from each epoch's time [s]
/// and its north and east model error [rad] (None where the truth has no row).
#[derive(Debug, Clone, Copy)]
pub struct SecondHalfRms {
    /// Start of the second half [s]: midway between the first and the last epoch.
    pub mid: f64,
    /// The last epoch [s].
    pub last: f64,
    /// Epochs of the second half.
    pub epochs: usize,
    /// Of those, the ones with a truth row.
    pub with_truth: usize,
    /// RMS north, east [arcsec] (None when no epoch of the second half has a truth row).
    pub rms_arcsec: Option<[f64; 2]>,
}

/// [`SecondHalfRms`] of the epochs `errors` (time [s], north and east model error [rad]); None
/// without epochs.
pub fn second_half_rms(errors: &[(f64, Option<[f64; 2]>)]) -> Option<SecondHalfRms> {
    let (first, last) = (errors.first()?, errors.last()?);
    let mid = 0.5 * (first.0 + last.0);
    let epochs = errors.iter().filter(|e| e.0 >= mid).count();
    let half: Vec<[f64; 2]> = errors
        .iter()
        .filter(|e| e.0 >= mid)
        .filter_map(|e| e.1)
        .collect();
    let rms = |c: usize| {
        (half.iter().map(|e| e[c] * e[c]).sum::<f64>() / half.len() as f64).sqrt() * ARCSEC_PER_RAD
    };
    Some(SecondHalfRms {
        mid,
        last: last.0,
        epochs,
        with_truth: half.len(),
        rms_arcsec: (!half.is_empty()).then(|| [rms(0), rms(1)]),
    })
}

/// The drift at the end of one GNSS outage.
#[derive(Debug, Clone, serde::Serialize)]
pub struct OutageDrift {
    /// START of `--outage START,DURATION`: seconds from the first IMU sample.
    pub start_from_first_sample_s: f64,
    /// DURATION [s].
    pub duration_s: f64,
    /// Start of the window on the data's clock [s].
    pub start_s: f64,
    /// End of the window on the data's clock [s].
    pub end_s: f64,
    /// Time of the first aiding fix after the outage [s].
    pub fix_t_s: f64,
    /// North drift [m].
    pub drift_n_m: f64,
    /// East drift [m].
    pub drift_e_m: f64,
    /// Horizontal drift [m].
    pub drift_horizontal_m: f64,
}

/// For each outage, the pos_ne innovation (computed − fix, before the update) at the first
/// fix after it: the drift of the filter's solution over the outage. `t_first`, `t_last`: the
/// first and last IMU sample [s].
pub fn outage_drifts(
    outages: &[Outage],
    run: &FilterRun,
    t_first: f64,
    t_last: f64,
) -> Result<Vec<OutageDrift>> {
    let mut out = Vec::new();
    for o in outages {
        // the first position fix after the outage, its residual before any update (applied
        // or rejected by the innovation gate, and the east one not after the north)
        let Some(&(fix_t, [n, e])) = run.pos_ne_prior.iter().find(|p| p.0 >= o.end_s) else {
            bail!(
                "--outage {}: no position fix after it inside the data (which end at {}): nothing to measure the drift against",
                o.words(t_first),
                crate::io::aiding::time_from_first_sample(t_last, t_first)
            );
        };
        out.push(OutageDrift {
            start_from_first_sample_s: o.start_s - t_first,
            duration_s: o.end_s - o.start_s,
            start_s: o.start_s,
            end_s: o.end_s,
            fix_t_s: fix_t,
            drift_n_m: n,
            drift_e_m: e,
            drift_horizontal_m: n.hypot(e),
        });
    }
    Ok(out)
}
