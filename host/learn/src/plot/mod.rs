//! PNG charts (learning curves and the like), rendered in memory.
//!
//! [`render_png`] draws one or more [`Panel`]s into an RGB buffer with `plotters`' bitmap
//! backend and encodes it with the `png` crate, so callers write the file themselves (e.g.
//! with [`crate::output::write_file`]). Text uses an embedded DejaVu Sans font, so no system
//! font library is needed at build or run time.
//!
//! Any data is accepted: non-finite values, values beyond ±[`MAX_ABS`] and (on a log axis
//! without a floor) values below [`MIN_LOG`] are skipped, lines and bands break where points
//! are skipped, and ranges and tick marks are computed here (`axis`). Each series has its
//! own colour, dash pattern and marker (`style`); the legend never covers data (`legend`).

mod axis;
mod legend;
pub mod panels;
mod style;

use std::sync::OnceLock;

use plotters::backend::RGBPixel;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use axis::{Axis, tick_label};
use legend::{Entry, Ink, Legend, ink_band, ink_path};
use style::Style;

/// One curve: points (x, y), optionally with a shaded band around it.
///
/// Drawn as a line (or only markers: `scatter`) with markers, thinned where the points are
/// too dense to tell apart.
#[derive(Debug, Clone, Copy, Default)]
pub struct Line<'a> {
    /// Legend text (shown when the panel has two series or more).
    pub label: &'a str,
    /// The points, in drawing order; unusable ones (NaN, ±inf, …) are skipped.
    pub points: &'a [(f64, f64)],
    /// A shaded band, `(low, high)` at each point's x (e.g. where 90 % of runs lie); extra
    /// or missing entries are ignored, an unusable one breaks the band.
    pub band: Option<&'a [(f64, f64)]>,
    /// Markers only, no line (e.g. single noisy roll-outs around a mean).
    pub scatter: bool,
}

impl<'a> Line<'a> {
    /// A plain line of `points`, labelled `label`.
    pub fn new(label: &'a str, points: &'a [(f64, f64)]) -> Line<'a> {
        Line {
            label,
            points,
            ..Line::default()
        }
    }
}

/// One chart panel.
#[derive(Debug, Clone, Copy, Default)]
pub struct Panel<'a> {
    /// Caption above the panel (none when empty).
    pub title: &'a str,
    /// Description of the x axis.
    pub x_label: &'a str,
    /// Description of the y axis.
    pub y_label: &'a str,
    /// The curves, each in its own colour, dash pattern and marker.
    pub series: &'a [Line<'a>],
    /// Logarithmic y axis; values below the floor, or without one non-positive values, are
    /// then skipped.
    pub log_y: bool,
    /// On a log axis, the smallest value drawn: smaller ones, zero included, are drawn at it,
    /// and the y axis' description says so. Ignored on a linear axis, or when not a usable
    /// log value.
    pub floor: Option<f64>,
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
static FONT_BYTES: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

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

/// Rows and columns [`render_png`] lays `n` panels out in: a column up to 3 panels, then
/// a near-square grid.
pub fn grid(n: usize) -> (usize, usize) {
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
    /// Runs of band samples `(x, low, high)`; `low` is −∞ where it falls off a log axis
    /// without a floor (drawn down to the axis).
    bands: Vec<Vec<(f64, f64, f64)>>,
}

fn usable(v: f64, log: bool) -> bool {
    v.is_finite() && v.abs() <= MAX_ABS && (!log || v >= MIN_LOG)
}

/// The y values a panel can draw.
#[derive(Clone, Copy)]
struct Scale {
    log: bool,
    floor: Option<f64>,
}

impl Scale {
    fn of(panel: &Panel<'_>) -> Scale {
        Scale {
            log: panel.log_y,
            floor: panel.floor.filter(|f| panel.log_y && usable(*f, true)),
        }
    }

    /// Where `v` is drawn, if at all.
    fn y(&self, v: f64) -> Option<f64> {
        if !usable(v, false) {
            return None;
        }
        match self.floor {
            Some(f) if v < f => Some(f),
            _ => (!self.log || v >= MIN_LOG).then_some(v),
        }
    }
}

/// Splits `items` into runs of consecutive `Some`s.
fn runs<T>(items: impl Iterator<Item = Option<T>>) -> Vec<Vec<T>> {
    let mut out: Vec<Vec<T>> = vec![Vec::new()];
    for item in items {
        match (item, out.last_mut()) {
            (Some(v), Some(run)) => run.push(v),
            (None, Some(run)) if !run.is_empty() => out.push(Vec::new()),
            _ => {}
        }
    }
    out.retain(|r| !r.is_empty());
    out
}

fn clean(s: &Line<'_>, scale: Scale) -> Clean {
    let x = |x: f64| usable(x, false).then_some(x);
    let points = s
        .points
        .iter()
        .map(|&(px, py)| Some((x(px)?, scale.y(py)?)));
    let band = s
        .band
        .unwrap_or_default()
        .iter()
        .zip(s.points)
        .map(|(&(lo, hi), &(px, _))| {
            if lo.is_nan() || hi.is_nan() {
                return None; // `min` and `max` would drop a NaN
            }
            let (lo, hi) = (lo.min(hi), lo.max(hi));
            let low = match scale.y(lo) {
                Some(v) => v,
                // Finite but below a log axis: the band reaches down to the axis.
                None if lo.is_finite() && hi.is_finite() => f64::NEG_INFINITY,
                None => return None,
            };
            Some((x(px)?, low, scale.y(hi)?))
        });
    Clean {
        runs: runs(points),
        bands: runs(band),
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
    let scale = Scale::of(panel);
    let cleaned: Vec<Clean> = panel.series.iter().map(|s| clean(s, scale)).collect();
    let hline = panel.hline.filter(|(y, _)| usable(*y, panel.log_y));

    let xs = cleaned.iter().flat_map(|c| {
        let pts = c.runs.iter().flatten().map(|p| p.0);
        pts.chain(c.bands.iter().flatten().map(|b| b.0))
    });
    let x_axis = Axis::fit(xs, false);
    let ys = cleaned.iter().flat_map(|c| {
        let pts = c.runs.iter().flatten().map(|p| p.1);
        let band = c.bands.iter().flatten().flat_map(|b| [b.1, b.2]);
        pts.chain(band.filter(|v| v.is_finite()))
    });
    let y_axis = Axis::fit(ys.chain(hline.map(|h| h.0)), panel.log_y);

    // Decorations only when the panel is big enough to hold them.
    let full = pw >= 120 && ph >= 80;
    let fs = (f64::from(pw.min(ph)) / 22.0).clamp(8.0, 18.0);
    let n_x = (f64::from(pw) / (fs * 7.0)).clamp(2.0, 10.0) as usize;
    let n_y = (f64::from(ph) / (fs * 3.0)).clamp(2.0, 10.0) as usize;
    let margin = if full { (fs * 0.6) as u32 } else { 2 };
    // A long title shrinks to the panel's width rather than run off it.
    let title_fs = fit(
        area,
        panel.title,
        (7.0, fs * 1.25),
        pw.saturating_sub(2 * margin),
    );
    let title_h =
        match area.estimate_text_size(panel.title, &(FONT, title_fs).into_text_style(area)) {
            Ok((_, h)) if full && !panel.title.is_empty() => h + 2 * (h / 2).min(5),
            _ => 0,
        };
    let y_desc = match scale.floor {
        Some(f) => format!(
            "{}  (< {} drawn at {})",
            panel.y_label,
            tick_label(f),
            tick_label(f)
        ),
        None => panel.y_label.to_string(),
    };
    // Wide enough for the longest y tick label plus the rotated axis description.
    let chars = y_axis
        .ticks(n_y, false)
        .iter()
        .map(|v| tick_label(*v).chars().count())
        .max()
        .unwrap_or(1);
    let y_area = ((chars as f64 * 0.6 + 2.5) * fs).min(f64::from(pw) / 3.0) as u32;
    let x_area = (fs * 3.2) as u32;

    // The plot's size, as the chart builder will lay it out (less the legend's strip).
    let plot = (
        pw.saturating_sub(2 * margin + y_area),
        ph.saturating_sub(2 * margin + title_h + x_area),
    );
    let legend = if full && panel.series.len() >= 2 {
        let entries = panel
            .series
            .iter()
            .enumerate()
            .map(|(i, s)| Entry {
                label: s.label,
                style: Style::of(i),
                line: !s.scatter,
                band: s.band.is_some(),
            })
            .collect();
        let legend = Legend::new(area, entries, fs)?;
        let spot = legend.place(&ink(&cleaned, hline, x_axis, y_axis), plot);
        Some((legend, spot))
    } else {
        None
    };
    let strip = legend.as_ref().map_or(0, |(l, spot)| l.strip(spot));
    // A long axis description shrinks to the plot's height, a little: the x axis' shrinks
    // with it.
    let desc_fs = fit(area, &y_desc, (0.8 * fs, fs), plot.1.saturating_sub(strip));

    // The title and the legend's strip above the plot are laid out here: a top label area
    // of the chart builder would get tick labels too.
    let mut inner = area.margin(margin, margin, margin, margin);
    if full && !panel.title.is_empty() {
        inner = inner
            .titled(panel.title, (FONT, title_fs))
            .map_err(draw_err)?;
    }
    if strip > 0 {
        inner = inner.split_vertically(strip).1;
    }
    let mut builder = ChartBuilder::on(&inner);
    if full {
        builder.x_label_area_size(x_area).y_label_area_size(y_area);
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
            .y_desc(y_desc)
            .label_style((FONT, fs))
            .axis_desc_style((FONT, desc_fs))
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

    let plot = chart.plotting_area();
    // Every band under every line, so no band hides another series' line.
    for (i, c) in cleaned.iter().enumerate() {
        for band in &c.bands {
            let lo = |v: f64| if v.is_finite() { v } else { y_axis.lo };
            let upper = band.iter().map(|b| (b.0, b.2));
            let lower = band.iter().rev().map(|b| (b.0, lo(b.1)));
            let outline: Vec<(f64, f64)> = upper.chain(lower).collect();
            plot.draw(&Polygon::new(outline, Style::of(i).band()))
                .map_err(draw_err)?;
        }
    }
    let marker = if full {
        (fs / 5.0).clamp(2.0, 4.0) as u32
    } else {
        1
    };
    let plot_w = f64::from(plot.dim_in_pixel().0.max(1));
    let n_series = cleaned.len().max(1);
    for (i, (series, c)) in panel.series.iter().zip(&cleaned).enumerate() {
        let style = Style::of(i);
        if !series.scatter {
            for run in &c.runs {
                style.stroke(plot, run.clone(), 2)?;
            }
        }
        // Pixels between neighbouring points: a dense line gets a marker every few points
        // (at an offset per series, so markers of different series do not coincide).
        let n = c.runs.iter().map(Vec::len).sum::<usize>().max(1);
        let gap = plot_w / n as f64;
        let every = if series.scatter {
            1
        } else {
            (f64::from(marker * 8) / gap).ceil().max(1.0) as usize
        };
        let offset = i * every / n_series;
        for p in c.runs.iter().flatten().skip(offset).step_by(every) {
            style.mark(plot, *p, marker)?;
        }
    }

    if let Some((legend, spot)) = legend {
        let (x0, y0) = plot.get_base_pixel();
        let (ax, ay) = area.get_base_pixel();
        legend.draw(area, &spot, (x0 - ax, y0 - ay), plot.dim_in_pixel())?;
    }
    Ok(())
}

/// The font size from `least` to `size` at which `text` fits `room` pixels best (text
/// measurement is approximate: a tenth is kept spare).
fn fit<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    text: &str,
    (least, size): (f64, f64),
    room: u32,
) -> f64 {
    match area.estimate_text_size(text, &(FONT, size).into_text_style(area)) {
        Ok((w, _)) if w > 0 => {
            let scale = 0.9 * f64::from(room) / f64::from(w);
            (size * scale.min(1.0)).max(least)
        }
        _ => size,
    }
}

/// Where the panel's data lie, in fractions of the plot, for placing the legend.
fn ink(cleaned: &[Clean], hline: Option<(f64, &str)>, x: Axis, y: Axis) -> Ink {
    let frac = |a: Axis, v: f64| {
        let (lo, hi) = (a.lin(a.lo), a.lin(a.hi));
        if v.is_finite() {
            (a.lin(v) - lo) / (hi - lo)
        } else {
            0.0 // a band down to the axis
        }
    };
    let mut ink = Ink::new();
    for c in cleaned {
        for run in &c.runs {
            let pts: Vec<(f64, f64)> = run.iter().map(|p| (frac(x, p.0), frac(y, p.1))).collect();
            ink_path(&mut ink, &pts);
        }
        for band in &c.bands {
            let b: Vec<(f64, f64, f64)> = band
                .iter()
                .map(|b| (frac(x, b.0), frac(y, b.1), frac(y, b.2)))
                .collect();
            ink_band(&mut ink, &b);
        }
    }
    if let Some((v, _)) = hline {
        ink_path(&mut ink, &[(0.0, frac(y, v)), (1.0, frac(y, v))]);
    }
    ink
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
            ..Panel::default()
        }
    }

    fn curve(n: usize, scale: f64) -> Vec<(f64, f64)> {
        (0..n)
            .map(|i| (i as f64, scale * (-(i as f64) / 50.0).exp() + 1e-3))
            .collect()
    }

    fn has(px: &[u8], c: RGBColor) -> bool {
        px.chunks(3).any(|p| p == [c.0, c.1, c.2])
    }

    #[test]
    fn decodes_to_requested_size_and_draws_something() {
        let pts = curve(50, 1.0);
        let series = [Line::new("a", &pts)];
        let px = render_ok(&[panel(&series, false)], 320, 240);
        assert!(px.iter().any(|&b| b != 255), "not blank");
        // The curve's colour appears somewhere.
        assert!(has(&px, Style::of(0).colour));
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
        let band = [
            (nan, 1.0),
            (-1.0, inf),
            (0.0, 1e308),
            (2.0, 1.0),
            (-inf, -1e300),
        ];
        let sets: [&[(f64, f64)]; 9] = [
            &empty, &one, &flat, &zeros, &bad, &mixed, &huge, &tiny, &close,
        ];
        for log_y in [false, true] {
            for pts in sets {
                for (band, floor) in [
                    (None, None),
                    (Some(&band[..]), Some(1e-3)),
                    (Some(&band[..1]), Some(nan)),
                    (Some(pts), Some(0.0)),
                    (Some(&band[..]), Some(-inf)),
                ] {
                    for scatter in [false, true] {
                        let series = [
                            Line {
                                band,
                                scatter,
                                ..Line::new("s", pts)
                            },
                            Line::new("", &empty),
                        ];
                        for hline in [
                            None,
                            Some((0.0, "zero")),
                            Some((nan, "nan")),
                            Some((1e-3, "p")),
                        ] {
                            let p = Panel {
                                hline,
                                floor,
                                ..panel(&series, log_y)
                            };
                            render_ok(&[p], 160, 120);
                            let single = Panel {
                                series: &series[..1],
                                ..p
                            };
                            render_ok(&[single], 160, 120);
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn a_floor_draws_zeros_on_a_log_axis_and_says_so() {
        let zeros = [(0.0, 0.0), (1.0, 0.0), (2.0, 0.0)];
        let series = [Line::new("spill", &zeros)];
        let bare = render_ok(&[panel(&series, true)], 320, 240);
        assert!(!has(&bare, Style::of(0).colour), "zeros off a log axis");
        let floored = Panel {
            floor: Some(0.01),
            ..panel(&series, true)
        };
        assert!(has(&render_ok(&[floored], 320, 240), Style::of(0).colour));
        assert_eq!(Scale::of(&floored).y(-1.0), Some(0.01));
        assert_eq!(Scale::of(&floored).y(0.5), Some(0.5));
        assert_eq!(Scale::of(&floored).y(f64::NAN), None);
        // No floor on a linear axis, nor an unusable one.
        for (log_y, floor) in [(false, 0.01), (true, 0.0), (true, f64::INFINITY)] {
            let p = Panel {
                floor: Some(floor),
                ..panel(&series, log_y)
            };
            assert_eq!(Scale::of(&p).floor, None);
        }
    }

    #[test]
    fn bands_break_where_unusable_and_reach_down_to_a_log_axis() {
        let pts = [(0.0, 1.0), (1.0, 1.0), (2.0, 1.0), (3.0, 1.0)];
        let band = [(0.5, 2.0), (f64::NAN, 2.0), (0.0, 2.0), (0.5, 1.5)];
        let s = Line {
            band: Some(&band),
            ..Line::new("m", &pts)
        };
        let linear = clean(&s, Scale::of(&panel(&[], false)));
        assert_eq!(
            linear.bands,
            vec![
                vec![(0.0, 0.5, 2.0)],
                vec![(2.0, 0.0, 2.0), (3.0, 0.5, 1.5)]
            ]
        );
        let log = clean(&s, Scale::of(&panel(&[], true)));
        assert_eq!(log.bands[1][0], (2.0, f64::NEG_INFINITY, 2.0));
        // A band without a line still shows.
        let series = [s, Line::new("other", &pts)];
        let px = render_ok(&[panel(&series, true)], 320, 240);
        // The band: the first series' colour over white, at the band's opacity.
        let c = Style::of(0).colour;
        let tint = [c.0, c.1, c.2].map(|v| 255.0 - 0.18 * (255.0 - f64::from(v)));
        let near = |p: &[u8]| {
            p.iter()
                .zip(tint)
                .all(|(v, t)| (f64::from(*v) - t).abs() < 3.0)
        };
        assert!(px.chunks(3).any(near));
    }

    #[test]
    fn odd_sizes_and_many_panels() {
        let pts = curve(20, 3.0);
        let series = [
            Line::new(
                "a very long label that will not fit anywhere in such a small chart",
                &pts,
            ),
            Line::new("another", &pts),
        ];
        let long = "a title far too long for its panel ".repeat(20);
        let p = |log_y| Panel {
            title: &long,
            x_label: "ünïcödé σ² ✓",
            y_label: "",
            series: &series,
            log_y,
            floor: Some(1e-3),
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
    fn three_panels_of_200_points_with_bands_render_quickly() {
        let a = curve(200, 1.0);
        let b = curve(200, 2.0);
        let band: Vec<(f64, f64)> = a.iter().map(|p| (p.1 * 0.8, p.1 * 1.2)).collect();
        let noisy: Vec<(f64, f64)> = (0..200)
            .map(|i| (i as f64, ((i * 37 % 11) as f64) / 10.0))
            .collect();
        let series = [
            Line {
                band: Some(&band),
                ..Line::new("train", &a)
            },
            Line {
                band: Some(&band),
                ..Line::new("test", &b)
            },
            Line {
                scatter: true,
                ..Line::new("single", &noisy)
            },
        ];
        let panels = [
            Panel {
                hline: Some((0.01, "precision")),
                floor: Some(1e-3),
                ..panel(&series, true)
            },
            panel(&series, false),
            panel(&series[..2], true),
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
