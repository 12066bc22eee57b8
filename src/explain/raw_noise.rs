//! The sensors' white noise read from the raw IMU increments, apart from the filter: the Allan
//! variance at τ = 0.2 s in 2-s blocks, from the quietest blocks. A noise level the filter fits
//! well above what the raw increments show is not the sensor's white noise: it stands in for
//! something the model lacks (an effect that acts with the motion, or a correlated noise).
//!
//! Motion, vibration and any other signal in a block only raise its Allan variance, so the
//! quietest blocks bound the white noise from above; at 0.2 s a sensor's own low-pass filter
//! (≤ 1/10 of that) does not lower it, and a bias instability adds little. Each block's
//! statistic uses the differences of its clusters in disjoint pairs (five per axis), which are
//! independent: under white noise alone it is AVAR·χ²₁₅/15 exactly, and the quietest fifth of
//! the blocks is read against that spread.

use crate::estimate::stats;

/// Length of one Allan cluster [s].
pub(super) const CLUSTER_S: f64 = 0.2;
/// Clusters per block (5 differences of cluster means in disjoint pairs per axis).
const BLOCK_CLUSTERS: usize = 10;
/// Longest sample interval taken into a cluster [s]: a longer one (a gap) ends the block.
const LONGEST_INTERVAL_S: f64 = 0.5 * CLUSTER_S;
/// The fraction of blocks, quietest first, whose quantile is read.
const QUIET_FRACTION: f64 = 0.2;
/// Independent differences per axis in a block.
const PAIRS: usize = BLOCK_CLUSTERS / 2;
/// Fewest blocks (2 s each) for a reading.
const MIN_BLOCKS: usize = 30;

/// White noise densities read from the raw increments (SI).
#[derive(Debug, Clone, Copy)]
pub(super) struct RawNoise {
    /// Gyro white noise (angle random walk) [rad/√s], at most.
    pub(super) gyro: f64,
    /// Accelerometer white noise (velocity random walk) [m/s/√s], at most.
    pub(super) accel: f64,
    /// Blocks read.
    pub(super) blocks: usize,
}

/// Per block: the sums of squared pair differences of each sensor, the clusters so far, the
/// first cluster mean of an open pair and the clusters' total length [s].
#[derive(Default)]
struct Block {
    sums: [f64; 2],
    clusters: usize,
    open: Option<[nalgebra::Vector3<f64>; 2]>,
    tau: f64,
}

/// The reading, sample by sample: fed every IMU sample of a pass the caller makes anyway
/// ([`Reading::push`]), then [`Reading::finish`]ed.
#[derive(Default)]
pub(super) struct Reading {
    /// Per sensor, each finished block's statistic and its τ [s].
    out: [Vec<(f64, f64)>; 2],
    block: Block,
    /// The open cluster: summed increments, length [s], samples.
    sum: [nalgebra::Vector3<f64>; 2],
    t_c: f64,
    n_c: usize,
    t_prev: Option<f64>,
}

impl Reading {
    /// Takes one sample (time [s], increments Δθ [rad] and Δv [m/s] over the interval before it).
    pub(super) fn push(&mut self, s: &crate::io::imu::ImuSample) {
        let dt = self.t_prev.map_or(f64::NAN, |t| s.t - t);
        self.t_prev = Some(s.t);
        // (the first sample, a repeated time or NaN: no interval)
        if dt.is_nan() || dt <= 0.0 {
            return;
        }
        // a gap breaks the block: no difference across it
        if dt > LONGEST_INTERVAL_S {
            self.block = Block::default();
            self.close_cluster();
            return;
        }
        self.sum[0] += s.dtheta;
        self.sum[1] += s.dv;
        self.t_c += dt;
        self.n_c += 1;
        if self.t_c < CLUSTER_S - 0.5 * dt {
            return;
        }
        if self.n_c >= 2 {
            let mean = [self.sum[0] / self.t_c, self.sum[1] / self.t_c];
            let block = &mut self.block;
            match block.open.take() {
                Some(p) => {
                    for k in 0..2 {
                        block.sums[k] += (mean[k] - p[k]).norm_squared();
                    }
                }
                None => block.open = Some(mean),
            }
            block.clusters += 1;
            block.tau += self.t_c;
            if block.clusters == BLOCK_CLUSTERS {
                let (d, tau) = (PAIRS as f64, block.tau / BLOCK_CLUSTERS as f64);
                for (o, sum_sq) in self.out.iter_mut().zip(block.sums) {
                    // ½ mean square difference, averaged over the three axes
                    o.push((sum_sq / (2.0 * 3.0 * d), tau));
                }
                *block = Block::default();
            }
        }
        self.close_cluster();
    }

    /// Starts the next cluster empty.
    fn close_cluster(&mut self) {
        (self.sum, self.t_c, self.n_c) = ([nalgebra::Vector3::zeros(); 2], 0.0, 0);
    }

    /// [`RawNoise`] from the samples pushed; None when they held fewer than [`MIN_BLOCKS`]
    /// blocks of at least two samples per cluster (a sample interval longer than
    /// [`LONGEST_INTERVAL_S`] ends a block).
    pub(super) fn finish(self) -> Option<RawNoise> {
        let blocks = self.out[0].len();
        if blocks < MIN_BLOCKS {
            return None;
        }
        // under white noise alone a block's statistic is AVAR · χ²_k / k, k = 3 axes × 5 pairs
        let k = 3.0 * PAIRS as f64;
        let q = stats::chi2_isf(1.0 - QUIET_FRACTION, k) / k;
        let density = |mut v: Vec<(f64, f64)>| {
            v.sort_by(|a, b| a.0.total_cmp(&b.0));
            let (avar, tau) = v[(v.len() as f64 * QUIET_FRACTION) as usize];
            // white noise N: AVAR(τ) = N² / τ
            (avar / q * tau).sqrt()
        };
        let [g, a] = self.out;
        Some(RawNoise {
            gyro: density(g),
            accel: density(a),
            blocks,
        })
    }
}

/// How far a fitted white-noise scale's 95 % interval must lie above the raw reading's scale
/// to contradict it.
pub(super) const MARGIN: f64 = 1.25;

/// What the raw reading `raw` [SI] of a sensor's white noise says of a fitted scale `interval`
/// (of the stated `stated` [SI]), in `unit` (`to_unit` from SI): Err(why) when the interval starts
/// above [`MARGIN`]× the reading's scale (the fit is not the sensor's white noise), Ok(words)
/// when the reading allows it; None when nothing is stated or read.
pub(super) fn judge(
    what: &str,
    interval: [f64; 2],
    stated: f64,
    raw: f64,
    to_unit: f64,
    unit: &str,
    blocks: usize,
) -> Option<Result<String, String>> {
    if !(stated > 0.0 && raw > 0.0) {
        return None;
    }
    let raw_scale = raw / stated;
    let reading = format!(
        "the raw {what} increments show a white noise of at most {} {unit} ({}× the stated; Allan deviation at {CLUSTER_S} s in the quietest fifth of {blocks} blocks of 2 s)",
        super::sig3(raw * to_unit),
        super::sig3(raw_scale),
    );
    Some(if interval[0] > MARGIN * raw_scale {
        Err(format!(
            "{reading}, and the fit is at least {}× the stated (its 95 % interval's lower end, or its search bound), above {MARGIN}× that: the level the filter needs is not the sensor's white noise",
            super::sig3(interval[0])
        ))
    } else {
        Ok(format!("{reading}, which allows it"))
    })
}

/// The words for a white-noise level of `what` ("gyro", "accelerometer") when the data give no
/// raw reading.
pub(super) fn no_reading(what: &str) -> String {
    format!(
        "the raw {what} increments give no reading of it (fewer than {MIN_BLOCKS} blocks of 2 s with two or more samples per {CLUSTER_S}-s cluster and no interval over {LONGEST_INTERVAL_S} s), so nothing checks it against the sensor's own noise"
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::imu::{ImuData, ImuSample};
    use nalgebra::Vector3;

    /// `seconds` of 100 Hz increments with white noise of densities `arw` [rad/√s] and `vrw`
    /// [m/s/√s], and a rotation that changes at the times `moving` accepts [s].
    fn imu(seconds: f64, arw: f64, vrw: f64, moving: impl Fn(f64) -> bool) -> ImuData {
        let mut rng = crate::sim::rng::Rng::new(11);
        let dt = 0.01;
        let samples = (1..=(seconds / dt) as usize)
            .map(|k| {
                let t = k as f64 * dt;
                let turn = if moving(t) {
                    0.3 * (3.0 * t).sin()
                } else {
                    0.0
                };
                let mut g =
                    |s: f64| Vector3::new(rng.normal(), rng.normal(), rng.normal()) * s * dt.sqrt();
                let dtheta = Vector3::new(0.0, 0.0, turn * dt) + g(arw);
                let dv = Vector3::new(0.0, 0.0, -9.8 * dt) + g(vrw);
                ImuSample { t, dtheta, dv }
            })
            .collect();
        ImuData { samples }
    }

    fn read_of(d: &ImuData) -> Option<RawNoise> {
        let mut r = Reading::default();
        d.samples.iter().for_each(|s| r.push(s));
        r.finish()
    }

    #[test]
    fn white_noise_is_read_at_its_density_and_motion_only_raises_it() {
        let (arw, vrw) = (1e-4, 2e-3);
        let quiet = read_of(&imu(600.0, arw, vrw, |_| false)).unwrap();
        assert!((quiet.gyro / arw - 1.0).abs() < 0.05, "{quiet:?}");
        assert!((quiet.accel / vrw - 1.0).abs() < 0.05, "{quiet:?}");
        // turning for 1 s in every 4 s (half the blocks hold a turn): the quiet fifth of all
        // is two fifths of the quiet blocks, a little high (an upper bound)
        let turning = read_of(&imu(600.0, arw, vrw, |t| (0.5..1.5).contains(&(t % 4.0)))).unwrap();
        assert!((0.97..1.15).contains(&(turning.gyro / arw)), "{turning:?}");
        // a turn in every block: the reading rises, never falls
        let most = read_of(&imu(600.0, arw, vrw, |t| (0.5..1.5).contains(&(t % 2.0)))).unwrap();
        assert!(most.gyro > 1.5 * arw, "{most:?}");
        // turning throughout: the reading rises (an upper bound), never falls
        let always = read_of(&imu(600.0, arw, vrw, |_| true)).unwrap();
        assert!(always.gyro > 1.5 * arw, "{always:?}");
        // an odd first interval, and a sample merged into the next once a second: still read
        let mut odd = imu(600.0, arw, vrw, |_| false);
        let first = odd.samples[0];
        odd.samples.insert(
            0,
            ImuSample {
                t: first.t - 0.009,
                dtheta: first.dtheta * 0.1,
                dv: first.dv * 0.1,
            },
        );
        odd.samples[1].dtheta *= 0.9;
        odd.samples[1].dv *= 0.9;
        let mut k = 50;
        while k + 1 < odd.samples.len() {
            let gone = odd.samples.remove(k);
            odd.samples[k].dtheta += gone.dtheta;
            odd.samples[k].dv += gone.dv;
            k += 99;
        }
        let r = read_of(&odd).expect("a reading");
        assert!((r.gyro / arw - 1.0).abs() < 0.05, "{r:?}");
        // too little data for a reading
        assert!(read_of(&imu(40.0, arw, vrw, |_| false)).is_none());
    }

    #[test]
    fn a_fit_above_the_raw_reading_by_more_than_the_margin_contradicts_it() {
        let c = |lo: f64| judge("gyro", [lo, 2.0 * lo], 1.0, 1.0, 1.0, "u", 100).unwrap();
        assert!(c(1.3).is_err());
        let allowed = c(1.2).unwrap();
        assert!(
            allowed.contains("at most 1.00 u (1.00× the stated"),
            "{allowed}"
        );
        assert!(allowed.ends_with("which allows it"), "{allowed}");
        // nothing stated or read: no judgement
        assert!(judge("gyro", [5.0, 6.0], 0.0, 1.0, 1.0, "u", 100).is_none());
    }
}
