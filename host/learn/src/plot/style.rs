//! How a series looks: its colour, dash pattern and marker shape, by its place in the
//! panel. Dashes and markers cycle with different periods (3 and 4), so series stay apart
//! in grayscale print too.

use plotters::coord::CoordTranslate;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

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

#[derive(Debug, Clone, Copy, PartialEq)]
enum Dash {
    Solid,
    Dashed,
    Dotted,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Marker {
    Circle,
    Square,
    Triangle,
    Cross,
}

/// The look of the series at index `i` of a panel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Style {
    pub(super) colour: RGBColor,
    dash: Dash,
    marker: Marker,
}

impl Style {
    pub(super) fn of(i: usize) -> Style {
        let colour = match COLOURS.get(i) {
            Some(c) => *c,
            None => {
                let (r, g, b) = Palette99::pick(i).rgb();
                RGBColor(r, g, b)
            }
        };
        Style {
            colour,
            dash: [Dash::Solid, Dash::Dashed, Dash::Dotted][i % 3],
            marker: [
                Marker::Circle,
                Marker::Square,
                Marker::Triangle,
                Marker::Cross,
            ][i % 4],
        }
    }

    /// Draws the polyline `points` in this series' dash pattern, `width` pixels wide.
    pub(super) fn stroke<DB: DrawingBackend, CT: CoordTranslate>(
        &self,
        area: &DrawingArea<DB, CT>,
        points: Vec<CT::From>,
        width: u32,
    ) -> Result<(), String>
    where
        CT::From: Clone,
    {
        let style = self.colour.stroke_width(width);
        // Dash lengths grow with the width, so thick lines keep their pattern.
        let w = width.max(1);
        let (on, off) = match self.dash {
            Dash::Solid => {
                return area
                    .draw(&PathElement::new(points, style))
                    .map_err(super::draw_err);
            }
            Dash::Dashed => (5 * w, 3 * w),
            Dash::Dotted => (w, 2 * w),
        };
        area.draw(&DashedPathElement::new(points, on, off, style))
            .map_err(super::draw_err)
    }

    /// Draws this series' marker centred at `at`, `size` pixels from centre to edge.
    pub(super) fn mark<DB: DrawingBackend, CT: CoordTranslate>(
        &self,
        area: &DrawingArea<DB, CT>,
        at: CT::From,
        size: u32,
    ) -> Result<(), String> {
        let fill = self.colour.filled();
        let s = size as i32;
        let base = EmptyElement::at(at);
        match self.marker {
            Marker::Circle => area.draw(&(base + Circle::new((0, 0), size, fill))),
            Marker::Square => area.draw(&(base + Rectangle::new([(-s, -s), (s, s)], fill))),
            Marker::Triangle => area.draw(&(base + TriangleMarker::new((0, 0), size + 1, fill))),
            Marker::Cross => {
                let line = self.colour.stroke_width(2);
                area.draw(&(base + Cross::new((0, 0), size + 1, line)))
            }
        }
        .map_err(super::draw_err)
    }

    /// Colour of this series' shaded band.
    pub(super) fn band(&self) -> ShapeStyle {
        self.colour.mix(0.18).filled()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neighbouring_series_differ_in_dash_and_marker() {
        for i in 0..30 {
            let (a, b) = (Style::of(i), Style::of(i + 1));
            assert!(a.dash != b.dash && a.marker != b.marker, "{i}");
        }
        assert_eq!(Style::of(0).colour, COLOURS[0]);
    }
}
