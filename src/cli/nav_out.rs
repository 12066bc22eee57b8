//! `filter`'s navigation solution, `nav.txt`: the navigator corrected by the filter's error
//! estimate, with 1-σ from its covariance, written as the samples come (DESIGN §9's truth layout
//! first), and `nav.png` (the track and the σ envelopes).

use sinsmodel::estimate::filter::Observer;
use sinsmodel::io::atomic_file::AtomicFile;
use sinsmodel::io::fixed::write_sci;
use sinsmodel::io::truth::{write_row, TruthRow};
use sinsmodel::model::Model;
use sinsmodel::nav::earth;
use sinsmodel::nav::strapdown::NavState;
use std::io::Write;

pub use sinsmodel::nav::free_inertial::RowClock;

/// Most points kept per plotted curve (older points thinned as the run grows).
const PLOT_POINTS: usize = 4000;

/// Points kept for a plot, thinned by two whenever full, so memory stays bounded.
struct Thinned {
    points: Vec<(f64, f64)>,
    stride: u64,
    seen: u64,
}

impl Thinned {
    fn new() -> Self {
        Thinned {
            points: Vec::new(),
            stride: 1,
            seen: 0,
        }
    }
    fn push(&mut self, p: (f64, f64)) {
        if self.seen.is_multiple_of(self.stride) {
            self.points.push(p);
            if self.points.len() >= PLOT_POINTS {
                self.points = self.points.iter().step_by(2).copied().collect();
                self.stride *= 2;
            }
        }
        self.seen += 1;
    }
}

/// Rows handed to the writing thread at once.
const BATCH_ROWS: usize = 1024;
/// Batches in flight between the filter and the writing thread (memory stays bounded).
const BATCHES_IN_FLIGHT: usize = 4;
/// Bytes of formatted rows the writing thread hands to the file at once (at least the atomic
/// file's 1 MiB buffer, which then passes them through without a copy and stays untouched).
const CHUNK_BYTES: usize = 1 << 20;

/// One nav.txt row before formatting: the corrected state and the 1-σ columns the model has.
struct NavRow {
    row: TruthRow,
    sig: [f64; 9],
    n_sig: u8,
}

/// The thread that formats and writes nav.txt rows behind the filter (the same bytes as
/// writing them in line; the filter's thread only computes them): the batches' sender, and
/// the thread, which hands the file back (or the first write error).
struct RowWriter {
    tx: std::sync::mpsc::SyncSender<Vec<NavRow>>,
    thread: std::thread::JoinHandle<Result<AtomicFile, String>>,
}

impl RowWriter {
    fn spawn(mut file: AtomicFile) -> anyhow::Result<RowWriter> {
        let (tx, rx) = std::sync::mpsc::sync_channel::<Vec<NavRow>>(BATCHES_IN_FLIGHT);
        let thread = std::thread::Builder::new()
            .name("nav.txt".into())
            .spawn(move || {
                let w = file.writer();
                // rows are formatted straight into one large chunk, handed to the file whole
                // (larger than the file's buffer, so not copied into it)
                let mut chunk = Vec::with_capacity(CHUNK_BYTES + 512);
                for batch in rx {
                    for r in &batch {
                        // the truth layout (same digits), then the sigmas
                        write_row(&mut chunk, &r.row).map_err(|e| e.to_string())?;
                        chunk.pop(); // its newline
                        for v in &r.sig[..r.n_sig as usize] {
                            chunk.push(b' ');
                            write_sci(&mut chunk, *v, 4).map_err(|e| e.to_string())?;
                        }
                        chunk.push(b'\n');
                        if chunk.len() >= CHUNK_BYTES {
                            w.write_all(&chunk).map_err(|e| e.to_string())?;
                            chunk.clear();
                        }
                    }
                }
                w.write_all(&chunk).map_err(|e| e.to_string())?;
                Ok(file)
            })?;
        Ok(RowWriter { tx, thread })
    }
}

/// Writes `nav.txt` rows from the filter's [`Observer::nav_sample`].
pub struct NavWriter {
    writer: Option<RowWriter>,
    batch: Vec<NavRow>,
    clock: RowClock,
    idx: [Option<usize>; 9],
    n: usize,
    origin: Option<(f64, f64)>,
    track: Thinned,
    sigma: [Thinned; 3],
    /// The first write error or non-finite value met (checked after the run).
    pub error: Option<String>,
    /// Rows written.
    pub rows: u64,
}

/// State names in nav.txt's σ order: position, velocity, attitude.
const STATES: [&str; 9] = [
    "dlat", "dlon", "dh", "dv_n", "dv_e", "dv_d", "phi_n", "phi_e", "phi_d",
];

impl NavWriter {
    /// Starts `path` (atomic) with its header; rows when `clock` says.
    pub fn create(
        path: &std::path::Path,
        model: &Model,
        clock: RowClock,
        provenance: &str,
    ) -> anyhow::Result<NavWriter> {
        let mut file = AtomicFile::create(path)?;
        let idx = STATES.map(|s| model.index_of(s));
        let w = file.writer();
        writeln!(w, "# {provenance}")?;
        writeln!(
            w,
            "# navigation solution: the navigator corrected by the filter's estimate ({} states), {}",
            model.name,
            clock.words()
        )?;
        let mut cols = String::from(
            "# t[s] lat lon [deg] h[m] v_n v_e v_d [m/s] roll pitch yaw [deg] (NED, FRD; DESIGN §9 truth layout)",
        );
        let names = [
            "sigma_n[m]",
            "sigma_e[m]",
            "sigma_h[m]",
            "sigma_vn[m/s]",
            "sigma_ve[m/s]",
            "sigma_vd[m/s]",
            "sigma_tilt_n[deg]",
            "sigma_tilt_e[deg]",
            "sigma_tilt_d[deg]",
        ];
        for (k, n) in names.iter().enumerate() {
            if idx[k].is_some() {
                cols.push(' ');
                cols.push_str(n);
            }
        }
        writeln!(w, "{cols}")?;
        if idx[2].is_none() {
            writeln!(
                w,
                "# no sigma_h / sigma_vd: the model's vertical channel is fixed, not estimated (use +vertical)"
            )?;
        }
        writeln!(
            w,
            "# attitude sigmas are the tilt errors about north, east, down (= roll, pitch, yaw near level)"
        )?;
        Ok(NavWriter {
            writer: Some(RowWriter::spawn(file)?),
            batch: Vec::with_capacity(BATCH_ROWS),
            clock,
            idx,
            n: model.n(),
            origin: None,
            track: Thinned::new(),
            sigma: [Thinned::new(), Thinned::new(), Thinned::new()],
            error: None,
            rows: 0,
        })
    }

    /// Flushes and moves the file into place; draws `png`.
    pub fn finish(mut self, png: &std::path::Path) -> anyhow::Result<()> {
        let file = self.close();
        if let Some(e) = self.error {
            anyhow::bail!("{e}");
        }
        file.ok_or_else(|| anyhow::anyhow!("nav.txt: its writing thread ended early"))?
            .commit()?;
        use sinsmodel::report::plot::{line_plot, Scale, Series};
        let dir = png.parent().unwrap_or(std::path::Path::new("."));
        let stem = png.file_stem().and_then(|s| s.to_str()).unwrap_or("nav");
        line_plot(
            &dir.join(format!("{stem}_track.png")),
            "filter: navigation solution, track",
            "east of the start [m]",
            "north of the start [m]",
            &[Series {
                label: "track".into(),
                points: self.track.points,
            }],
            Scale::Linear,
        )?;
        let [mut sn, mut se, mut sh] = self.sigma;
        // times from the first sample; the absolute start goes into the title
        let t0 = sn.points.first().map(|p| p.0).unwrap_or(0.0);
        for p in sn
            .points
            .iter_mut()
            .chain(se.points.iter_mut())
            .chain(sh.points.iter_mut())
        {
            p.0 -= t0;
        }
        let mut series = vec![
            Series {
                label: "sigma north".into(),
                points: sn.points,
            },
            Series {
                label: "sigma east".into(),
                points: se.points,
            },
        ];
        if !sh.points.is_empty() {
            series.push(Series {
                label: "sigma height".into(),
                points: sh.points,
            });
        }
        line_plot(
            &dir.join(format!("{stem}_sigma.png")),
            &format!("filter: 1-sigma of the position (envelopes); first sample at t = {t0:.3} s"),
            "time from the first sample [s]",
            "1-sigma [m] (log scale)",
            &series,
            Scale::LogY,
        )
    }

    /// Hands the last rows to the writing thread and waits for it: the file, or None with the
    /// thread's error in `self.error` (unless one was met first).
    fn close(&mut self) -> Option<AtomicFile> {
        self.send_batch();
        let w = self.writer.take()?;
        drop(w.tx);
        match w.thread.join() {
            Ok(Ok(f)) => Some(f),
            Ok(Err(e)) => {
                self.error.get_or_insert(e);
                None
            }
            Err(_) => {
                self.error
                    .get_or_insert_with(|| "nav.txt: its writing thread panicked".into());
                None
            }
        }
    }

    /// Hands the rows collected so far to the writing thread (one that stopped on an error
    /// takes no more; its error comes with the join in [`NavWriter::finish`]).
    fn send_batch(&mut self) {
        if self.batch.is_empty() {
            return;
        }
        let batch = std::mem::replace(&mut self.batch, Vec::with_capacity(BATCH_ROWS));
        if let Some(w) = &self.writer {
            let _ = w.tx.send(batch);
        }
    }

    fn row(&mut self, s: &NavState, x: &[f64], p: &[f64]) -> Result<(), String> {
        let get = |k: usize| self.idx[k].map(|i| x[i]).unwrap_or(0.0);
        let var = |k: usize| self.idx[k].map(|i| p[i * self.n + i]);
        let phi = nalgebra::Vector3::new(get(6), get(7), get(8));
        let q = nalgebra::UnitQuaternion::from_scaled_axis(phi) * s.q;
        let corrected = NavState {
            t: s.t,
            lat: s.lat - get(0),
            lon: s.lon - get(1),
            h: s.h - get(2),
            v: s.v - nalgebra::Vector3::new(get(3), get(4), get(5)),
            q,
        };
        let rm = earth::radius_meridian(corrected.lat) + corrected.h;
        let rn = (earth::radius_transverse(corrected.lat) + corrected.h) * corrected.lat.cos();
        let scale = [
            rm,
            rn,
            1.0,
            1.0,
            1.0,
            1.0,
            180.0 / std::f64::consts::PI,
            180.0 / std::f64::consts::PI,
            180.0 / std::f64::consts::PI,
        ];
        let (mut sig, mut n_sig) = ([0.0; 9], 0usize);
        for (k, sc) in scale.iter().enumerate() {
            if let Some(v) = var(k) {
                let sd = v.max(0.0).sqrt() * sc;
                if !(sd.is_finite() && v > -1e-12) {
                    return Err(format!(
                        "nav.txt: the variance of {} is not finite or negative at t = {:.3} s",
                        STATES[k], s.t
                    ));
                }
                sig[n_sig] = sd;
                n_sig += 1;
            }
        }
        let row = TruthRow {
            t: corrected.t,
            lat: corrected.lat,
            lon: corrected.lon,
            h: corrected.h,
            v: corrected.v,
            euler: corrected.euler(),
        };
        let finite = [row.lat, row.lon, row.h, row.v.x, row.v.y, row.v.z]
            .iter()
            .chain(row.euler.iter())
            .all(|v| v.is_finite());
        if !finite {
            return Err(format!(
                "nav.txt: the navigation solution is not finite at t = {:.3} s",
                s.t
            ));
        }
        let (lat0, lon0) = *self.origin.get_or_insert((row.lat, row.lon));
        self.track
            .push(((row.lon - lon0) * rn, (row.lat - lat0) * rm));
        self.sigma[0].push((row.t, sig[0]));
        self.sigma[1].push((row.t, sig[1]));
        if self.idx[2].is_some() {
            self.sigma[2].push((row.t, sig[2]));
        }
        self.batch.push(NavRow {
            row,
            sig,
            n_sig: n_sig as u8,
        });
        if self.batch.len() >= BATCH_ROWS {
            self.send_batch();
        }
        self.rows += 1;
        Ok(())
    }
}

impl Observer for NavWriter {
    fn nav_sample(&mut self, s: &NavState, x: &[f64], p: &[f64]) {
        // rows on the samples' times, as navigate writes them
        if !self.clock.due(s.t) || self.error.is_some() {
            return;
        }
        if let Err(e) = self.row(s, x, p) {
            self.error = Some(e);
        }
    }
}
