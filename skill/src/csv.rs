//! Demonstration and trajectory CSV: a header `t,<name>,…` then one row per
//! sample, `t` in seconds and strictly increasing, one column per DoF.
//! Errors name the file, line and column.

use crate::Error;

/// A parsed demonstration.
#[derive(Debug, Clone, PartialEq)]
pub struct Demo {
    /// DoF names from the header (without `t`).
    pub names: Vec<String>,
    /// Sample times.
    pub times: Vec<f32>,
    /// Positions, row-major: `times.len() × names.len()`.
    pub positions: Vec<f32>,
}

/// The fewest data rows a demonstration may have (second differences need 3).
pub const MIN_ROWS: usize = 3;

/// Parses demonstration CSV text; `file` names it in error messages.
pub fn parse_demo(file: &str, text: &str) -> Result<Demo, Error> {
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
    let mut positions = Vec::new();
    for (line, row) in lines {
        if row.trim().is_empty() {
            continue;
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
            let v: f32 = cell
                .parse()
                .map_err(|_| err(line, Some(c + 1), format!("`{cell}` is not a number")))?;
            if !v.is_finite() {
                return Err(err(
                    line,
                    Some(c + 1),
                    format!("`{cell}` is not a finite number"),
                ));
            }
            if c == 0 {
                if let Some(&prev) = times.last()
                    && v <= prev
                {
                    return Err(err(
                        line,
                        Some(1),
                        format!("t = {v} does not increase (previous row t = {prev})"),
                    ));
                }
                times.push(v);
            } else {
                positions.push(v);
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

/// Refuses a recording whose rotation-vector columns (`<p>rx,<p>ry,<p>rz`,
/// adjacent) jump between two rows by more than the rotation between them
/// (by over 1 rad): a rotation vector wraps by 2π as the angle passes 180°,
/// and a DMP fitted across the jump would swing the long way round. The
/// message names the row and says to record a quaternion instead.
pub fn check_rotation_vectors(file: &str, demo: &Demo) -> Result<(), Error> {
    let width = demo.names.len();
    for c in 0..width.saturating_sub(2) {
        let Some(prefix) = demo.names[c].strip_suffix("rx") else {
            continue;
        };
        if demo.names[c + 1] != format!("{prefix}ry") || demo.names[c + 2] != format!("{prefix}rz")
        {
            continue;
        }
        let rotation =
            |row: &[f32]| primo_core::quaternion::Quaternion::exp([row[c], row[c + 1], row[c + 2]]);
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

/// A time in seconds to the microsecond, without trailing zeros: 9·0.1
/// prints as 0.9, not as f32's 0.90000004 or a sum of steps' 0.9000000000000001.
pub fn seconds(t: f64) -> String {
    let t = format!("{t:.6}");
    t.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// Writes a trajectory CSV: header `t,<names>` then one row per sample.
pub fn write_rows<V: IntoIterator<Item = f32>>(
    out: &mut impl std::io::Write,
    names: &[String],
    rows: impl Iterator<Item = (f32, V)>,
) -> std::io::Result<()> {
    writeln!(out, "t,{}", names.join(","))?;
    for (t, values) in rows {
        write!(out, "{}", seconds(f64::from(t)))?;
        for v in values {
            write!(out, ",{v}")?;
        }
        writeln!(out)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn msg(text: &str) -> String {
        parse_demo("d.csv", text).unwrap_err().to_string()
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
            "d.csv:4:1: t = 0.5 does not increase (previous row t = 0.5)"
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
