//! IMU logs described, not converted by hand: a TOML description of a logger's file layout
//! (delimiter, header row, comment prefix), its time column and clock unit, the kind of signal
//! (rates or increments) with their units (the project's unit parser, raw counts as
//! `"0.1 arcsec"` per count), and where the sensor's axes point on the body. Read into the
//! project's FRD increments over each sample interval. Format: `docs/formats.md`.

use crate::io::imu::ImuSample;
use crate::io::lines::{shown, Lines};
use crate::io::sample_source::{SampleSource, MAX_FORCE, MAX_RATE};
use crate::io::units::{parse_quantity, parse_unit};
use anyhow::{anyhow, bail, Context, Result};
use nalgebra::{Matrix3, Vector3};
use serde::Deserialize;
use std::path::Path;
use toml::Spanned;

/// How fields are separated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Delimiter {
    /// Runs of spaces or tabs.
    Whitespace,
    /// One character (`,`, `;`, tab, `|`).
    Char(char),
}

/// A column by header name or by 1-based index.
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(untagged)]
pub enum ColumnRef {
    /// Name in the header row.
    Name(String),
    /// 1-based index.
    Index(i64),
}

/// What the six signal columns hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Angular rate and specific force, integrated over each interval.
    Rate,
    /// Angle and velocity increments over (t_prev, t].
    Increment,
}

/// How a rate becomes an increment over (t_{k−1}, t_k].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Integration {
    /// (y_{k−1} + y_k)/2 · (t_k − t_{k−1}).
    Trapezoid,
    /// y_k · (t_k − t_{k−1}): the sample is the mean rate over the interval ending at t_k.
    Hold,
}

/// A parsed and checked IMU format description.
#[derive(Debug, Clone)]
pub struct ImuFormat {
    /// Where the description came from (for messages).
    pub origin: String,
    /// Field separator.
    pub delimiter: Delimiter,
    /// The first data line (after `skip_lines`) holds column names.
    pub header: bool,
    /// Lines skipped before anything else.
    pub skip_lines: usize,
    /// Lines starting with this prefix are skipped (empty: none).
    pub comment: String,
    /// Time column.
    pub time: ColumnRef,
    /// Seconds per unit of the time column.
    pub time_to_s: f64,
    /// Rates or increments.
    pub kind: Kind,
    /// Integration rule for rates.
    pub integration: Integration,
    /// Gyro columns (sensor x, y, z).
    pub gyro: [ColumnRef; 3],
    /// SI per unit of the gyro columns (rad/s or rad).
    pub gyro_to_si: f64,
    /// Accelerometer columns (sensor x, y, z).
    pub accel: [ColumnRef; 3],
    /// SI per unit of the accelerometer columns (m/s² or m/s).
    pub accel_to_si: f64,
    /// Sensor axes to FRD body: v_body = axes · v_sensor (a proper rotation).
    pub axes: Matrix3<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFormat {
    file: Option<RawFile>,
    time: RawTime,
    signals: RawSignals,
    axes: Option<RawAxes>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFile {
    delimiter: Option<Spanned<String>>,
    header: Option<bool>,
    skip_lines: Option<Spanned<i64>>,
    comment: Option<Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTime {
    column: Spanned<ColumnRef>,
    unit: Option<Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSignals {
    kind: Spanned<String>,
    integration: Option<Spanned<String>>,
    gyro: Spanned<Vec<ColumnRef>>,
    gyro_unit: Spanned<String>,
    accel: Spanned<Vec<ColumnRef>>,
    accel_unit: Spanned<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawAxes {
    x: Option<Spanned<String>>,
    y: Option<Spanned<String>>,
    z: Option<Spanned<String>>,
    rotation: Option<Spanned<Vec<Vec<f64>>>>,
}

fn column_words(c: &ColumnRef) -> String {
    match c {
        ColumnRef::Name(n) => format!("`{}`", n.escape_debug()),
        ColumnRef::Index(i) => format!("{i}"),
    }
}

/// The FRD body unit vector a direction word names.
fn direction(word: &str) -> Option<Vector3<f64>> {
    Some(match word.trim().to_ascii_lowercase().as_str() {
        "forward" | "front" => Vector3::new(1.0, 0.0, 0.0),
        "back" | "backward" | "rear" => Vector3::new(-1.0, 0.0, 0.0),
        "right" => Vector3::new(0.0, 1.0, 0.0),
        "left" => Vector3::new(0.0, -1.0, 0.0),
        "down" => Vector3::new(0.0, 0.0, 1.0),
        "up" => Vector3::new(0.0, 0.0, -1.0),
        _ => return None,
    })
}

/// SI value of one unit written as a unit (`"deg/s"`) or a quantity per count (`"0.1 arcsec"`),
/// checked against the dimension of `si_unit`.
fn unit_scale(text: &str, si_unit: &str) -> Result<f64, String> {
    let t = text.trim();
    let first_is_number = t
        .split_whitespace()
        .next()
        .is_some_and(|w| w.parse::<f64>().is_ok());
    let q = if first_is_number {
        parse_quantity(t).map_err(|e| e.0)?
    } else {
        parse_quantity(&format!("1 {t}")).map_err(|e| e.0)?
    };
    let want = parse_unit(si_unit).map_err(|e| e.0)?;
    if q.dim != want.dim {
        return Err(format!(
            "`{t}` has dimension {} but a {si_unit} unit is needed here",
            q.dim
        ));
    }
    let s = q.si / want.to_si;
    if !(s.is_finite() && s > 0.0) {
        return Err(format!("`{t}`: the scale must be positive and finite"));
    }
    Ok(s)
}

impl ImuFormat {
    /// Reads and checks a description file.
    pub fn load(path: &Path) -> Result<ImuFormat> {
        if !std::fs::metadata(path).is_ok_and(|m| m.is_file()) {
            bail!(
                "IMU format {}: not a regular file (missing, a directory, a dangling link, a device or a pipe)",
                path.display()
            );
        }
        let text = crate::io::lines::read_small_text(path, "IMU format description")
            .with_context(|| format!("--imu-format {}: cannot read the file", path.display()))?;
        ImuFormat::parse(&text, &path.display().to_string())
    }

    /// Parses and checks description text; `origin` names it in messages (`origin:line: …`).
    pub fn parse(text: &str, origin: &str) -> Result<ImuFormat> {
        let src = Desc { text, origin };
        let raw: RawFormat = toml::from_str(text).map_err(|e| {
            let l = e.span().map(|s| src.line(s.start)).unwrap_or(0);
            let msg = e.message().trim();
            let msg = if msg.contains("untagged enum ColumnRef") {
                "a column is a header name (a string) or a 1-based index (a whole number)"
            } else {
                msg
            };
            anyhow!("{origin}:{l}: {msg}")
        })?;
        let file = raw.file.unwrap_or(RawFile {
            delimiter: None,
            header: None,
            skip_lines: None,
            comment: None,
        });
        let delimiter = src.delimiter(&file)?;
        let skip_lines = src.skip_lines(&file)?;
        let header = file.header.unwrap_or(false);
        let comment = src.comment(&file)?;

        let time = src.column(&raw.time.column, header)?;
        let time_to_s = match &raw.time.unit {
            None => 1.0,
            Some(u) => unit_scale(u.get_ref(), "s")
                .map_err(|e| src.at(u.span(), format!("[time] unit: {e}")))?,
        };
        let (kind, integration) = src.kind_and_integration(&raw.signals)?;
        let gyro = src.three(&raw.signals.gyro, "gyro", header)?;
        let accel = src.three(&raw.signals.accel, "accel", header)?;
        let (gyro_to_si, accel_to_si) = src.signal_scales(&raw.signals, kind)?;
        let mut all: Vec<&ColumnRef> = vec![&time];
        all.extend(gyro.iter());
        all.extend(accel.iter());
        for (i, a) in all.iter().enumerate() {
            if all[..i].contains(a) {
                return Err(anyhow!(
                    "{origin}: column {} is used twice among time, gyro and accel",
                    column_words(a)
                ));
            }
        }
        let axes = src.axes(raw.axes.as_ref())?;
        Ok(ImuFormat {
            origin: origin.to_string(),
            delimiter,
            header,
            skip_lines,
            comment,
            time,
            time_to_s,
            kind,
            integration,
            gyro,
            gyro_to_si,
            accel,
            accel_to_si,
            axes,
        })
    }

    fn split<'a>(&self, line: &'a str) -> Vec<&'a str> {
        match self.delimiter {
            Delimiter::Whitespace => line.split_whitespace().collect(),
            Delimiter::Char(c) => line.split(c).map(|f| f.trim().trim_matches('"')).collect(),
        }
    }

    /// The samples of a data file described by this format, read one at a time.
    pub fn source(&self, path: &Path) -> Result<Box<dyn SampleSource>> {
        let lines = Lines::open(path, "IMU file")?;
        Ok(Box::new(FormatSource {
            fmt: self.clone(),
            lines,
            cols: None,
            width: None,
            prev: None,
            skipped: 0,
        }))
    }
}

/// A described data file's rows turned into samples one at a time.
struct FormatSource {
    fmt: ImuFormat,
    lines: Lines<std::io::BufReader<std::fs::File>>,
    cols: Option<[usize; 7]>,
    width: Option<usize>,
    prev: Option<(f64, Vector3<f64>, Vector3<f64>)>,
    skipped: usize,
}

impl SampleSource for FormatSource {
    fn fraction(&self) -> f64 {
        self.lines.fraction()
    }

    fn next_sample(&mut self) -> Result<Option<(ImuSample, usize)>> {
        let file = self.lines.name().to_string();
        loop {
            let Some(raw_line) = self.lines.next_line()? else {
                return Ok(None);
            };
            let this = &self.fmt;
            if self.skipped < this.skip_lines {
                self.skipped += 1;
                continue;
            }
            let lineno = raw_line.no;
            let line = raw_line.text.trim();
            if line.is_empty() || (!this.comment.is_empty() && line.starts_with(&this.comment)) {
                continue;
            }
            let fields = this.split(line);
            if self.cols.is_none() {
                self.cols = Some(this.columns(&fields, &file, lineno)?);
                if this.header {
                    self.width = Some(fields.len());
                    continue;
                }
            }
            let c = self.cols.unwrap_or([0; 7]);
            this.check_width(&mut self.width, fields.len(), &file, lineno)?;
            let v = row_values(&fields, &c, &file, lineno)?;
            let (t, g, a) = this.signals(&v, self.prev.map(|p| p.0), &file, lineno)?;
            if let Some(sample) = this.sample(&mut self.prev, t, g, a) {
                return Ok(Some((sample, lineno)));
            }
        }
    }
}

impl ImuFormat {
    /// The 0-based field of column `c` in the header `names` of data file `file`, whose header
    /// is at line `lineno`.
    fn resolve(&self, names: &[&str], c: &ColumnRef, file: &str, lineno: usize) -> Result<usize> {
        match c {
            ColumnRef::Index(i) => Ok(*i as usize - 1),
            ColumnRef::Name(n) => names.iter().position(|h| h == n).ok_or_else(|| {
                anyhow!(
                    "{}: column `{}` is not in the header of {file}:{lineno} (it has: {})",
                    self.origin,
                    shown(n),
                    shown(&names.join(", "))
                )
            }),
        }
    }

    /// Checks a header row `names` (data file `file`, line `lineno`): more than one field (else
    /// the delimiter is wrong), no name twice.
    fn check_header(&self, names: &[&str], file: &str, lineno: usize) -> Result<()> {
        if names.len() == 1 {
            if let Some(d) = [',', ';', '\t', '|', ' ']
                .iter()
                .find(|d| names[0].contains(**d))
            {
                bail!(
                    "{file}:{lineno}: the header is one field with `{}` in it: is [file] delimiter right in {}? (it reads `{}`)",
                    d.escape_debug(),
                    self.origin,
                    match self.delimiter {
                        Delimiter::Whitespace => "whitespace".to_string(),
                        Delimiter::Char(c) => c.escape_debug().to_string(),
                    }
                );
            }
        }
        for (k, n) in names.iter().enumerate() {
            if names[..k].contains(n) {
                bail!(
                    "{file}:{lineno}: the header names `{}` twice: name the column by its 1-based index in {}",
                    n.escape_debug(),
                    self.origin
                );
            }
        }
        Ok(())
    }

    /// The 0-based fields of the time, gyro x, y, z and accel x, y, z columns, from the first
    /// row `fields` (the header, when there is one) of data file `file` at line `lineno`.
    fn columns(&self, fields: &[&str], file: &str, lineno: usize) -> Result<[usize; 7]> {
        let names: Vec<&str> = if self.header {
            fields.to_vec()
        } else {
            Vec::new()
        };
        if self.header {
            self.check_header(&names, file, lineno)?;
        }
        let mut c = [0usize; 7];
        let all = [
            &self.time,
            &self.gyro[0],
            &self.gyro[1],
            &self.gyro[2],
            &self.accel[0],
            &self.accel[1],
            &self.accel[2],
        ];
        for (k, r) in all.iter().enumerate() {
            c[k] = self.resolve(&names, r, file, lineno)?;
        }
        for k in 0..7 {
            if c[..k].contains(&c[k]) {
                bail!(
                    "{}: column {} is used twice among time, gyro and accel (by name and by index)",
                    self.origin,
                    c[k] + 1
                );
            }
        }
        Ok(c)
    }

    /// Checks that a row of `n` fields (data file `file`, line `lineno`) is as wide as the
    /// header or the first row; `width` is set from the first.
    fn check_width(
        &self,
        width: &mut Option<usize>,
        n: usize,
        file: &str,
        lineno: usize,
    ) -> Result<()> {
        match *width {
            None => *width = Some(n),
            Some(w) if w != n => bail!(
                "{file}:{lineno}: {} fields where {} has {w}{}",
                n,
                if self.header {
                    "the header"
                } else {
                    "the first row"
                },
                if n > w {
                    " (a decimal comma, or a delimiter inside a value?)"
                } else {
                    ""
                }
            ),
            Some(_) => {}
        }
        Ok(())
    }

    /// Time [s] and the FRD gyro and accelerometer signals in SI of one row's column values `v`
    /// (data file `file`, line `lineno`), checked: time finite and after the previous `t_prev`
    /// [s], rates within what any IMU measures.
    fn signals(
        &self,
        v: &[f64; 7],
        t_prev: Option<f64>,
        file: &str,
        lineno: usize,
    ) -> Result<(f64, Vector3<f64>, Vector3<f64>)> {
        let t = v[0] * self.time_to_s;
        let g = self.axes * Vector3::new(v[1], v[2], v[3]) * self.gyro_to_si;
        let a = self.axes * Vector3::new(v[4], v[5], v[6]) * self.accel_to_si;
        if !t.is_finite() {
            bail!(
                "{file}:{lineno}: the time is not finite after [time] unit in {}",
                self.origin
            );
        }
        if let Some(tp) = t_prev {
            if t <= tp {
                bail!("{file}:{lineno}: time {t} s does not increase (previous {tp} s)");
            }
        }
        // what any IMU measures: the rate (or increment over the interval) in range
        let dt_here = t_prev.map(|tp| t - tp);
        let (w_rate, f_rate) = match (self.kind, dt_here) {
            (Kind::Rate, _) => (g.norm(), a.norm()),
            (Kind::Increment, Some(d)) => (g.norm() / d, a.norm() / d),
            (Kind::Increment, None) => (0.0, 0.0),
        };
        if w_rate.is_nan() || w_rate > MAX_RATE {
            bail!(
                "{file}:{lineno}: angular rate {w_rate:.3e} rad/s is beyond any IMU (<= {MAX_RATE} rad/s): check the value, gyro_unit and [time] unit in {}",
                self.origin
            );
        }
        if f_rate.is_nan() || f_rate > MAX_FORCE {
            bail!(
                "{file}:{lineno}: specific force {f_rate:.3e} m/s^2 is beyond any IMU (<= 2000 g): check the value, accel_unit and [time] unit in {}",
                self.origin
            );
        }
        Ok((t, g, a))
    }

    /// The sample a row at `t` [s] with signals `g`, `a` (SI) gives: the increments as read, or
    /// the rates integrated since the previous row `prev` (none for the first); `prev` moves on.
    fn sample(
        &self,
        prev: &mut Option<(f64, Vector3<f64>, Vector3<f64>)>,
        t: f64,
        g: Vector3<f64>,
        a: Vector3<f64>,
    ) -> Option<ImuSample> {
        let last = prev.replace((t, g, a));
        match self.kind {
            Kind::Increment => Some(ImuSample {
                t,
                dtheta: g,
                dv: a,
            }),
            Kind::Rate => last.map(|(tp, gp, ap)| {
                let dt = t - tp;
                let (dtheta, dv) = match self.integration {
                    Integration::Hold => (g * dt, a * dt),
                    Integration::Trapezoid => ((g + gp) * 0.5 * dt, (a + ap) * 0.5 * dt),
                };
                ImuSample { t, dtheta, dv }
            }),
        }
    }
}

/// The seven column values `c` of one row's `fields` (data file `file`, line `lineno`), each a
/// finite number.
fn row_values(fields: &[&str], c: &[usize; 7], file: &str, lineno: usize) -> Result<[f64; 7]> {
    let mut v = [0.0f64; 7];
    for k in 0..7 {
        let f = fields.get(c[k]).ok_or_else(|| {
            anyhow!(
                "{file}:{lineno}: has {} fields, column {} is needed",
                fields.len(),
                c[k] + 1
            )
        })?;
        let shown = || {
            f.chars()
                .take(40)
                .collect::<String>()
                .escape_debug()
                .to_string()
        };
        let x: f64 = f.parse().map_err(|_| {
            anyhow!(
                "{file}:{lineno}: column {}: `{}` is not a number",
                c[k] + 1,
                shown()
            )
        })?;
        if !x.is_finite() {
            bail!(
                "{file}:{lineno}: column {}: `{}` is not finite",
                c[k] + 1,
                shown()
            );
        }
        v[k] = x;
    }
    Ok(v)
}

/// A description's text and name, to point messages at its lines.
struct Desc<'a> {
    /// The description text.
    text: &'a str,
    /// Its name in messages.
    origin: &'a str,
}

impl Desc<'_> {
    /// The 1-based line of byte offset `start` in the text.
    fn line(&self, start: usize) -> usize {
        crate::io::lines::line_at(self.text, start)
    }

    /// The error `msg` at the line where `span` starts (`origin:line: msg`).
    fn at(&self, span: std::ops::Range<usize>, msg: String) -> anyhow::Error {
        anyhow!("{}:{}: {msg}", self.origin, self.line(span.start))
    }

    /// The field separator of `[file] delimiter` (whitespace by default).
    fn delimiter(&self, file: &RawFile) -> Result<Delimiter> {
        Ok(match &file.delimiter {
            None => Delimiter::Whitespace,
            Some(d) => match d.get_ref().as_str() {
                "whitespace" | " " => Delimiter::Whitespace,
                "tab" | "\t" => Delimiter::Char('\t'),
                s if s.chars().count() == 1 && !s.starts_with(|c: char| c.is_alphanumeric() || c == '.' || c == '-' || c == '+') => {
                    Delimiter::Char(s.chars().next().unwrap_or(','))
                }
                s => {
                    return Err(self.at(
                        d.span(),
                        format!("[file] delimiter `{s}`: use \"whitespace\", \"tab\" or one punctuation character such as \",\" or \";\""),
                    ))
                }
            },
        })
    }

    /// The comment prefix of `[file] comment` (`#` by default; empty: no comments). A prefix
    /// that can begin a number (a digit, sign or dot) is refused: it would drop data rows.
    fn comment(&self, file: &RawFile) -> Result<String> {
        let Some(c) = &file.comment else {
            return Ok("#".into());
        };
        let text = c.get_ref();
        if text.starts_with(|ch: char| ch.is_ascii_digit() || "+-.".contains(ch)) {
            return Err(self.at(
                c.span(),
                format!(
                    "[file] comment `{}`: a comment prefix that can begin a number (a digit, sign or dot) would drop every data row starting with it; use a character no number starts with, such as \"#\", \"%\" or \"//\"",
                    crate::io::lines::shown(text)
                ),
            ));
        }
        Ok(text.clone())
    }

    /// The lines `[file] skip_lines` skips (0 to 1000000, 0 by default).
    fn skip_lines(&self, file: &RawFile) -> Result<usize> {
        Ok(match &file.skip_lines {
            None => 0,
            Some(s) if (0..=1_000_000).contains(s.get_ref()) => *s.get_ref() as usize,
            Some(s) => {
                return Err(self.at(
                    s.span(),
                    format!(
                        "[file] skip_lines = {}: expected 0 ..= 1000000",
                        s.get_ref()
                    ),
                ))
            }
        })
    }

    /// A checked column reference: an index 1 to 10000, or a non-empty name when the file has a
    /// `header`.
    fn column(&self, c: &Spanned<ColumnRef>, header: bool) -> Result<ColumnRef> {
        match c.get_ref() {
            ColumnRef::Index(i) if *i < 1 || *i > 10_000 => Err(self.at(
                c.span(),
                format!("column index {i}: columns count from 1 (and up to 10000)"),
            )),
            ColumnRef::Name(_) if !header => Err(self.at(
                c.span(),
                "a column named by its header needs `header = true` in [file]; or give its 1-based index".into(),
            )),
            ColumnRef::Name(n) if n.trim().is_empty() => {
                Err(self.at(c.span(), "empty column name".into()))
            }
            r => Ok(r.clone()),
        }
    }

    /// The three checked columns (sensor x, y, z) of `[signals] what`.
    fn three(
        &self,
        v: &Spanned<Vec<ColumnRef>>,
        what: &str,
        header: bool,
    ) -> Result<[ColumnRef; 3]> {
        if v.get_ref().len() != 3 {
            return Err(self.at(
                v.span(),
                format!(
                    "[signals] {what}: expected three columns (sensor x, y, z), found {}",
                    v.get_ref().len()
                ),
            ));
        }
        let cols: Vec<ColumnRef> = v
            .get_ref()
            .iter()
            .map(|c| self.column(&Spanned::new(v.span(), c.clone()), header))
            .collect::<Result<_>>()?;
        Ok([cols[0].clone(), cols[1].clone(), cols[2].clone()])
    }

    /// `[signals] kind` and `integration` (trapezoid by default, for rates only).
    fn kind_and_integration(&self, signals: &RawSignals) -> Result<(Kind, Integration)> {
        let kind = match signals.kind.get_ref().as_str() {
            "rate" => Kind::Rate,
            "increment" => Kind::Increment,
            k => {
                return Err(self.at(
                    signals.kind.span(),
                    format!("[signals] kind `{k}`: expected \"rate\" or \"increment\""),
                ))
            }
        };
        let integration = match &signals.integration {
            None => Integration::Trapezoid,
            Some(i) => match i.get_ref().as_str() {
                "trapezoid" => Integration::Trapezoid,
                "hold" => Integration::Hold,
                s => {
                    return Err(self.at(
                        i.span(),
                        format!("[signals] integration `{s}`: expected \"trapezoid\" or \"hold\""),
                    ))
                }
            },
        };
        if kind == Kind::Increment {
            if let Some(i) = &signals.integration {
                return Err(self.at(
                    i.span(),
                    "[signals] integration applies to kind = \"rate\" only".into(),
                ));
            }
        }
        Ok((kind, integration))
    }

    /// SI per unit of the gyro and accelerometer columns (rad/s and m/s², or rad and m/s for
    /// increments).
    fn signal_scales(&self, signals: &RawSignals, kind: Kind) -> Result<(f64, f64)> {
        let (gsi, asi) = match kind {
            Kind::Rate => ("rad/s", "m/s^2"),
            Kind::Increment => ("rad", "m/s"),
        };
        let gyro_to_si = unit_scale(signals.gyro_unit.get_ref(), gsi).map_err(|e| {
            self.at(
                signals.gyro_unit.span(),
                format!("[signals] gyro_unit (kind {}): {e}", signals.kind.get_ref()),
            )
        })?;
        let accel_to_si = unit_scale(signals.accel_unit.get_ref(), asi).map_err(|e| {
            self.at(
                signals.accel_unit.span(),
                format!(
                    "[signals] accel_unit (kind {}): {e}",
                    signals.kind.get_ref()
                ),
            )
        })?;
        Ok((gyro_to_si, accel_to_si))
    }

    /// Sensor axes to FRD body from `[axes]`: the identity without it, a rotation matrix, or
    /// the body direction of each sensor axis.
    fn axes(&self, axes: Option<&RawAxes>) -> Result<Matrix3<f64>> {
        Ok(match axes {
            None => Matrix3::identity(),
            Some(RawAxes {
                x: None,
                y: None,
                z: None,
                rotation: Some(r),
            }) => self.rotation(r)?,
            Some(RawAxes {
                x: Some(xw),
                y: Some(yw),
                z: Some(zw),
                rotation: None,
            }) => self.directions(xw, yw, zw)?,
            Some(_) => {
                let l = self
                    .text
                    .lines()
                    .position(|l| l.trim() == "[axes]")
                    .map(|k| k + 1)
                    .unwrap_or(0);
                bail!("{}:{l}: [axes] takes either x, y and z (directions) or rotation (a 3×3 matrix), not a mix or a part", self.origin)
            }
        })
    }

    /// `[axes] rotation`: three rows of three numbers, orthonormal with determinant +1.
    fn rotation(&self, r: &Spanned<Vec<Vec<f64>>>) -> Result<Matrix3<f64>> {
        let rows = r.get_ref();
        if rows.len() != 3 || rows.iter().any(|row| row.len() != 3) {
            return Err(self.at(
                r.span(),
                "[axes] rotation: expected three rows of three numbers (sensor to body, FRD)"
                    .into(),
            ));
        }
        let m = Matrix3::from_fn(|i, j| rows[i][j]);
        let err = (m * m.transpose() - Matrix3::identity()).amax();
        if !m.iter().all(|v| v.is_finite()) || err > 1e-6 || m.determinant() < 0.0 {
            return Err(self.at(
                r.span(),
                format!("[axes] rotation is not a rotation matrix (|M Mᵀ − I| = {err:.1e}, det {:.3}): rows must be orthonormal with determinant +1", m.determinant()),
            ));
        }
        Ok(m)
    }

    /// `[axes] x, y, z`: the body direction of each sensor axis, a right-handed frame.
    fn directions(
        &self,
        xw: &Spanned<String>,
        yw: &Spanned<String>,
        zw: &Spanned<String>,
    ) -> Result<Matrix3<f64>> {
        let mut m = Matrix3::zeros();
        for (k, (name, w)) in [("x", xw), ("y", yw), ("z", zw)].iter().enumerate() {
            let d = direction(w.get_ref()).ok_or_else(|| {
                self.at(
                    w.span(),
                    format!(
                        "[axes] {name} = \"{}\": expected forward, back, right, left, down or up",
                        w.get_ref()
                    ),
                )
            })?;
            m.set_column(k, &d);
        }
        let det = m.determinant();
        if det.abs() < 0.5 {
            return Err(self.at(xw.span(), "[axes] two sensor axes point the same way (or opposite): each of x, y, z needs its own body axis".into()));
        }
        if det < 0.0 {
            return Err(self.at(xw.span(), format!(
                "[axes] x = {}, y = {}, z = {} is a left-handed frame: one axis is flipped (an IMU's axes are right-handed; e.g. forward, left, up or forward, right, down)",
                xw.get_ref(), yw.get_ref(), zw.get_ref()
            )));
        }
        Ok(m)
    }
}

/// The description beside a data file, `FILE.format.toml`, when there is one.
pub fn beside(data: &Path) -> Option<std::path::PathBuf> {
    let mut name = data.file_name()?.to_os_string();
    name.push(".format.toml");
    let p = data.with_file_name(name);
    // anything at that path counts: a directory or a dangling link is reported when loaded
    std::fs::symlink_metadata(&p).is_ok().then_some(p)
}
