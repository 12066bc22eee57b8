//! `filter`'s navigation solution, `nav.txt`: the navigator corrected by the filter's error
//! estimate, with 1-σ from its covariance, written as the samples come (DESIGN §9's truth layout
//! first), and `nav.png` (the track and the σ envelopes).

use sinsmodel::estimate::filter::Observer;
use sinsmodel::io::atomic_file::AtomicFile;
use sinsmodel::model::Model;
use sinsmodel::nav::nav_rows::{PlotPoints, RawRow, RowWriter, BATCH_ROWS, STATES};
use sinsmodel::nav::strapdown::NavState;
use std::io::Write;

pub use sinsmodel::nav::free_inertial::RowClock;

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

/// Writes `nav.txt` rows from the filter's [`Observer::nav_sample`].
pub struct NavWriter {
    writer: RowWriter,
    batch: Vec<RawRow>,
    clock: RowClock,
    idx: [Option<usize>; 9],
    n: usize,
    /// Rows handed to the writing thread (written, unless [`NavWriter::finish`] says why not).
    pub rows: u64,
}

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
            writer: RowWriter::spawn(file, path, idx.map(|i| i.is_some()), start_writeback)?,
            batch: Vec::with_capacity(BATCH_ROWS),
            clock,
            idx,
            n: model.n(),
            rows: 0,
        })
    }

    /// Hands the last rows over, waits for the writing thread (which started the file's
    /// write-back as it wrote and syncs it), moves the file into place and draws `png`'s two
    /// plots.
    pub fn finish(mut self, png: &std::path::Path) -> anyhow::Result<()> {
        self.send_batch();
        let (file, plots) = self.writer.finish().map_err(anyhow::Error::msg)?;
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
        self.writer.send(batch);
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
