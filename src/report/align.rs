//! `align`'s words: where the stretch at rest starts, the attitude with its σ, the latitude
//! (given, estimated or not determined), the coarse headings and the gyro bias estimates.

use crate::estimate::align::Alignment;

/// The lines of an alignment `a`; `lat_given` when the latitude was given (`--lat`).
pub fn lines(a: &Alignment, lat_given: bool) -> Vec<String> {
    let mut v = vec![format!(
        "at rest from {:.0} s after the start (the longest stretch judged at rest)",
        a.skipped_s
    )];
    v.push(match (a.heading_deg, a.heading_sigma_deg) {
        (Some(hd), Some(hs)) => format!(
            "roll {:.4} deg  pitch {:.4} deg  heading {hd:.3} deg (1-sigma {hs:.3} deg)",
            a.roll_deg, a.pitch_deg
        ),
        _ => format!(
            "roll {:.4} deg  pitch {:.4} deg  heading: not determined (see below)",
            a.roll_deg, a.pitch_deg
        ),
    });
    if let Some(n) = &a.heading_note {
        v.push(n.to_string());
    }
    v.push(latitude(a, lat_given));
    if a.heading_deg.is_none() {
        // no coarse heading either: the same gyros
    } else if a.heading_windows_deg.is_empty() {
        v.push("coarse heading: no complete one-minute window in the static data".into());
    } else {
        let (lo, hi) = a
            .heading_windows_deg
            .iter()
            .fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
        v.push(format!(
            "coarse heading over {} one-minute windows: {lo:.3} .. {hi:.3} deg",
            a.heading_windows_deg.len()
        ));
    }
    let b = |k: usize| {
        format!(
            "{:.4} ± {:.4}",
            a.gyro_bias_deg_h[k], a.gyro_bias_sigma_deg_h[k]
        )
    };
    v.push(format!(
        "gyro bias estimates x y z [deg/h], with 1-σ (fine alignment; x and y also the heading's): {}, {}, {}",
        b(0),
        b(1),
        b(2)
    ));
    v
}

/// The latitude line: given, estimated (with its σ when windows spread), or not determined.
fn latitude(a: &Alignment, lat_given: bool) -> String {
    match (lat_given, a.lat_deg) {
        (true, Some(l)) => format!("latitude {l:.4} deg (given)"),
        (_, None) => "latitude: not determined (it comes from the Earth rate's direction, which the gyro bias hides); pass --lat".to_string(),
        (false, Some(l)) if a.lat_sigma_deg.is_some_and(|s| s > 0.0) => format!(
            "latitude {l:.4} deg (estimated from the Earth-rate and gravity directions, 1-sigma {:.4} deg)",
            a.lat_sigma_deg.unwrap_or_default()
        ),
        (false, Some(l)) => format!(
            "latitude {l:.4} deg (estimated from one window only: no spread to give a sigma; pass --lat if known)"
        ),
    }
}
