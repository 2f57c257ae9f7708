//! PNG charts (learning curves and the like), rendered in memory.
//!
//! [`render_png`] draws one or more [`Panel`]s into an RGB buffer with `plotters`' bitmap
//! backend and encodes it with the `png` crate, so callers write the file themselves (e.g.
//! with [`crate::output::write_file`]). Text uses an embedded DejaVu Sans font, so no system
//! font library is needed at build or run time.
//!
//! Any data is accepted: non-finite values, values beyond ±[`MAX_ABS`] and (on a log axis)
//! values below [`MIN_LOG`] are skipped, lines break where points are skipped, and ranges
//! and tick marks are computed here, in bounded loops, rather than by `plotters`, whose
//! float tick search can loop forever on degenerate ranges.

use std::ops::Range;
use std::sync::OnceLock;

use plotters::backend::RGBPixel;
use plotters::coord::ranged1d::{KeyPointHint, NoDefaultFormatting, Ranged, ValueFormatter};
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// One curve: points (x, y), optionally a ± spread per point drawn as error bars.
///
/// Drawn as a line, with a marker per point when the points are far enough apart not to
/// merge into the line.
pub struct Line<'a> {
    /// Legend text (shown when the panel has two series or more).
    pub label: &'a str,
    /// The points, in drawing order; unusable ones (NaN, ±inf, …) are skipped.
    pub points: &'a [(f64, f64)],
    /// Half-height of the error bar at each point (`points[i].1 ± spread[i]`); extra or
    /// missing entries are ignored, as are non-finite ones.
    pub spread: Option<&'a [f64]>,
}

/// One chart panel.
pub struct Panel<'a> {
    /// Caption above the panel (none when empty).
    pub title: &'a str,
    /// Description of the x axis.
    pub x_label: &'a str,
    /// Description of the y axis.
    pub y_label: &'a str,
    /// The curves, each in its own colour.
    pub series: &'a [Line<'a>],
    /// Logarithmic y axis; non-positive y values are then skipped.
    pub log_y: bool,
    /// Optional horizontal reference line at `y` with a label, e.g. the precision (skipped
    /// when `y` cannot be plotted, e.g. zero on a log axis).
    pub hline: Option<(f64, &'a str)>,
}

/// Largest magnitude plotted; beyond it the ranges' arithmetic could overflow.
pub const MAX_ABS: f64 = 1e300;
/// Smallest value plotted on a log axis (keeps `log10` well away from subnormals).
pub const MIN_LOG: f64 = 1e-300;
/// Largest image accepted, in pixels (the RGB buffer is three bytes per pixel).
pub const MAX_PIXELS: u64 = 1 << 26;

/// The family name the embedded font is registered under; `plotters` uses it by default too.
const FONT: &str = "sans-serif";
/// DejaVu Sans (licence in `assets/DejaVuSans.LICENSE`).
static FONT_BYTES: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// Distinct colours for the series (Tableau 10); more series fall back to `Palette99`.
const COLOURS: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// Renders the panels stacked vertically (or in a grid when more than 3) into a PNG and
/// returns its bytes.
///
/// No panels give a blank image. Errors: a zero or too large size (more than
/// [`MAX_PIXELS`]), or a failure to draw or encode.
pub fn render_png(panels: &[Panel<'_>], width: u32, height: u32) -> Result<Vec<u8>, PlotError> {
    render(panels, width, height).map_err(PlotError)
}

/// A chart that could not be drawn.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct PlotError(String);

fn render(panels: &[Panel<'_>], width: u32, height: u32) -> Result<Vec<u8>, String> {
    if width == 0 || height == 0 {
        return Err(format!("cannot draw a {width}×{height} image"));
    }
    let pixels = u64::from(width) * u64::from(height);
    if pixels > MAX_PIXELS {
        return Err(format!(
            "a {width}×{height} image is too large (at most {MAX_PIXELS} pixels)"
        ));
    }
    register_font()?;
    let len = usize::try_from(pixels * 3).map_err(|e| format!("image buffer: {e}"))?;
    let mut buf = vec![255u8; len];
    {
        let backend = BitMapBackend::<RGBPixel>::with_buffer_and_format(&mut buf, (width, height))
            .map_err(|e| format!("bitmap: {e}"))?;
        let root = backend.into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        let (rows, cols) = grid(panels.len());
        if !panels.is_empty() {
            for (panel, area) in panels.iter().zip(root.split_evenly((rows, cols))) {
                draw_panel(&area, panel)?;
            }
        }
        root.present().map_err(draw_err)?;
    }
    encode(&buf, width, height)
}

/// Registers the embedded font once per process; later calls return the first outcome.
fn register_font() -> Result<(), String> {
    static DONE: OnceLock<Result<(), String>> = OnceLock::new();
    DONE.get_or_init(|| {
        plotters::style::register_font(FONT, FontStyle::Normal, FONT_BYTES)
            .map_err(|_| "the embedded font is not a valid TrueType font".to_string())
    })
    .clone()
}

fn draw_err(e: impl std::fmt::Display) -> String {
    format!("cannot draw the chart: {e}")
}

/// Rows and columns: a column up to 3 panels, then a near-square grid.
fn grid(n: usize) -> (usize, usize) {
    if n <= 3 {
        return (n.max(1), 1);
    }
    let cols = n.isqrt() + usize::from(n.isqrt() * n.isqrt() < n);
    (n.div_ceil(cols), cols)
}

fn encode(rgb: &[u8], width: u32, height: u32) -> Result<Vec<u8>, String> {
    let err = |e: png::EncodingError| format!("cannot encode the PNG: {e}");
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, width, height);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    // Charts are mostly flat colour: the fast deflate already compresses them well.
    enc.set_compression(png::Compression::Fast);
    let mut writer = enc.write_header().map_err(err)?;
    writer.write_image_data(rgb).map_err(err)?;
    writer.finish().map_err(err)?;
    Ok(out)
}

/// A series reduced to what can be drawn.
struct Clean {
    /// Runs of consecutive usable points; the line breaks between runs.
    runs: Vec<Vec<(f64, f64)>>,
    /// Error bars: (x, low, y, high); `low` is NaN when it falls off a log axis.
    bars: Vec<(f64, f64, f64, f64)>,
}

fn usable(v: f64, log: bool) -> bool {
    v.is_finite() && v.abs() <= MAX_ABS && (!log || v >= MIN_LOG)
}

fn clean(s: &Line<'_>, log: bool) -> Clean {
    let mut runs: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut run = Vec::new();
    let mut bars = Vec::new();
    for (i, &(x, y)) in s.points.iter().enumerate() {
        if !(usable(x, false) && usable(y, log)) {
            if !run.is_empty() {
                runs.push(std::mem::take(&mut run));
            }
            continue;
        }
        run.push((x, y));
        let spread = s.spread.and_then(|d| d.get(i)).map(|d| d.abs());
        if let Some(d) = spread.filter(|d| d.is_finite() && *d > 0.0) {
            let hi = (y + d).min(MAX_ABS);
            let lo = (y - d).max(-MAX_ABS);
            bars.push((x, if usable(lo, log) { lo } else { f64::NAN }, y, hi));
        }
    }
    if !run.is_empty() {
        runs.push(run);
    }
    Clean { runs, bars }
}

/// A 1-D axis with our own mapping and tick marks (see the module docs for why).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Axis {
    lo: f64,
    hi: f64,
    log: bool,
}

impl Axis {
    /// Fits the axis to the values (already `usable`) with a 5 % margin.
    fn fit(values: impl Iterator<Item = f64>, log: bool) -> Axis {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for v in values {
            lo = lo.min(v);
            hi = hi.max(v);
        }
        if lo > hi {
            return if log {
                Axis {
                    lo: 1.0,
                    hi: 10.0,
                    log,
                }
            } else {
                Axis {
                    lo: 0.0,
                    hi: 1.0,
                    log,
                }
            };
        }
        if log {
            // Fit in decades; a flat curve gets a one-decade window.
            let (mut l, mut h) = (lo.log10(), hi.log10());
            if h - l < 1e-6 {
                l -= 0.5;
                h += 0.5;
            } else {
                let pad = 0.05 * (h - l);
                l -= pad;
                h += pad;
            }
            let (l, h) = (l.max(-300.0), h.min(300.0));
            return Axis {
                lo: 10f64.powf(l),
                hi: 10f64.powf(h),
                log,
            };
        }
        let scale = lo.abs().max(hi.abs());
        // Spans too small for f64 to tick (relative or absolute) count as flat.
        if hi - lo <= 1e-10 * scale || hi - lo < 1e-250 {
            let c = 0.5 * (lo + hi);
            let half = if c.abs() < 1e-200 { 1.0 } else { 0.1 * c.abs() };
            return Axis {
                lo: c - half,
                hi: c + half,
                log,
            };
        }
        let pad = 0.05 * (hi - lo);
        Axis {
            lo: lo - pad,
            hi: hi + pad,
            log,
        }
    }

    fn lin(&self, v: f64) -> f64 {
        if self.log { v.log10() } else { v }
    }

    /// Bold ticks (`light == false`) or the finer grid, at most `max_n` of them.
    fn ticks(&self, max_n: usize, light: bool) -> Vec<f64> {
        let max_n = max_n.clamp(1, 200);
        if !self.log {
            return nice_ticks(self.lo, self.hi, max_n);
        }
        let (l, h) = (self.lo.log10(), self.hi.log10());
        if !(l.is_finite() && h.is_finite() && l < h) {
            return Vec::new();
        }
        // Bounded: the axis lies within 10^±300.
        let (k0, k1) = (l.floor() as i32, h.ceil() as i32);
        let decades = usize::try_from(k1 - k0).unwrap_or(0).max(1);
        let within = |v: &f64| *v >= self.lo * (1.0 - 1e-9) && *v <= self.hi * (1.0 + 1e-9);
        let with_mantissas = |ms: &[f64]| -> Vec<f64> {
            (k0..=k1)
                .flat_map(|k| ms.iter().map(move |m| m * 10f64.powi(k)))
                .filter(within)
                .collect()
        };
        let step = decades.div_ceil(max_n).max(1);
        let powers: Vec<f64> = (k0..=k1)
            .filter(|k| ((k - k0) as usize).is_multiple_of(step))
            .map(|k| 10f64.powi(k))
            .filter(within)
            .collect();
        let ticks = if light {
            if decades <= 30 {
                with_mantissas(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0])
            } else {
                (k0..=k1).map(|k| 10f64.powi(k)).filter(within).collect()
            }
        } else if powers.len() >= 3 {
            powers
        } else {
            let ticks = with_mantissas(&[1.0, 2.0, 5.0]);
            // Less than a decade or so: 1-2-5 ticks are too sparse, use linear ones.
            if ticks.len() >= 3 {
                ticks
            } else {
                nice_ticks(self.lo, self.hi, max_n)
            }
        };
        if ticks.len() > max_n {
            let every = ticks.len().div_ceil(max_n);
            ticks.into_iter().step_by(every).collect()
        } else {
            ticks
        }
    }
}

/// Round ticks (1, 2 or 5 × 10^k apart) in `[lo, hi]`, at most about `max_n`.
fn nice_ticks(lo: f64, hi: f64, max_n: usize) -> Vec<f64> {
    let span = hi - lo;
    if !(span.is_finite() && span > 0.0) {
        return Vec::new();
    }
    let n = max_n as f64;
    let mag = 10f64.powf((span / n).log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| span / s <= n)
        .unwrap_or(10.0 * mag);
    if !(step.is_finite() && step > 0.0) {
        return Vec::new();
    }
    let first = (lo / step).ceil();
    let mut out = Vec::new();
    // Multiplying (rather than accumulating) keeps ticks exact-ish; the bound keeps the
    // loop finite whatever rounding does.
    for i in 0..=max_n + 1 {
        let v = (first + i as f64) * step;
        if v > hi + 1e-9 * step {
            break;
        }
        out.push(if v.abs() < 1e-9 * step { 0.0 } else { v });
    }
    out
}

impl Ranged for Axis {
    type FormatOption = NoDefaultFormatting;
    type ValueType = f64;

    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        let (a, b) = (self.lin(self.lo), self.lin(self.hi));
        let t = (self.lin(*v) - a) / (b - a);
        // Anything far off the axis is pinned just outside it, so the rasteriser never
        // walks millions of off-screen pixels.
        let t = if t.is_nan() { 0.0 } else { t.clamp(-1.0, 2.0) };
        let px = f64::from(limit.0) + t * (f64::from(limit.1) - f64::from(limit.0));
        px.round() as i32
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        let light = hint.weight().allow_light_points();
        // plotters asks for up to 10 light lines per label, too dense a linear grid.
        let n = if light && !self.log {
            hint.bold_points().saturating_mul(5)
        } else {
            hint.max_num_points()
        };
        self.ticks(n, light)
    }

    fn range(&self) -> Range<f64> {
        self.lo..self.hi
    }
}

impl ValueFormatter<f64> for Axis {
    fn format(v: &f64) -> String {
        tick_label(*v)
    }
}

/// Short tick label: up to 6 significant digits, scientific for very large or small values.
fn tick_label(v: f64) -> String {
    fn trim(s: &str) -> &str {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.')
        } else {
            s
        }
    }
    let a = v.abs();
    if v == 0.0 || !v.is_finite() {
        return if v.is_nan() {
            "NaN".into()
        } else {
            format!("{v}")
        };
    }
    if !(1e-4..1e6).contains(&a) {
        let s = format!("{v:.3e}");
        return match s.split_once('e') {
            Some((m, e)) => format!("{}e{e}", trim(m)),
            None => s,
        };
    }
    let decimals = (5 - a.log10().floor() as i32).clamp(0, 10) as usize;
    trim(&format!("{v:.decimals$}")).to_string()
}

fn colour(i: usize) -> RGBColor {
    match COLOURS.get(i) {
        Some(c) => *c,
        None => {
            let (r, g, b) = Palette99::pick(i).rgb();
            RGBColor(r, g, b)
        }
    }
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    panel: &Panel<'_>,
) -> Result<(), String> {
    let (pw, ph) = area.dim_in_pixel();
    if pw < 8 || ph < 8 {
        return Ok(()); // nothing legible fits
    }
    let cleaned: Vec<Clean> = panel.series.iter().map(|s| clean(s, panel.log_y)).collect();
    let hline = panel.hline.filter(|(y, _)| usable(*y, panel.log_y));

    let xs = cleaned
        .iter()
        .flat_map(|c| c.runs.iter().flatten().map(|p| p.0));
    let x_axis = Axis::fit(xs, false);
    let ys = cleaned.iter().flat_map(|c| {
        let pts = c.runs.iter().flatten().map(|p| p.1);
        let bars = c.bars.iter().flat_map(|b| [b.1, b.3]);
        pts.chain(bars.filter(|v| usable(*v, panel.log_y)))
    });
    let y_axis = Axis::fit(ys.chain(hline.map(|h| h.0)), panel.log_y);

    // Decorations only when the panel is big enough to hold them.
    let full = pw >= 120 && ph >= 80;
    let fs = (f64::from(pw.min(ph)) / 22.0).clamp(8.0, 18.0);
    let n_x = (f64::from(pw) / (fs * 7.0)).clamp(2.0, 10.0) as usize;
    let n_y = (f64::from(ph) / (fs * 3.0)).clamp(2.0, 10.0) as usize;
    let mut builder = ChartBuilder::on(area);
    builder.margin(if full { (fs * 0.6) as u32 } else { 2 });
    if full {
        if !panel.title.is_empty() {
            builder.caption(panel.title, (FONT, fs * 1.25));
        }
        // Wide enough for the longest y tick label plus the rotated axis description.
        let chars = y_axis
            .ticks(n_y, false)
            .iter()
            .map(|v| tick_label(*v).chars().count())
            .max()
            .unwrap_or(1);
        let y_area = (chars as f64 * 0.6 + 2.5) * fs;
        builder
            .x_label_area_size((fs * 3.2) as u32)
            .y_label_area_size(y_area.min(f64::from(pw) / 3.0) as u32);
    }
    let mut chart = builder
        .build_cartesian_2d(x_axis, y_axis)
        .map_err(draw_err)?;

    if full {
        chart
            .configure_mesh()
            .x_labels(n_x)
            .y_labels(n_y)
            .x_desc(panel.x_label)
            .y_desc(panel.y_label)
            .label_style((FONT, fs))
            .axis_desc_style((FONT, fs))
            .bold_line_style(RGBColor(200, 200, 200))
            .light_line_style(RGBColor(238, 238, 238))
            .draw()
            .map_err(draw_err)?;
    }

    if let Some((y, label)) = hline {
        let style = RGBColor(90, 90, 90).stroke_width(1);
        let line = vec![(x_axis.lo, y), (x_axis.hi, y)];
        chart
            .draw_series(std::iter::once(DashedPathElement::new(line, 6, 4, style)))
            .map_err(draw_err)?;
        if full && !label.is_empty() {
            let text = TextStyle::from((FONT, fs * 0.9).into_font())
                .color(&RGBColor(60, 60, 60))
                .pos(Pos::new(HPos::Left, VPos::Bottom));
            let at = EmptyElement::at((x_axis.lo, y)) + Text::new(label.to_string(), (5, -3), text);
            chart.draw_series(std::iter::once(at)).map_err(draw_err)?;
        }
    }

    let marker = if full {
        (fs / 5.0).clamp(2.0, 4.0) as u32
    } else {
        1
    };
    let plot_w = f64::from(chart.plotting_area().dim_in_pixel().0.max(1));
    for (i, (series, c)) in panel.series.iter().zip(&cleaned).enumerate() {
        let col = colour(i);
        // Pixels between neighbouring points: dense curves get no markers (they would
        // merge into a thick line) and narrower error-bar caps.
        let n = c.runs.iter().map(Vec::len).sum::<usize>().max(1);
        let gap = plot_w / n as f64;
        let cap = (f64::from(marker * 2 + 2)).min(gap * 0.6) as u32;
        let bar_style = col.mix(0.6).stroke_width(1);
        let bars = c.bars.iter().map(|&(x, lo, y, hi)| {
            // A lower end off the log axis is drawn down to the axis' bottom.
            let lo = if lo.is_nan() { y_axis.lo } else { lo };
            ErrorBar::new_vertical(x, lo, y, hi, bar_style, cap)
        });
        chart.draw_series(bars).map_err(draw_err)?;
        let lines = c
            .runs
            .iter()
            .map(|run| PathElement::new(run.clone(), col.stroke_width(2)));
        let anno = chart.draw_series(lines).map_err(draw_err)?;
        if panel.series.len() >= 2 {
            anno.label(series.label).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2))
            });
        }
        if gap >= f64::from(marker * 4) {
            let dots = c
                .runs
                .iter()
                .flatten()
                .map(|&p| Circle::new(p, marker, col.filled()));
            chart.draw_series(dots).map_err(draw_err)?;
        }
    }

    if full && panel.series.len() >= 2 {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .label_font((FONT, fs))
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(160, 160, 160))
            .draw()
            .map_err(draw_err)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Instant;

    /// Decodes the PNG and returns (width, height, RGB pixels).
    fn decode(bytes: &[u8]) -> (u32, u32, Vec<u8>) {
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "PNG signature");
        let mut reader = png::Decoder::new(std::io::Cursor::new(bytes))
            .read_info()
            .expect("PNG header");
        let mut buf = vec![0; reader.output_buffer_size().expect("buffer size")];
        let info = reader.next_frame(&mut buf).expect("PNG data");
        assert_eq!(info.color_type, png::ColorType::Rgb);
        buf.truncate(info.buffer_size());
        (info.width, info.height, buf)
    }

    fn render_ok(panels: &[Panel<'_>], w: u32, h: u32) -> Vec<u8> {
        let bytes = render_png(panels, w, h).expect("render");
        let (dw, dh, px) = decode(&bytes);
        assert_eq!((dw, dh), (w, h));
        px
    }

    fn panel<'a>(series: &'a [Line<'a>], log_y: bool) -> Panel<'a> {
        Panel {
            title: "title",
            x_label: "x",
            y_label: "y",
            series,
            log_y,
            hline: None,
        }
    }

    fn curve(n: usize, scale: f64) -> Vec<(f64, f64)> {
        (0..n)
            .map(|i| (i as f64, scale * (-(i as f64) / 50.0).exp() + 1e-3))
            .collect()
    }

    #[test]
    fn decodes_to_requested_size_and_draws_something() {
        let pts = curve(50, 1.0);
        let series = [Line {
            label: "a",
            points: &pts,
            spread: None,
        }];
        let px = render_ok(&[panel(&series, false)], 320, 240);
        assert!(px.iter().any(|&b| b != 255), "not blank");
        // The curve's colour appears somewhere.
        let c = COLOURS[0];
        assert!(px.chunks(3).any(|p| p == [c.0, c.1, c.2]));
    }

    #[test]
    fn no_panels_is_a_blank_image() {
        let px = render_ok(&[], 40, 30);
        assert!(px.iter().all(|&b| b == 255));
    }

    #[test]
    fn bad_sizes_are_errors() {
        assert!(render_png(&[], 0, 10).is_err());
        assert!(render_png(&[], 10, 0).is_err());
        assert!(render_png(&[], 100_000, 100_000).is_err());
    }

    #[test]
    fn degenerate_inputs_give_valid_pngs() {
        let nan = f64::NAN;
        let inf = f64::INFINITY;
        let empty: [(f64, f64); 0] = [];
        let one = [(3.0, 7.0)];
        let flat = [(0.0, 2.0), (1.0, 2.0), (2.0, 2.0)];
        let zeros = [(0.0, 0.0), (1.0, 0.0), (2.0, -1.0)];
        let bad = [(nan, 1.0), (1.0, nan), (inf, 2.0), (2.0, -inf), (nan, nan)];
        let mixed = [(0.0, 1.0), (1.0, nan), (2.0, 0.0), (3.0, 1e-9), (4.0, 1e6)];
        let huge = [
            (-1e308, 1e308),
            (0.0, -1e300),
            (1e300, 1e-320),
            (1.0, f64::MAX),
        ];
        let tiny = [(0.0, 1e-320), (1e-310, 0.0), (5e-324, 5e-324)];
        let close = [(1e15, 1e15), (1e15 + 1.0, 1e15 + 0.125)];
        let spread = [nan, -1.0, inf, 1e308, 0.0];
        let sets: [&[(f64, f64)]; 9] = [
            &empty, &one, &flat, &zeros, &bad, &mixed, &huge, &tiny, &close,
        ];
        for log_y in [false, true] {
            for pts in sets {
                for spread in [None, Some(&spread[..]), Some(&spread[..1])] {
                    let series = [
                        Line {
                            label: "s",
                            points: pts,
                            spread,
                        },
                        Line {
                            label: "",
                            points: &empty,
                            spread: None,
                        },
                    ];
                    for hline in [
                        None,
                        Some((0.0, "zero")),
                        Some((nan, "nan")),
                        Some((1e-3, "p")),
                    ] {
                        let p = Panel {
                            hline,
                            ..panel(&series, log_y)
                        };
                        render_ok(&[p], 160, 120);
                        let single = Panel {
                            series: &series[..1],
                            ..panel(&series, log_y)
                        };
                        render_ok(&[single], 160, 120);
                    }
                }
            }
        }
    }

    #[test]
    fn odd_sizes_and_many_panels() {
        let pts = curve(20, 3.0);
        let series = [Line {
            label: "a very long label that will not fit anywhere in such a small chart",
            points: &pts,
            spread: None,
        }];
        let long = "a title far too long for its panel ".repeat(20);
        let p = |log_y| Panel {
            title: &long,
            x_label: "ünïcödé σ² ✓",
            y_label: "",
            series: &series,
            log_y,
            hline: Some((0.5, "ref")),
        };
        for (w, h) in [(1, 1), (7, 300), (300, 7), (60, 40), (121, 81), (2000, 90)] {
            render_ok(&[p(false), p(true)], w, h);
        }
        let many: Vec<Panel<'_>> = (0..40).map(|i| p(i % 2 == 0)).collect();
        render_ok(&many, 400, 300);
        render_ok(&many[..5], 600, 400);
    }

    #[test]
    fn grid_layout() {
        assert_eq!(grid(0), (1, 1));
        assert_eq!(grid(1), (1, 1));
        assert_eq!(grid(3), (3, 1));
        assert_eq!(grid(4), (2, 2));
        assert_eq!(grid(5), (2, 3));
        assert_eq!(grid(7), (3, 3));
        assert_eq!(grid(10), (3, 4));
    }

    #[test]
    fn ticks_are_bounded_and_inside() {
        let axes = [
            Axis::fit([0.0, 1.0].into_iter(), false),
            Axis::fit([-1e300, 1e300].into_iter(), false),
            Axis::fit([1e15, 1e15 + 1e6].into_iter(), false),
            Axis::fit([1e-300, 1e300].into_iter(), true),
            Axis::fit([0.5, 0.6].into_iter(), true),
            Axis::fit([3.0].into_iter(), true),
            Axis::fit([1e-3, 10.0].into_iter(), true),
        ];
        for a in axes {
            assert!(a.lo < a.hi && a.lo.is_finite() && a.hi.is_finite(), "{a:?}");
            for light in [false, true] {
                let t = a.ticks(10, light);
                assert!(t.len() <= 12, "{a:?}: {t:?}");
                assert!(light || t.len() >= 2, "{a:?}: {t:?}");
                for v in t {
                    assert!(v >= a.lo - 1e-9 * a.lo.abs() && v <= a.hi * (1.0 + 1e-9) + 1e-12);
                }
            }
        }
    }

    #[test]
    fn tick_labels_are_short() {
        assert_eq!(tick_label(0.0), "0");
        assert_eq!(tick_label(1.5), "1.5");
        assert_eq!(tick_label(0.1 + 0.2), "0.3");
        assert_eq!(tick_label(1000.5), "1000.5");
        assert_eq!(tick_label(-250.0), "-250");
        assert_eq!(tick_label(1e-5), "1e-5");
        assert_eq!(tick_label(2.5e7), "2.5e7");
        assert_eq!(tick_label(0.00125), "0.00125");
    }

    #[test]
    fn three_panels_of_200_points_with_error_bars_render_quickly() {
        let a = curve(200, 1.0);
        let b = curve(200, 2.0);
        let spread: Vec<f64> = a.iter().map(|p| p.1 * 0.2).collect();
        let series = [
            Line {
                label: "train",
                points: &a,
                spread: Some(&spread),
            },
            Line {
                label: "test",
                points: &b,
                spread: Some(&spread),
            },
        ];
        let panels = [
            Panel {
                hline: Some((0.01, "precision")),
                ..panel(&series, true)
            },
            panel(&series, false),
            panel(&series, true),
        ];
        let start = Instant::now();
        let bytes = render_png(&panels, 800, 900).expect("render");
        let took = start.elapsed();
        let (w, h, _) = decode(&bytes);
        assert_eq!((w, h), (800, 900));
        if let Ok(dir) = std::env::var("PRIMO_PLOT_SAMPLE") {
            std::fs::write(std::path::Path::new(&dir).join("plot-sample.png"), &bytes)
                .expect("write sample");
        }
        assert!(took.as_secs_f64() < 1.0, "took {took:?}");
    }
}
