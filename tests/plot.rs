//! Plots render with the embedded font (no system font libraries) and appear atomically.

use sinsmodel::report::plot::{line_plot, Scale, Series};

#[test]
fn line_plot_writes_a_png() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("x.png");
    let s = Series {
        label: "sin".into(),
        points: (0..100)
            .map(|k| (k as f64, (k as f64 / 10.0).sin()))
            .collect(),
    };
    line_plot(&p, "title", "x [s]", "y [m]", &[s], Scale::Linear).unwrap();
    let bytes = std::fs::read(&p).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    assert!(
        bytes.len() > 5000,
        "a real picture with text: {} bytes",
        bytes.len()
    );
    let s = Series {
        label: "adev".into(),
        points: (1..50)
            .map(|k| (k as f64, 1.0 / (k as f64).sqrt()))
            .collect(),
    };
    line_plot(
        &dir.path().join("log.png"),
        "log",
        "tau [s]",
        "adev",
        &[s],
        Scale::LogLog,
    )
    .unwrap();
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        2,
        "no partial files left"
    );
}

/// Decodes a PNG into (width, height, RGB rows).
fn decode(path: &std::path::Path) -> (usize, usize, Vec<u8>) {
    let dec = png::Decoder::new(std::fs::File::open(path).unwrap());
    let mut reader = dec.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb, "RGB plots");
    buf.truncate(info.buffer_size());
    (info.width as usize, info.height as usize, buf)
}

/// The pixels within `band` of the picture's edge that are not white: a label or line cut
/// off at the edge leaves some.
fn inked_at_edge(path: &std::path::Path, band: usize) -> usize {
    let (w, h, px) = decode(path);
    let mut n = 0;
    for y in 0..h {
        for x in 0..w {
            let edge = x < band || y < band || x >= w - band || y >= h - band;
            let p = &px[3 * (y * w + x)..3 * (y * w + x) + 3];
            if edge && p.iter().any(|&c| c < 200) {
                n += 1;
            }
        }
    }
    n
}

/// Data as real logs give them: absolute GPS times, a curve through zero and a NaN on a log
/// axis, long legend labels, a dense min/max envelope. Nothing may reach the picture's edge
/// (a clipped tick label or a line drawn outside the axes would), and the legend strip right
/// of the axes holds ink (the legend is drawn, outside the data).
#[test]
fn plots_of_awkward_data_stay_inside_the_picture() {
    let dir = tempfile::tempdir().unwrap();
    let t0 = 1_752_003_262.985;
    let envelope = |scale: f64| Series {
        label: format!("sigma north, a long legend label {scale}"),
        points: (0..4000)
            .map(|k| {
                let t = t0 + 0.137 * k as f64;
                let v = scale * (0.01 + 0.5 * (-(k as f64) / 80.0).exp());
                (t, if k % 2 == 0 { v } else { 0.9 * v })
            })
            .collect(),
    };
    let mut with_gaps = envelope(2.0);
    with_gaps.points[100].1 = 0.0;
    with_gaps.points[200].1 = -1.0;
    with_gaps.points[300].1 = f64::NAN;
    for (name, scale, series) in [
        ("log.png", Scale::LogY, vec![envelope(1.0), with_gaps]),
        ("lin.png", Scale::Linear, vec![envelope(1.0), envelope(3.0)]),
    ] {
        let p = dir.path().join(name);
        line_plot(&p, "sigma", "time [s]", "1-sigma [m]", &series, scale).unwrap();
        assert_eq!(
            inked_at_edge(&p, 3),
            0,
            "{name}: something reaches the edge"
        );
        let (w, h, px) = decode(&p);
        assert_eq!((w, h), (1000, 600));
        let legend_ink = (60..200)
            .flat_map(|y| (w - 300..w - 10).map(move |x| (x, y)))
            .filter(|&(x, y)| px[3 * (y * w + x)] < 128)
            .count();
        assert!(legend_ink > 200, "{name}: no legend right of the axes");
        // below the legend the strip is empty: no axes, grid or data under it
        let under = (250..h - 10)
            .flat_map(|y| (w - 300..w - 10).map(move |x| (x, y)))
            .filter(|&(x, y)| px[3 * (y * w + x)] < 200)
            .count();
        assert_eq!(
            under, 0,
            "{name}: the legend strip holds more than the legend"
        );
    }
}

/// Tick labels: a few significant digits, never a run of absolute-time digits.
#[test]
fn tick_labels_are_short() {
    use sinsmodel::report::plot::tick;
    assert_eq!(tick(600.0), "600");
    assert_eq!(tick(0.05), "0.05");
    assert_eq!(tick(2.5), "2.5");
    assert_eq!(tick(-120.26), "-120.3");
    assert_eq!(tick(0.0), "0");
    assert_eq!(tick(1.752e9), "1.8e9");
    assert_eq!(tick(1e-5), "1.0e-5");
}
