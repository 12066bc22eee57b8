//! `filter`'s navigation solution rows, `nav.txt`: the navigator corrected by the filter's
//! error estimate, with 1-σ from its covariance (DESIGN §9's truth layout first), formed,
//! formatted and written on a thread of their own behind the filter, which hands it only the
//! navigator's state and nine estimates and variances per row.

use crate::io::atomic_file::AtomicFile;
use crate::io::fixed::push_sci;
use crate::io::truth::{push_row_values, TruthRow};
use crate::nav::earth;
use crate::nav::strapdown::NavState;
use std::io::Write;

/// State names in nav.txt's σ order: position, velocity, attitude.
pub const STATES: [&str; 9] = [
    "dlat", "dlon", "dh", "dv_n", "dv_e", "dv_d", "phi_n", "phi_e", "phi_d",
];

/// Most points kept per plotted curve (older points thinned as the run grows).
const PLOT_POINTS: usize = 4000;

/// Points kept for a plot, thinned by two whenever full, so memory stays bounded.
pub struct Thinned {
    /// The points kept, oldest first.
    pub points: Vec<(f64, f64)>,
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
pub const BATCH_ROWS: usize = 512;
/// Batches in flight between the filter and the writing thread (memory stays bounded).
const BATCHES_IN_FLIGHT: usize = 4;
/// Bytes of formatted rows the writing thread hands to the file at once (straight to the file,
/// past the atomic file's buffer, which holds the header only).
const CHUNK_BYTES: usize = 256 << 10;
/// Bytes written between two requests to the operating system to start writing them to disk,
/// so that the commit's final sync waits for the last few only.
const WRITEBACK_BYTES: usize = 8 << 20;

/// One nav.txt row as the filter hands it over: the navigator's state, the error estimates of
/// the nine navigation states in nav.txt's σ order (zero where the model has none) and their
/// variances (meaningful where it has them). Everything else is computed by the writing thread.
pub struct RawRow {
    /// The navigator's state.
    pub s: NavState,
    /// The error estimates of dlat, dlon [rad], dh [m], dv_n, dv_e, dv_d [m/s], phi_n, phi_e,
    /// phi_d [rad].
    pub dx: [f64; 9],
    /// Their variances (in the same units, squared).
    pub var: [f64; 9],
}

/// The points the writing thread keeps for the plots: the track [m east, m north of the first
/// row] and the 1-σ of north, east, height [m] against time [s].
pub struct PlotPoints {
    /// The track: east, north of the first row [m].
    pub track: Thinned,
    /// 1-σ of north, east, height [m] against time [s] (height empty without one).
    pub sigma: [Thinned; 3],
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

/// The thread that turns the filter's rows into nav.txt's and formats and writes them behind
/// the filter (the same bytes as doing it in line; the filter's thread only copies the state
/// and its σ out): the batches' sender, and the thread, which hands the synced file and the
/// plots' points back (or the first error: a row that is not finite, a failed write).
pub struct RowWriter {
    tx: std::sync::mpsc::SyncSender<Vec<RawRow>>,
    thread: std::thread::JoinHandle<Result<(AtomicFile, PlotPoints), String>>,
}

impl RowWriter {
    /// Starts the thread on `file` (its header written; `path` names it in messages), with the
    /// σ columns `present` in [`STATES`] order; `writeback` is called on the file after every
    /// few MiB written (a hint to start writing them to disk, or nothing).
    pub fn spawn(
        mut file: AtomicFile,
        path: &std::path::Path,
        present: [bool; 9],
        writeback: fn(&std::fs::File),
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
                        push_row_values(&mut chunk, &row);
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
                                writeback(out);
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

    /// Hands a batch of rows over (a thread that stopped on an error takes no more; its error
    /// comes from [`RowWriter::finish`]).
    pub fn send(&self, batch: Vec<RawRow>) {
        let _ = self.tx.send(batch);
    }

    /// Ends the rows and waits for the thread: the synced file and the plots' points, or the
    /// first error.
    pub fn finish(self) -> Result<(AtomicFile, PlotPoints), String> {
        drop(self.tx);
        self.thread
            .join()
            .unwrap_or_else(|_| Err("nav.txt: its writing thread panicked".into()))
    }
}
