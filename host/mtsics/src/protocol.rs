//! MT-SICS on the wire: responses, weights and line framing, shared by the
//! client and the simulated scale so both speak exactly the same bytes.

use std::fmt;

use crate::Fixed;

/// The longest line (without CR LF) either side accepts, bytes. MT-SICS
/// lines are short; anything longer is a broken line, not a response.
pub const MAX_LINE: usize = 128;

/// A mass unit the scale may answer in: the one primo's scale answers in
/// too (MT-SICS writes [`Unit::symbol`]).
pub use primo_protocol::scale::Unit;

/// A weight as the scale shows it: a value in a unit, with as many
/// decimals as the scale sent (its resolution).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Weight {
    /// The value in `unit`.
    pub value: f64,
    /// The unit.
    pub unit: Unit,
    /// Digits after the decimal point (0 to 9).
    pub decimals: u8,
}

impl Weight {
    /// The weight in grams.
    pub fn grams(&self) -> f64 {
        self.value * 10f64.powi(self.unit.exponent().into())
    }

    /// The same weight in `unit`, its decimals shifted so the resolution is
    /// kept (0.01 g is 10 mg, or 0.00001 kg).
    pub fn to(&self, unit: Unit) -> Weight {
        let shift = i32::from(unit.exponent()) - i32::from(self.unit.exponent());
        Weight {
            value: self.value * 10f64.powi(-shift),
            unit,
            decimals: (i32::from(self.decimals) + shift).clamp(0, 9) as u8,
        }
    }
}

impl fmt::Display for Weight {
    /// `123.45 g`: the value with its decimals, never `-0.00`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {}", self.value_text(), self.unit.symbol())
    }
}

impl Weight {
    fn value_text(&self) -> String {
        Fixed(self.value, usize::from(self.decimals.min(9))).to_string()
    }
}

/// Whether the scale considered a weight stable when it sent it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stability {
    /// `S`: the display had settled.
    Stable,
    /// `D`: dynamic, the display was still moving (only `SI` sends this).
    Dynamic,
}

/// The command a response answers, as the response's first field names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reply {
    /// `S`: answers `S` and `SI`.
    Weight,
    /// `Z`: zero on a stable reading.
    Zero,
    /// `ZI`: zero immediately.
    ZeroImmediately,
    /// `T`: tare on a stable reading.
    Tare,
    /// `TA`: the tare value (query or preset).
    TareValue,
    /// `TAC`: clear the tare.
    ClearTare,
    /// `I2`: balance data.
    BalanceData,
    /// `I4`: serial number; also the answer to `@` and the power-on line.
    Serial,
}

impl Reply {
    const ALL: [Reply; 8] = [
        Reply::Weight,
        Reply::Zero,
        Reply::ZeroImmediately,
        Reply::Tare,
        Reply::TareValue,
        Reply::ClearTare,
        Reply::BalanceData,
        Reply::Serial,
    ];

    /// The response's first field (`S`, `Z`, `ZI`, `T`, `TA`, `TAC`, `I2`, `I4`).
    pub fn id(self) -> &'static str {
        match self {
            Reply::Weight => "S",
            Reply::Zero => "Z",
            Reply::ZeroImmediately => "ZI",
            Reply::Tare => "T",
            Reply::TareValue => "TA",
            Reply::ClearTare => "TAC",
            Reply::BalanceData => "I2",
            Reply::Serial => "I4",
        }
    }

    /// Whether `+`/`-` (overload/underload) can answer this command.
    fn has_range(self) -> bool {
        matches!(
            self,
            Reply::Weight | Reply::Zero | Reply::ZeroImmediately | Reply::Tare
        )
    }
}

/// One MT-SICS response line, typed.
#[derive(Debug, Clone, PartialEq)]
pub enum Response {
    /// `S S <value> <unit>` or `S D <value> <unit>`: a weight.
    Weight(Weight, Stability),
    /// `Z A`: zero set.
    Zeroed,
    /// `ZI S` / `ZI D`: zero set immediately, on a stable or a moving reading.
    ZeroedImmediately(Stability),
    /// `T S <value> <unit>`: tared; the tare weight.
    Tared(Weight),
    /// `TA A <value> <unit>`: the current (or just preset) tare weight.
    TareValue(Weight),
    /// `TAC A`: tare cleared.
    TareCleared,
    /// `I2 A "<text>" ...`: balance type and capacity.
    BalanceData(Vec<String>),
    /// `I4 A "<serial>"`: the serial number, the answer to `@`, and the
    /// line a scale sends unprompted at power-on.
    Serial(String),
    /// `<id> I`: cannot execute now (busy, or no stable reading within the
    /// scale's own timeout); `S I` is "busy".
    NotExecutable(Reply),
    /// `<id> +`: overload (or above the zero/tare range).
    Overload(Reply),
    /// `<id> -`: underload (or below the zero/tare range).
    Underload(Reply),
    /// `<id> L`: a parameter was wrong (`TA <value> <unit>`).
    InvalidParameter(Reply),
    /// `ES`: syntax error, the scale did not recognize the command.
    SyntaxError,
    /// `ET`: transmission error, the scale received a garbled command.
    TransmissionError,
    /// `EL`: logic error, the command cannot be executed.
    LogicError,
}

impl fmt::Display for Response {
    /// The response line as the scale sends it, without CR LF: weights
    /// right-aligned in 10 characters (`S S     100.00 g`).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let weight = |f: &mut fmt::Formatter<'_>, head: &str, w: &Weight| {
            write!(f, "{head} {:>10} {}", w.value_text(), w.unit.symbol())
        };
        let texts = |f: &mut fmt::Formatter<'_>, head: &str, texts: &[String]| {
            f.write_str(head)?;
            texts.iter().try_for_each(|t| write!(f, " \"{t}\""))
        };
        let status = |s: Stability| match s {
            Stability::Stable => "S",
            Stability::Dynamic => "D",
        };
        match self {
            Response::Weight(w, s) => weight(f, &format!("S {}", status(*s)), w),
            Response::Zeroed => f.write_str("Z A"),
            Response::ZeroedImmediately(s) => write!(f, "ZI {}", status(*s)),
            Response::Tared(w) => weight(f, "T S", w),
            Response::TareValue(w) => weight(f, "TA A", w),
            Response::TareCleared => f.write_str("TAC A"),
            Response::BalanceData(t) => texts(f, "I2 A", t),
            Response::Serial(s) => texts(f, "I4 A", std::slice::from_ref(s)),
            Response::NotExecutable(r) => write!(f, "{} I", r.id()),
            Response::Overload(r) => write!(f, "{} +", r.id()),
            Response::Underload(r) => write!(f, "{} -", r.id()),
            Response::InvalidParameter(r) => write!(f, "{} L", r.id()),
            Response::SyntaxError => f.write_str("ES"),
            Response::TransmissionError => f.write_str("ET"),
            Response::LogicError => f.write_str("EL"),
        }
    }
}

/// A line that is not an MT-SICS response: the line (quoted, escaped) and
/// why it is wrong.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ResponseError {
    /// The line as received, non-printable bytes escaped (`\xff`, `\r`),
    /// cut after [`MAX_LINE`] bytes.
    pub line: String,
    /// What is wrong with it, and where.
    pub reason: String,
}

impl fmt::Display for ResponseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "`{}`: {}", self.line, self.reason)
    }
}

impl std::error::Error for ResponseError {}

/// `bytes` printable: printable ASCII kept, every other byte escaped
/// (`\r`, `\xff`, and `\\` for a backslash), cut after [`MAX_LINE`] bytes
/// with the full length noted.
pub fn quote(bytes: &[u8]) -> String {
    let head = bytes.get(..MAX_LINE).unwrap_or(bytes);
    let mut text = String::with_capacity(head.len());
    for &b in head {
        if (b' '..=b'~').contains(&b) && b != b'\\' {
            text.push(char::from(b));
        } else {
            text.extend(b.escape_ascii().map(char::from));
        }
    }
    if bytes.len() > MAX_LINE {
        text.push_str(&format!("... ({} bytes)", bytes.len()));
    }
    text
}

/// Parses one response line (a trailing CR LF is allowed and ignored).
/// Any bytes at all give a typed response or an error naming the field and
/// the reason; it never panics.
///
/// ```
/// use primo_mtsics::{parse_response, Response, Stability, Unit};
/// let Ok(Response::Weight(w, Stability::Stable)) = parse_response(b"S S     100.00 g\r\n") else {
///     panic!("a stable weight");
/// };
/// assert_eq!((w.value, w.unit, w.decimals), (100.0, Unit::G, 2));
/// let e = parse_response(b"S S 12,5 g").unwrap_err();
/// assert_eq!(e.to_string(), "`S S 12,5 g`: field 3 `12,5` is not a decimal number");
/// ```
pub fn parse_response(line: &[u8]) -> Result<Response, ResponseError> {
    let line = strip_terminator(line);
    let fail = |reason: String| ResponseError {
        line: quote(line),
        reason,
    };
    if line.len() > MAX_LINE {
        return Err(fail(format!(
            "{} bytes, longer than any MT-SICS line ({MAX_LINE})",
            line.len()
        )));
    }
    let text = std::str::from_utf8(line).map_err(|e| {
        fail(format!(
            "byte {} is not text (not UTF-8)",
            e.valid_up_to() + 1
        ))
    })?;
    if let Some((i, c)) = text.char_indices().find(|(_, c)| c.is_control()) {
        return Err(fail(format!("control character {:?} at byte {}", c, i + 1)));
    }
    let fields = split_fields(text).map_err(&fail)?;
    let mut iter = fields.iter();
    let Some(id) = iter.next() else {
        return Err(fail("empty line".into()));
    };
    let rest: Vec<&Field> = iter.collect();
    if let Some(e) = [
        ("ES", Response::SyntaxError),
        ("ET", Response::TransmissionError),
        ("EL", Response::LogicError),
    ]
    .into_iter()
    .find(|(s, _)| *s == id.text)
    {
        return match rest.len() {
            0 => Ok(e.1),
            n => Err(fail(format!(
                "`{}` stands alone, found {n} more field(s)",
                e.0
            ))),
        };
    }
    let Some(reply) = Reply::ALL.into_iter().find(|r| r.id() == id.text) else {
        return Err(fail(format!(
            "field 1 `{}` is not an MT-SICS response (S, Z, ZI, T, TA, TAC, I2, I4, ES, ET, EL)",
            id.text
        )));
    };
    let Some((status, args)) = rest.split_first() else {
        return Err(fail(format!("`{}` without a status field", reply.id())));
    };
    let head = format!("`{} {}`", reply.id(), status.text);
    let none = |r: Response| {
        if args.is_empty() {
            Ok(r)
        } else {
            Err(fail(format!(
                "{head} takes no more fields, found {}",
                args.len()
            )))
        }
    };
    match (reply, status.text) {
        (r, "I") => none(Response::NotExecutable(r)),
        (r, "+") if r.has_range() => none(Response::Overload(r)),
        (r, "-") if r.has_range() => none(Response::Underload(r)),
        (Reply::TareValue, "L") => none(Response::InvalidParameter(Reply::TareValue)),
        (Reply::Weight, "S") => Ok(Response::Weight(
            weight(&head, args).map_err(fail)?,
            Stability::Stable,
        )),
        (Reply::Weight, "D") => Ok(Response::Weight(
            weight(&head, args).map_err(fail)?,
            Stability::Dynamic,
        )),
        (Reply::Zero, "A") => none(Response::Zeroed),
        (Reply::ZeroImmediately, "S") => none(Response::ZeroedImmediately(Stability::Stable)),
        (Reply::ZeroImmediately, "D") => none(Response::ZeroedImmediately(Stability::Dynamic)),
        (Reply::Tare, "S") => Ok(Response::Tared(weight(&head, args).map_err(fail)?)),
        (Reply::TareValue, "A") => Ok(Response::TareValue(weight(&head, args).map_err(fail)?)),
        (Reply::ClearTare, "A") => none(Response::TareCleared),
        (Reply::BalanceData, "A") => Ok(Response::BalanceData(
            texts(&head, args, usize::MAX).map_err(fail)?,
        )),
        (Reply::Serial, "A") => {
            let mut serial = texts(&head, args, 1).map_err(fail)?;
            Ok(Response::Serial(serial.pop().unwrap_or_default()))
        }
        _ => Err(fail(format!("{head} is not a response MT-SICS defines"))),
    }
}

/// The line without one trailing CR LF, LF or CR.
/// The response that ends a line whose start is noise (the tail of a
/// broken line, bytes garbled at power-on): the longest tail that parses,
/// starting at a word boundary (never after a letter), and where it starts.
/// `None` if no tail is a response.
///
/// ```
/// use primo_mtsics::{parse_tail, Response};
/// let (at, r) = parse_tail(b"\xff\x00S S 1S S      5.00 g\r\n").unwrap();
/// assert_eq!((at, r.to_string()), (7, "S S       5.00 g".to_string()));
/// assert!(parse_tail(b"YES").is_none());
/// ```
pub fn parse_tail(line: &[u8]) -> Option<(usize, Response)> {
    let line = strip_terminator(line);
    (1..line.len()).find_map(|at| {
        let after_letter = line.get(at - 1).is_some_and(u8::is_ascii_alphabetic);
        let tail = line.get(at..).filter(|_| !after_letter)?;
        parse_response(tail).ok().map(|r| (at, r))
    })
}

fn strip_terminator(line: &[u8]) -> &[u8] {
    let line = line.strip_suffix(b"\n").unwrap_or(line);
    line.strip_suffix(b"\r").unwrap_or(line)
}

/// One whitespace-separated field; a quoted one keeps its spaces.
struct Field<'a> {
    text: &'a str,
    quoted: bool,
    /// 1-based position in the line.
    number: usize,
}

fn split_fields(text: &str) -> Result<Vec<Field<'_>>, String> {
    let mut fields = Vec::new();
    let mut rest = text.trim_start_matches(' ');
    while !rest.is_empty() {
        let number = fields.len() + 1;
        let (field, after) = if let Some(inner) = rest.strip_prefix('"') {
            let end = inner
                .find('"')
                .ok_or_else(|| format!("field {number}: the quote is never closed"))?;
            let after = inner.get(end + 1..).unwrap_or_default();
            if !(after.is_empty() || after.starts_with(' ')) {
                return Err(format!(
                    "field {number}: text follows the closing quote without a space"
                ));
            }
            let text = inner.get(..end).unwrap_or_default();
            (
                Field {
                    text,
                    quoted: true,
                    number,
                },
                after,
            )
        } else {
            let end = rest.find(' ').unwrap_or(rest.len());
            let text = rest.get(..end).unwrap_or_default();
            if text.contains('"') {
                return Err(format!("field {number} `{text}`: a quote inside a field"));
            }
            (
                Field {
                    text,
                    quoted: false,
                    number,
                },
                rest.get(end..).unwrap_or_default(),
            )
        };
        fields.push(field);
        rest = after.trim_start_matches(' ');
    }
    Ok(fields)
}

/// `<value> <unit>` after `head`.
fn weight(head: &str, args: &[&Field]) -> Result<Weight, String> {
    let [value, unit] = args else {
        return Err(format!(
            "{head} needs a value and a unit, found {} field(s) after it",
            args.len()
        ));
    };
    if let Some(f) = [value, unit].into_iter().find(|f| f.quoted) {
        return Err(format!("field {} is quoted text, not a weight", f.number));
    }
    let (number, decimals) = parse_value(value.text).ok_or_else(|| {
        format!(
            "field {} `{}` is not a decimal number",
            value.number, value.text
        )
    })?;
    let unit = Unit::from_symbol(unit.text).ok_or_else(|| {
        format!(
            "field {} `{}` is not a unit this client knows (g, mg, kg)",
            unit.number, unit.text
        )
    })?;
    Ok(Weight {
        value: number,
        unit,
        decimals,
    })
}

/// One or more (at most `most`) quoted texts after `head`.
fn texts(head: &str, args: &[&Field], most: usize) -> Result<Vec<String>, String> {
    if args.is_empty() || args.len() > most {
        return Err(match most {
            1 => format!(
                "{head} needs one quoted text, found {} field(s)",
                args.len()
            ),
            _ => format!("{head} needs quoted text, found none"),
        });
    }
    args.iter()
        .map(|f| {
            if f.quoted {
                Ok(f.text.to_string())
            } else {
                Err(format!(
                    "field {} `{}` should be quoted text",
                    f.number, f.text
                ))
            }
        })
        .collect()
}

/// A plain decimal `[+-]digits[.digits]` and its count of decimals; no
/// exponents, `inf` or `NaN`, which no scale sends.
pub fn parse_value(text: &str) -> Option<(f64, u8)> {
    let digits = text.strip_prefix(['+', '-']).unwrap_or(text);
    let (int, frac) = digits.split_once('.').unwrap_or((digits, ""));
    let all_digits = |s: &str| s.bytes().all(|b| b.is_ascii_digit());
    let ok = (1..=12).contains(&int.len())
        && all_digits(int)
        && frac.len() <= 9
        && all_digits(frac)
        && !(digits.contains('.') && frac.is_empty());
    if !ok {
        return None;
    }
    let value: f64 = text.parse().ok()?;
    Some((value, frac.len() as u8))
}

/// Splits a byte stream into lines at LF (a CR before it dropped). A line
/// that grows past [`MAX_LINE`] without an LF comes out once, as it is so
/// far, and the rest of it up to the next LF is dropped.
#[derive(Debug, Default)]
pub struct Lines {
    buf: Vec<u8>,
    /// Inside an over-long line already handed out.
    skipping: bool,
}

impl Lines {
    /// Appends received bytes.
    pub fn push(&mut self, bytes: &[u8]) {
        self.buf.extend_from_slice(bytes);
    }

    /// Forgets everything received so far.
    pub fn clear(&mut self) {
        self.buf.clear();
        self.skipping = false;
    }

    /// The next complete line, if any.
    pub fn next_line(&mut self) -> Option<Vec<u8>> {
        loop {
            match self.buf.iter().position(|&b| b == b'\n') {
                Some(end) => {
                    let mut line: Vec<u8> = self.buf.drain(..=end).collect();
                    line.pop();
                    if line.last() == Some(&b'\r') {
                        line.pop();
                    }
                    if !std::mem::take(&mut self.skipping) {
                        return Some(line);
                    }
                }
                None if self.buf.len() > MAX_LINE => {
                    if self.skipping {
                        self.buf.clear();
                        return None;
                    }
                    self.skipping = true;
                    return Some(std::mem::take(&mut self.buf));
                }
                None => return None,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ok(line: &str) -> Response {
        parse_response(line.as_bytes()).unwrap_or_else(|e| panic!("{e}"))
    }

    fn err(line: &[u8]) -> String {
        match parse_response(line) {
            Ok(r) => panic!("{line:?} parsed as {r:?}"),
            Err(e) => e.to_string(),
        }
    }

    fn grams(value: f64, decimals: u8) -> Weight {
        Weight {
            value,
            unit: Unit::G,
            decimals,
        }
    }

    #[test]
    fn every_response_form() {
        use Response as R;
        let cases = [
            (
                "S S     100.00 g",
                R::Weight(grams(100.0, 2), Stability::Stable),
            ),
            (
                "S D      -3.1 g",
                R::Weight(grams(-3.1, 1), Stability::Dynamic),
            ),
            (
                "S S 12 mg",
                R::Weight(
                    Weight {
                        value: 12.0,
                        unit: Unit::Mg,
                        decimals: 0,
                    },
                    Stability::Stable,
                ),
            ),
            (
                "S S   +1.23456 kg",
                R::Weight(
                    Weight {
                        value: 1.23456,
                        unit: Unit::Kg,
                        decimals: 5,
                    },
                    Stability::Stable,
                ),
            ),
            ("S I", R::NotExecutable(Reply::Weight)),
            ("S +", R::Overload(Reply::Weight)),
            ("S -", R::Underload(Reply::Weight)),
            ("Z A", R::Zeroed),
            ("Z I", R::NotExecutable(Reply::Zero)),
            ("Z +", R::Overload(Reply::Zero)),
            ("Z -", R::Underload(Reply::Zero)),
            ("ZI S", R::ZeroedImmediately(Stability::Stable)),
            ("ZI D", R::ZeroedImmediately(Stability::Dynamic)),
            ("ZI I", R::NotExecutable(Reply::ZeroImmediately)),
            ("T S      50.00 g", R::Tared(grams(50.0, 2))),
            ("T I", R::NotExecutable(Reply::Tare)),
            ("T +", R::Overload(Reply::Tare)),
            ("T -", R::Underload(Reply::Tare)),
            ("TA A       0.00 g", R::TareValue(grams(0.0, 2))),
            ("TA I", R::NotExecutable(Reply::TareValue)),
            ("TA L", R::InvalidParameter(Reply::TareValue)),
            ("TAC A", R::TareCleared),
            ("TAC I", R::NotExecutable(Reply::ClearTare)),
            (
                "I2 A \"primo-sim 4200.00 g\"",
                R::BalanceData(vec!["primo-sim 4200.00 g".into()]),
            ),
            (
                "I2 A \"XS205\" \"220.00 g\"",
                R::BalanceData(vec!["XS205".into(), "220.00 g".into()]),
            ),
            ("I4 A \"B123456789\"", R::Serial("B123456789".into())),
            ("I4 A \"\"", R::Serial(String::new())),
            ("I4 I", R::NotExecutable(Reply::Serial)),
            ("ES", R::SyntaxError),
            ("ET", R::TransmissionError),
            ("EL", R::LogicError),
        ];
        for (line, want) in cases {
            assert_eq!(ok(line), want, "{line}");
            // The same with CR LF, and a bare LF.
            assert_eq!(ok(&format!("{line}\r\n")), want, "{line}");
            assert_eq!(ok(&format!("{line}\n")), want, "{line}");
        }
    }

    #[test]
    fn formatting_is_the_mtsics_layout_and_parses_back() {
        let responses = [
            Response::Weight(grams(100.0, 2), Stability::Stable),
            Response::Weight(grams(-0.001, 2), Stability::Dynamic),
            Response::Tared(grams(12345.678, 3)),
            Response::TareValue(grams(0.0, 2)),
            Response::BalanceData(vec!["a b".into(), "c".into()]),
            Response::Serial("0123456789".into()),
            Response::Overload(Reply::Weight),
            Response::InvalidParameter(Reply::TareValue),
            Response::ZeroedImmediately(Stability::Dynamic),
            Response::LogicError,
        ];
        assert_eq!(responses[0].to_string(), "S S     100.00 g");
        assert_eq!(responses[1].to_string(), "S D       0.00 g");
        assert_eq!(responses[5].to_string(), "I4 A \"0123456789\"");
        for r in responses {
            let back = ok(&r.to_string());
            match (&r, &back) {
                (Response::Weight(a, _), Response::Weight(b, _)) => {
                    assert!((a.value - b.value).abs() < 0.01 && a.decimals == b.decimals)
                }
                _ => assert_eq!(back, r),
            }
        }
    }

    #[test]
    fn malformed_lines_say_what_where_and_why() {
        let cases: [(&[u8], &str); 19] = [
            (b"", "``: empty line"),
            (b"   \r\n", "`   `: empty line"),
            (b"S", "`S`: `S` without a status field"),
            (
                b"S S",
                "`S S`: `S S` needs a value and a unit, found 0 field(s) after it",
            ),
            (
                b"S S 12.00",
                "`S S 12.00`: `S S` needs a value and a unit, found 1 field(s) after it",
            ),
            (
                b"S S 1 g x",
                "`S S 1 g x`: `S S` needs a value and a unit, found 3 field(s) after it",
            ),
            (
                b"S S 12,5 g",
                "`S S 12,5 g`: field 3 `12,5` is not a decimal number",
            ),
            (
                b"S S 1e3 g",
                "`S S 1e3 g`: field 3 `1e3` is not a decimal number",
            ),
            (
                b"S S NaN g",
                "`S S NaN g`: field 3 `NaN` is not a decimal number",
            ),
            (
                b"S S 12. g",
                "`S S 12. g`: field 3 `12.` is not a decimal number",
            ),
            (
                b"S S 12.00 lb",
                "`S S 12.00 lb`: field 4 `lb` is not a unit this client knows (g, mg, kg)",
            ),
            (
                b"S S 12.00 G",
                "`S S 12.00 G`: field 4 `G` is not a unit this client knows (g, mg, kg)",
            ),
            (b"S X", "`S X`: `S X` is not a response MT-SICS defines"),
            (
                b"TAC +",
                "`TAC +`: `TAC +` is not a response MT-SICS defines",
            ),
            (b"S I 5", "`S I 5`: `S I` takes no more fields, found 1"),
            (b"ES x", "`ES x`: `ES` stands alone, found 1 more field(s)"),
            (
                b"HELLO",
                "`HELLO`: field 1 `HELLO` is not an MT-SICS response (S, Z, ZI, T, TA, TAC, I2, I4, ES, ET, EL)",
            ),
            (
                b"I4 A B123",
                "`I4 A B123`: field 3 `B123` should be quoted text",
            ),
            (
                b"I4 A \"B1",
                "`I4 A \"B1`: field 3: the quote is never closed",
            ),
        ];
        for (line, want) in cases {
            assert_eq!(err(line), want);
        }
        assert_eq!(
            err(b"I4 A \"a\" \"b\""),
            "`I4 A \"a\" \"b\"`: `I4 A` needs one quoted text, found 2 field(s)"
        );
        assert_eq!(
            err(b"I4 A \"a\"b"),
            "`I4 A \"a\"b`: field 3: text follows the closing quote without a space"
        );
        assert_eq!(
            err(b"S S 1\"2 g"),
            "`S S 1\"2 g`: field 3 `1\"2`: a quote inside a field"
        );
        assert_eq!(err(b"I2 A"), "`I2 A`: `I2 A` needs quoted text, found none");
        assert_eq!(
            err(b"S S \"1\" g"),
            "`S S \"1\" g`: field 3 is quoted text, not a weight"
        );
    }

    #[test]
    fn binary_control_and_overlong_lines_are_quoted_escaped() {
        assert_eq!(
            err(b"S S \xff\xfe g\r\n"),
            "`S S \\xff\\xfe g`: byte 5 is not text (not UTF-8)"
        );
        assert_eq!(
            err(b"S\tS 1 g"),
            "`S\\tS 1 g`: control character '\\t' at byte 2"
        );
        assert_eq!(
            err(b"S S 1 g\r\r\n"),
            "`S S 1 g\\r`: control character '\\r' at byte 8"
        );
        let long = vec![b'A'; 300];
        let e = err(&long);
        assert!(
            e.ends_with("... (300 bytes)`: 300 bytes, longer than any MT-SICS line (128)"),
            "{e}"
        );
        assert!(e.len() < 300, "{e}");
    }

    #[test]
    fn never_panics_on_any_short_input() {
        // Every 1- and 2-byte line, and lines built from the protocol's own
        // pieces: parse or fail, never panic.
        for a in 0..=255u8 {
            let _ = parse_response(&[a]);
            for b in 0..=255u8 {
                let _ = parse_response(&[a, b]);
            }
        }
        let pieces: [&[u8]; 12] = [
            b"S", b" ", b"\"", b"A", b"I4", b"1.5", b"g", b"-", b".", b"\r", b"\n", b"\xc3",
        ];
        let mut line = Vec::new();
        for i in 0..200_000usize {
            line.clear();
            let mut k = i;
            while k > 0 {
                line.extend_from_slice(pieces[k % pieces.len()]);
                k /= pieces.len();
            }
            let _ = parse_response(&line);
        }
    }

    #[test]
    fn units_convert_keeping_the_resolution() {
        let w = grams(123.45, 2);
        let mg = w.to(Unit::Mg);
        assert_eq!((mg.to_string(), mg.decimals), ("123450 mg".to_string(), 0));
        assert_eq!(w.to(Unit::Kg).to_string(), "0.12345 kg");
        assert!((w.to(Unit::Kg).grams() - 123.45).abs() < 1e-9);
        assert_eq!(grams(-0.004, 2).to_string(), "0.00 g");
    }

    #[test]
    fn values_are_plain_decimals() {
        assert_eq!(parse_value("-12.50"), Some((-12.5, 2)));
        assert_eq!(parse_value("+7"), Some((7.0, 0)));
        for bad in [
            "",
            "-",
            ".5",
            "5.",
            "1e3",
            "inf",
            "1.2.3",
            "0x10",
            "1234567890123",
            "1.0000000001",
        ] {
            assert_eq!(parse_value(bad), None, "{bad}");
        }
    }

    #[test]
    fn lines_split_at_lf_and_cut_overlong_lines_once() {
        let mut lines = Lines::default();
        lines.push(b"S S 1 g\r\nZ A\nS ");
        assert_eq!(lines.next_line().unwrap(), b"S S 1 g");
        assert_eq!(lines.next_line().unwrap(), b"Z A");
        assert_eq!(lines.next_line(), None);
        lines.push(b"I\r\n");
        assert_eq!(lines.next_line().unwrap(), b"S I");
        lines.push(&[b'x'; 200]);
        assert_eq!(lines.next_line().unwrap().len(), 200);
        lines.push(&[b'y'; 200]);
        assert_eq!(lines.next_line(), None);
        lines.push(b"yyy\r\nES\r\n");
        assert_eq!(lines.next_line().unwrap(), b"ES");
        lines.push(b"partial");
        lines.clear();
        lines.push(b"\n");
        assert_eq!(lines.next_line().unwrap(), b"");
    }
}
