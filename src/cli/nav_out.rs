//! `filter`'s navigation solution, `nav.txt`: the navigator corrected by the filter's error
//! estimate, with 1-σ from its covariance, written as the samples come (DESIGN §9's truth layout
//! first), and `nav.png` (the track and the σ envelopes).

use sinsmodel::estimate::filter::Observer;
use sinsmodel::io::atomic_file::AtomicFile;
use sinsmodel::io::fixed::push_sci;
use sinsmodel::io::truth::{push_row, TruthRow};
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
const BATCH_ROWS: usize = 512;
/// Batches in flight between the filter and the writing thread (memory stays bounded).
const BATCHES_IN_FLIGHT: usize = 2;
/// Bytes of formatted rows the writing thread hands to the file at once (straight to the file,
/// past the atomic file's buffer, which holds the header only).
const CHUNK_BYTES: usize = 256 << 10;
/// Bytes written between two requests to the operating system to start writing them to disk,
/// so that the commit's final sync waits for the last few only.
const WRITEBACK_BYTES: usize = 8 << 20;

/// One nav.txt row as the filter hands it over: the navigator's state, the error estimates of
/// the nine navigation states in nav.txt's σ order (zero where the model has none) and their
/// variances (meaningful where it has them). Everything else is computed by the writing thread.
struct RawRow {
    s: NavState,
    dx: [f64; 9],
    var: [f64; 9],
}

/// The points the writing thread keeps for the plots: the track [m east, m north of the first
/// row] and the 1-σ of north, east, height [m] against time [s].
struct PlotPoints {
    track: Thinned,
    sigma: [Thinned; 3],
}

/// What turns the filter's rows into nav.txt's: which σ columns the model has, the track's
/// origin and the plots' points.
struct RowFormer {
    present: [bool; 9],
    origin: Option<(f64, f64)>,
    plots: PlotPoints,
}

impl RowFormer {
    /// The corrected state and its σ columns (how many), or why the row cannot be written.
    fn row(&mut self, r: &RawRow) -> Result<(TruthRow, [f64; 9], usize), String> {
        let (s, dx) = (&r.s, &r.dx);
        let phi = nalgebra::Vector3::new(dx[6], dx[7], dx[8]);
        let q = nalgebra::UnitQuaternion::from_scaled_axis(phi) * s.q;
        let corrected = NavState {
            t: s.t,
            lat: s.lat - dx[0],
            lon: s.lon - dx[1],
            h: s.h - dx[2],
            v: s.v - nalgebra::Vector3::new(dx[3], dx[4], dx[5]),
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
            if self.present[k] {
                let v = r.var[k];
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
        let p = &mut self.plots;
        p.track.push(((row.lon - lon0) * rn, (row.lat - lat0) * rm));
        p.sigma[0].push((row.t, sig[0]));
        p.sigma[1].push((row.t, sig[1]));
        if self.present[2] {
            p.sigma[2].push((row.t, sig[2]));
        }
        Ok((row, sig, n_sig))
    }
}

/// Asks the operating system to start writing `file`'s dirty pages to disk now (without
/// waiting for it), so that the sync at the commit has little left to wait for.
fn start_writeback(file: &std::fs::File) {
    #[cfg(target_os = "linux")]
    {
        use std::os::fd::AsRawFd;
        // SAFETY: a plain system call on an open descriptor; a failure only loses the hint
        unsafe {
            libc::sync_file_range(file.as_raw_fd(), 0, 0, libc::SYNC_FILE_RANGE_WRITE);
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = file;
}

/// The thread that turns the filter's rows into nav.txt's and formats and writes them behind
/// the filter (the same bytes as doing it in line; the filter's thread only copies the state
/// and its σ out): the batches' sender, and the thread, which hands the synced file and the
/// plots' points back (or the first error: a row that is not finite, a failed write).
struct RowWriter {
    tx: std::sync::mpsc::SyncSender<Vec<RawRow>>,
    thread: std::thread::JoinHandle<Result<(AtomicFile, PlotPoints), String>>,
}

impl RowWriter {
    fn spawn(
        mut file: AtomicFile,
        path: &std::path::Path,
        present: [bool; 9],
    ) -> anyhow::Result<RowWriter> {
        let shown = path.display().to_string();
        let (tx, rx) = std::sync::mpsc::sync_channel::<Vec<RawRow>>(BATCHES_IN_FLIGHT);
        let thread = std::thread::Builder::new()
            .name("nav.txt".into())
            .spawn(move || {
                let mut former = RowFormer {
                    present,
                    origin: None,
                    plots: PlotPoints {
                        track: Thinned::new(),
                        sigma: [Thinned::new(), Thinned::new(), Thinned::new()],
                    },
                };
                // the header out of the buffer; rows are formatted straight into one large
                // chunk, handed to the file whole
                file.writer().flush().map_err(|e| e.to_string())?;
                let mut out = file.writer().file();
                let mut chunk = Vec::with_capacity(CHUNK_BYTES + 512);
                let mut unsynced = 0usize;
                for batch in rx {
                    for r in &batch {
                        let (row, sig, n_sig) = former.row(r)?;
                        // the truth layout (same digits), then the sigmas
                        push_row(&mut chunk, &row);
                        chunk.pop(); // its newline
                        for v in &sig[..n_sig] {
                            chunk.push(b' ');
                            push_sci(&mut chunk, *v, 4);
                        }
                        chunk.push(b'\n');
                        if chunk.len() >= CHUNK_BYTES {
                            out.write_all(&chunk)
                                .map_err(|e| format!("cannot write {shown}: {e}"))?;
                            unsynced += chunk.len();
                            chunk.clear();
                            if unsynced >= WRITEBACK_BYTES {
                                start_writeback(out);
                                unsynced = 0;
                            }
                        }
                    }
                }
                out.write_all(&chunk)
                    .and_then(|_| out.sync_all())
                    .map_err(|e| format!("cannot write {shown}: {e}"))?;
                Ok((file, former.plots))
            })?;
        Ok(RowWriter { tx, thread })
    }
}

/// Writes `nav.txt` rows from the filter's [`Observer::nav_sample`].
pub struct NavWriter {
    writer: Option<RowWriter>,
    batch: Vec<RawRow>,
    clock: RowClock,
    idx: [Option<usize>; 9],
    n: usize,
    /// The first write error or non-finite value met (checked after the run).
    pub error: Option<String>,
    /// Rows handed to the writing thread (written, unless [`NavWriter::finish`] says why not).
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
            writer: Some(RowWriter::spawn(file, path, idx.map(|i| i.is_some()))?),
            batch: Vec::with_capacity(BATCH_ROWS),
            clock,
            idx,
            n: model.n(),
            error: None,
            rows: 0,
        })
    }

    /// Hands the last rows over, waits for the writing thread (which started the file's
    /// write-back as it wrote and syncs it), moves the file into place and draws `png`'s two
    /// plots.
    pub fn finish(mut self, png: &std::path::Path) -> anyhow::Result<()> {
        self.send_batch();
        let w = self
            .writer
            .take()
            .ok_or_else(|| anyhow::anyhow!("nav.txt: its writing thread is gone"))?;
        drop(w.tx);
        let done = match w.thread.join() {
            Ok(Ok(done)) => Some(done),
            Ok(Err(e)) => {
                self.error.get_or_insert(e);
                None
            }
            Err(_) => {
                self.error
                    .get_or_insert_with(|| "nav.txt: its writing thread panicked".into());
                None
            }
        };
        if let Some(e) = self.error {
            anyhow::bail!("{e}");
        }
        let (file, plots) =
            done.ok_or_else(|| anyhow::anyhow!("nav.txt: its writing thread ended early"))?;
        file.commit()?;
        draw_plots(png, plots)
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

    /// Copies the state, the nine estimates and their variances out for the writing thread.
    fn row(&mut self, s: &NavState, x: &[f64], p: &[f64]) {
        let (mut dx, mut var) = ([0.0; 9], [0.0; 9]);
        for (k, i) in self.idx.iter().enumerate() {
            if let Some(i) = *i {
                dx[k] = x[i];
                var[k] = p[i * self.n + i];
            }
        }
        self.batch.push(RawRow { s: *s, dx, var });
        if self.batch.len() >= BATCH_ROWS {
            self.send_batch();
        }
        self.rows += 1;
    }
}

/// Draws the track and the σ envelopes beside `png`: `STEM_track.png` and `STEM_sigma.png`.
fn draw_plots(png: &std::path::Path, plots: PlotPoints) -> anyhow::Result<()> {
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
            points: plots.track.points,
        }],
        Scale::Linear,
    )?;
    let [mut sn, mut se, mut sh] = plots.sigma;
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

impl Observer for NavWriter {
    fn nav_sample(&mut self, s: &NavState, x: &[f64], p: &[f64]) {
        // rows on the samples' times, as navigate writes them
        if !self.clock.due(s.t) {
            return;
        }
        self.row(s, x, p);
    }
}
