//! What a chart shows: series of points, their styles, the axes' scales and labels.

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Style {
    /// A solid line, 2 px wide, in the next colour of the palette.
    Line,
    /// A solid line with a filled circle at each point (at most about 60 markers: a
    /// longer series gets every k-th point marked).
    LineWithMarkers,
    /// A dashed grey line, for reference slopes and other guides (no palette colour).
    Dashed,
}

/// The scale of an axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    /// Linear.
    Linear,
    /// Base-10 logarithmic: only positive values are shown.
    Log,
}

/// One line of a chart.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// The legend entry; an empty label keeps the series out of the legend.
    pub label: String,
    /// The points `(x, y)` in drawing order. Non-finite points, and non-positive
    /// coordinates on a log axis, are not drawn: the line breaks there.
    pub points: Vec<(f64, f64)>,
    /// How it is drawn.
    pub style: Style,
}

impl Series {
    /// A series labelled `label` through `points`, drawn as `style`.
    pub fn new(label: impl Into<String>, points: Vec<(f64, f64)>, style: Style) -> Self {
        Series {
            label: label.into(),
            points,
            style,
        }
    }

    /// A series through `(x[i], y[i])` (the shorter of the two sets the length).
    pub fn from_xy(label: impl Into<String>, x: &[f64], y: &[f64], style: Style) -> Self {
        Series::new(
            label,
            x.iter().copied().zip(y.iter().copied()).collect(),
            style,
        )
    }
}

/// A line chart: title, axis labels and scales, and the series it draws.
#[derive(Clone, Debug, PartialEq)]
pub struct Figure {
    /// The title above the plot (none when empty).
    pub title: String,
    /// The label of the horizontal axis, with its unit, e.g. `t [ms]`.
    pub x_label: String,
    /// The label of the vertical axis, with its unit.
    pub y_label: String,
    /// The scale of the horizontal axis.
    pub x_scale: Scale,
    /// The scale of the vertical axis.
    pub y_scale: Scale,
    /// The series, drawn in order (the first is drawn first, so below the others).
    pub series: Vec<Series>,
}

impl Figure {
    /// An empty figure with linear axes.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        Figure {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            x_scale: Scale::Linear,
            y_scale: Scale::Linear,
            series: Vec::new(),
        }
    }

    /// The same figure with both axes logarithmic.
    pub fn log_log(mut self) -> Self {
        self.x_scale = Scale::Log;
        self.y_scale = Scale::Log;
        self
    }

    /// The same figure with `series` added after the others.
    pub fn with(mut self, series: Series) -> Self {
        self.series.push(series);
        self
    }
}

/// Number of points of a reference slope: enough for a smooth curve on linear axes.
const SLOPE_POINTS: usize = 33;

/// A reference slope line `y = c x^p` (`p = order`) over `x_range`, with `c` chosen
/// so that it passes through `anchor = (x_anchor, y_anchor)`, drawn dashed and
/// labelled `label` (e.g. "order 1").
///
/// Points are spaced geometrically when the range is positive (a straight line on
/// log-log axes), evenly otherwise. An anchor at `x = 0` with a negative order gives
/// non-finite points, which are not drawn.
pub fn reference_slope(label: &str, order: f64, x_range: (f64, f64), anchor: (f64, f64)) -> Series {
    let (x0, x1) = x_range;
    let c = anchor.1 / anchor.0.powf(order);
    let geometric = x0 > 0.0 && x1 > 0.0;
    let n = SLOPE_POINTS - 1;
    let points = (0..=n)
        .map(|i| {
            let s = i as f64 / n as f64;
            let x = if geometric {
                x0 * (x1 / x0).powf(s)
            } else {
                x0 + (x1 - x0) * s
            };
            (x, c * x.powf(order))
        })
        .collect();
    Series::new(label, points, Style::Dashed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reference_slope_passes_through_anchor_with_its_order() {
        let s = reference_slope("order 2", 2.0, (0.01, 1.0), (0.1, 3.0));
        assert_eq!(s.style, Style::Dashed);
        assert_eq!(s.label, "order 2");
        let (xa, ya) = s.points[0];
        let (xb, yb) = *s.points.last().unwrap();
        assert!((xa - 0.01).abs() < 1e-15 && (xb - 1.0).abs() < 1e-12);
        // y = 300 x^2
        assert!((ya - 300.0 * xa * xa).abs() < 1e-12);
        assert!((yb - 300.0).abs() < 1e-9);
        let slope = (yb / ya).ln() / (xb / xa).ln();
        assert!((slope - 2.0).abs() < 1e-12);
    }

    #[test]
    fn builders() {
        let f = Figure::new("T", "x", "y").log_log().with(Series::from_xy(
            "a",
            &[1.0, 2.0],
            &[3.0],
            Style::Line,
        ));
        assert_eq!((f.x_scale, f.y_scale), (Scale::Log, Scale::Log));
        assert_eq!(f.series[0].points, vec![(1.0, 3.0)]);
    }
}
