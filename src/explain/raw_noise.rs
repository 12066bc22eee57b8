//! The sensors' white noise read from the raw IMU increments, apart from the filter: the Allan
//! variance at τ = 0.2 s in 2-s blocks, from the quietest blocks. A noise level the filter fits
//! well above what the raw increments show is not the sensor's white noise: it stands in for
//! something the model lacks (an effect that acts with the motion, or a correlated noise).
//!
//! Motion, vibration and any other signal in a block only raise its Allan variance, so the
//! quietest blocks bound the white noise from above; at 0.2 s a sensor's own low-pass filter
//! (≤ 1/10 of that) does not lower it, and a bias instability adds little. The quietest fifth of
//! the blocks is read against the χ² spread their statistic has under white noise alone.

use super::ExplainData;
use crate::estimate::stats;

/// Length of one Allan cluster [s].
pub(super) const CLUSTER_S: f64 = 0.2;
/// Clusters per block (9 differences of successive cluster means per axis).
const BLOCK_CLUSTERS: usize = 10;
/// The fraction of blocks, quietest first, whose quantile is read.
const QUIET_FRACTION: f64 = 0.2;
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

/// Per block: the Allan variance of each sensor at τ (mean over the three axes) and τ [s].
#[derive(Default)]
struct Block {
    sums: [f64; 2],
    diffs: usize,
    prev: Option<[nalgebra::Vector3<f64>; 2]>,
    tau: f64,
}

/// Reads [`RawNoise`] from `data`'s IMU increments; None when the data hold fewer than
/// [`MIN_BLOCKS`] blocks of at least two samples per cluster.
pub(super) fn read(data: &ExplainData) -> anyhow::Result<Option<RawNoise>> {
    let mut samples = data.imu.samples()?;
    let (mut out, mut block) = ([Vec::new(), Vec::new()], Block::default());
    let (mut sum, mut t_c, mut n_c) = ([nalgebra::Vector3::zeros(); 2], 0.0, 0usize);
    let mut t_prev = f64::NAN;
    let mut dt_nominal = f64::NAN;
    while let Some(s) = samples.next_sample()? {
        let dt = s.t - t_prev;
        t_prev = s.t;
        // (the first sample, a repeated time or NaN: no interval)
        if dt.is_nan() || dt <= 0.0 {
            continue;
        }
        if dt_nominal.is_nan() {
            dt_nominal = dt;
        }
        // a gap breaks the block: no difference across it
        if dt > 2.5 * dt_nominal {
            (block, sum, t_c, n_c) = (Block::default(), [nalgebra::Vector3::zeros(); 2], 0.0, 0);
            continue;
        }
        sum[0] += s.dtheta;
        sum[1] += s.dv;
        t_c += dt;
        n_c += 1;
        if t_c < CLUSTER_S - 0.5 * dt {
            continue;
        }
        if n_c >= 2 {
            let mean = [sum[0] / t_c, sum[1] / t_c];
            if let Some(p) = block.prev {
                for k in 0..2 {
                    block.sums[k] += (mean[k] - p[k]).norm_squared();
                }
                block.diffs += 1;
            }
            block.prev = Some(mean);
            block.tau += t_c;
            if block.diffs + 1 == BLOCK_CLUSTERS {
                let (d, tau) = (block.diffs as f64, block.tau / BLOCK_CLUSTERS as f64);
                for (o, sum_sq) in out.iter_mut().zip(block.sums) {
                    // ½ mean square difference, averaged over the three axes
                    o.push((sum_sq / (2.0 * 3.0 * d), tau));
                }
                block = Block::default();
            }
        }
        (sum, t_c, n_c) = ([nalgebra::Vector3::zeros(); 2], 0.0, 0);
    }
    let blocks = out[0].len();
    if blocks < MIN_BLOCKS {
        return Ok(None);
    }
    // under white noise alone a block's statistic is AVAR · χ²_k / k, k = 3 axes × 9
    let k = 3.0 * (BLOCK_CLUSTERS - 1) as f64;
    let q = stats::chi2_isf(1.0 - QUIET_FRACTION, k) / k;
    let density = |v: &mut Vec<(f64, f64)>| {
        v.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (avar, tau) = v[(v.len() as f64 * QUIET_FRACTION) as usize];
        // white noise N: AVAR(τ) = N² / τ
        (avar / q * tau).sqrt()
    };
    let [mut g, mut a] = out;
    Ok(Some(RawNoise {
        gyro: density(&mut g),
        accel: density(&mut a),
        blocks,
    }))
}

/// How far a fitted white-noise scale's 95 % interval must lie above the raw reading's scale
/// to contradict it.
pub(super) const MARGIN: f64 = 1.25;

/// Why a fitted white-noise scale `interval` (of the stated `stated` [SI]) is not the sensor's
/// white noise, given the raw reading `raw` [SI] of the same sensor in `unit` (`to_unit` from SI);
/// None when the fit is within [`MARGIN`] of the raw reading or below it.
pub(super) fn contradiction(
    what: &str,
    interval: [f64; 2],
    stated: f64,
    raw: f64,
    to_unit: f64,
    unit: &str,
    blocks: usize,
) -> Option<String> {
    if !(stated > 0.0 && raw > 0.0) {
        return None;
    }
    let raw_scale = raw / stated;
    (interval[0] > MARGIN * raw_scale).then(|| {
        format!(
            "the raw {what} increments show a white noise of at most {} {unit} ({}× the stated; Allan deviation at {CLUSTER_S} s in the quietest fifth of {blocks} blocks of 2 s), and the fit's 95 % interval starts at {}× the stated, above {MARGIN}× that: the level the filter needs is not the sensor's white noise",
            super::sig3(raw * to_unit),
            super::sig3(raw_scale),
            super::sig3(interval[0])
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::estimate::filter::AidingEpoch;
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
        let aid: [AidingEpoch; 0] = [];
        let data = ExplainData {
            imu: super::super::ImuInput::Memory(d),
            aid: &aid,
            truth: None,
            start: crate::nav::strapdown::NavState {
                t: 0.0,
                lat: 0.5,
                lon: 2.0,
                h: 0.0,
                v: Vector3::zeros(),
                q: nalgebra::UnitQuaternion::identity(),
            },
        };
        read(&data).unwrap()
    }

    #[test]
    fn white_noise_is_read_at_its_density_and_motion_only_raises_it() {
        let (arw, vrw) = (1e-4, 2e-3);
        let quiet = read_of(&imu(600.0, arw, vrw, |_| false)).unwrap();
        assert!((quiet.gyro / arw - 1.0).abs() < 0.05, "{quiet:?}");
        assert!((quiet.accel / vrw - 1.0).abs() < 0.05, "{quiet:?}");
        // turning for 1 s in every 4 s (half the blocks hold a turn): the quiet fifth reads
        // the noise
        let turning = read_of(&imu(600.0, arw, vrw, |t| (0.5..1.5).contains(&(t % 4.0)))).unwrap();
        assert!((turning.gyro / arw - 1.0).abs() < 0.05, "{turning:?}");
        // a turn in every block: the reading rises, never falls
        let most = read_of(&imu(600.0, arw, vrw, |t| (0.5..1.5).contains(&(t % 2.0)))).unwrap();
        assert!(most.gyro > 1.5 * arw, "{most:?}");
        // turning throughout: the reading rises (an upper bound), never falls
        let always = read_of(&imu(600.0, arw, vrw, |_| true)).unwrap();
        assert!(always.gyro > 1.5 * arw, "{always:?}");
        // too little data for a reading
        assert!(read_of(&imu(40.0, arw, vrw, |_| false)).is_none());
    }

    #[test]
    fn a_fit_above_the_raw_reading_by_more_than_the_margin_contradicts_it() {
        let c = |lo: f64| contradiction("gyro", [lo, 2.0 * lo], 1.0, 1.0, 1.0, "u", 100);
        assert!(c(1.3).is_some());
        assert!(c(1.2).is_none());
        // nothing stated or read: no judgement
        assert!(contradiction("gyro", [5.0, 6.0], 0.0, 1.0, 1.0, "u", 100).is_none());
    }
}
