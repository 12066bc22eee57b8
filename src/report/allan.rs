//! `allan`'s words and plots: each channel's noise terms in display units (deg/h, ug), the note
//! on the τ the fits use, and the log-log plots of the gyros and accelerometers (with the `cli`
//! feature).

use crate::estimate::allan::{AllanCurve, NoiseFit};
use crate::io::units::STANDARD_GRAVITY;
use std::path::{Path, PathBuf};

/// rad/s to deg/h.
const R2DH: f64 = 180.0 / std::f64::consts::PI * 3600.0;

/// The plot file of one sensor (`suffix`: `gyro` or `accel`) under the prefix `prefix`:
/// PREFIX_SUFFIX.png.
pub fn plot_path(prefix: &Path, suffix: &str) -> PathBuf {
    PathBuf::from(format!("{}_{suffix}.png", prefix.display()))
}

/// One channel's noise terms in display units, saying where the data do not support a value.
pub fn fit_line(name: &str, f: &NoiseFit) -> String {
    let gyro = name.starts_with("gyro");
    let r2dh = R2DH;
    let ug = 1e6 / STANDARD_GRAVITY;
    let (white, bi, rw) = if gyro {
        (
            format!("ARW {} deg/sqrt(h)", num(f.white * r2dh / 60.0)),
            format!("{} deg/h", num(f.bias_instability * r2dh)),
            format!("RRW {} deg/h/sqrt(h)", num(f.random_walk * r2dh * 60.0)),
        )
    } else {
        (
            format!("VRW {} ug/sqrt(Hz)", num(f.white * ug)),
            format!("{} ug", num(f.bias_instability * ug)),
            format!("RRW {} ug/sqrt(s)", num(f.random_walk * ug)),
        )
    };
    let white = if f.white.is_finite() {
        white
    } else {
        "white noise not determined (no -1/2 slope)".into()
    };
    let bi = if !f.bias_instability.is_finite() {
        "bias instability not determined (too little data)".to_string()
    } else if f.bias_instability_upper_bound {
        format!("bias instability <= {bi} (curve still falling: an upper bound)")
    } else {
        format!("bias instability {bi}")
    };
    let rw = if f.random_walk.is_finite() {
        rw
    } else {
        "RRW not resolved by these data (no +1/2 slope within the supported tau)".into()
    };
    format!("{name:<8} {white}  {bi}  {rw}")
}

/// The note on the τ the fits use: at most a ninth of the `curve`'s span.
pub fn fit_span_note(curve: &AllanCurve) -> String {
    format!(
        "(fits use tau <= {:.3e} s, a ninth of the {:.1} s of data: at least 9 independent clusters)",
        curve.span_s / 9.0,
        curve.span_s
    )
}

/// Three significant digits.
fn num(v: f64) -> String {
    crate::explain::sig3(v)
}

/// Writes PREFIX_gyro.png [deg/h] and PREFIX_accel.png [ug]: the Allan deviation of the six
/// `curves` (gyros then accelerometers) on log-log axes.
#[cfg(feature = "cli")]
pub fn plots(prefix: &Path, curves: &[AllanCurve]) -> anyhow::Result<()> {
    use super::plot::{line_plot, Scale, Series};
    use crate::estimate::allan::CHANNELS;
    let series = |range: std::ops::Range<usize>, scale: f64| -> Vec<Series> {
        range
            .map(|k| Series {
                label: CHANNELS[k].into(),
                points: curves[k]
                    .tau_s
                    .iter()
                    .zip(&curves[k].adev)
                    .map(|(t, a)| (*t, a * scale))
                    .collect(),
            })
            .collect()
    };
    line_plot(
        &plot_path(prefix, "gyro"),
        "Allan deviation, gyros",
        "tau [s]",
        "ADEV [deg/h]",
        &series(0..3, R2DH),
        Scale::LogLog,
    )?;
    line_plot(
        &plot_path(prefix, "accel"),
        "Allan deviation, accelerometers",
        "tau [s]",
        "ADEV [ug]",
        &series(3..6, 1e6 / STANDARD_GRAVITY),
        Scale::LogLog,
    )
}
