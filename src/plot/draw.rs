//! Drawing a [`Figure`] to PNG and SVG with plotters.
//!
//! Text uses DejaVu Sans, embedded in the binary (`assets/fonts/`) and registered
//! with plotters once under the family name `sans-serif`, so charts render the same
//! on a machine without system fonts.

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Once;

use ab_glyph::FontRef;
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::register_font;

use super::axis::{usable, Axis, TICKS};
use super::figure::{Figure, Scale, Series, Style};
use super::text::GlyphText;
use crate::error::{Error, Result};

/// Width and height of the PNG (and of the SVG's canvas), in pixels.
pub const SIZE: (u32, u32) = (1200, 800);

/// The font family every text of a chart uses.
const FAMILY: &str = "sans-serif";
/// Font sizes in pixels, readable when 1200 px are printed at column width.
const TITLE_PX: u32 = 36;
const LABEL_PX: u32 = 28;
const TICK_PX: u32 = 22;
const LEGEND_PX: u32 = 22;

/// Line width of a series, in pixels.
const LINE_PX: u32 = 2;
/// Marker radius of [`Style::LineWithMarkers`], in pixels.
const MARKER_PX: u32 = 5;
/// At most about this many markers per series.
const MAX_MARKERS: usize = 60;

/// DejaVu Sans (see `assets/fonts/LICENSE-DejaVu.txt`).
static FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
static REGISTER: Once = Once::new();
static REGISTERED: AtomicBool = AtomicBool::new(false);

/// Tableau 10 without its grey (kept for dashed reference lines).
const PALETTE: [RGBColor; 9] = [
    RGBColor(0x1f, 0x77, 0xb4),
    RGBColor(0xff, 0x7f, 0x0e),
    RGBColor(0x2c, 0xa0, 0x2c),
    RGBColor(0xd6, 0x27, 0x28),
    RGBColor(0x94, 0x67, 0xbd),
    RGBColor(0x8c, 0x56, 0x4b),
    RGBColor(0xe3, 0x77, 0xc2),
    RGBColor(0xbc, 0xbd, 0x22),
    RGBColor(0x17, 0xbe, 0xcf),
];
/// Greys and dash patterns (dash, gap) of successive dashed series.
const DASHED: [(RGBColor, u32, u32); 3] = [
    (RGBColor(0x55, 0x55, 0x55), 14, 8),
    (RGBColor(0x88, 0x88, 0x88), 6, 6),
    (RGBColor(0x33, 0x33, 0x33), 22, 6),
];

/// Registers the embedded font under [`FAMILY`], once per process.
fn ensure_font() -> std::result::Result<(), String> {
    REGISTER.call_once(|| {
        let ok = register_font(FAMILY, FontStyle::Normal, FONT).is_ok();
        REGISTERED.store(ok, Ordering::SeqCst);
    });
    if REGISTERED.load(Ordering::SeqCst) {
        Ok(())
    } else {
        Err("the embedded DejaVu Sans font could not be loaded".into())
    }
}

/// `stem` with `.ext` appended (not replacing an extension-like part of the stem).
fn with_suffix(stem: &Path, ext: &str) -> PathBuf {
    let mut s: OsString = stem.as_os_str().to_owned();
    s.push(".");
    s.push(ext);
    PathBuf::from(s)
}

/// Draws `fig` to `<stem>.png` (1200x800 px) and `<stem>.svg`; returns both paths.
///
/// The parent directory of `stem` is created if missing. Axis ranges come from the
/// drawable points (finite, and positive on a log axis) with a small margin; a
/// figure with none still draws, over a placeholder range.
pub fn draw(fig: &Figure, stem: &Path) -> Result<[PathBuf; 2]> {
    let png = with_suffix(stem, "png");
    let svg = with_suffix(stem, "svg");
    if let Some(dir) = stem.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    }
    let fail = |path: &Path, msg: String| Error::io(path, std::io::Error::other(msg));
    ensure_font().map_err(|m| fail(&png, m))?;
    let plan = Plan::new(fig);
    {
        let font = FontRef::try_from_slice(FONT).map_err(|e| fail(&png, e.to_string()))?;
        let root = GlyphText::new(BitMapBackend::new(&png, SIZE), font).into_drawing_area();
        render(&root, fig, &plan).map_err(|e| fail(&png, format!("drawing failed: {e}")))?;
    }
    {
        let root = SVGBackend::new(&svg, SIZE).into_drawing_area();
        render(&root, fig, &plan).map_err(|e| fail(&svg, format!("drawing failed: {e}")))?;
    }
    Ok([png, svg])
}

/// What is drawn: the axes and, per series, its unbroken runs of drawable points.
struct Plan {
    x: Axis,
    y: Axis,
    runs: Vec<Vec<Vec<(f64, f64)>>>,
}

impl Plan {
    fn new(fig: &Figure) -> Plan {
        let ok = |&(x, y): &(f64, f64)| usable(fig.x_scale, x) && usable(fig.y_scale, y);
        let runs: Vec<Vec<Vec<(f64, f64)>>> = fig
            .series
            .iter()
            .map(|s| {
                let mut runs = vec![];
                let mut run = vec![];
                for p in &s.points {
                    if ok(p) {
                        run.push(*p);
                    } else if !run.is_empty() {
                        runs.push(std::mem::take(&mut run));
                    }
                }
                if !run.is_empty() {
                    runs.push(run);
                }
                runs
            })
            .collect();
        let all = || runs.iter().flatten().flatten();
        Plan {
            x: Axis::from_values(fig.x_scale, all().map(|p| p.0)),
            y: Axis::from_values(fig.y_scale, all().map(|p| p.1)),
            runs,
        }
    }
}

impl Plan {
    /// The y axis with the lines in the lower share `q` of its height.
    fn y_with_headroom(&self, scale: Scale, q: f64) -> Axis {
        let ys = || self.runs.iter().flatten().flatten().map(|p| p.1);
        let lo = ys().fold(f64::INFINITY, f64::min);
        let hi = ys().fold(f64::NEG_INFINITY, f64::max);
        if lo >= hi {
            return self.y.clone();
        }
        let top = match scale {
            Scale::Linear => lo + (hi - lo) / q,
            Scale::Log => lo * (hi / lo).powf(1.0 / q),
        };
        Axis::from_values(scale, ys().chain([top]))
    }
}

/// Colour, width and dash pattern of each series, in order.
fn looks(series: &[Series]) -> Vec<(RGBColor, Option<(u32, u32)>)> {
    let (mut colour, mut dashed) = (0, 0);
    series
        .iter()
        .map(|s| match s.style {
            Style::Dashed => {
                let (c, dash, gap) = DASHED[dashed % DASHED.len()];
                dashed += 1;
                (c, Some((dash, gap)))
            }
            Style::Line | Style::LineWithMarkers => {
                colour += 1;
                (PALETTE[(colour - 1) % PALETTE.len()], None)
            }
        })
        .collect()
}

/// Margins around the plot (the title above them), in pixels.
const MARGIN: u32 = 24;
const MARGIN_RIGHT: u32 = 48;
/// Height of the area under the plot: tick labels and the axis label.
const X_AREA: u32 = TICK_PX + LABEL_PX + 28;
/// Width of a legend entry's line sample and the legend's inner margin.
const LEGEND_SAMPLE: u32 = 52;
const LEGEND_MARGIN: u32 = 12;

/// Width of the area left of the plot: the widest tick label of `y`, the rotated
/// axis label and gaps.
fn y_area<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    y: &Axis,
    font: &TextStyle<'_>,
) -> std::result::Result<u32, DrawingAreaErrorKind<DB::ErrorType>> {
    let mut widest = 0;
    for v in y.ticks() {
        widest = widest.max(area.estimate_text_size(&y.label(*v), font)?.0);
    }
    Ok(widest + LABEL_PX + 36)
}

/// Draws the whole chart on `root` and presents it (writes the file).
fn render<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    fig: &Figure,
    plan: &Plan,
) -> std::result::Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    root.fill(&WHITE)?;
    let title_font = (FAMILY, TITLE_PX).into_font();
    let label_font = (FAMILY, LABEL_PX).into_font();
    let tick_font: TextStyle = (FAMILY, TICK_PX).into_font().into();
    let legend_font: TextStyle = (FAMILY, LEGEND_PX).into_font().into();

    let area = if fig.title.is_empty() {
        root.clone()
    } else {
        root.margin(12, 0, 0, 0).titled(&fig.title, title_font)?
    };

    // The legend: inside the plot where it hides no line, else above the lines in
    // head room made at the top of the y range.
    let mut y = plan.y.clone();
    let mut legend = None;
    let labels: Vec<&str> = fig
        .series
        .iter()
        .map(|s| s.label.as_str())
        .filter(|l| !l.is_empty())
        .collect();
    if !labels.is_empty() {
        let mut text_w = 0;
        for l in &labels {
            text_w = text_w.max(area.estimate_text_size(l, &legend_font)?.0);
        }
        // The box as plotters lays it out: lines 1.25 font sizes apart, the last
        // one as high as the font's layout box.
        let bw = f64::from(text_w + LEGEND_SAMPLE + 2 * LEGEND_MARGIN);
        let bh = f64::from(LEGEND_PX) * (1.25 * (labels.len() - 1) as f64 + 1.0 / 1.24)
            + f64::from(2 * LEGEND_MARGIN);
        let (w, h) = area.dim_in_pixel();
        let pw =
            f64::from(w.saturating_sub(MARGIN + MARGIN_RIGHT + y_area(&area, &y, &tick_font)?));
        let ph = f64::from(h.saturating_sub(2 * MARGIN + X_AREA));
        let (pos, covered) = legend_place(plan, (pw, ph), (bw + 10.0, bh + 10.0));
        legend = Some(pos);
        if covered > 0 && ph > 0.0 {
            // The box is 5 px below the top; 12 px more between it and the lines.
            y = plan.y_with_headroom(fig.y_scale, ((ph - bh - 17.0) / ph).max(0.4));
            legend = Some(SeriesLabelPosition::UpperRight);
        }
    }

    let y_area = y_area(&area, &y, &tick_font)?;
    let mut chart = ChartBuilder::on(&area)
        .margin(MARGIN)
        .margin_right(MARGIN_RIGHT)
        .x_label_area_size(X_AREA)
        .y_label_area_size(y_area)
        .build_cartesian_2d(plan.x.clone(), y)?;
    chart
        .configure_mesh()
        .x_labels(TICKS)
        .y_labels(TICKS)
        .label_style(tick_font.clone())
        .axis_desc_style(label_font)
        .x_desc(fig.x_label.as_str())
        .y_desc(fig.y_label.as_str())
        .bold_line_style(BLACK.mix(0.15))
        .light_line_style(BLACK.mix(0.05))
        .axis_style(BLACK.mix(0.8))
        .draw()?;

    for ((s, runs), (colour, dash)) in fig.series.iter().zip(&plan.runs).zip(looks(&fig.series)) {
        let line = colour.stroke_width(LINE_PX);
        let anno = match dash {
            Some((dash, gap)) => chart.draw_series(
                runs.iter()
                    .map(|r| DashedPathElement::new(r.clone(), dash, gap, line)),
            )?,
            None => chart.draw_series(runs.iter().map(|r| PathElement::new(r.clone(), line)))?,
        };
        if !s.label.is_empty() {
            anno.label(s.label.as_str());
            let markers = s.style == Style::LineWithMarkers;
            match (dash, markers) {
                (Some((dash, gap)), _) => anno.legend(move |(x, y)| {
                    DashedPathElement::new(vec![(x, y), (x + 40, y)], dash, gap, line)
                }),
                (None, true) => anno.legend(move |(x, y)| {
                    EmptyElement::at((x, y))
                        + PathElement::new(vec![(0, 0), (40, 0)], line)
                        + Circle::new((20, 0), MARKER_PX, colour.filled())
                }),
                (None, false) => {
                    anno.legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 40, y)], line))
                }
            };
        }
        if s.style == Style::LineWithMarkers {
            let n: usize = runs.iter().map(Vec::len).sum();
            let every = n.div_ceil(MAX_MARKERS).max(1);
            chart.draw_series(
                runs.iter()
                    .flatten()
                    .step_by(every)
                    .map(|p| Circle::new(*p, MARKER_PX, colour.filled())),
            )?;
        }
    }

    if let Some(position) = legend {
        chart
            .configure_series_labels()
            .position(position)
            .legend_area_size(LEGEND_SAMPLE)
            .margin(LEGEND_MARGIN)
            .label_font(legend_font)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.5))
            .draw()?;
    }
    root.present()?;
    Ok(())
}

/// The place for a legend box of `size` pixels in a plot of `plot` pixels that
/// covers the fewest points of the lines (upper right first among equals), and how
/// many points of the lines (sampled every few pixels) it covers.
fn legend_place(plan: &Plan, plot: (f64, f64), size: (f64, f64)) -> (SeriesLabelPosition, usize) {
    use SeriesLabelPosition::*;
    let ((w, h), (bw, bh)) = (plot, size);
    // Points along the lines, in pixels from the upper left corner of the plot.
    let mut samples = vec![];
    for run in plan.runs.iter().flatten() {
        let px: Vec<(f64, f64)> = run
            .iter()
            .map(|&(x, y)| (plan.x.frac(x) * w, (1.0 - plan.y.frac(y)) * h))
            .collect();
        samples.extend(px.first().copied());
        for seg in px.windows(2) {
            let (a, b) = (seg[0], seg[1]);
            let k = ((b.0 - a.0).hypot(b.1 - a.1) / 4.0)
                .ceil()
                .clamp(1.0, 100.0) as usize;
            samples.extend((1..=k).map(|i| {
                let t = i as f64 / k as f64;
                (a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t)
            }));
        }
    }
    let covered = |x0: f64, y0: f64| {
        samples
            .iter()
            .filter(|(x, y)| *x >= x0 && *x <= x0 + bw && *y >= y0 && *y <= y0 + bh)
            .count()
    };
    let (left, mid, right) = (0.0, (w - bw) / 2.0, w - bw);
    let (top, middle, bottom) = (0.0, (h - bh) / 2.0, h - bh);
    let candidates = [
        (UpperRight, right, top),
        (UpperLeft, left, top),
        (LowerRight, right, bottom),
        (LowerLeft, left, bottom),
        (MiddleRight, right, middle),
        (UpperMiddle, mid, top),
        (LowerMiddle, mid, bottom),
        (MiddleLeft, left, middle),
    ];
    let mut best = (UpperRight, usize::MAX);
    for (pos, x0, y0) in candidates {
        let c = covered(x0, y0);
        if c < best.1 {
            best = (pos, c);
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::super::figure::{reference_slope, Series};
    use super::*;

    /// Width and height from the PNG's IHDR chunk.
    fn png_size(bytes: &[u8]) -> (u32, u32) {
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
        assert_eq!(&bytes[12..16], b"IHDR");
        let be = |b: &[u8]| u32::from_be_bytes([b[0], b[1], b[2], b[3]]);
        (be(&bytes[16..20]), be(&bytes[20..24]))
    }

    #[test]
    fn draws_png_and_svg_with_legend() {
        let dir = tempfile::tempdir().unwrap();
        let t: Vec<f64> = (0..200).map(|i| i as f64 * 0.1).collect();
        let fig = Figure::new("Damped oscillation", "t [ms]", "u_y [mm]")
            .with(Series::new(
                "probe tip",
                t.iter().map(|&t| (t, (-0.1 * t).exp() * t.cos())).collect(),
                Style::Line,
            ))
            .with(Series::new(
                "envelope",
                t.iter().map(|&t| (t, (-0.1 * t).exp())).collect(),
                Style::LineWithMarkers,
            ))
            .with(Series::new(
                "zero",
                vec![(0.0, 0.0), (20.0, 0.0)],
                Style::Dashed,
            ));
        let [png, svg] = draw(&fig, &dir.path().join("sub/osc")).unwrap();
        assert_eq!(png, dir.path().join("sub/osc.png"));
        let bytes = std::fs::read(&png).unwrap();
        assert!(bytes.len() > 1000);
        assert_eq!(png_size(&bytes), SIZE);
        let text = std::fs::read_to_string(&svg).unwrap();
        for label in [
            "probe tip",
            "envelope",
            "zero",
            "Damped oscillation",
            "u_y [mm]",
        ] {
            assert!(text.contains(label), "{label} missing from the SVG");
        }
    }

    #[test]
    fn log_log_with_non_positive_and_non_finite_points_draws() {
        let dir = tempfile::tempdir().unwrap();
        let h = [0.5, 0.25, 0.125, 0.0625, 0.0, -1.0];
        let fig = Figure::new("Convergence", "h [m]", "error")
            .log_log()
            .with(Series::new(
                "L2 error",
                h.iter()
                    .map(|&h| (h, h * h))
                    .chain([(f64::NAN, 1.0), (1.0, f64::INFINITY)])
                    .collect(),
                Style::LineWithMarkers,
            ))
            .with(reference_slope("order 2", 2.0, (0.0625, 0.5), (0.5, 0.5)));
        let [png, svg] = draw(&fig, &dir.path().join("conv")).unwrap();
        assert_eq!(png_size(&std::fs::read(png).unwrap()), SIZE);
        assert!(std::fs::read_to_string(svg).unwrap().contains("order 2"));
    }

    #[test]
    fn empty_figures_draw() {
        let dir = tempfile::tempdir().unwrap();
        draw(&Figure::new("", "x", "y"), &dir.path().join("empty")).unwrap();
        let fig = Figure::new("Nothing positive", "x", "y")
            .log_log()
            .with(Series::new("none", vec![(0.0, -1.0)], Style::Line));
        draw(&fig, &dir.path().join("empty_log")).unwrap();
    }

    #[test]
    fn unwritable_target_is_an_error_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let blocker = dir.path().join("file");
        std::fs::write(&blocker, b"x").unwrap();
        let err = draw(&Figure::new("t", "x", "y"), &blocker.join("fig")).unwrap_err();
        assert!(err.to_string().contains("file"), "{err}");
    }
}

#[cfg(test)]
mod demo {
    use super::super::figure::{reference_slope, Series};
    use super::*;

    /// Draws sample figures into `plotdemo/figures` under the temporary directory:
    /// `cargo test --release --lib plot::draw::demo -- --ignored`.
    #[test]
    #[ignore]
    fn demo_figures() {
        let dir = std::env::temp_dir().join("plotdemo/figures");
        let dir = dir.as_path();
        let h: Vec<f64> = (0..6).map(|i| 0.5f64.powi(i)).collect();
        let fig = Figure::new(
            "Convergence of the displacement",
            "mesh size h [m]",
            "L2 error [m]",
        )
        .log_log()
        .with(Series::new(
            "Quad4",
            h.iter().map(|&h| (h, 3e-3 * h * h)).collect(),
            Style::LineWithMarkers,
        ))
        .with(Series::new(
            "Tri3",
            h.iter().map(|&h| (h, 8e-3 * h * h * (1.0 + h))).collect(),
            Style::LineWithMarkers,
        ))
        .with(Series::new(
            "time error",
            h.iter()
                .map(|&h| (h, 2e-4 * h))
                .chain([(0.0, 1.0)])
                .collect(),
            Style::LineWithMarkers,
        ))
        .with(reference_slope(
            "order 1",
            1.0,
            (1.0 / 32.0, 1.0),
            (1.0, 4e-4),
        ))
        .with(reference_slope(
            "order 2",
            2.0,
            (1.0 / 32.0, 1.0),
            (1.0, 6e-3),
        ));
        for p in draw(&fig, &dir.join("convergence")).unwrap() {
            println!("{}", p.display());
        }
        let fig = Figure::new("Narrow log range", "x [-]", "y [-]")
            .log_log()
            .with(Series::new(
                "a",
                vec![(3.1e-3, 1.0), (8.9e-3, 1.3)],
                Style::Line,
            ));
        draw(&fig, &dir.join("narrow")).unwrap();
        draw(&Figure::new("Empty", "x [-]", "y [-]"), &dir.join("empty")).unwrap();
    }
}
