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
