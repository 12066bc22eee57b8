//! Fuzz target bodies, shared by cargo-fuzz (`fuzz/`) and the stable corpus test
//! (`tests/fuzz_corpus.rs`).
//!
//! Each `pub fn NAME(data: &[u8])` takes arbitrary bytes, feeds them to one parser, and panics
//! only when a property breaks. The property is the same everywhere: no panic, no hang, and no
//! NaN or infinity in anything a parser accepts. Refusing an input with an error is always fine.
//! See `docs/fuzzing.md`.

use crate::io::units;
use crate::model::jacobian::{jacobian, parse_points, PointSpec, Points};
use crate::model::Model;
use crate::sim::scenario::Scenario;
use sinsmodel_units::fuzz_property::{bounded, finite};
use std::path::Path;
use std::sync::OnceLock;

/// Names of the targets, as `fuzz/fuzz_targets/NAME.rs` and `fuzz/corpus/NAME/` use them.
pub const TARGETS: [&str; 15] = [
    "spec",
    "units",
    "scenario",
    "jacobian_point",
    "imu_text",
    "psins",
    "gnss_imu_csv",
    "imu_format",
    "rtklib_pos",
    "aiding",
    "truth",
    "matlab",
    "dataset",
    "noise",
    "eval_case",
];

/// The target function of a name in [`TARGETS`]; `spec` is the spec compiler's own
/// (`sinsmodel_codegen::fuzzing::spec`: the compiler is a build-time crate the runtime does not
/// link), so it gives `None` here.
pub fn target(name: &str) -> Option<fn(&[u8])> {
    match name {
        "units" => Some(units),
        "scenario" => Some(scenario),
        "jacobian_point" => Some(jacobian_point),
        "imu_text" => Some(imu_text),
        "psins" => Some(psins),
        "gnss_imu_csv" => Some(gnss_imu_csv),
        "imu_format" => Some(imu_format),
        "rtklib_pos" => Some(rtklib_pos),
        "aiding" => Some(aiding),
        "truth" => Some(truth),
        "matlab" => Some(matlab),
        "dataset" => Some(dataset),
        "noise" => Some(noise),
        "eval_case" => Some(eval_case),
        _ => None,
    }
}

/// The unit and quantity parser (`"0.01 deg/h"`, `"10 ug/g^2"`, `"1 deg/sqrt(h)"`).
///
/// Up to the first newline is a quantity, after it a unit it is expected in (none: the
/// quantity's own text is also tried as a unit). Property: an accepted unit has a finite,
/// positive factor to SI and bounded dimension exponents; an accepted quantity is finite in SI
/// and in the expected unit, and has the expected unit's dimension.
pub fn units(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let (quantity, unit) = match text.split_once('\n') {
        Some((q, u)) => (q, u),
        None => (text.as_ref(), text.as_ref()),
    };
    for u in [quantity, unit] {
        if let Ok(parsed) = units::parse_unit(u) {
            finite(parsed.to_si, &format!("factor to SI of `{u}`"));
            assert!(parsed.to_si > 0.0, "unit `{u}` has factor {}", parsed.to_si);
            bounded(parsed.dim, &format!("unit `{u}`"));
        }
    }
    if let Ok(q) = units::parse_quantity(quantity) {
        finite(q.si, &format!("quantity `{quantity}`"));
        bounded(q.dim, &format!("quantity `{quantity}`"));
    }
    if let Ok(v) = units::parse_quantity_as(quantity, unit) {
        finite(v, &format!("`{quantity}` in `{unit}`"));
        let q = units::parse_quantity(quantity).expect("accepted as a unit, so as a quantity");
        let u = units::parse_unit(unit).expect("accepted as expected, so as a unit");
        assert_eq!(q.dim, u.dim, "`{quantity}` accepted as `{unit}`");
    }
}

/// The scenario reader (`sinsmodel simulate SCENARIO`): TOML text, nothing simulated.
/// Property: every number of an accepted scenario is finite, and so is its duration.
pub fn scenario(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(s) = Scenario::parse(text, "fuzz.toml") else {
        return;
    };
    finite(s.imu_rate_hz, "imu_rate_hz");
    finite(s.truth_rate_hz, "truth_rate_hz");
    let st = &s.start;
    for (v, what) in [
        (st.lat_deg, "lat_deg"),
        (st.lon_deg, "lon_deg"),
        (st.h_m, "h_m"),
        (st.speed_mps, "speed_mps"),
    ] {
        finite(v, what);
    }
    st.euler_deg.iter().for_each(|&v| finite(v, "euler_deg"));
    for g in &s.segments {
        finite(g.duration_s, "duration_s");
        finite(g.accel_mps2, "accel_mps2");
        finite(g.yaw_rate_deg_s, "yaw_rate_deg_s");
    }
    for v in &s.vibration {
        finite(v.freq_hz, "vibration freq_hz");
        finite(v.phase_deg, "vibration phase_deg");
        v.band_hz
            .iter()
            .flatten()
            .for_each(|&b| finite(b, "vibration band_hz"));
        v.schedule
            .iter()
            .flatten()
            .flatten()
            .for_each(|&w| finite(w, "vibration schedule"));
        for q in [&v.amplitude, &v.psd].into_iter().flatten() {
            if let Ok(q) = units::parse_quantity(q) {
                finite(q.si, "vibration amplitude or psd");
            }
        }
    }
    for &(k, v) in &s.errors {
        finite(v, &format!("error of term {k}"));
    }
    let n = &s.noise;
    for v in [
        n.arw,
        n.vrw,
        n.gyro_bias_rw,
        n.accel_bias_rw,
        n.gyro_quantum,
        n.accel_quantum,
    ] {
        finite(v, "noise");
    }
    if let Some((rate, sne, sd, _)) = s.gnss {
        finite(rate, "gnss rate_hz");
        finite(sne, "gnss sigma_ne");
        finite(sd, "gnss sigma_d");
    }
    finite(s.duration(), "duration");
}

/// P31, built once.
fn p31() -> &'static Model {
    static MODEL: OnceLock<Model> = OnceLock::new();
    MODEL.get_or_init(|| Model::parse("P31").expect("P31 is a preset"))
}

/// The linearisation-point reader of `sinsmodel jacobian --at POINT.json` (one object or an
/// array), then A and H of P31 at each accepted point. Property: every number of A and H at an
/// accepted point is finite.
pub fn jacobian_point(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let points: Vec<PointSpec> = match parse_points(text) {
        Ok(Points::One(p)) => vec![p],
        Ok(Points::Many(v)) => v,
        Err(_) => return,
    };
    for p in &points {
        let Ok(out) = jacobian(p31(), p, false) else {
            continue;
        };
        for (i, row) in out.a.iter().enumerate() {
            for (j, &v) in row.iter().enumerate() {
                assert!(v.is_finite(), "A[{i}][{j}] = {v} at accepted point {p:?}");
            }
        }
        for (name, h) in &out.h {
            for (i, row) in h.iter().enumerate() {
                for (j, &v) in row.iter().enumerate() {
                    assert!(
                        v.is_finite(),
                        "H {name}[{i}][{j}] = {v} at accepted point {p:?}"
                    );
                }
            }
        }
    }
}

/// A per-process scratch directory for the reader targets (the readers read files): in
/// /dev/shm when there is one, so that writing an input costs little.
fn scratch() -> &'static Path {
    static DIR: OnceLock<std::path::PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let base = if Path::new("/dev/shm").is_dir() {
            std::path::PathBuf::from("/dev/shm")
        } else {
            std::env::temp_dir()
        };
        let d = base.join(format!("sinsmodel-fuzz-{}", std::process::id()));
        std::fs::create_dir_all(&d).expect("scratch directory for the reader targets");
        d
    })
}

/// Writes each (file name, bytes) into the scratch directory (a subdirectory per thread, so
/// that targets run side by side in one test process do not share files) and returns their
/// paths.
fn files(items: &[(&str, &[u8])]) -> Vec<std::path::PathBuf> {
    let dir = scratch().join(format!("{:?}", std::thread::current().id()).replace(['(', ')'], ""));
    std::fs::create_dir_all(&dir).expect("scratch directory of a thread");
    items
        .iter()
        .map(|(name, bytes)| {
            let p = dir.join(name);
            std::fs::write(&p, bytes).expect("write a fuzz input");
            p
        })
        .collect()
}

/// Splits `data` in two at a length its first two bytes give (for targets that read two files).
fn split2(data: &[u8]) -> Option<(&[u8], &[u8])> {
    if data.len() < 2 {
        return None;
    }
    let rest = &data[2..];
    let k = u16::from_le_bytes([data[0], data[1]]) as usize % (rest.len() + 1);
    Some(rest.split_at(k))
}

/// What every accepted IMU stream must hold: finite samples, strictly increasing time, rates and
/// forces within what any IMU measures.
fn check_imu(stream: crate::io::imu_stream::ImuStream) {
    use crate::io::imu_stream::{MAX_FORCE, MAX_RATE};
    let interval = stream.interval();
    finite(interval, "median interval");
    let Ok(data) = stream.collect() else {
        return;
    };
    let mut prev: Option<f64> = None;
    for s in &data.samples {
        finite(s.t, "sample time");
        for v in s.dtheta.iter().chain(s.dv.iter()) {
            finite(*v, "increment");
        }
        let dt = match prev {
            Some(p) => {
                assert!(s.t > p, "accepted time {} after {p}", s.t);
                s.t - p
            }
            None => interval,
        };
        assert!(
            s.dtheta.norm() / dt <= MAX_RATE * (1.0 + 1e-12),
            "accepted rate beyond bound"
        );
        assert!(
            s.dv.norm() / dt <= MAX_FORCE * (1.0 + 1e-12),
            "accepted force beyond bound"
        );
        prev = Some(s.t);
    }
}

/// The project's IMU text, through the path every command takes ([`ImuStream::open`]).
pub fn imu_text(data: &[u8]) {
    let p = files(&[("imu.txt", data)]);
    if let Ok((s, _)) = crate::io::imu_stream::ImuStream::open(&p[0], None) {
        check_imu(s);
    }
}

/// A PSINS `.imu` log, through [`ImuStream::open`]; an accepted header must be finite too.
pub fn psins(data: &[u8]) {
    let p = files(&[("log.imu", data)]);
    if let Ok(log) = crate::io::imu_stream::read_psins(&p[0]) {
        for v in log.euler_deg.iter().chain(&log.v_ned) {
            finite(*v, "PSINS header value");
        }
        finite(log.interval, "PSINS interval");
    }
    if let Ok((s, _)) = crate::io::imu_stream::ImuStream::open(&p[0], None) {
        check_imu(s);
    }
}

/// A GNSS_IMU csv with its RTKLIB time-tag file (the input split in two), through
/// [`ImuStream::open`].
pub fn gnss_imu_csv(data: &[u8]) {
    let Some((tag, csv)) = split2(data) else {
        return;
    };
    let p = files(&[("log.csv", csv), ("log.csv.tag", tag)]);
    if let Ok((s, _)) = crate::io::imu_stream::ImuStream::open(&p[0], None) {
        check_imu(s);
    }
}

/// A format description and a data file it describes (the input split in two).
pub fn imu_format(data: &[u8]) {
    let Some((desc, body)) = split2(data) else {
        return;
    };
    let p = files(&[("fmt.toml", desc), ("log.dat", body)]);
    if let Ok((s, _)) = crate::io::imu_stream::ImuStream::open(&p[1], Some(&p[0])) {
        check_imu(s);
    }
}

/// An RTKLIB `.pos` solution: accepted epochs finite, in range, time increasing.
pub fn rtklib_pos(data: &[u8]) {
    let p = files(&[("sol.pos", data)]);
    if let Ok(epochs) = crate::io::readers::rtklib::read(&p[0]) {
        let mut prev = f64::NEG_INFINITY;
        for e in &epochs {
            for v in [e.t, e.lat_deg, e.lon_deg, e.h]
                .iter()
                .chain(&e.sigma_neu)
                .chain(e.v_ned.iter().flatten())
            {
                finite(*v, ".pos value");
            }
            assert!(e.t > prev, "accepted .pos time does not increase");
            assert!(e.lat_deg.abs() < 90.0, "accepted latitude {}", e.lat_deg);
            prev = e.t;
        }
    }
}

/// A position aiding file: accepted fixes finite, σ positive.
pub fn aiding(data: &[u8]) {
    let p = files(&[("aid.txt", data)]);
    if let Ok(fixes) = crate::io::aiding::read(&p[0]) {
        for f in &fixes {
            for v in [f.t, f.lat, f.lon, f.h].iter().chain(&f.sigma) {
                finite(*v, "aiding value");
            }
            assert!(f.sigma.iter().all(|s| *s > 0.0), "accepted sigma <= 0");
        }
    }
}

/// Panics naming `what` unless every value of every row is finite.
fn finite_rows(rows: &[crate::io::truth::TruthRow], what: &str) {
    for r in rows {
        for v in [r.t, r.lat, r.lon, r.h]
            .iter()
            .chain(r.v.iter())
            .chain(r.euler.iter())
        {
            finite(*v, what);
        }
    }
}

/// A truth file, read whole and as the filter reads it ([`crate::io::truth::TruthReader`]).
pub fn truth(data: &[u8]) {
    use crate::io::truth::TruthLookup;
    let p = files(&[("truth.txt", data)]);
    if let Ok(rows) = crate::io::truth::read(&p[0]) {
        finite_rows(&rows, "truth value");
    }
    if let Ok(mut reader) = crate::io::truth::TruthReader::open(&p[0]) {
        for k in 0..50 {
            match reader.at(k as f64 * 0.5, 0.25) {
                Ok(Some(r)) => finite(r.lat, "truth latitude"),
                Ok(None) => {}
                Err(_) => break,
            }
        }
    }
}

/// A MATLAB `.mat` file: as an IMU array through [`ImuStream::open`] (checked like every
/// stream) and as a reference `avp` array (accepted rows finite, angles in radians' range).
pub fn matlab(data: &[u8]) {
    let p = files(&[("log.mat", data)]);
    if let Ok((s, _)) = crate::io::imu_stream::ImuStream::open(&p[0], None) {
        check_imu(s);
    }
    if let Ok(rows) = crate::io::truth::read(&p[0]) {
        finite_rows(&rows, "avp value");
        for r in &rows {
            assert!(
                r.lat.abs() <= std::f64::consts::FRAC_PI_2,
                "accepted latitude {}",
                r.lat
            );
        }
    }
}

/// A whole data set as `filter`, `navigate` and `explain` open it
/// ([`crate::data::DataOptions::open`], then the IMU read to its end): an IMU text file and a
/// position aiding file (the input after its first byte, split in two). The first byte picks the
/// options: bit 0 `--init auto` (else `--init 28.22,112.99,0,0,0,0`, where the seed corpus
/// lies), bit 1 `--static-aid 28.22,112.99,0` instead of the aiding file, bit 2 `--zupt 0.01`,
/// bit 3 `--grade mems`, bit 4 `--force`, bit 5 `--mode closed`. So every check of a run's
/// inputs runs on it: the first seconds' and every later 10-s window's magnitudes (unit, scale
/// and clock slips), a rest claim against the motion, the GNSS fixes against themselves and
/// against the IMU's clock, the start against the first fix. Property: an accepted data set has
/// finite samples with time increasing and finite aiding epochs with σ > 0 inside the IMU data.
pub fn dataset(data: &[u8]) {
    let _ = dataset_outcome(data);
}

/// The body of [`dataset`], with what became of the input: None when it holds no two files,
/// else whether the data set was accepted (read to its end) or refused, and why.
pub fn dataset_outcome(data: &[u8]) -> Option<anyhow::Result<()>> {
    let (&flags, rest) = data.split_first()?;
    let (imu, aid) = split2(rest)?;
    let p = files(&[("ds_imu.txt", imu), ("ds_aid.txt", aid)]);
    let mut o = crate::data::DataOptions::none();
    o.imu = Some(p[0].clone());
    o.init = Some(
        if flags & 1 != 0 {
            "auto"
        } else {
            "28.22,112.99,0,0,0,0"
        }
        .into(),
    );
    if flags & 2 != 0 {
        o.static_aid = Some(vec![28.22, 112.99, 0.0]);
    } else {
        o.aid = Some(p[1].clone());
    }
    o.zupt = (flags & 4 != 0).then_some(0.01);
    o.grade = (flags & 8 != 0).then(|| "mems".to_string());
    o.force = flags & 16 != 0;
    if flags & 32 != 0 {
        o.mode = Some("closed".into());
    }
    let mut ds = match o.open(&mut |_| {}) {
        Ok(ds) => ds,
        Err(e) => return Some(Err(e)),
    };
    finite(ds.step_s, "filter step");
    let mut prev = f64::NEG_INFINITY;
    let mut last = ds.start.t;
    loop {
        let s = match ds.imu.next() {
            Ok(Some(s)) => s,
            Ok(None) => break,
            Err(e) => return Some(Err(e)),
        };
        finite(s.t, "sample time");
        s.dtheta
            .iter()
            .chain(s.dv.iter())
            .for_each(|v| finite(*v, "increment"));
        assert!(s.t > prev, "accepted time {} after {prev}", s.t);
        prev = s.t;
        last = s.t;
    }
    for e in ds.aid.epochs().take_while(|e| e.t <= last) {
        finite(e.t, "aiding time");
        if let Some((v, sigma)) = e.vel {
            v.iter().for_each(|x| finite(*x, "aiding velocity"));
            assert!(
                sigma.is_finite() && sigma > 0.0,
                "accepted velocity σ {sigma}"
            );
        }
        if let Some((lat, lon, h, sigma)) = e.pos {
            [lat, lon, h]
                .iter()
                .for_each(|x| finite(*x, "aiding position"));
            assert!(
                lat.abs() <= std::f64::consts::FRAC_PI_2,
                "accepted latitude {lat}"
            );
            assert!(
                sigma.iter().all(|s| s.is_finite() && *s > 0.0),
                "accepted position σ {sigma:?}"
            );
        }
    }
    Some(Ok(()))
}

/// The noise levels `--noise` gives: the input as an `allan --json` file, and as the option's
/// inline text (`arw=0.3 deg/sqrt(h), vrw=150 ug/sqrt(Hz)`). Property: accepted white noises
/// are finite and > 0, accepted bias random walks finite and >= 0.
pub fn noise(data: &[u8]) {
    let p = files(&[("noise.json", data)]);
    let check = |n: crate::data::NoiseGiven| {
        for (v, what) in [(n.arw, "arw"), (n.vrw, "vrw")] {
            assert!(v.is_finite() && v > 0.0, "accepted {what} {v}");
        }
        for (v, what) in [
            (n.gyro_bias_rw, "gyro_bias_rw"),
            (n.accel_bias_rw, "accel_bias_rw"),
        ] {
            assert!(v.is_finite() && v >= 0.0, "accepted {what} {v}");
        }
    };
    if let Ok(n) = crate::data::noise_given(&p[0]) {
        check(n);
    }
    if let Ok(n) = crate::data::setup::noise_inline(&String::from_utf8_lossy(data)) {
        check(n);
    }
}

/// One stored case of an `explain-eval` campaign (a `cases.json` entry, JSON), checked as
/// `explain-eval --merge` checks it against the published campaign's settings
/// (`docs/explain-eval/sensor-600/cases.json`: seed 7, seven groups, 600 s). Property: an accepted case has
/// finite numbers (λ > 0, σ > 0, a truth ≠ 0) and flags that agree with what it named.
pub fn eval_case(data: &[u8]) {
    use crate::experiment::explain_eval::{CaseResult, EvalSpec};
    let Ok(c) = serde_json::from_slice::<CaseResult>(data) else {
        return;
    };
    let spec = EvalSpec {
        seed: 7,
        groups: ["d", "kaq", "kas", "kao", "kgf", "kgq", "size"]
            .map(String::from)
            .to_vec(),
        ..EvalSpec::default()
    };
    if crate::experiment::eval_check::check_case(&spec, &c).is_err() {
        return;
    }
    if let Some(l) = c.lambda {
        assert!(l.is_finite() && l > 0.0, "accepted lambda {l}");
    }
    if let Some(t) = c.truth {
        assert!(t.is_finite() && t != 0.0, "accepted truth {t}");
    }
    if let Some(e) = c.estimate {
        finite(e, "estimate");
    }
    if let Some(s) = c.sigma {
        assert!(s.is_finite() && s > 0.0, "accepted sigma {s}");
    }
    if let Some(g) = c.gain_recovery {
        finite(g, "gain_recovery");
    }
    assert!(
        !(c.detected && c.named.is_empty()),
        "detected with nothing named"
    );
    assert!(!(c.term.is_none() && c.detected), "a null case detected");
}
