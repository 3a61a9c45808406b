//! Log-log line charts as SVG, drawn with plotters: the benchmark's time and error panels
//! (`bench.svg`) and the stress suite's error and time-against-error charts.
//!
//! A [`Figure`] is one or more [`Panel`]s in rows of `columns`, each with its own legend (to
//! the right of the plot or under it). Text is left to the SVG viewer's sans-serif font, so no
//! font files or system font libraries are needed.

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// Font of every text.
const FONT: &str = "sans-serif";
/// Legend row height, pixels.
const LEGEND_ROW: u32 = 17;
/// Width of a legend placed right of the plot, pixels.
const LEGEND_RIGHT_W: u32 = 290;
/// Colour of the marker lines (targets, limits).
const RULE_COLOUR: RGBColor = RGBColor(0xbb, 0x00, 0x00);

/// Colour from `#rrggbb` (black if malformed).
pub fn hex(text: &str) -> RGBColor {
    let v = u32::from_str_radix(text.trim_start_matches('#'), 16).unwrap_or(0);
    RGBColor((v >> 16) as u8, (v >> 8) as u8, v as u8)
}

/// How a series' points are joined.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Line {
    Solid,
    Dashed,
    /// Short dashes, to tell a third series of one colour apart.
    Dotted,
    /// Points only.
    NoLine,
}

/// Mark drawn at each point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Marker {
    /// Filled circle.
    Circle,
    /// Hollow square.
    Square,
    /// Filled triangle.
    Triangle,
    /// Hollow diamond, larger than the others so a mark drawn on top stays visible inside.
    Diamond,
}

/// One labelled set of points.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend text.
    pub label: String,
    pub colour: RGBColor,
    pub line: Line,
    pub marker: Marker,
    /// (x, y); points that a log axis cannot show (non-positive, NaN) are left out.
    pub points: Vec<(f64, f64)>,
    /// Text beside each point (empty: none).
    pub point_labels: Vec<String>,
}

impl Series {
    /// A series without points yet.
    pub fn new(label: impl Into<String>, colour: RGBColor, line: Line, marker: Marker) -> Series {
        Series {
            label: label.into(),
            colour,
            line,
            marker,
            points: Vec::new(),
            point_labels: Vec::new(),
        }
    }

    /// Adds a point where a log-log chart can draw it.
    pub fn push(&mut self, x: f64, y: f64) {
        if drawable(x) && drawable(y) {
            self.points.push((x, y));
        }
    }

    /// Adds a point with a label beside it.
    pub fn push_labelled(&mut self, x: f64, y: f64, label: impl Into<String>) {
        if drawable(x) && drawable(y) {
            self.points.push((x, y));
            self.point_labels.push(label.into());
        }
    }
}

fn drawable(v: f64) -> bool {
    v.is_finite() && v > 0.0
}

/// Ticks and labels of the x axis.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum XTicks {
    /// Every power of ten, labelled `1e<k>`.
    Decades,
    /// Every power of two, labelled as integers (bandwidths).
    PowersOfTwo,
    /// Each distinct x of the data, labelled as integers, the range padded a little.
    DataValues,
}

/// A marker line across the plot (a target, a limit) with its label.
#[derive(Clone, Debug)]
pub struct Rule {
    pub at: f64,
    pub label: String,
}

/// Where a panel's legend goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LegendPlace {
    /// A column right of the plot.
    Right,
    /// Two columns under the plot.
    Below,
}

/// One log-log chart.
#[derive(Clone, Debug)]
pub struct Panel {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x_ticks: XTicks,
    pub series: Vec<Series>,
    /// Vertical marker lines.
    pub x_rules: Vec<Rule>,
    /// Horizontal marker lines.
    pub y_rules: Vec<Rule>,
}

/// Panels in rows of `columns` (filled left to right, top to bottom), each `panel_width`
/// wide with a plot `plot_height` high.
#[derive(Clone, Debug)]
pub struct Figure {
    pub panels: Vec<Panel>,
    pub panel_width: u32,
    pub plot_height: u32,
    pub legend: LegendPlace,
    /// Panels per row (at least 1).
    pub columns: usize,
}

impl Figure {
    /// The SVG document.
    pub fn svg(&self) -> Result<String, String> {
        let legend_rows = self
            .panels
            .iter()
            .map(|p| legend_entries(p).count())
            .max()
            .unwrap_or(0);
        let legend_h = match self.legend {
            LegendPlace::Right => 0,
            LegendPlace::Below => legend_rows.div_ceil(2) as u32 * LEGEND_ROW + 12,
        };
        let n = self.panels.len().max(1);
        let columns = self.columns.clamp(1, n);
        let rows = n.div_ceil(columns);
        let width = self.panel_width * columns as u32;
        let height = (self.plot_height + legend_h) * rows as u32;
        let mut out = String::new();
        {
            let root = SVGBackend::with_string(&mut out, (width, height)).into_drawing_area();
            root.fill(&WHITE).map_err(|e| e.to_string())?;
            let areas = root.split_evenly((rows, columns));
            for (panel, area) in self.panels.iter().zip(&areas) {
                let (plot, legend) = match self.legend {
                    LegendPlace::Right => {
                        area.split_horizontally(self.panel_width - LEGEND_RIGHT_W)
                    }
                    LegendPlace::Below => area.split_vertically(self.plot_height),
                };
                draw_panel(&plot, panel).map_err(|e| e.to_string())?;
                let columns = if self.legend == LegendPlace::Right {
                    1
                } else {
                    2
                };
                draw_legend(&legend, panel, columns, self.legend).map_err(|e| e.to_string())?;
            }
            root.present().map_err(|e| e.to_string())?;
        }
        Ok(out)
    }
}

/// The series that appear (those with points), in legend order.
fn legend_entries(panel: &Panel) -> impl Iterator<Item = &Series> {
    panel.series.iter().filter(|s| !s.points.is_empty())
}

/// `log10` range covering `values`: whole decades, at least one.
fn decade_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let Some((lo, hi)) = min_max(values) else {
        return (0.0, 1.0);
    };
    let (a, b) = (lo.log10().floor(), hi.log10().ceil());
    (a, b.max(a + 1.0))
}

/// `log2` range covering `values`: whole octaves, at least one.
fn octave_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let Some((lo, hi)) = min_max(values) else {
        return (0.0, 1.0);
    };
    let (a, b) = (lo.log2().floor(), hi.log2().ceil());
    (a, b.max(a + 1.0))
}

fn min_max(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    values
        .filter(|&v| drawable(v))
        .fold(None, |acc, v| match acc {
            None => Some((v, v)),
            Some((a, b)) => Some((f64::min(a, v), f64::max(b, v))),
        })
}

/// Distinct x values of the panel's points, ascending.
fn data_xs(panel: &Panel) -> Vec<f64> {
    let mut xs: Vec<f64> = panel
        .series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.0))
        .collect();
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    xs
}

/// The x axis: range and tick values.
fn x_axis(panel: &Panel) -> (f64, f64, Vec<f64>) {
    let xs = panel
        .series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.0))
        .chain(panel.x_rules.iter().map(|r| r.at));
    match panel.x_ticks {
        XTicks::Decades => {
            let (a, b) = decade_range(xs);
            let ticks = (a as i32..=b as i32).map(|k| 10f64.powi(k)).collect();
            (10f64.powf(a), 10f64.powf(b), ticks)
        }
        XTicks::PowersOfTwo => {
            let (a, b) = octave_range(xs);
            let ticks = (a as i32..=b as i32).map(|k| 2f64.powi(k)).collect();
            (2f64.powf(a), 2f64.powf(b), ticks)
        }
        XTicks::DataValues => {
            let ticks = data_xs(panel);
            let (lo, hi) = min_max(ticks.iter().copied()).unwrap_or((1.0, 10.0));
            // A little room so the end points are not on the frame.
            let pad = 10f64.powf(0.08);
            (lo / pad, hi * pad, ticks)
        }
    }
}

/// The y axis: range, labelled ticks (decades; also 2 and 5 times them when the range is
/// two decades or less) and minor ticks (2..9 times each decade up to twelve decades). A
/// labelled point in the top quarter decade gets a decade of room above it for its label.
fn y_axis(panel: &Panel) -> (f64, f64, Vec<f64>, Vec<f64>) {
    let ys = panel
        .series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.1))
        .chain(panel.y_rules.iter().map(|r| r.at));
    let (a, mut b) = decade_range(ys);
    let top_label = panel
        .series
        .iter()
        .filter(|s| !s.point_labels.is_empty())
        .flat_map(|s| s.points.iter().map(|p| p.1.log10()))
        .fold(f64::NEG_INFINITY, f64::max);
    if top_label > b - 0.25 {
        b += 1.0;
    }
    let decades = (b - a).round() as i32;
    let (a, b) = (a as i32, b as i32);
    let mut labelled = Vec::new();
    let mut minor = Vec::new();
    for k in a..=b {
        let decade = 10f64.powi(k);
        labelled.push(decade);
        if k == b {
            break;
        }
        for m in 2..10 {
            if decades <= 2 && (m == 2 || m == 5) {
                labelled.push(m as f64 * decade);
            } else if decades <= 12 {
                minor.push(m as f64 * decade);
            }
        }
    }
    (10f64.powi(a), 10f64.powi(b), labelled, minor)
}

/// `1e<k>` for a power of ten, `<m>e<k>` for a multiple of one.
fn exponent_label(v: f64) -> String {
    let k = v.log10().floor();
    let m = (v / 10f64.powf(k)).round();
    format!("{m}e{k}")
}

type LogAxis =
    plotters::coord::combinators::WithKeyPoints<plotters::coord::combinators::LogCoord<f64>>;
type Plot<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<LogAxis, LogAxis>>;
type DrawResult<T> =
    std::result::Result<T, plotters::drawing::DrawingAreaErrorKind<std::io::Error>>;

fn draw_panel(area: &DrawingArea<SVGBackend<'_>, Shift>, panel: &Panel) -> DrawResult<()> {
    let caption = (FONT, 15).into_font();
    if legend_entries(panel).next().is_none() {
        let (w, h) = area.dim_in_pixel();
        area.draw(&Text::new(
            format!("{}: no data", panel.title),
            (w as i32 / 2, h as i32 / 2),
            TextStyle::from(caption.clone()).pos(Pos::new(HPos::Center, VPos::Center)),
        ))?;
        return Ok(());
    }
    let (x0, x1, x_ticks) = x_axis(panel);
    let (y0, y1, y_labelled, y_minor) = y_axis(panel);
    let x_spec = (x0..x1).log_scale().with_key_points(x_ticks);
    let y_spec = (y0..y1)
        .log_scale()
        .with_key_points(y_labelled)
        .with_light_points(y_minor);
    let mut chart = ChartBuilder::on(area)
        .caption(&panel.title, caption)
        .margin(12)
        .x_label_area_size(44)
        .y_label_area_size(72)
        .build_cartesian_2d(x_spec, y_spec)?;
    let integer_label = |v: &f64| format!("{}", v.round());
    let decade_label = |v: &f64| exponent_label(*v);
    let x_format: &dyn Fn(&f64) -> String = if panel.x_ticks == XTicks::Decades {
        &decade_label
    } else {
        &integer_label
    };
    chart
        .configure_mesh()
        .x_desc(&panel.x_label)
        .y_desc(&panel.y_label)
        .x_label_formatter(x_format)
        .y_label_formatter(&decade_label)
        .label_style((FONT, 12))
        .axis_desc_style((FONT, 13))
        .bold_line_style(hex("#dddddd"))
        .light_line_style(hex("#f3f3f3"))
        .draw()?;
    draw_rules(&mut chart, panel, (x0, x1), (y0, y1))?;
    // Reverse order: the first legend entries end up on top where lines coincide.
    for s in legend_entries(panel).collect::<Vec<_>>().into_iter().rev() {
        draw_series(&mut chart, s)?;
    }
    Ok(())
}

fn draw_rules(
    chart: &mut Plot<'_, '_>,
    panel: &Panel,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
) -> DrawResult<()> {
    let style = ShapeStyle::from(RULE_COLOUR).stroke_width(1);
    let text = (FONT, 11).into_font().color(&RULE_COLOUR);
    for r in &panel.x_rules {
        chart.draw_series(DashedLineSeries::new([(r.at, y0), (r.at, y1)], 6, 4, style))?;
        chart.draw_series(std::iter::once(
            EmptyElement::at((r.at, y1))
                + Text::new(
                    r.label.clone(),
                    (-4, 6),
                    text.clone().pos(Pos::new(HPos::Right, VPos::Top)),
                ),
        ))?;
    }
    for r in &panel.y_rules {
        chart.draw_series(DashedLineSeries::new([(x0, r.at), (x1, r.at)], 2, 3, style))?;
        chart.draw_series(std::iter::once(
            EmptyElement::at((x0, r.at))
                + Text::new(
                    r.label.clone(),
                    (4, -3),
                    text.clone().pos(Pos::new(HPos::Left, VPos::Bottom)),
                ),
        ))?;
    }
    Ok(())
}

/// Runs `$body` with `$shape` bound to a closure that builds the mark of `$marker` in
/// `$colour` at a point (each mark is its own element type, hence a macro).
macro_rules! with_marker {
    ($marker:expr, $colour:expr, |$shape:ident| $body:expr) => {{
        let colour: RGBColor = $colour;
        let outline = ShapeStyle::from(colour).stroke_width(2);
        let fill = colour.filled();
        let blank = WHITE.filled();
        match $marker {
            Marker::Circle => {
                let $shape = |at| EmptyElement::at(at) + Circle::new((0, 0), 3, fill);
                $body
            }
            Marker::Square => {
                let $shape = |at| {
                    EmptyElement::at(at)
                        + Rectangle::new([(-4, -4), (4, 4)], blank)
                        + Rectangle::new([(-4, -4), (4, 4)], outline)
                };
                $body
            }
            Marker::Triangle => {
                let $shape =
                    |at| EmptyElement::at(at) + Polygon::new(vec![(0, -5), (-4, 3), (4, 3)], fill);
                $body
            }
            Marker::Diamond => {
                let corners = [(0, -6), (6, 0), (0, 6), (-6, 0), (0, -6)];
                let $shape = |at| {
                    EmptyElement::at(at)
                        + Polygon::new(corners.to_vec(), blank)
                        + PathElement::new(corners.to_vec(), outline)
                };
                $body
            }
        }
    }};
}

fn draw_series(chart: &mut Plot<'_, '_>, s: &Series) -> DrawResult<()> {
    let style = ShapeStyle::from(s.colour).stroke_width(2);
    let points = s.points.iter().copied();
    match s.line {
        Line::Solid => {
            chart.draw_series(LineSeries::new(points, style))?;
        }
        Line::Dashed => {
            chart.draw_series(DashedLineSeries::new(points, 6, 4, style))?;
        }
        Line::Dotted => {
            chart.draw_series(DashedLineSeries::new(points, 2, 3, style))?;
        }
        Line::NoLine => {}
    }
    with_marker!(s.marker, s.colour, |shape| {
        chart.draw_series(s.points.iter().map(|&p| shape(p)))?
    });
    let text = (FONT, 9).into_font().color(&s.colour);
    chart.draw_series(
        s.points
            .iter()
            .zip(&s.point_labels)
            .map(|(&p, label)| EmptyElement::at(p) + Text::new(label.clone(), (5, -13), &text)),
    )?;
    Ok(())
}

fn draw_legend(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    panel: &Panel,
    columns: usize,
    place: LegendPlace,
) -> DrawResult<()> {
    let (width, _) = area.dim_in_pixel();
    // Under the plot the legend lines up with the plot area (after the y labels).
    let (left, top, column_w) = match place {
        LegendPlace::Right => (8, 64, width as i32),
        LegendPlace::Below => (84, 8, (width as i32 - 84) / columns as i32),
    };
    let text = TextStyle::from((FONT, 11).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
    for (i, s) in legend_entries(panel).enumerate() {
        let x = left + (i % columns) as i32 * column_w;
        let y = top + (i / columns) as i32 * LEGEND_ROW as i32;
        let style = ShapeStyle::from(s.colour).stroke_width(2);
        match s.line {
            Line::Solid => area.draw(&PathElement::new(vec![(x, y), (x + 30, y)], style))?,
            Line::Dashed => area.draw(&DashedPathElement::new(
                vec![(x, y), (x + 30, y)],
                6,
                4,
                style,
            ))?,
            Line::Dotted => area.draw(&DashedPathElement::new(
                vec![(x, y), (x + 30, y)],
                2,
                3,
                style,
            ))?,
            Line::NoLine => {}
        }
        with_marker!(s.marker, s.colour, |shape| area
            .draw(&shape((x + 15, y)))?);
        area.draw(&Text::new(s.label.clone(), (x + 38, y), &text))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pixel of `v` on a log axis over `range` drawn on `pixels`.
    fn pixel_of(range: (f64, f64), v: f64, pixels: (i32, i32)) -> i32 {
        use plotters::coord::ranged1d::Ranged;
        let axis: plotters::coord::combinators::LogCoord<f64> =
            (range.0..range.1).log_scale().into();
        axis.map(&v, pixels)
    }

    fn panel(series: Vec<Series>, x_ticks: XTicks) -> Panel {
        Panel {
            title: "title & <more>".into(),
            x_label: "bandwidth B".into(),
            y_label: "error".into(),
            x_ticks,
            series,
            x_rules: vec![Rule {
                at: 1024.0,
                label: "limit".into(),
            }],
            y_rules: vec![Rule {
                at: 1e-14,
                label: "target".into(),
            }],
        }
    }

    /// A labelled point near the top decade line gets room for its label.
    #[test]
    fn labels_get_room_at_the_top() {
        let mut s = Series::new("x", hex("#000000"), Line::Solid, Marker::Circle);
        s.push(1.0, 7e-2);
        let mut p = panel(vec![s.clone()], XTicks::Decades);
        p.y_rules.clear();
        assert_eq!(y_axis(&p).1, 1e-1);
        s.push_labelled(2.0, 7e-2, "16");
        p.series = vec![s];
        assert_eq!(y_axis(&p).1, 1.0);
    }

    /// Decade and octave ranges enclose the data, in whole steps.
    #[test]
    fn ranges_enclose_the_data() {
        assert_eq!(decade_range([3e-15, 2e-13].into_iter()), (-15.0, -12.0));
        assert_eq!(decade_range([1e-14].into_iter()), (-14.0, -13.0));
        assert_eq!(octave_range([16.0, 2048.0].into_iter()), (4.0, 11.0));
        assert_eq!(octave_range([100.0].into_iter()), (6.0, 7.0));
        assert_eq!(decade_range([f64::NAN, -1.0].into_iter()), (0.0, 1.0));
    }

    /// Labels name the value: 1e-14, 5e-3.
    #[test]
    fn exponent_labels() {
        assert_eq!(exponent_label(1e-14), "1e-14");
        assert_eq!(exponent_label(5e-3), "5e-3");
        assert_eq!(exponent_label(1.0), "1e0");
    }

    /// Log axis: a decade takes the same pixels wherever it is.
    #[test]
    fn log_axis_spaces_decades_evenly() {
        let px = |v| pixel_of((1e-16, 1e-12), v, (0, 400));
        assert_eq!(px(1e-16), 0);
        assert_eq!(px(1e-14), 200);
        assert_eq!(px(1e-12), 400);
    }

    /// Non-drawable points are left out; the SVG names every series, tick and rule, escapes
    /// text, and a panel without points says so.
    #[test]
    fn svg_has_series_ticks_and_legend() {
        let mut a = Series::new(
            "complex (~B^0.73)",
            hex("#0072B2"),
            Line::Solid,
            Marker::Circle,
        );
        for (b, e) in [
            (16.0, 1e-15),
            (64.0, 2e-15),
            (256.0, 5e-15),
            (512.0, f64::NAN),
        ] {
            a.push(b, e);
        }
        assert_eq!(a.points.len(), 3);
        let mut p = Series::new("SOFT", hex("#000000"), Line::NoLine, Marker::Square);
        p.push_labelled(32.0, 3e-14, "B=128");
        let figure = Figure {
            panels: vec![
                panel(vec![a, p], XTicks::PowersOfTwo),
                panel(Vec::new(), XTicks::Decades),
            ],
            panel_width: 600,
            plot_height: 400,
            legend: LegendPlace::Below,
            columns: 2,
        };
        let svg = figure.svg().unwrap();
        assert!(svg.starts_with("<svg"), "{}", &svg[..100]);
        // Side by side; one column stacks the panels.
        assert!(svg.contains("width=\"1200\""), "{}", &svg[..200]);
        let stacked = Figure {
            columns: 1,
            ..figure.clone()
        }
        .svg()
        .unwrap();
        assert!(stacked.contains("width=\"600\""), "{}", &stacked[..200]);
        for needle in [
            "complex (~B^0.73)",
            "SOFT",
            "B=128",
            "target",
            "limit",
            "\n1024\n",
            "\n16\n",
            "\n1e-14\n",
            "title &amp; &lt;more&gt;",
            "no data",
            "bandwidth B",
        ] {
            assert!(svg.contains(needle), "{needle:?} missing");
        }
        assert_eq!(hex("#0072B2"), RGBColor(0x00, 0x72, 0xb2));
    }
}
