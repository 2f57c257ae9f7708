//! The legend: boxed in the first corner of the plot that its data leave empty, else in a
//! strip between the title and the plot, so it never covers data.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::style::Style;
use super::{FONT, draw_err};

/// What a panel's data cover, in fractions of the plot (0 to 1, y up): vertical spans
/// `(x, low, high)`; a point of a line is a span of no height.
pub(super) type Ink = Vec<(f64, f64, f64)>;

/// Samples the polyline `points` (plot fractions) into `ink`, densely enough that no
/// legend box fits between two samples.
pub(super) fn ink_path(ink: &mut Ink, points: &[(f64, f64)]) {
    if let [only] = points {
        ink.push((only.0, only.1, only.1));
    }
    for w in points.windows(2) {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        let n = ((x1 - x0).hypot(y1 - y0) / STEP).ceil().clamp(1.0, 500.0) as usize;
        for k in 0..=n {
            let t = k as f64 / n as f64;
            let y = y0 + t * (y1 - y0);
            ink.push((x0 + t * (x1 - x0), y, y));
        }
    }
}

/// Samples a band `(x, low, high)` (plot fractions) into `ink`.
pub(super) fn ink_band(ink: &mut Ink, band: &[(f64, f64, f64)]) {
    if let [only] = band {
        ink.push(*only);
    }
    for w in band.windows(2) {
        let ((x0, l0, h0), (x1, l1, h1)) = (w[0], w[1]);
        let n = ((x1 - x0).abs() / STEP).ceil().clamp(1.0, 500.0) as usize;
        for k in 0..=n {
            let t = k as f64 / n as f64;
            let mix = |a: f64, b: f64| a + t * (b - a);
            ink.push((mix(x0, x1), mix(l0, l1), mix(h0, h1)));
        }
    }
}

/// Sampling step along paths, in plot fractions.
const STEP: f64 = 0.004;

/// One entry: a sample of the series' line (or only its marker) and band, and its label.
pub(super) struct Entry<'a> {
    pub(super) label: &'a str,
    pub(super) style: Style,
    pub(super) line: bool,
    pub(super) band: bool,
}

/// Where the legend goes.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Spot {
    /// Boxed inside the plot, in this corner.
    Corner { right: bool, top: bool },
    /// Above the plot, the entries of each row by index.
    Above(Vec<Vec<usize>>),
}

/// A panel's legend, measured.
pub(super) struct Legend<'a> {
    entries: Vec<Entry<'a>>,
    /// Each label's width in pixels.
    widths: Vec<u32>,
    fs: f64,
}

impl<'a> Legend<'a> {
    /// Measures the labels of `entries` at font size `fs`.
    pub(super) fn new<DB: DrawingBackend>(
        area: &DrawingArea<DB, Shift>,
        entries: Vec<Entry<'a>>,
        fs: f64,
    ) -> Result<Legend<'a>, String> {
        let font = (FONT, fs).into_text_style(area);
        let widths = entries
            .iter()
            .map(|e| area.estimate_text_size(e.label, &font).map(|s| s.0))
            .collect::<Result<_, _>>()
            .map_err(draw_err)?;
        Ok(Legend {
            entries,
            widths,
            fs,
        })
    }

    fn pad(&self) -> u32 {
        (self.fs * 0.5) as u32
    }

    fn row_h(&self) -> u32 {
        (self.fs * 1.4) as u32
    }

    fn sample_w(&self) -> u32 {
        (self.fs * 2.4) as u32
    }

    fn entry_w(&self, i: usize) -> u32 {
        self.sample_w() + self.pad() + self.widths.get(i).copied().unwrap_or(0)
    }

    /// The boxed list's size in pixels.
    fn box_size(&self) -> (u32, u32) {
        let w = (0..self.entries.len()).map(|i| self.entry_w(i)).max();
        let rows = self.entries.len() as u32;
        (
            w.unwrap_or(0) + 2 * self.pad(),
            rows * self.row_h() + 2 * self.pad(),
        )
    }

    /// The entries in rows that fit `width` pixels, at least one entry a row.
    fn rows(&self, width: u32) -> Vec<Vec<usize>> {
        let gap = 2 * self.pad();
        let mut rows: Vec<Vec<usize>> = Vec::new();
        let mut used = 0;
        for i in 0..self.entries.len() {
            let w = self.entry_w(i);
            match rows.last_mut() {
                Some(row) if used + gap + w <= width => {
                    row.push(i);
                    used += gap + w;
                }
                _ => {
                    rows.push(vec![i]);
                    used = w;
                }
            }
        }
        rows
    }

    /// The first corner (upper right, upper left, lower right, lower left) where the box
    /// covers none of `ink` in a plot of `plot` pixels, else rows above it.
    pub(super) fn place(&self, ink: &[(f64, f64, f64)], plot: (u32, u32)) -> Spot {
        let (w, h) = (f64::from(plot.0.max(1)), f64::from(plot.1.max(1)));
        let (bw, bh) = self.box_size();
        // The box, its inset from the axes and a few pixels' clearance around it.
        let clear = f64::from(2 * self.pad() + 4);
        let (fw, fh) = ((f64::from(bw) + clear) / w, (f64::from(bh) + clear) / h);
        if fw <= 0.6 && fh <= 0.8 {
            for (right, top) in [(true, true), (false, true), (true, false), (false, false)] {
                let (x0, y0) = (
                    if right { 1.0 - fw } else { 0.0 },
                    if top { 1.0 - fh } else { 0.0 },
                );
                let (x1, y1) = (x0 + fw, y0 + fh);
                let hit =
                    |&(x, lo, hi): &(f64, f64, f64)| x >= x0 && x <= x1 && hi >= y0 && lo <= y1;
                if !ink.iter().any(hit) {
                    return Spot::Corner { right, top };
                }
            }
        }
        Spot::Above(self.rows(plot.0))
    }

    /// Height of the strip above the plot that `spot` needs (0 for a corner).
    pub(super) fn strip(&self, spot: &Spot) -> u32 {
        match spot {
            Spot::Corner { .. } => 0,
            Spot::Above(rows) => rows.len() as u32 * self.row_h() + self.pad(),
        }
    }

    /// Draws the legend at `spot` on `area`, whose plot starts at `origin` (pixels from
    /// the area's corner) and is `plot` pixels large.
    pub(super) fn draw<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        spot: &Spot,
        origin: (i32, i32),
        plot: (u32, u32),
    ) -> Result<(), String> {
        let (pad, row_h) = (self.pad() as i32, self.row_h() as i32);
        match spot {
            Spot::Corner { right, top } => {
                let (bw, bh) = self.box_size();
                let (bw, bh) = (bw as i32, bh as i32);
                let x = if *right {
                    origin.0 + plot.0 as i32 - pad - bw
                } else {
                    origin.0 + pad
                };
                let y = if *top {
                    origin.1 + pad
                } else {
                    origin.1 + plot.1 as i32 - pad - bh
                };
                let corners = [(x, y), (x + bw, y + bh)];
                area.draw(&Rectangle::new(corners, WHITE.mix(0.9).filled()))
                    .map_err(draw_err)?;
                area.draw(&Rectangle::new(corners, RGBColor(160, 160, 160)))
                    .map_err(draw_err)?;
                for i in 0..self.entries.len() {
                    let cy = y + pad + row_h * i as i32 + row_h / 2;
                    self.entry(area, i, (x + pad, cy))?;
                }
            }
            Spot::Above(rows) => {
                let top = origin.1 - self.strip(spot) as i32;
                for (r, row) in rows.iter().enumerate() {
                    let cy = top + row_h * r as i32 + row_h / 2;
                    let mut x = origin.0;
                    for &i in row {
                        self.entry(area, i, (x, cy))?;
                        x += (self.entry_w(i) + 2 * self.pad()) as i32;
                    }
                }
            }
        }
        Ok(())
    }

    /// Draws entry `i` with its sample starting at `at` (its vertical centre).
    fn entry<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        i: usize,
        at: (i32, i32),
    ) -> Result<(), String> {
        let Some(e) = self.entries.get(i) else {
            return Ok(());
        };
        let (x, y) = at;
        let sw = self.sample_w() as i32;
        if e.band {
            let h = (self.fs * 0.45) as i32;
            area.draw(&Rectangle::new(
                [(x, y - h), (x + sw, y + h)],
                e.style.band(),
            ))
            .map_err(draw_err)?;
        }
        if e.line {
            e.style.stroke(area, vec![(x, y), (x + sw, y)], 2)?;
        }
        e.style.mark(
            area,
            (x + sw / 2, y),
            (self.fs / 5.0).clamp(2.0, 4.0) as u32,
        )?;
        let text = TextStyle::from((FONT, self.fs).into_font())
            .color(&RGBColor(30, 30, 30))
            .pos(Pos::new(HPos::Left, VPos::Center));
        let at = (x + sw + self.pad() as i32, y);
        area.draw(&Text::new(e.label.to_string(), at, text))
            .map_err(draw_err)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn legend(labels: &[&'static str]) -> Legend<'static> {
        Legend {
            entries: labels
                .iter()
                .enumerate()
                .map(|(i, label)| Entry {
                    label,
                    style: Style::of(i),
                    line: true,
                    band: false,
                })
                .collect(),
            widths: labels.iter().map(|l| 8 * l.len() as u32).collect(),
            fs: 14.0,
        }
    }

    #[test]
    fn the_legend_goes_where_the_data_are_not() {
        let l = legend(&["a", "b"]);
        let plot = (800, 400);
        let along = |points: &[(f64, f64)]| {
            let mut ink = Ink::new();
            ink_path(&mut ink, points);
            l.place(&ink, plot)
        };
        // A curve falling from the upper left to the lower right leaves the upper right
        // empty only once it has fallen; a rising one, the upper left.
        let (right, left) = (
            Spot::Corner {
                right: true,
                top: true,
            },
            Spot::Corner {
                right: false,
                top: true,
            },
        );
        assert_eq!(along(&[(0.0, 1.0), (0.2, 0.1), (1.0, 0.0)]), right);
        assert_eq!(along(&[(0.0, 0.0), (0.8, 0.9), (1.0, 1.0)]), left);
        // A band over the whole plot: above it.
        let mut ink = Ink::new();
        ink_band(&mut ink, &[(0.0, 0.0, 1.0), (1.0, 0.0, 1.0)]);
        let above = l.place(&ink, plot);
        assert_eq!(above, Spot::Above(vec![vec![0, 1]]));
        assert!(l.strip(&above) > 0);
        // No data: any corner.
        assert!(matches!(l.place(&[], plot), Spot::Corner { .. }));
    }

    #[test]
    fn rows_above_wrap_to_the_width() {
        let l = legend(&["first label", "second label", "third label"]);
        assert_eq!(l.rows(10_000), vec![vec![0, 1, 2]]);
        assert_eq!(l.rows(300), vec![vec![0, 1], vec![2]]);
        assert_eq!(l.rows(1), vec![vec![0], vec![1], vec![2]]);
    }
}
