//! Demonstration and trajectory CSV: a header `t,<name>,…` then one row per
//! sample, `t` in seconds and strictly increasing (from any origin: Unix
//! time is fine), one column per DoF. Errors name the file, line and column.

use primo_core::quaternion::Quaternion;

use crate::Error;
use crate::seconds::push_seconds;
use crate::stamps::Stamps;

/// A parsed demonstration.
#[derive(Debug, Clone, PartialEq)]
pub struct Demo {
    /// DoF names from the header (without `t`).
    pub names: Vec<String>,
    /// Sample times, s since the first sample ([`crate::stamps`]).
    pub times: Vec<f32>,
    /// Positions, row-major: `times.len() × names.len()`.
    pub positions: Vec<f32>,
}

/// The fewest data rows a demonstration may have (second differences need 3).
pub const MIN_ROWS: usize = 3;

/// The most data rows a demonstration may have (1000 s recorded at
/// 1 kHz): more are refused before they are stored.
pub const MAX_DEMO_ROWS: usize = 1_000_000;

/// Parses demonstration CSV text; `file` names it in error messages. A
/// leading byte-order mark (a spreadsheet's "CSV UTF-8") is skipped.
pub fn parse_demo(file: &str, text: &str) -> Result<Demo, Error> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let err = |line: usize, col: Option<usize>, msg: String| {
        Error::File(match col {
            Some(c) => format!("{file}:{line}:{c}: {msg}"),
            None => format!("{file}:{line}: {msg}"),
        })
    };
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim_end_matches('\r')));
    let Some((_, header)) = lines.by_ref().find(|(_, l)| !l.trim().is_empty()) else {
        return Err(Error::File(format!(
            "{file}:1: empty file: expected a header row `t,<name>,...`"
        )));
    };
    let header_line = text.lines().position(|l| !l.trim().is_empty()).unwrap_or(0) + 1;
    let cells: Vec<&str> = header.split(',').map(str::trim).collect();
    if cells.first() != Some(&"t") {
        let first = cells.first().copied().unwrap_or("");
        let why = if first.parse::<f64>().is_ok() {
            " (the header row is missing)"
        } else {
            ""
        };
        return Err(err(
            header_line,
            Some(1),
            format!("first header column must be `t`, found `{first}`{why}"),
        ));
    }
    if cells.len() < 2 {
        return Err(err(
            header_line,
            None,
            "header names no DoF column after `t`".into(),
        ));
    }
    let names: Vec<String> = cells[1..].iter().map(|s| s.to_string()).collect();
    for (i, n) in names.iter().enumerate() {
        if n.is_empty() {
            return Err(err(header_line, Some(i + 2), "empty column name".into()));
        }
        if names[..i].contains(n) {
            return Err(err(
                header_line,
                Some(i + 2),
                format!("duplicate column name `{n}`"),
            ));
        }
    }
    let width = cells.len();
    let mut times = Vec::new();
    let mut stamps = Stamps::new();
    let mut positions = Vec::new();
    for (line, row) in lines {
        if row.trim().is_empty() {
            continue;
        }
        if times.len() == MAX_DEMO_ROWS {
            return Err(err(
                line,
                None,
                format!("a demonstration has at most {MAX_DEMO_ROWS} data rows"),
            ));
        }
        let cells: Vec<&str> = row.split(',').map(str::trim).collect();
        if cells.len() != width {
            return Err(err(
                line,
                None,
                format!(
                    "expected {width} columns like the header, found {}",
                    cells.len()
                ),
            ));
        }
        for (c, cell) in cells.iter().enumerate() {
            // Times in f64: a stamp in Unix time is relative only then.
            let v: f64 = cell
                .parse()
                .map_err(|_| err(line, Some(c + 1), format!("`{cell}` is not a number")))?;
            let single = v as f32;
            if !v.is_finite() || (c > 0 && !single.is_finite()) {
                return Err(err(
                    line,
                    Some(c + 1),
                    format!("`{cell}` is not a finite number"),
                ));
            }
            if c == 0 {
                let t = stamps.push(v).map_err(|why| {
                    err(
                        line,
                        Some(1),
                        format!("t = {cell} {}", why.why("the previous row")),
                    )
                })?;
                times.push(t);
            } else {
                positions.push(single);
            }
        }
    }
    if times.len() < MIN_ROWS {
        return Err(Error::File(format!(
            "{file}: too few rows: a demonstration needs at least {MIN_ROWS} data rows, found {}",
            times.len()
        )));
    }
    Ok(Demo {
        names,
        times,
        positions,
    })
}

/// The adjacent rotation-vector column groups `<p>rx,<p>ry,<p>rz`: each
/// group's first column and its prefix.
fn rotation_vector_groups(names: &[String]) -> Vec<(usize, &str)> {
    (0..names.len().saturating_sub(2))
        .filter_map(|c| {
            let prefix = names[c].strip_suffix("rx")?;
            (names[c + 1] == format!("{prefix}ry") && names[c + 2] == format!("{prefix}rz"))
                .then_some((c, prefix))
        })
        .collect()
}

/// Refuses a recording whose rotation-vector columns (`<p>rx,<p>ry,<p>rz`,
/// adjacent) jump between two rows by more than the rotation between them
/// (by over 1 rad): a rotation vector wraps by 2π as the angle passes 180°,
/// and a DMP fitted across the jump would swing the long way round. The
/// message names the row and says to record a quaternion instead.
pub fn check_rotation_vectors(file: &str, demo: &Demo) -> Result<(), Error> {
    let width = demo.names.len();
    for (c, prefix) in rotation_vector_groups(&demo.names) {
        let rotation = |row: &[f32]| Quaternion::exp([row[c], row[c + 1], row[c + 2]]);
        for (i, pair) in demo
            .positions
            .chunks_exact(width)
            .collect::<Vec<_>>()
            .windows(2)
            .enumerate()
        {
            let (a, b) = (pair[0], pair[1]);
            let step = ((b[c] - a[c]).powi(2)
                + (b[c + 1] - a[c + 1]).powi(2)
                + (b[c + 2] - a[c + 2]).powi(2))
            .sqrt();
            let relative = rotation(b).mul(&rotation(a).conj());
            let v = (relative.x.powi(2) + relative.y.powi(2) + relative.z.powi(2)).sqrt();
            let turn = 2.0 * v.atan2(relative.w.abs());
            if step > turn + 1.0 {
                return Err(Error::File(format!(
                    "{file}: rows {} and {}: the rotation vector {}…{} jumps by {step:.2} rad \
                     for a turn of {turn:.3} rad (it wraps by 2π where the angle passes 180°); \
                     record the orientation as {prefix}qw,{prefix}qx,{prefix}qy,{prefix}qz \
                     (a quaternion) instead",
                    i + 1,
                    i + 2,
                    demo.names[c],
                    demo.names[c + 2]
                )));
            }
        }
    }
    Ok(())
}

/// The recording with its rotation-vector columns (`<p>rx,<p>ry,<p>rz`,
/// adjacent) as quaternion columns `<p>qw,<p>qx,<p>qy,<p>qz`: every row's
/// rotation exactly, its sign the one nearer the previous row's. Where a
/// rotation vector wraps by 2π (its angle passing 180°) its quaternion
/// flips sign; keeping the sign continuous undoes the wrap. `None` without
/// such columns; else the recording and the data rows (from 1) where a
/// vector wrapped, each the later row of its pair.
pub fn rotation_vectors_as_quaternions(demo: &Demo) -> Option<(Demo, Vec<usize>)> {
    let groups = rotation_vector_groups(&demo.names);
    if groups.is_empty() {
        return None;
    }
    // Copies the columns between the groups, and each group's quaternion.
    fn convert<T: Clone>(
        from: &[T],
        groups: &[(usize, &str)],
        mut group: impl FnMut(usize, &[T]) -> [T; 4],
        out: &mut Vec<T>,
    ) {
        let mut c = 0;
        for (j, (start, _)) in groups.iter().enumerate() {
            out.extend_from_slice(&from[c..*start]);
            out.extend(group(j, &from[*start..start + 3]));
            c = start + 3;
        }
        out.extend_from_slice(&from[c..]);
    }
    let mut names = Vec::new();
    convert(
        &demo.names,
        &groups,
        |j, _| ["qw", "qx", "qy", "qz"].map(|n| format!("{}{n}", groups[j].1)),
        &mut names,
    );
    let mut last: Vec<Option<Quaternion>> = vec![None; groups.len()];
    let mut sign = vec![1.0f32; groups.len()];
    let mut wraps = Vec::new();
    let mut positions = Vec::new();
    for (row, values) in demo.positions.chunks_exact(demo.names.len()).enumerate() {
        convert(
            values,
            &groups,
            |j, r| {
                let q = Quaternion::exp([r[0], r[1], r[2]]);
                if last[j].is_some_and(|p| p.dot(&q) < 0.0) {
                    sign[j] = -sign[j];
                    wraps.push(row + 1);
                }
                last[j] = Some(q);
                q.to_array().map(|v| sign[j] * v)
            },
            &mut positions,
        );
    }
    wraps.dedup();
    Some((
        Demo {
            names,
            times: demo.times.clone(),
            positions,
        },
        wraps,
    ))
}

/// Appends `v` as `Display` prints it (the shortest digits that read back
/// as the same `f32`, laid out without an exponent), several times faster:
/// the digits come from Żmij, the layout is `Display`'s. Where two
/// shortest candidates are equally near (0.2 % of values), Żmij may pick
/// the other: the same length, the same number read back. Trajectory files
/// are mostly these numbers.
pub fn push_f32(out: &mut Vec<u8>, v: f32) {
    if !v.is_finite() {
        out.extend_from_slice(v.to_string().as_bytes());
        return;
    }
    let mut buffer = zmij::Buffer::new();
    let text = buffer.format_finite(v).as_bytes();
    let (negative, text) = match text.split_first() {
        Some((b'-', rest)) => (true, rest),
        _ => (false, text),
    };
    let (mantissa, exponent) = match text.iter().position(|c| *c == b'e') {
        // Plain already (most numbers): `Display` has no `.0` on integers.
        None => {
            if negative {
                out.push(b'-');
            }
            out.extend_from_slice(text.strip_suffix(b".0").unwrap_or(text));
            return;
        }
        Some(e) => (
            &text[..e],
            std::str::from_utf8(&text[e + 1..])
                .ok()
                .and_then(|x| x.parse::<i32>().ok())
                .unwrap_or(0),
        ),
    };
    // The digits (at most 9 for an f32), and where the decimal point goes
    // among them.
    let point = mantissa
        .iter()
        .position(|c| *c == b'.')
        .unwrap_or(mantissa.len());
    let mut digits = [0u8; 16];
    let mut len = 0;
    for c in mantissa.iter().filter(|c| **c != b'.') {
        if let Some(d) = digits.get_mut(len) {
            *d = *c;
            len += 1;
        }
    }
    let leading = digits[..len].iter().take_while(|c| **c == b'0').count();
    let mut point = point as i32 + exponent - leading as i32;
    let mut digits = &digits[leading..len];
    while let Some((b'0', rest)) = digits.split_last() {
        digits = rest;
    }
    if negative {
        out.push(b'-');
    }
    if digits.is_empty() {
        out.push(b'0');
    } else if point <= 0 {
        out.extend_from_slice(b"0.");
        out.extend(std::iter::repeat_n(b'0', point.unsigned_abs() as usize));
        out.extend_from_slice(digits);
    } else if point as usize >= digits.len() {
        out.extend_from_slice(digits);
        point -= digits.len() as i32;
        out.extend(std::iter::repeat_n(b'0', point as usize));
    } else {
        let (int, frac) = digits.split_at(point as usize);
        out.extend_from_slice(int);
        out.push(b'.');
        out.extend_from_slice(frac);
    }
}

/// CSV text as every file primo writes has it: fields separated by
/// commas, rows ended by `\n`, a field holding a comma, a quote or a line
/// break enclosed in quotes with its quotes doubled (RFC 4180).
///
/// ```
/// use primo_skill::csv::Csv;
/// let mut csv = Csv::new();
/// csv.text("t").text("why");
/// csv.end_row();
/// csv.seconds(0.5).text("a \"limit\", exceeded");
/// csv.end_row();
/// assert_eq!(csv.as_bytes(), b"t,why\n0.5,\"a \"\"limit\"\", exceeded\"\n");
/// ```
#[derive(Debug, Clone, Default)]
pub struct Csv {
    out: Vec<u8>,
    /// A field was written on the current row.
    open: bool,
}

impl Csv {
    /// Empty.
    pub fn new() -> Csv {
        Csv::default()
    }

    fn separate(&mut self) {
        if self.open {
            self.out.push(b',');
        }
        self.open = true;
    }

    /// A field of text, quoted where it must be.
    pub fn text(&mut self, text: &str) -> &mut Csv {
        self.separate();
        if text.contains([',', '"', '\n', '\r']) {
            self.out.push(b'"');
            self.out
                .extend_from_slice(text.replace('"', "\"\"").as_bytes());
            self.out.push(b'"');
        } else {
            self.out.extend_from_slice(text.as_bytes());
        }
        self
    }

    /// A field as `value` displays (a number, a name), quoted where it
    /// must be.
    pub fn display(&mut self, value: impl std::fmt::Display) -> &mut Csv {
        self.text(&value.to_string())
    }

    /// An `f32` with the shortest digits that read back as it
    /// ([`push_f32`]).
    pub fn f32(&mut self, v: f32) -> &mut Csv {
        self.separate();
        push_f32(&mut self.out, v);
        self
    }

    /// A time in seconds, to the microsecond without trailing zeros.
    pub fn seconds(&mut self, t: f64) -> &mut Csv {
        self.separate();
        push_seconds(&mut self.out, t);
        self
    }

    /// Ends the row.
    pub fn end_row(&mut self) {
        self.out.push(b'\n');
        self.open = false;
    }

    /// The text so far.
    pub fn as_bytes(&self) -> &[u8] {
        &self.out
    }

    /// Empties it, for the next rows.
    pub fn clear(&mut self) {
        self.out.clear();
        self.open = false;
    }

    /// The text.
    pub fn into_bytes(self) -> Vec<u8> {
        self.out
    }
}

/// Writes a trajectory CSV: header `t,<names>` then one row per sample.
pub fn write_rows<V: IntoIterator<Item = f32>>(
    out: &mut impl std::io::Write,
    names: &[String],
    rows: impl Iterator<Item = (f32, V)>,
) -> std::io::Result<()> {
    let mut csv = Csv::new();
    csv.text("t");
    for name in names {
        csv.text(name);
    }
    csv.end_row();
    for (t, values) in rows {
        csv.seconds(f64::from(t));
        for v in values {
            csv.f32(v);
        }
        csv.end_row();
        out.write_all(csv.as_bytes())?;
        csv.clear();
    }
    out.write_all(csv.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn msg(text: &str) -> String {
        parse_demo("d.csv", text).unwrap_err().to_string()
    }

    /// `Display`'s digits, but for exact ties between two shortest
    /// candidates (2015.65625 → Żmij 2015.6562, `Display` 2015.6563): the
    /// same length, the same number read back.
    #[test]
    fn push_f32_prints_as_display_does() {
        let mut differ = 0;
        let mut check = |v: f32| {
            let mut out = Vec::new();
            push_f32(&mut out, v);
            let (fast, display) = (String::from_utf8(out).unwrap(), v.to_string());
            if fast != display {
                differ += 1;
                assert_eq!(fast.len(), display.len());
                assert_eq!(fast.parse::<f32>().unwrap().to_bits(), v.to_bits());
            }
        };
        for v in [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            1e-7,
            1.5e-45,
            f32::MIN_POSITIVE,
            f32::MAX,
            f32::MIN,
            1e20,
            123456.79,
            0.099999905,
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ] {
            check(v);
        }
        // Every 65,521st bit pattern: all exponents, signs and digit counts.
        for bits in (0..=u32::MAX).step_by(65_521) {
            check(f32::from_bits(bits));
        }
        // Measured: 128 of 65,553.
        assert!(differ < 200, "{differ}");
    }

    #[test]
    fn a_wrapped_rotation_vector_is_refused_with_its_row() {
        // Yaw 179° then −179° (2° of turn, a 358° jump of the vector).
        let (a, b) = (179f32.to_radians(), -179f32.to_radians());
        let text = format!("t,x,rx,ry,rz\n0,0,0,0,{a}\n0.1,0,0,0,{a}\n0.2,0,0,0,{b}\n");
        let demo = parse_demo("d.csv", &text).unwrap();
        let e = check_rotation_vectors("d.csv", &demo)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("d.csv: rows 2 and 3: the rotation vector rx…rz jumps"),
            "{e}"
        );
        assert!(e.contains("qw,qx,qy,qz"), "{e}");
        // A fast but genuine turn is fine.
        let text = format!("t,rx,ry,rz\n0,0,0,0\n0.1,0,0,1.5\n0.2,0,0,{a}\n");
        let demo = parse_demo("d.csv", &text).unwrap();
        assert!(check_rotation_vectors("d.csv", &demo).is_ok());
    }

    #[test]
    fn rotation_vectors_become_sign_continuous_quaternions() {
        // Yaw 178°, 179°, then −180° and −179° (the vector wrapped).
        let yaws = [178f32, 179.0, -180.0, -179.0].map(f32::to_radians);
        let rows: String = (yaws.iter().enumerate())
            .map(|(i, yaw)| format!("0.{i},1,0,0,{yaw},2\n"))
            .collect();
        let demo = parse_demo("d.csv", &format!("t,x,rx,ry,rz,y\n{rows}")).unwrap();
        assert!(check_rotation_vectors("d.csv", &demo).is_err());
        let (q, wraps) = rotation_vectors_as_quaternions(&demo).unwrap();
        assert_eq!(q.names, ["x", "qw", "qx", "qy", "qz", "y"]);
        assert_eq!(wraps, [3]);
        let rows: Vec<&[f32]> = q.positions.chunks_exact(6).collect();
        for (row, yaw) in rows.iter().zip([178f32, 179.0, 180.0, 181.0]) {
            let half = yaw.to_radians() / 2.0;
            let expect = [1.0, half.cos(), 0.0, 0.0, half.sin(), 2.0];
            for (a, b) in row.iter().zip(expect) {
                assert!((a - b).abs() < 1e-6, "{yaw}: {row:?}");
            }
        }
        let plain = parse_demo("d.csv", "t,x\n0,1\n1,2\n2,3\n").unwrap();
        assert!(rotation_vectors_as_quaternions(&plain).is_none());
    }

    #[test]
    fn a_demo_of_too_many_rows_is_refused() {
        let mut text = String::from("t,x\n");
        for i in 0..=MAX_DEMO_ROWS {
            text.push_str(&format!("{i},0\n"));
        }
        let e = parse_demo("d.csv", &text).unwrap_err().to_string();
        assert_eq!(
            e,
            format!(
                "d.csv:{}: a demonstration has at most 1000000 data rows",
                MAX_DEMO_ROWS + 2
            )
        );
    }

    #[test]
    fn skips_a_byte_order_mark() {
        let demo = parse_demo("d.csv", "\u{feff}t,x\n0,1\n1,2\n2,3\n").unwrap();
        assert_eq!(demo.names, ["x"]);
    }

    #[test]
    fn parses_a_demo() {
        let d = parse_demo("d.csv", "t, x ,y\r\n0,1,2\n0.5,3,4\n\n1,5,6\n").unwrap();
        assert_eq!(d.names, ["x", "y"]);
        assert_eq!(d.times, [0.0, 0.5, 1.0]);
        assert_eq!(d.positions, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
    }

    #[test]
    fn errors_name_file_line_and_column() {
        assert_eq!(
            msg(""),
            "d.csv:1: empty file: expected a header row `t,<name>,...`"
        );
        assert_eq!(
            msg("0,1\n1,2\n2,3\n"),
            "d.csv:1:1: first header column must be `t`, found `0` (the header row is missing)"
        );
        assert_eq!(
            msg("t,x\n0,1\n0.5,abc\n1,2\n"),
            "d.csv:3:2: `abc` is not a number"
        );
        assert_eq!(
            msg("t,x\n0,1\n0.5,2\n0.5,3\n"),
            "d.csv:4:1: t = 0.5 does not increase: the previous row is at t = 0.5"
        );
        assert_eq!(
            msg("t,x\n0,1\n1,2\n"),
            "d.csv: too few rows: a demonstration needs at least 3 data rows, found 2"
        );
        assert_eq!(
            msg("t,x\n0,1\n1,2,3\n"),
            "d.csv:3: expected 2 columns like the header, found 3"
        );
        assert_eq!(msg("t,x,x\n"), "d.csv:1:3: duplicate column name `x`");
        assert_eq!(
            msg("t,x\n0,NaN\n"),
            "d.csv:2:2: `NaN` is not a finite number"
        );
        assert_eq!(
            msg("t\n0\n"),
            "d.csv:1: header names no DoF column after `t`"
        );
    }
}
