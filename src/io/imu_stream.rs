//! IMU samples read one at a time, whatever the file's format, through one validated path:
//! every sample that leaves [`ImuStream`] has a finite, strictly increasing time, no gap longer
//! than 5 sample intervals, and an angular rate and specific force within what any IMU measures.
//! `navigate` and `filter` run on the stream, so their memory does not grow with the file; the
//! commands that need all samples at once (align, allan, imu-check, explain) [`ImuStream::collect`]
//! them.
//!
//! The stream reads ahead the first [`HEAD_SECONDS`] (at most [`HEAD_MAX_SAMPLES`] samples): the
//! median sample interval comes from them, and so does what is judged on the first seconds
//! (imu-check's plausibility, the start time).

use crate::io::imu::{ImuData, ImuSample, TableRows};
pub use crate::io::sample_source::{SampleSource, MAX_FORCE, MAX_RATE};
use anyhow::{bail, Context, Result};
use nalgebra::Vector3;
use std::path::Path;

/// Seconds of data read ahead when a stream opens [s].
pub const HEAD_SECONDS: f64 = 10.0;
/// Most samples read ahead when a stream opens.
pub const HEAD_MAX_SAMPLES: usize = 200_000;
/// Fewest samples read ahead, whatever their span (a time in ms read as s makes 10 s hold one).
pub const HEAD_MIN_SAMPLES: usize = 20;
/// Plausible median sample interval of a strapdown IMU [s]: 10 µs to 1 s (slower data cannot
/// follow a vehicle's turns; a 100 Hz clock in ms read as s shows 10 s).
pub const INTERVAL_RANGE: (f64, f64) = (1e-5, 1.0);
/// Largest gap between two samples, in median sample intervals.
pub const MAX_GAP_INTERVALS: f64 = 5.0;

/// Samples already in memory (formats read whole, tests, simulated data).
struct MemorySource {
    samples: std::vec::IntoIter<ImuSample>,
    total: usize,
    taken: usize,
}

impl SampleSource for MemorySource {
    fn next_sample(&mut self) -> Result<Option<(ImuSample, usize)>> {
        self.taken += 1;
        Ok(self.samples.next().map(|s| (s, 0)))
    }
    fn fraction(&self) -> f64 {
        self.taken as f64 / self.total.max(1) as f64
    }
}

/// The project's text format (`t dθx dθy dθz dvx dvy dvz`, FRD increments).
struct TextSource {
    rows: TableRows<std::io::BufReader<std::fs::File>>,
}

impl SampleSource for TextSource {
    fn next_sample(&mut self) -> Result<Option<(ImuSample, usize)>> {
        Ok(self.rows.next_row()?.map(|(line, v)| {
            (
                ImuSample {
                    t: v[0],
                    dtheta: Vector3::new(v[1], v[2], v[3]),
                    dv: Vector3::new(v[4], v[5], v[6]),
                },
                line,
            )
        }))
    }
    fn fraction(&self) -> f64 {
        self.rows.fraction()
    }
}

/// IMU samples of one file, read and validated one at a time (see the module docs).
pub struct ImuStream {
    src: Box<dyn SampleSource>,
    name: String,
    /// The samples read ahead (validated), handed out first.
    head: Vec<ImuSample>,
    /// Index of the next head sample to hand out.
    head_next: usize,
    interval: f64,
    prev_t: Option<f64>,
    delivered: u64,
    last_t: f64,
    /// A sample read by [`ImuStream::skip_through`] past its time, handed out next.
    pending: Option<ImuSample>,
    /// Judge each window of [`HEAD_SECONDS`] after the head, in the order added
    /// ([`ImuStream::judge_windows`]), then an empty one at the end of the file.
    judges: Vec<WindowCheck>,
    /// The window check has been told the file ended.
    ended: bool,
    /// The samples after the head not yet judged.
    window: Vec<ImuSample>,
    /// Intervals longer than twice the median (samples missing, within [`MAX_GAP_INTERVALS`]).
    short_gaps: u64,
    /// The longest of them [s] and the time before it [s].
    longest_gap: (f64, f64),
}

/// A check of the samples of one window after the head (consecutive, in time order); its error
/// ends the stream.
pub type WindowCheck = Box<dyn FnMut(&[ImuSample]) -> Result<()>>;

impl ImuStream {
    /// A stream over `src`; `name` is the file's name in messages. Reads the head ahead and
    /// checks it: at least two samples and a plausible median interval.
    pub fn new(src: Box<dyn SampleSource>, name: &str) -> Result<ImuStream> {
        ImuStream::with_hint(src, name, "the time column and its unit")
    }

    /// [`ImuStream::new`], with the words that say where the clock's unit is set (for a wrong
    /// median interval).
    pub fn with_hint(
        mut src: Box<dyn SampleSource>,
        name: &str,
        clock_hint: &str,
    ) -> Result<ImuStream> {
        let mut head: Vec<(ImuSample, usize)> = Vec::new();
        while head.len() < HEAD_MAX_SAMPLES {
            let Some((s, line)) = src.next_sample()? else {
                break;
            };
            let at = |line: usize| at(name, line, head.len() + 1);
            if !s.t.is_finite() {
                bail!("{}: the time is not finite", at(line));
            }
            if let Some((p, _)) = head.last() {
                if s.t <= p.t {
                    bail!(
                        "{}: time {} does not increase (previous {})",
                        at(line),
                        s.t,
                        p.t
                    );
                }
            }
            let span = head.first().map(|f| s.t - f.0.t).unwrap_or(0.0);
            head.push((s, line));
            // (and at least HEAD_MIN_SAMPLES: a clock read 1000× slow still shows its samples)
            if span >= HEAD_SECONDS && head.len() >= HEAD_MIN_SAMPLES {
                break;
            }
        }
        if head.len() < 2 {
            bail!("{name}: fewer than two IMU samples");
        }
        let mut d: Vec<f64> = head
            .iter()
            .zip(head.iter().skip(1))
            .map(|(a, b)| b.0.t - a.0.t)
            .collect();
        d.sort_by(f64::total_cmp);
        let interval = d[d.len() / 2];
        if !(INTERVAL_RANGE.0..=INTERVAL_RANGE.1).contains(&interval) {
            bail!(
                "--imu {name}: median sample interval {interval:.3e} s ({:.3e} Hz) is not a strapdown IMU's ({} .. {} s): check {clock_hint}{}",
                1.0 / interval,
                INTERVAL_RANGE.0,
                INTERVAL_RANGE.1,
                if interval > INTERVAL_RANGE.1 {
                    format!(
                        " (a time in ms read as s gives 1000× the interval: {:.3} s, {:.0} Hz, if so)",
                        interval / 1000.0,
                        1000.0 / interval
                    )
                } else if interval < INTERVAL_RANGE.0 {
                    " (a time in s read as ms, or µs, gives 1/1000 of the interval)".to_string()
                } else {
                    String::new()
                }
            );
        }
        let mut stream = ImuStream {
            src,
            name: name.to_string(),
            head: Vec::with_capacity(head.len()),
            head_next: 0,
            interval,
            prev_t: None,
            delivered: 0,
            last_t: f64::NAN,
            pending: None,
            judges: Vec::new(),
            ended: false,
            window: Vec::new(),
            short_gaps: 0,
            longest_gap: (0.0, f64::NAN),
        };
        // validate the head in order, as every later sample will be (prev_t then stands at the
        // last head sample, where the samples after the head continue)
        for (s, line) in head {
            stream.check(&s, line, stream.head.len() as u64 + 1)?;
            stream.head.push(s);
        }
        Ok(stream)
    }

    /// Opens an IMU file as `format` describes it (`--imu-format`), else as the description
    /// beside it (`FILE.format.toml`), else by extension (`.imu` PSINS, `.csv` GNSS_IMU with its
    /// `.tag`, anything else the project's text); also returns the words saying which was used.
    pub fn open(path: &Path, format: Option<&Path>) -> Result<(ImuStream, String)> {
        ImuStream::open_with(path, format, None)
    }

    /// [`ImuStream::open`] with a GPST − IMU clock offset [s] for a GNSS_IMU csv
    /// (`--clock-offset`, instead of its `.tag` file); refused for other formats.
    pub fn open_with(
        path: &Path,
        format: Option<&Path>,
        clock_offset: Option<f64>,
    ) -> Result<(ImuStream, String)> {
        if let Some(o) = clock_offset {
            if !(o.is_finite() && o.abs() <= 1e10) {
                bail!("--clock-offset {o}: expected seconds within ±1e10");
            }
            let csv = format.is_none()
                && crate::io::imu_format::beside(path).is_none()
                && path.extension().is_some_and(|e| e == "csv");
            if !csv {
                bail!("--clock-offset applies to a GNSS_IMU .csv read by its extension (a format description sets its own [time] column and unit)");
            }
        }
        use crate::io::imu_format::{beside, ImuFormat};
        use crate::io::readers::{gnss_imu, matlab, psins};
        if let Some((file, var)) = matlab::split(path) {
            if format.is_some() {
                bail!("--imu-format describes text layouts; a .mat file is read as a PSINS [wm vm t] array");
            }
            let (data, name) = matlab::read_imu(&file, var.as_deref())?;
            let how = format!(
                "as a PSINS [wm(3) vm(3) t] array of increments, right-forward-up, from MATLAB variable {name} (chosen by its extension)"
            );
            return Ok((ImuStream::from_data(data, &name)?, how));
        }
        let name = path.display().to_string();
        if !std::fs::metadata(path).is_ok_and(|m| m.is_file()) {
            bail!(
                "--imu {name}: cannot read IMU file (missing, or not a regular file: a directory, device or pipe)"
            );
        }
        if let Some(f) = format {
            let fmt = ImuFormat::load(f)?;
            return Ok((
                fmt.stream(path)?,
                format!("as described by {}", f.display()),
            ));
        }
        if let Some(f) = beside(path) {
            let fmt = ImuFormat::load(&f)?;
            return Ok((
                fmt.stream(path)?,
                format!("as described by {} (found beside it)", f.display()),
            ));
        }
        let other = "--imu-format FILE.toml describes any other layout (docs/formats.md)";
        match path.extension().and_then(|e| e.to_str()) {
            Some("imu") => {
                let how = "as a PSINS .imu log (chosen by its extension)";
                let (_, src) =
                    psins::open(path).with_context(|| format!("reading {name} {how}; {other}"))?;
                Ok((
                    ImuStream::new(Box::new(src), &name)
                        .with_context(|| format!("reading {name} {how}; {other}"))?,
                    format!("{how}; {other}"),
                ))
            }
            Some("csv") => {
                let how = match clock_offset {
                    None => "as a GNSS_IMU csv on GPST with its .tag file (chosen by its extension)".to_string(),
                    Some(o) => format!("as a GNSS_IMU csv, clock offset {o} s from --clock-offset (chosen by its extension)"),
                };
                let log = gnss_imu::read_with(path, clock_offset).with_context(|| {
                    format!("reading {name} {how}; {other} (formats/gnss-imu-csv.toml reads it without the .tag)")
                })?;
                Ok((
                    ImuStream::from_data(log.imu, &name)?,
                    format!("{how}; {other}"),
                ))
            }
            _ => Ok((
                ImuStream::text(path)?,
                format!("as sinsmodel IMU text (t dtheta_xyz [rad] dv_xyz [m/s], FRD); {other}"),
            )),
        }
    }

    /// The project's text IMU format, streamed.
    pub fn text(path: &Path) -> Result<ImuStream> {
        let rows = TableRows::open(path, 7, "IMU file")?;
        let src = crate::io::sample_source::ReadAhead::spawn(Box::new(TextSource { rows }))?;
        ImuStream::new(Box::new(src), &path.display().to_string())
    }

    /// Samples already in memory, validated like a file's.
    pub fn from_data(data: ImuData, name: &str) -> Result<ImuStream> {
        let total = data.samples.len();
        ImuStream::new(
            Box::new(MemorySource {
                samples: data.samples.into_iter(),
                total,
                taken: 0,
            }),
            name,
        )
    }

    /// Checks one sample against the previous one: time, gap, rate and force.
    fn check(&mut self, s: &ImuSample, line: usize, index: u64) -> Result<()> {
        let here = || at(&self.name, line, index as usize);
        if !s.t.is_finite() {
            bail!("{}: the time is not finite", here());
        }
        let dt = match self.prev_t {
            Some(p) => {
                let d = s.t - p;
                if d <= 0.0 {
                    bail!("{}: time {} does not increase (previous {p})", here(), s.t);
                }
                if d > MAX_GAP_INTERVALS * self.interval {
                    bail!(
                        "{}: gap of {d:.4} s after t = {p} (more than {MAX_GAP_INTERVALS} sample intervals of {:.4} s)",
                        here(),
                        self.interval
                    );
                }
                if d > 2.0 * self.interval {
                    self.short_gaps += 1;
                    if d > self.longest_gap.0 {
                        self.longest_gap = (d, p);
                    }
                }
                d
            }
            None => self.interval,
        };
        let (w, f) = (s.dtheta.norm() / dt, s.dv.norm() / dt);
        // an increment over a tiny interval (or one whose square overflows) is beyond any IMU
        // too: said in words, never printed as inf
        let num = |v: f64| {
            if v.is_finite() {
                format!("{v:.3e}")
            } else {
                "too large to represent".to_string()
            }
        };
        if w.is_nan() || f.is_nan() {
            bail!(
                "{}: the increments over an interval of {dt:.3e} s give no rate or force (check the values and the clock)",
                here()
            );
        }
        if w > MAX_RATE {
            bail!(
                "{}: angular rate {} rad/s (increment over {dt:.3e} s) is beyond any IMU (<= {MAX_RATE} rad/s): check the values, their unit and the clock",
                here(),
                num(w)
            );
        }
        if f > MAX_FORCE {
            bail!(
                "{}: specific force {} m/s^2 (increment over {dt:.3e} s) is beyond any IMU (<= 2000 g): check the values, their unit and the clock",
                here(),
                num(f)
            );
        }
        self.prev_t = Some(s.t);
        Ok(())
    }

    /// The next validated sample, or None at the end of the file.
    #[allow(clippy::should_implement_trait)]
    pub fn next(&mut self) -> Result<Option<ImuSample>> {
        if let Some(s) = self.pending.take() {
            return Ok(Some(s));
        }
        let s = if let Some(&s) = self.head.get(self.head_next) {
            // validated when the stream opened
            self.head_next += 1;
            s
        } else {
            let Some((s, line)) = self.src.next_sample()? else {
                self.judge_window()?;
                self.judge_end()?;
                return Ok(None);
            };
            self.check(&s, line, self.delivered + 1)?;
            if !self.judges.is_empty() {
                self.window.push(s);
                let span = s.t - self.window[0].t;
                if span >= HEAD_SECONDS && self.window.len() >= HEAD_MIN_SAMPLES {
                    self.judge_window()?;
                }
            }
            s
        };
        self.delivered += 1;
        self.last_t = s.t;
        Ok(Some(s))
    }

    /// Has `check` judge, after the checks added before it, every window of [`HEAD_SECONDS`]
    /// read from now on (the head is judged where the stream is opened), the last, shorter one
    /// at the end of the file, then an empty one.
    pub fn judge_windows(&mut self, check: WindowCheck) {
        self.judges.push(check);
    }

    /// Judges the samples collected since the last window and forgets them.
    fn judge_window(&mut self) -> Result<()> {
        if self.window.is_empty() {
            return Ok(());
        }
        let r = self.judges.iter_mut().try_for_each(|j| j(&self.window));
        self.window.clear();
        r
    }

    /// Tells the window check the file has ended (an empty window, once).
    fn judge_end(&mut self) -> Result<()> {
        if self.ended {
            return Ok(());
        }
        self.ended = true;
        self.say_gaps();
        self.judges.iter_mut().try_for_each(|j| j(&[]))
    }

    /// Warns (once per run) of the intervals longer than twice the median the file held: the
    /// run integrates across them, but samples a logger dropped take their increments with them.
    fn say_gaps(&self) {
        if let Some(w) = self.gap_warning() {
            crate::io::warnings::warn_once(&w);
        }
    }

    /// The words of [`ImuStream::say_gaps`] for the samples read so far; None without such
    /// intervals.
    fn gap_warning(&self) -> Option<String> {
        if self.short_gaps == 0 {
            return None;
        }
        let (d, t) = self.longest_gap;
        Some(format!(
            "--imu {}: {} interval(s) longer than twice the median {:.4} s (the longest {d:.4} s after t = {t:.3} s): integrated across; if the logger dropped those samples, their increments (motion) are lost, if it summed them into the next sample nothing is; `sinsmodel imu-check` lists the clock",
            self.name,
            self.short_gaps,
            self.interval
        ))
    }

    /// Reads and drops the samples whose time is at or before `t` [s] (a run that starts at
    /// `t`); returns how many.
    pub fn skip_through(&mut self, t: f64) -> Result<u64> {
        let mut n = 0;
        while let Some(s) = self.next()? {
            if s.t > t {
                self.pending = Some(s);
                break;
            }
            n += 1;
        }
        Ok(n)
    }

    /// The samples read ahead when the stream opened (the first [`HEAD_SECONDS`]).
    pub fn head(&self) -> &[ImuSample] {
        &self.head
    }

    /// Median sample interval of the head [s].
    pub fn interval(&self) -> f64 {
        self.interval
    }

    /// Time of the first sample [s].
    pub fn first_t(&self) -> f64 {
        self.head[0].t
    }

    /// When a run over the stream starts [s]: the start of the first sample's interval on a
    /// uniform clock (first time − interval); on a jittered clock that interval is unknown, so
    /// the run starts at the first sample's time and integrates from the second sample (a
    /// median interval in its place had put up to 10 ms of gravity into the first step).
    pub fn start_time(&self) -> f64 {
        // RMS deviation of the head's intervals from the median interval (no copy of the head)
        let n = self.head.len().saturating_sub(1).max(1) as f64;
        let jitter = (self
            .head
            .windows(2)
            .map(|w| (w[1].t - w[0].t - self.interval).powi(2))
            .sum::<f64>()
            / n)
            .sqrt();
        if self.head.len() > 2 && jitter > 1e-6 * self.interval {
            self.first_t()
        } else {
            self.first_t() - self.interval
        }
    }

    /// Time of the last sample handed out [s] (NaN before the first).
    pub fn last_t(&self) -> f64 {
        self.last_t
    }

    /// Number of samples handed out so far.
    pub fn count(&self) -> u64 {
        self.delivered
    }

    /// Fraction of the input read so far.
    pub fn fraction(&self) -> f64 {
        self.src.fraction()
    }

    /// The file's name as messages show it.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The same samples, all read into memory first (the pre-streaming path: a baseline for
    /// `sinsmodel bench`).
    pub fn into_memory(self) -> Result<ImuStream> {
        let name = self.name.clone();
        ImuStream::from_data(self.collect()?, &name)
    }

    /// Reads every remaining sample into memory.
    pub fn collect(mut self) -> Result<ImuData> {
        let mut samples = Vec::new();
        while let Some(s) = self.next()? {
            samples.push(s);
        }
        Ok(ImuData { samples })
    }
}

/// `file:line` where the sample has a line, else `file: sample N`.
fn at(name: &str, line: usize, index: usize) -> String {
    if line > 0 {
        format!("{name}:{line}")
    } else {
        format!("{name}: sample {index}")
    }
}

/// Reading whole files through the validated stream: each reader hands out a source, the
/// stream checks every sample.
impl crate::io::imu_format::ImuFormat {
    /// Reads a data file described by this format into FRD increments; errors name the data
    /// file and line (or the description's line for a column name it lacks).
    pub fn read(&self, path: &Path) -> Result<ImuData> {
        self.stream(path)?.collect()
    }

    /// A stream of the validated samples of a data file described by this format.
    pub fn stream(&self, path: &Path) -> Result<ImuStream> {
        ImuStream::with_hint(
            self.source(path)?,
            &path.display().to_string(),
            &format!("[time] unit in {}", self.origin),
        )
    }
}

/// Reads the text IMU format; any malformed row, NaN, non-increasing time, implausible rate or
/// force, or gap longer than 5 intervals is an error naming the file and line.
pub fn read_text(path: &Path) -> Result<ImuData> {
    ImuStream::text(path)?.collect()
}

/// Reads a PSINS `.imu` file whole (header and validated samples).
pub fn read_psins(path: &Path) -> Result<crate::io::readers::psins::PsinsLog> {
    let (mut log, src) = crate::io::readers::psins::open(path)?;
    log.imu = ImuStream::new(Box::new(src), &path.display().to_string())?.collect()?;
    Ok(log)
}

/// Reads an IMU file as `format` describes it (`--imu-format`), else as the description beside
/// it (`FILE.format.toml`), else by extension; also returns the words saying which was used.
/// Every sample is validated ([`crate::io::imu_stream::ImuStream`]).
pub fn read_imu(path: &Path, format: Option<&Path>) -> Result<(ImuData, String)> {
    let (stream, how) = ImuStream::open(path, format)?;
    Ok((stream.collect()?, how))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn data(ts: &[f64], w: f64) -> ImuData {
        ImuData {
            samples: ts
                .iter()
                .map(|&t| ImuSample {
                    t,
                    dtheta: Vector3::new(w * 0.01, 0.0, 0.0),
                    dv: Vector3::new(0.0, 0.0, -0.098),
                })
                .collect(),
        }
    }

    /// Intervals of 2–5 median intervals (dropped samples) pass, and are said once at the end.
    #[test]
    fn short_gaps_are_said() {
        let mut ts: Vec<f64> = (1..=3000).map(|k| k as f64 * 0.01).collect();
        let read = |ts: &[f64]| {
            let mut s = ImuStream::from_data(data(ts, 0.1), "mem").unwrap();
            let mut n = 0;
            while s.next().unwrap().is_some() {
                n += 1;
            }
            (n, s.gap_warning())
        };
        assert_eq!(read(&ts), (3000, None));
        // three samples dropped after the head (a 0.04-s interval), two more later, and a jitter
        // of 1.9 intervals, not a gap
        ts.remove(2001);
        ts.remove(2001);
        ts.remove(2001);
        ts.remove(2500);
        ts.remove(2500);
        ts[2700] += 0.009;
        let (n, w) = read(&ts);
        assert_eq!(n, 2995);
        let w = w.expect("a warning");
        assert!(
            w.starts_with("--imu mem: 2 interval(s) longer than twice the median 0.0100 s (the longest 0.0400 s after t = 20.010 s)"),
            "{w}"
        );
    }

    #[test]
    fn streams_validate_every_sample() {
        let ts: Vec<f64> = (1..=3000).map(|k| k as f64 * 0.01).collect();
        let s = ImuStream::from_data(data(&ts, 0.1), "mem").unwrap();
        assert!((s.interval() - 0.01).abs() < 1e-12);
        assert_eq!(s.head().len(), 1001);
        assert_eq!(s.collect().unwrap().samples.len(), 3000);
        // a gap beyond the head
        let mut ts2 = ts.clone();
        for t in ts2.iter_mut().skip(2000) {
            *t += 1.0;
        }
        let e = ImuStream::from_data(data(&ts2, 0.1), "mem")
            .unwrap()
            .collect()
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("mem: sample 2001: gap of 1.0100 s"), "{e}");
        // an absurd rate (1e308 finite in the file)
        let e = ImuStream::from_data(data(&ts, 1e308), "mem")
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("beyond any IMU"), "{e}");
        // a clock in ms read as s
        let ms: Vec<f64> = (1..50).map(|k| k as f64 * 20.0).collect();
        let e = ImuStream::from_data(data(&ms, 0.0), "mem")
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("median sample interval"), "{e}");
    }
}
