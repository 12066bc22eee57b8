//! IMU logs described, not converted by hand: a TOML description of a logger's file layout
//! (delimiter, header row, comment prefix), its time column and clock unit, the kind of signal
//! (rates or increments) with their units (the project's unit parser, raw counts as
//! `"0.1 arcsec"` per count), and where the sensor's axes point on the body. Read into the
//! project's FRD increments over each sample interval. Format: `docs/formats.md`.

use crate::io::imu::{ImuData, ImuSample};
use crate::io::imu_stream::{ImuStream, SampleSource, MAX_FORCE, MAX_RATE};
use crate::io::lines::{shown, Lines};
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
    comment: Option<String>,
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
        let line = |start: usize| crate::io::lines::line_at(text, start);
        let at = |span: std::ops::Range<usize>, msg: String| {
            anyhow!("{origin}:{}: {msg}", line(span.start))
        };
        let raw: RawFormat = toml::from_str(text).map_err(|e| {
            let l = e.span().map(|s| line(s.start)).unwrap_or(0);
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
        let delimiter = match &file.delimiter {
            None => Delimiter::Whitespace,
            Some(d) => match d.get_ref().as_str() {
                "whitespace" | " " => Delimiter::Whitespace,
                "tab" | "\t" => Delimiter::Char('\t'),
                s if s.chars().count() == 1 && !s.starts_with(|c: char| c.is_alphanumeric() || c == '.' || c == '-' || c == '+') => {
                    Delimiter::Char(s.chars().next().unwrap_or(','))
                }
                s => {
                    return Err(at(
                        d.span(),
                        format!("[file] delimiter `{s}`: use \"whitespace\", \"tab\" or one punctuation character such as \",\" or \";\""),
                    ))
                }
            },
        };
        let skip_lines = match &file.skip_lines {
            None => 0,
            Some(s) if (0..=1_000_000).contains(s.get_ref()) => *s.get_ref() as usize,
            Some(s) => {
                return Err(at(
                    s.span(),
                    format!(
                        "[file] skip_lines = {}: expected 0 ..= 1000000",
                        s.get_ref()
                    ),
                ))
            }
        };
        let header = file.header.unwrap_or(false);
        let comment = file.comment.unwrap_or_else(|| "#".into());

        let check_col = |c: &Spanned<ColumnRef>| -> Result<ColumnRef> {
            match c.get_ref() {
                ColumnRef::Index(i) if *i < 1 || *i > 10_000 => Err(at(
                    c.span(),
                    format!("column index {i}: columns count from 1 (and up to 10000)"),
                )),
                ColumnRef::Name(_) if !header => Err(at(
                    c.span(),
                    "a column named by its header needs `header = true` in [file]; or give its 1-based index".into(),
                )),
                ColumnRef::Name(n) if n.trim().is_empty() => {
                    Err(at(c.span(), "empty column name".into()))
                }
                r => Ok(r.clone()),
            }
        };
        let time = check_col(&raw.time.column)?;
        let time_to_s = match &raw.time.unit {
            None => 1.0,
            Some(u) => unit_scale(u.get_ref(), "s")
                .map_err(|e| at(u.span(), format!("[time] unit: {e}")))?,
        };
        let kind = match raw.signals.kind.get_ref().as_str() {
            "rate" => Kind::Rate,
            "increment" => Kind::Increment,
            k => {
                return Err(at(
                    raw.signals.kind.span(),
                    format!("[signals] kind `{k}`: expected \"rate\" or \"increment\""),
                ))
            }
        };
        let integration = match &raw.signals.integration {
            None => Integration::Trapezoid,
            Some(i) => match i.get_ref().as_str() {
                "trapezoid" => Integration::Trapezoid,
                "hold" => Integration::Hold,
                s => {
                    return Err(at(
                        i.span(),
                        format!("[signals] integration `{s}`: expected \"trapezoid\" or \"hold\""),
                    ))
                }
            },
        };
        if kind == Kind::Increment {
            if let Some(i) = &raw.signals.integration {
                return Err(at(
                    i.span(),
                    "[signals] integration applies to kind = \"rate\" only".into(),
                ));
            }
        }
        let three = |v: &Spanned<Vec<ColumnRef>>, what: &str| -> Result<[ColumnRef; 3]> {
            if v.get_ref().len() != 3 {
                return Err(at(
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
                .map(|c| check_col(&Spanned::new(v.span(), c.clone())))
                .collect::<Result<_>>()?;
            Ok([cols[0].clone(), cols[1].clone(), cols[2].clone()])
        };
        let gyro = three(&raw.signals.gyro, "gyro")?;
        let accel = three(&raw.signals.accel, "accel")?;
        let (gsi, asi) = match kind {
            Kind::Rate => ("rad/s", "m/s^2"),
            Kind::Increment => ("rad", "m/s"),
        };
        let gyro_to_si = unit_scale(raw.signals.gyro_unit.get_ref(), gsi).map_err(|e| {
            at(
                raw.signals.gyro_unit.span(),
                format!(
                    "[signals] gyro_unit (kind {}): {e}",
                    raw.signals.kind.get_ref()
                ),
            )
        })?;
        let accel_to_si = unit_scale(raw.signals.accel_unit.get_ref(), asi).map_err(|e| {
            at(
                raw.signals.accel_unit.span(),
                format!(
                    "[signals] accel_unit (kind {}): {e}",
                    raw.signals.kind.get_ref()
                ),
            )
        })?;
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
        let axes = match &raw.axes {
            None => Matrix3::identity(),
            Some(RawAxes {
                x: None,
                y: None,
                z: None,
                rotation: Some(r),
            }) => {
                let rows = r.get_ref();
                if rows.len() != 3 || rows.iter().any(|row| row.len() != 3) {
                    return Err(at(
                        r.span(),
                        "[axes] rotation: expected three rows of three numbers (sensor to body, FRD)".into(),
                    ));
                }
                let m = Matrix3::from_fn(|i, j| rows[i][j]);
                let err = (m * m.transpose() - Matrix3::identity()).amax();
                if !m.iter().all(|v| v.is_finite()) || err > 1e-6 || m.determinant() < 0.0 {
                    return Err(at(
                        r.span(),
                        format!("[axes] rotation is not a rotation matrix (|M Mᵀ − I| = {err:.1e}, det {:.3}): rows must be orthonormal with determinant +1", m.determinant()),
                    ));
                }
                m
            }
            Some(RawAxes {
                x: Some(xw),
                y: Some(yw),
                z: Some(zw),
                rotation: None,
            }) => {
                let mut m = Matrix3::zeros();
                for (k, (name, w)) in [("x", xw), ("y", yw), ("z", zw)].iter().enumerate() {
                    let d = direction(w.get_ref()).ok_or_else(|| {
                        at(w.span(), format!("[axes] {name} = \"{}\": expected forward, back, right, left, down or up", w.get_ref()))
                    })?;
                    m.set_column(k, &d);
                }
                let det = m.determinant();
                if det.abs() < 0.5 {
                    return Err(at(xw.span(), "[axes] two sensor axes point the same way (or opposite): each of x, y, z needs its own body axis".into()));
                }
                if det < 0.0 {
                    return Err(at(xw.span(), format!(
                        "[axes] x = {}, y = {}, z = {} is a left-handed frame: one axis is flipped (an IMU's axes are right-handed; e.g. forward, left, up or forward, right, down)",
                        xw.get_ref(), yw.get_ref(), zw.get_ref()
                    )));
                }
                m
            }
            Some(_) => {
                let l = text
                    .lines()
                    .position(|l| l.trim() == "[axes]")
                    .map(|k| k + 1)
                    .unwrap_or(0);
                bail!("{origin}:{l}: [axes] takes either x, y and z (directions) or rotation (a 3×3 matrix), not a mix or a part")
            }
        };
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
        let this = &self.fmt;
        let file = self.lines.name().to_string();
        let _ = &file;
        let resolve = |names: &[&str], c: &ColumnRef, lineno: usize| -> Result<usize> {
            match c {
                ColumnRef::Index(i) => Ok(*i as usize - 1),
                ColumnRef::Name(n) => names.iter().position(|h| h == n).ok_or_else(|| {
                    anyhow!(
                        "{}: column `{}` is not in the header of {file}:{lineno} (it has: {})",
                        this.origin,
                        shown(n),
                        shown(&names.join(", "))
                    )
                }),
            }
        };
        loop {
            let Some(raw_line) = self.lines.next_line()? else {
                return Ok(None);
            };
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
                let names: Vec<&str> = if this.header {
                    fields.clone()
                } else {
                    Vec::new()
                };
                if this.header {
                    if names.len() == 1 {
                        if let Some(d) = [',', ';', '\t', '|', ' ']
                            .iter()
                            .find(|d| names[0].contains(**d))
                        {
                            bail!(
                                "{file}:{lineno}: the header is one field with `{}` in it: is [file] delimiter right in {}? (it reads `{}`)",
                                d.escape_debug(),
                                this.origin,
                                match this.delimiter {
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
                                this.origin
                            );
                        }
                    }
                }
                let mut c = [0usize; 7];
                let all = [
                    &this.time,
                    &this.gyro[0],
                    &this.gyro[1],
                    &this.gyro[2],
                    &this.accel[0],
                    &this.accel[1],
                    &this.accel[2],
                ];
                for (k, r) in all.iter().enumerate() {
                    c[k] = resolve(&names, r, lineno)?;
                }
                for k in 0..7 {
                    if c[..k].contains(&c[k]) {
                        bail!(
                            "{}: column {} is used twice among time, gyro and accel (by name and by index)",
                            this.origin,
                            c[k] + 1
                        );
                    }
                }
                self.cols = Some(c);
                if this.header {
                    self.width = Some(fields.len());
                    continue;
                }
            }
            let c = self.cols.unwrap_or([0; 7]);
            match self.width {
                None => self.width = Some(fields.len()),
                Some(w) if w != fields.len() => bail!(
                    "{file}:{lineno}: {} fields where {} has {w}{}",
                    fields.len(),
                    if this.header {
                        "the header"
                    } else {
                        "the first row"
                    },
                    if fields.len() > w {
                        " (a decimal comma, or a delimiter inside a value?)"
                    } else {
                        ""
                    }
                ),
                Some(_) => {}
            }
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
            let t = v[0] * this.time_to_s;
            let g = this.axes * Vector3::new(v[1], v[2], v[3]) * this.gyro_to_si;
            let a = this.axes * Vector3::new(v[4], v[5], v[6]) * this.accel_to_si;
            if !t.is_finite() {
                bail!(
                    "{file}:{lineno}: the time is not finite after [time] unit in {}",
                    this.origin
                );
            }
            if let Some((tp, _, _)) = self.prev {
                if t <= tp {
                    bail!("{file}:{lineno}: time {t} s does not increase (previous {tp} s)");
                }
            }
            // what any IMU measures: the rate (or increment over the interval) in range
            let dt_here = self.prev.map(|p| t - p.0);
            let (w_rate, f_rate) = match (this.kind, dt_here) {
                (Kind::Rate, _) => (g.norm(), a.norm()),
                (Kind::Increment, Some(d)) => (g.norm() / d, a.norm() / d),
                (Kind::Increment, None) => (0.0, 0.0),
            };
            if w_rate.is_nan() || w_rate > MAX_RATE {
                bail!(
                    "{file}:{lineno}: angular rate {w_rate:.3e} rad/s is beyond any IMU (<= {MAX_RATE} rad/s): check the value, gyro_unit and [time] unit in {}",
                    this.origin
                );
            }
            if f_rate.is_nan() || f_rate > MAX_FORCE {
                bail!(
                    "{file}:{lineno}: specific force {f_rate:.3e} m/s^2 is beyond any IMU (<= 2000 g): check the value, accel_unit and [time] unit in {}",
                    this.origin
                );
            }
            match this.kind {
                Kind::Increment => {
                    self.prev = Some((t, g, a));
                    return Ok(Some((
                        ImuSample {
                            t,
                            dtheta: g,
                            dv: a,
                        },
                        lineno,
                    )));
                }
                Kind::Rate => {
                    if let Some((tp, gp, ap)) = self.prev {
                        let dt = t - tp;
                        let (dtheta, dv) = match this.integration {
                            Integration::Hold => (g * dt, a * dt),
                            Integration::Trapezoid => ((g + gp) * 0.5 * dt, (a + ap) * 0.5 * dt),
                        };
                        self.prev = Some((t, g, a));
                        return Ok(Some((ImuSample { t, dtheta, dv }, lineno)));
                    }
                }
            }
            self.prev = Some((t, g, a));
        }
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
