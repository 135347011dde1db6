//! PNG plots of experiment results, drawn with plotters into memory (the caller writes the
//! file, atomically, like every other output). Text uses the bundled DejaVu Sans font, so no
//! system font library is needed.

use std::sync::Once;

use image::RgbImage;
use plotters::prelude::*;
use plotters::style::{FontStyle, register_font};

use haarshift::{Error, Result};

const WIDTH: u32 = 1100;
const HEIGHT: u32 = 700;
static FONT: Once = Once::new();

/// Makes the bundled font available under the family name "sans-serif".
fn register_bundled_font() {
    FONT.call_once(|| {
        let bytes = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
        // Registration only fails on a corrupt font, and the bundled one is checked by tests.
        let _ = register_font("sans-serif", FontStyle::Normal, bytes);
    });
}

fn plot_error(e: impl std::fmt::Display) -> Error {
    Error::parameter("plot", e.to_string())
}

/// Draws one chart into an RGB image: the white canvas, the caption and the label areas are
/// set up here, and `draw` builds the axes and series on the chart builder it is given.
fn render_chart(
    title: &str,
    x_label_area: u32,
    right_margin: u32,
    draw: impl FnOnce(&mut ChartBuilder<'_, '_, BitMapBackend<'_>>) -> Result<()>,
) -> Result<RgbImage> {
    register_bundled_font();
    let mut buffer = vec![0u8; (WIDTH * HEIGHT * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, (WIDTH, HEIGHT)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_error)?;
        let mut builder = ChartBuilder::on(&root);
        builder
            .caption(title, ("sans-serif", 26))
            .margin(20)
            .margin_right(right_margin)
            .x_label_area_size(x_label_area)
            .y_label_area_size(70);
        draw(&mut builder)?;
        root.present().map_err(plot_error)?;
    }
    RgbImage::from_raw(WIDTH, HEIGHT, buffer)
        .ok_or_else(|| plot_error("plot buffer has the wrong size"))
}

/// A labelled point of a scatter plot.
#[derive(Clone, Debug, PartialEq)]
pub struct LabeledPoint {
    /// Shown next to the point.
    pub label: String,
    /// Horizontal position (must be > 0 on log axes).
    pub x: f64,
    /// Vertical position (must be > 0 on log axes).
    pub y: f64,
}

/// A compact tick label: 3 significant digits, no trailing zeros.
fn short_number(v: f64) -> String {
    let text = format!("{v:.3e}");
    let parsed: f64 = text.parse().unwrap_or(v);
    let plain = format!("{parsed}");
    if plain.len() <= 8 {
        plain
    } else {
        format!("{parsed:.2e}")
    }
}

/// A log axis over `range` with ticks at 1, 2 and 5 times each power of ten, so that a range
/// within one or two decades still gets readable labels.
fn log_axis(
    range: std::ops::Range<f64>,
) -> impl plotters::coord::ranged1d::Ranged<ValueType = f64>
+ plotters::coord::ranged1d::ValueFormatter<f64> {
    let (lo, hi) = (range.start, range.end);
    let ticks: Vec<f64> = (lo.log10().floor() as i32..=hi.log10().ceil() as i32)
        .flat_map(|e| [1.0, 2.0, 5.0].map(|m| m * 10f64.powi(e)))
        .filter(|v| (lo..=hi).contains(v))
        .collect();
    range.log_scale().with_key_points(ticks)
}

/// The range of `values` widened by a factor on each side, for a log axis.
fn log_range(values: impl Iterator<Item = f64>) -> Result<std::ops::Range<f64>> {
    let (lo, hi) = values.fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    // An empty iterator leaves (inf, 0): refuse it along with zeros and negatives.
    if !(lo > 0.0 && lo <= hi && hi.is_finite()) {
        return Err(Error::parameter(
            "plot",
            "log-scale plots need positive, finite values",
        ));
    }
    Ok(lo / 1.5..hi * 1.5)
}

/// The grid, tick labels and axis titles of a log-log chart.
fn draw_log_mesh<X, Y>(
    chart: &mut ChartContext<'_, BitMapBackend<'_>, Cartesian2d<X, Y>>,
    x_label: &str,
    y_label: &str,
) -> Result<()>
where
    X: plotters::coord::ranged1d::Ranged<ValueType = f64>
        + plotters::coord::ranged1d::ValueFormatter<f64>,
    Y: plotters::coord::ranged1d::Ranged<ValueType = f64>
        + plotters::coord::ranged1d::ValueFormatter<f64>,
{
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .x_label_formatter(&|v| short_number(*v))
        .y_label_formatter(&|v| short_number(*v))
        .label_style(("sans-serif", 16))
        .draw()
        .map_err(plot_error)
}

/// The legend of a chart's labelled series, at `position` (`None`: plotters' default).
fn draw_legend<'a, 'b: 'a, X, Y>(
    chart: &mut ChartContext<'a, BitMapBackend<'b>, Cartesian2d<X, Y>>,
    position: Option<SeriesLabelPosition>,
) -> Result<()>
where
    X: plotters::coord::ranged1d::Ranged,
    Y: plotters::coord::ranged1d::Ranged,
{
    let mut legend = chart.configure_series_labels();
    if let Some(p) = position {
        legend.position(p);
    }
    legend
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()
        .map_err(plot_error)
}

/// A log-log scatter plot of `points` with the points of `frontier` joined by a line (a Pareto
/// frontier, say), as an RGB image.
///
/// ```
/// use haarshift_experiments::plot::{LabeledPoint, log_log_scatter};
/// let p = |label: &str, x, y| LabeledPoint { label: label.into(), x, y };
/// let pts = [p("linear", 0.01, 16.0), p("fft", 0.1, 2.4)];
/// let img = log_log_scatter("RMS against time", "seconds", "RMS", &pts, &pts).unwrap();
/// assert_eq!(img.dimensions(), (1100, 700));
/// ```
pub fn log_log_scatter(
    title: &str,
    x_label: &str,
    y_label: &str,
    points: &[LabeledPoint],
    frontier: &[LabeledPoint],
) -> Result<RgbImage> {
    let x_range = log_range(points.iter().map(|p| p.x))?;
    let y_range = log_range(points.iter().map(|p| p.y))?;
    render_chart(title, 50, 150, |builder| {
        let mut chart = builder
            .build_cartesian_2d(log_axis(x_range), log_axis(y_range))
            .map_err(plot_error)?;
        draw_log_mesh(&mut chart, x_label, y_label)?;
        let mut sorted: Vec<(f64, f64)> = frontier.iter().map(|p| (p.x, p.y)).collect();
        sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
        chart
            .draw_series(LineSeries::new(sorted, RED.stroke_width(2)))
            .map_err(plot_error)?;
        chart
            .draw_series(
                points
                    .iter()
                    .map(|p| Circle::new((p.x, p.y), 5, BLUE.filled())),
            )
            .map_err(plot_error)?;
        // Labels where they cover no other label or point; frontier points' labels first.
        let style: TextStyle = ("sans-serif", 14).into();
        let anchors: Vec<(i32, i32)> = points
            .iter()
            .map(|p| chart.backend_coord(&(p.x, p.y)))
            .collect();
        let sizes = points
            .iter()
            .map(|p| chart.plotting_area().estimate_text_size(&p.label, &style))
            .collect::<std::result::Result<Vec<_>, _>>()
            .map_err(plot_error)?;
        let mut order: Vec<usize> = (0..points.len()).collect();
        order.sort_by_key(|&i| !frontier.contains(&points[i]));
        let offsets = place_labels(&anchors, &sizes, &order);
        chart
            .draw_series(points.iter().zip(offsets).filter_map(|(p, offset)| {
                offset.map(|o| EmptyElement::at((p.x, p.y)) + Text::new(p.label.clone(), o, &style))
            }))
            .map_err(plot_error)?;
        Ok(())
    })
}

/// One named polyline of a [`log_log_lines`] plot.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    /// Legend entry.
    pub name: String,
    /// `(x, y)` points, joined in order of `x` (both > 0).
    pub points: Vec<(f64, f64)>,
}

/// Curves on log-log axes, one colour each, markers at their points and a legend (error
/// against kept coefficients per method, say), as an RGB image.
///
/// ```
/// use haarshift_experiments::plot::{Curve, log_log_lines};
/// let c = Curve { name: "haar".into(), points: vec![(4.0, 0.5), (64.0, 0.05)] };
/// let img = log_log_lines("error against coefficients", "coefficients", "RMS", &[c]).unwrap();
/// assert_eq!(img.dimensions(), (1100, 700));
/// ```
pub fn log_log_lines(
    title: &str,
    x_label: &str,
    y_label: &str,
    curves: &[Curve],
) -> Result<RgbImage> {
    let all = || curves.iter().flat_map(|c| c.points.iter());
    let x_range = log_range(all().map(|p| p.0))?;
    let y_range = log_range(all().map(|p| p.1))?;
    render_chart(title, 50, 30, |builder| {
        let mut chart = builder
            .build_cartesian_2d(log_axis(x_range), log_axis(y_range))
            .map_err(plot_error)?;
        draw_log_mesh(&mut chart, x_label, y_label)?;
        for (k, c) in curves.iter().enumerate() {
            let colour = Palette99::pick(k).to_rgba();
            let mut sorted = c.points.clone();
            sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
            chart
                .draw_series(LineSeries::new(sorted.clone(), colour.stroke_width(2)))
                .map_err(plot_error)?
                .label(c.name.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
                });
            chart
                .draw_series(
                    sorted
                        .into_iter()
                        .map(|p| Circle::new(p, 4, colour.filled())),
                )
                .map_err(plot_error)?;
        }
        draw_legend(&mut chart, Some(SeriesLabelPosition::UpperRight))
    })
}

/// Pixel offsets (from the point to the label's top-left corner) at which each label is
/// tried: to the right (level with the point, one line above, one line below), then the same
/// to the left; the three heights do not overlap.
fn label_spots(w: i32, h: i32) -> [(i32, i32); 6] {
    let (right, left) = (8, -8 - w);
    let level = -h / 2;
    let (above, below) = (level - h, level + h);
    [
        (right, level),
        (right, above),
        (right, below),
        (left, level),
        (left, above),
        (left, below),
    ]
}

/// Where to draw each label of points at pixel positions `anchors` with text sizes `sizes`:
/// for each point in `order`, the first of [`label_spots`] whose box overlaps neither a label
/// placed before it nor any point's marker; `None` (no label) when every spot is taken.
fn place_labels(
    anchors: &[(i32, i32)],
    sizes: &[(u32, u32)],
    order: &[usize],
) -> Vec<Option<(i32, i32)>> {
    type Box2 = (i32, i32, i32, i32);
    let overlaps = |a: Box2, b: Box2| a.0 < b.2 && b.0 < a.2 && a.1 < b.3 && b.1 < a.3;
    let markers: Vec<Box2> = anchors
        .iter()
        .map(|&(x, y)| (x - 5, y - 5, x + 6, y + 6))
        .collect();
    let mut placed: Vec<Box2> = Vec::new();
    let mut offsets = vec![None; anchors.len()];
    for &i in order {
        let (x, y) = anchors[i];
        let (w, h) = (sizes[i].0 as i32, sizes[i].1 as i32);
        let free = label_spots(w, h).into_iter().find(|&(dx, dy)| {
            let b = (x + dx, y + dy, x + dx + w, y + dy + h);
            !placed.iter().chain(&markers).any(|&o| overlaps(b, o))
        });
        if let Some((dx, dy)) = free {
            placed.push((x + dx, y + dy, x + dx + w, y + dy + h));
            offsets[i] = Some((dx, dy));
        }
    }
    offsets
}

/// One named series of values, one per category, for [`category_points`]; `None` marks a
/// missing value.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Legend entry.
    pub name: String,
    /// One value per category.
    pub values: Vec<Option<f64>>,
}

/// Values per category (methods, say) on a log vertical axis, one colour of marker per series
/// (images, say), as an RGB image.
///
/// ```
/// use haarshift_experiments::plot::{Series, category_points};
/// let s = Series { name: "camera".into(), values: vec![Some(16.0), Some(2.4)] };
/// let img = category_points("RMS per method", "RMS", &["linear".into(), "fft".into()], &[s]).unwrap();
/// assert_eq!(img.dimensions(), (1100, 700));
/// ```
pub fn category_points(
    title: &str,
    y_label: &str,
    categories: &[String],
    series: &[Series],
) -> Result<RgbImage> {
    let y_range = log_range(
        series
            .iter()
            .flat_map(|s| s.values.iter().flatten().copied()),
    )?;
    let n = categories.len().max(1);
    render_chart(title, 90, 20, |builder| {
        let mut chart = builder
            .build_cartesian_2d(-0.5f64..n as f64 - 0.5, log_axis(y_range))
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .x_labels(n)
            .x_label_formatter(&|x| {
                let i = x.round();
                if (x - i).abs() < 1e-6 && i >= 0.0 {
                    categories.get(i as usize).cloned().unwrap_or_default()
                } else {
                    String::new()
                }
            })
            .y_desc(y_label)
            .y_label_formatter(&|v| short_number(*v))
            .label_style(("sans-serif", 15))
            .draw()
            .map_err(plot_error)?;
        // Markers only: the categories are unordered, so lines between them would mislead.
        // Each series is nudged sideways a little so that equal values stay visible.
        let spread = 0.3 / series.len().max(1) as f64;
        for (k, s) in series.iter().enumerate() {
            let colour = Palette99::pick(k).to_rgba();
            let offset = (k as f64 - (series.len() as f64 - 1.0) / 2.0) * spread;
            let pts = s
                .values
                .iter()
                .enumerate()
                .filter_map(|(i, v)| v.map(|v| (i as f64 + offset, v)));
            chart
                .draw_series(pts.map(|p| Circle::new(p, 5, colour.filled())))
                .map_err(plot_error)?
                .label(s.name.clone())
                .legend(move |(x, y)| Circle::new((x + 10, y), 5, colour.filled()));
        }
        draw_legend(&mut chart, None)
    })
}

/// A contact sheet of gray tiles with a label under each, `columns` tiles to a row: each
/// tile's values (0..=255, clamped and rounded) are enlarged `zoom` times by pixel
/// replication, so that interpolation blur and ringing stay visible as they are.
///
/// ```
/// use haarshift_experiments::plot::labelled_tiles;
/// let a = ndarray::Array2::from_elem((4, 6), 255.0);
/// let b = ndarray::Array2::from_elem((4, 6), 0.0);
/// let sheet = labelled_tiles(&[("white".into(), a.view()), ("black".into(), b.view())], 2, 3).unwrap();
/// assert_eq!(sheet.width(), 2 * (6 * 3 + 8) + 8);
/// assert_eq!(sheet.get_pixel(8 + 1, 8 + 1).0, [255, 255, 255]);
/// assert_eq!(sheet.get_pixel(8 + 26 + 1, 8 + 1).0, [0, 0, 0]);
/// ```
pub fn labelled_tiles(
    tiles: &[(String, ndarray::ArrayView2<'_, f64>)],
    columns: usize,
    zoom: usize,
) -> Result<RgbImage> {
    // Each grey plane repeated three times: small figures, so the copies cost nothing.
    let grey: Vec<(String, ndarray::Array3<f64>)> = tiles
        .iter()
        .map(|(label, t)| {
            let rgb = ndarray::stack(ndarray::Axis(0), &[t.view(), t.view(), t.view()])
                .expect("three planes of one shape");
            (label.clone(), rgb)
        })
        .collect();
    let grey: Vec<(String, ndarray::ArrayView3<'_, f64>)> =
        grey.iter().map(|(l, t)| (l.clone(), t.view())).collect();
    labelled_colour_tiles(&grey, columns, zoom)
}

/// [`labelled_tiles`] in colour: each tile is `(3, H, W)` RGB planes of 0..=255 (the picture
/// grids of the relighting experiment: renders over their false-colour error images).
///
/// ```
/// use haarshift_experiments::plot::labelled_colour_tiles;
/// let mut red = ndarray::Array3::zeros((3, 4, 6));
/// red.index_axis_mut(ndarray::Axis(0), 0).fill(255.0);
/// let sheet = labelled_colour_tiles(&[("red".into(), red.view())], 1, 1).unwrap();
/// assert_eq!(sheet.get_pixel(8, 8).0, [255, 0, 0]);
/// ```
pub fn labelled_colour_tiles(
    tiles: &[(String, ndarray::ArrayView3<'_, f64>)],
    columns: usize,
    zoom: usize,
) -> Result<RgbImage> {
    const GAP: usize = 8;
    const LABEL: usize = 24;
    let Some((_, first)) = tiles.first() else {
        return Err(plot_error("no tiles to draw"));
    };
    let (_, th, tw) = first.dim();
    if tiles.iter().any(|(_, t)| t.dim() != (3, th, tw)) || th * tw == 0 || columns * zoom == 0 {
        return Err(plot_error(
            "tiles must be non-empty RGB planes of one size, columns and zoom at least 1",
        ));
    }
    let rows = tiles.len().div_ceil(columns);
    let cell_w = tw * zoom + GAP;
    let cell_h = th * zoom + LABEL + GAP;
    let (width, height) = (columns * cell_w + GAP, rows * cell_h + GAP);
    let size = |v: usize| u32::try_from(v).map_err(|_| plot_error("figure too large"));
    let (width, height) = (size(width)?, size(height)?);
    let mut sheet = RgbImage::from_pixel(width, height, image::Rgb([255, 255, 255]));
    let byte = |v: f64| v.clamp(0.0, 255.0).round() as u8;
    for (k, (_, tile)) in tiles.iter().enumerate() {
        let (x0, y0) = (GAP + (k % columns) * cell_w, GAP + (k / columns) * cell_h);
        for i in 0..th {
            for j in 0..tw {
                let rgb = image::Rgb([0, 1, 2].map(|c| byte(tile[[c, i, j]])));
                for (di, dj) in (0..zoom).flat_map(|di| (0..zoom).map(move |dj| (di, dj))) {
                    let (x, y) = ((x0 + j * zoom + dj) as u32, (y0 + i * zoom + di) as u32);
                    sheet.put_pixel(x, y, rgb);
                }
            }
        }
    }
    register_bundled_font();
    let mut buffer = sheet.into_raw();
    {
        let root = BitMapBackend::with_buffer(&mut buffer, (width, height)).into_drawing_area();
        for (k, (label, _)) in tiles.iter().enumerate() {
            let x = (GAP + (k % columns) * cell_w) as i32;
            let y = (GAP + (k / columns) * cell_h + th * zoom + 4) as i32;
            root.draw_text(label, &("sans-serif", 15).into_font().color(&BLACK), (x, y))
                .map_err(plot_error)?;
        }
        root.present().map_err(plot_error)?;
    }
    RgbImage::from_raw(width, height, buffer)
        .ok_or_else(|| plot_error("figure buffer has the wrong size"))
}

#[cfg(test)]
#[path = "plot_tests.rs"]
mod tests;
