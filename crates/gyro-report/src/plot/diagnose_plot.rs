//! `diagnose --report`: the figures of a sim-to-real diagnosis.
//!
//! - [`EnvelopePlot`]: panels of a real curve (ink) against the range of simulated
//!   ensemble members (shaded bands with their median dashed): Allan deviation and PSD
//!   on log-log axes, binned residuals and cross-correlation on linear ones.
//! - [`GapMapPlot`]: runs (rows) × statistics (columns) coloured by z on a diverging
//!   scale clipped at ±[`GapMapPlot::clip`], with a colour bar.
//! - [`AngleErrorPlot`]: per run, the max abs angle error without and with the
//!   compensation, as grouped bars.

use super::calibrate_plot::short_name;
use super::noise_plot::{log_chart, log_range, note};
use super::{
    colour, corner_legend, draw_err, draw_segments, legend_at, line_swatch, padded, sig, tick,
    titled, DrawResult, Figure, RenderError, Stroke, LABEL_PX, TICK_PX,
};
use gyro_diagnose::stretches;
use plotters::coord::combinators::BindKeyPoints;
use plotters::coord::combinators::WithKeyPoints;
use plotters::coord::ranged1d::Ranged;
use plotters::coord::types::{RangedCoordf64, RangedCoordi32};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::FontTransform;

/// Simulated values at each x: lower, middle and upper edge of a band.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Band {
    /// Legend text.
    pub label: String,
    /// Abscissae.
    pub x: Vec<f64>,
    /// Lower edge per x.
    pub lo: Vec<f64>,
    /// Middle (median) per x.
    pub mid: Vec<f64>,
    /// Upper edge per x.
    pub hi: Vec<f64>,
}

/// The real data of a panel.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Measured {
    /// Legend text.
    pub label: String,
    /// Abscissae.
    pub x: Vec<f64>,
    /// Values.
    pub y: Vec<f64>,
    /// Error bars (lower, upper) per point, if any.
    pub bars: Option<(Vec<f64>, Vec<f64>)>,
    /// Draw as markers (binned values) instead of a line.
    pub markers: bool,
}

/// One chart of an [`EnvelopePlot`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Panel {
    /// Horizontal axis description.
    pub x_desc: String,
    /// Vertical axis description.
    pub y_desc: String,
    /// Both axes logarithmic (otherwise both linear).
    pub log: bool,
    /// The real data.
    pub measured: Option<Measured>,
    /// Simulated bands, drawn under the real data (first blue, second orange).
    pub bands: Vec<Band>,
    /// Draw the lines x = 0 and y = 0 where they are in range (linear panels).
    pub zero_lines: bool,
    /// Shown in place of the chart when set (why there is nothing to draw).
    pub empty: Option<String>,
}

/// Real curves against simulated envelopes, one or more panels stacked.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EnvelopePlot {
    /// Title.
    pub title: String,
    /// Subtitle lines.
    pub subtitle: String,
    /// Panels, top to bottom.
    pub panels: Vec<Panel>,
}

/// Pixels per panel.
const PANEL_PX: u32 = 520;
/// Width of every figure of the report (px).
const WIDTH_PX: u32 = 1100;

/// Fill and line colours of the bands, in order.
const BAND_COLOURS: [(RGBColor, RGBColor); 2] = [
    (colour::SKY, colour::BLUE),
    (colour::ORANGE, colour::VERMILLION),
];

impl Panel {
    fn valid(&self, v: f64) -> bool {
        v.is_finite() && (!self.log || v > 0.0)
    }

    /// Data ranges (x, y), or `None` when nothing is drawable.
    fn ranges(&self) -> Option<((f64, f64), (f64, f64))> {
        let mut xs: Vec<f64> = Vec::new();
        let mut ys: Vec<f64> = Vec::new();
        for b in &self.bands {
            for i in 0..b.x.len() {
                if self.valid(b.x[i]) {
                    for v in [b.lo.get(i), b.mid.get(i), b.hi.get(i)]
                        .into_iter()
                        .flatten()
                    {
                        if self.valid(*v) {
                            xs.push(b.x[i]);
                            ys.push(*v);
                        }
                    }
                }
            }
        }
        if let Some(m) = &self.measured {
            for i in 0..m.x.len() {
                if self.valid(m.x[i]) && m.y.get(i).is_some_and(|v| self.valid(*v)) {
                    xs.push(m.x[i]);
                    ys.push(m.y[i]);
                    if let Some((lo, hi)) = &m.bars {
                        ys.extend(
                            [lo.get(i), hi.get(i)]
                                .into_iter()
                                .flatten()
                                .filter(|v| self.valid(**v)),
                        );
                    }
                }
            }
        }
        let min = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
        let max = |v: &[f64]| v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if xs.is_empty() {
            return None;
        }
        let (x0, x1, y0, y1) = (min(&xs), max(&xs), min(&ys), max(&ys));
        if self.log {
            // Room above for the legend.
            Some((log_range(x0, x1, 1.2), log_range(y0, y1 * 3.0, 1.4)))
        } else {
            let (a, b) = padded(y0, y1, 0.05);
            Some((padded(x0, x1, 0.03), (a, b + 0.3 * (b - a))))
        }
    }
}

/// Tick label of a linear axis: as [`tick`], with small values to 3 significant digits
/// (so float noise in a step of 1e-6 does not show).
fn linear_tick(value: &f64) -> String {
    let v = *value;
    if v != 0.0 && v.abs() < 1e-3 && v.abs() > 1e-300 {
        let s = format!("{v:.2e}");
        match s.split_once('e') {
            Some((mantissa, exp)) if mantissa.contains('.') => {
                let m = mantissa.trim_end_matches('0').trim_end_matches('.');
                format!("{m}e{exp}")
            }
            _ => s,
        }
    } else {
        tick(value)
    }
}

fn linear_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    x: (f64, f64),
    y: (f64, f64),
    (x_desc, y_desc): (&str, &str),
) -> Result<ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>, RenderError> {
    let mut chart = ChartBuilder::on(area)
        .margin_left(10)
        .margin_right(30)
        .margin_top(10)
        .x_label_area_size(50)
        .y_label_area_size(90)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)
        .map_err(draw_err)?;
    chart
        .configure_mesh()
        .x_labels(12)
        .y_labels(8)
        .x_label_formatter(&linear_tick)
        .y_label_formatter(&linear_tick)
        .light_line_style(BLACK.mix(0.04))
        .bold_line_style(BLACK.mix(0.12))
        .label_style(("sans-serif", TICK_PX))
        .axis_desc_style(("sans-serif", LABEL_PX))
        .x_desc(x_desc)
        .y_desc(y_desc)
        .draw()
        .map_err(draw_err)?;
    Ok(chart)
}

/// An envelope panel's chart: linear or log axes, x and y both `f64`.
type PanelChart<'a, DB, X, Y> = ChartContext<'a, DB, Cartesian2d<X, Y>>;

/// Maps a data point to [0, 1]² of the plotting area (for the legend's placement).
type Norm<'n> = &'n dyn Fn((f64, f64)) -> (f64, f64);

/// Draw the bands, the real data and the legend on `chart`; `norm` maps a data point to
/// [0, 1]² of the plotting area.
fn draw_contents<'a, DB, X, Y>(
    chart: &mut PanelChart<'a, DB, X, Y>,
    p: &Panel,
    (x, y): ((f64, f64), (f64, f64)),
    norm: Norm,
) -> DrawResult
where
    DB: DrawingBackend + 'a,
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    if p.zero_lines && !p.log {
        draw_zero_lines(chart, (x, y))?;
    }
    let mut lines: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut labels: Vec<String> = Vec::new();
    for (k, band) in p.bands.iter().enumerate() {
        let colours = BAND_COLOURS[k % BAND_COLOURS.len()];
        lines.extend(draw_band(chart, p, band, colours, y, norm)?);
        labels.push(band.label.clone());
    }
    if let Some(m) = &p.measured {
        lines.push(draw_measured(chart, p, m, y, norm)?);
        labels.push(m.label.clone());
    }
    if labels.is_empty() {
        return Ok(());
    }
    let label_refs: Vec<&str> = labels.iter().map(String::as_str).collect();
    corner_legend(chart, &lines, &label_refs, 0.9)
}

/// The lines x = 0 and y = 0, where they are in range.
fn draw_zero_lines<'a, DB, X, Y>(
    chart: &mut PanelChart<'a, DB, X, Y>,
    (x, y): ((f64, f64), (f64, f64)),
) -> DrawResult
where
    DB: DrawingBackend + 'a,
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let axis = colour::GREY.mix(0.7).stroke_width(1);
    if y.0 < 0.0 && y.1 > 0.0 {
        chart
            .draw_series(LineSeries::new([(x.0, 0.0), (x.1, 0.0)], axis))
            .map_err(draw_err)?;
    }
    if x.0 < 0.0 && x.1 > 0.0 {
        chart
            .draw_series(LineSeries::new([(0.0, y.0), (0.0, y.1)], axis))
            .map_err(draw_err)?;
    }
    Ok(())
}

/// One simulated band: its range shaded (per stretch of drawable points) and its median
/// dashed, in `(fill, line)` colours; returns its edges normalised by `norm`.
fn draw_band<'a, DB, X, Y>(
    chart: &mut PanelChart<'a, DB, X, Y>,
    p: &Panel,
    band: &Band,
    (fill, line): (RGBColor, RGBColor),
    y: (f64, f64),
    norm: Norm,
) -> Result<Vec<Vec<(f64, f64)>>, RenderError>
where
    DB: DrawingBackend + 'a,
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let clamp_y = |v: f64| v.clamp(y.0, y.1);
    let n = band.x.len().min(band.lo.len()).min(band.hi.len());
    let ok = |i: usize| p.valid(band.x[i]) && p.valid(band.lo[i]) && p.valid(band.hi[i]);
    let mut edges = Vec::new();
    for run in stretches(n, ok) {
        let mut poly: Vec<(f64, f64)> = run
            .clone()
            .map(|i| (band.x[i], clamp_y(band.hi[i])))
            .collect();
        poly.extend(run.clone().rev().map(|i| (band.x[i], clamp_y(band.lo[i]))));
        if run.len() == 1 {
            // A single x: a short vertical stroke.
            chart
                .draw_series(std::iter::once(PathElement::new(
                    poly,
                    fill.mix(0.6).stroke_width(6),
                )))
                .map_err(draw_err)?;
        } else {
            chart
                .draw_series(std::iter::once(Polygon::new(poly, fill.mix(0.3).filled())))
                .map_err(draw_err)?;
        }
        edges.push(run.clone().map(|i| norm((band.x[i], band.hi[i]))).collect());
        edges.push(run.map(|i| norm((band.x[i], band.lo[i]))).collect());
    }
    let mid: Vec<(f64, f64)> = (0..n.min(band.mid.len()))
        .filter(|&i| p.valid(band.x[i]) && p.valid(band.mid[i]))
        .map(|i| (band.x[i], clamp_y(band.mid[i])))
        .collect();
    let dashed = (line.stroke_width(2), Stroke::Dashed(7, 4));
    let swatch = move |(x, y)| {
        EmptyElement::at((x, y))
            + Rectangle::new([(0, -7), (22, 7)], fill.mix(0.3).filled())
            + PathElement::new(vec![(0, 0), (22, 0)], line.stroke_width(2))
    };
    draw_segments(
        chart,
        std::slice::from_ref(&mid),
        dashed,
        &band.label,
        swatch,
    )?;
    Ok(edges)
}

/// The real data, as markers or a line, with its error bars if any; returns its points
/// normalised by `norm`.
fn draw_measured<'a, DB, X, Y>(
    chart: &mut PanelChart<'a, DB, X, Y>,
    p: &Panel,
    m: &Measured,
    y: (f64, f64),
    norm: Norm,
) -> Result<Vec<(f64, f64)>, RenderError>
where
    DB: DrawingBackend + 'a,
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let n = m.x.len().min(m.y.len());
    let pts: Vec<(f64, f64)> = (0..n)
        .filter(|&i| p.valid(m.x[i]) && p.valid(m.y[i]))
        .map(|i| (m.x[i], m.y[i]))
        .collect();
    if let Some((lo, hi)) = &m.bars {
        let clamp_y = |v: f64| v.clamp(y.0, y.1);
        let bars: Vec<(f64, f64, f64, f64)> = (0..n.min(lo.len()).min(hi.len()))
            .filter(|&i| p.valid(m.x[i]) && p.valid(m.y[i]))
            .map(|i| {
                let l = if p.valid(lo[i]) { lo[i] } else { m.y[i] };
                let h = if p.valid(hi[i]) { hi[i] } else { m.y[i] };
                (m.x[i], clamp_y(l), m.y[i], clamp_y(h))
            })
            .collect();
        chart
            .draw_series(bars.iter().map(|&(x, l, v, h)| {
                ErrorBar::new_vertical(x, l, v, h, colour::INK.mix(0.7).stroke_width(1), 6)
            }))
            .map_err(draw_err)?;
    }
    if m.markers {
        chart
            .draw_series(
                pts.iter()
                    .map(|&pt| Circle::new(pt, 3, colour::INK.filled())),
            )
            .map_err(draw_err)?
            .label(m.label.clone())
            .legend(|(x, y)| {
                EmptyElement::at((x + 11, y))
                    + Circle::new((0, 0), 3, colour::INK.filled())
                    + PathElement::new(vec![(0, -7), (0, 7)], colour::INK.stroke_width(1))
            });
    } else {
        let solid = (colour::INK.stroke_width(2), Stroke::Solid);
        let swatch = line_swatch(colour::INK, 2);
        draw_segments(chart, std::slice::from_ref(&pts), solid, &m.label, swatch)?;
    }
    Ok(pts.iter().map(|&pt| norm(pt)).collect())
}

fn draw_panel<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, p: &Panel) -> DrawResult {
    if let Some(text) = &p.empty {
        return note(area, text);
    }
    let Some((x, y)) = p.ranges() else {
        return note(area, "nothing to draw: no finite value");
    };
    let descs = (p.x_desc.as_str(), p.y_desc.as_str());
    if p.log {
        let mut chart = log_chart(area, x, y, descs)?;
        let norm = |(a, b): (f64, f64)| {
            (
                (a / x.0).ln() / (x.1 / x.0).ln(),
                (b / y.0).ln() / (y.1 / y.0).ln(),
            )
        };
        draw_contents(&mut chart, p, (x, y), &norm)
    } else {
        let mut chart = linear_chart(area, x, y, descs)?;
        let norm = |(a, b): (f64, f64)| ((a - x.0) / (x.1 - x.0), (b - y.0) / (y.1 - y.0));
        draw_contents(&mut chart, p, (x, y), &norm)
    }
}

impl Figure for EnvelopePlot {
    fn size(&self) -> (u32, u32) {
        let lines = self.subtitle.lines().filter(|l| !l.is_empty()).count() as u32;
        (
            WIDTH_PX,
            50 + 22 * lines + PANEL_PX * self.panels.len().max(1) as u32,
        )
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        if self.panels.is_empty() {
            return Err(RenderError::Empty("no panel"));
        }
        let body = titled(root, &self.title, &self.subtitle)?;
        let n = self.panels.len();
        let (_, h) = body.dim_in_pixel();
        let mut rest = body;
        for (i, panel) in self.panels.iter().enumerate() {
            if i + 1 == n {
                draw_panel(&rest, panel)?;
            } else {
                let (top, bottom) = rest.split_vertically(h / n as u32);
                draw_panel(&top, panel)?;
                rest = bottom;
            }
        }
        Ok(())
    }
}

/// Runs × statistics coloured by z.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GapMapPlot {
    /// Title.
    pub title: String,
    /// Subtitle lines.
    pub subtitle: String,
    /// Row labels (runs), top to bottom.
    pub rows: Vec<String>,
    /// Rows from this index on are held-out runs (a line is drawn above it).
    pub holdout_from: usize,
    /// Column labels (statistics), left to right.
    pub columns: Vec<String>,
    /// z per row and column (NaN: no value).
    pub z: Vec<Vec<f64>>,
    /// Colours saturate at ±clip.
    pub clip: f64,
}

/// The diverging colour of `t` in [-1, 1] (blue, white, red; ColorBrewer RdBu).
pub fn diverging(t: f64) -> RGBColor {
    const STOPS: [(f64, (f64, f64, f64)); 5] = [
        (-1.0, (33.0, 102.0, 172.0)),
        (-0.5, (146.0, 197.0, 222.0)),
        (0.0, (247.0, 247.0, 247.0)),
        (0.5, (244.0, 165.0, 130.0)),
        (1.0, (178.0, 24.0, 43.0)),
    ];
    let t = if t.is_finite() {
        t.clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let k = STOPS
        .windows(2)
        .position(|w| t <= w[1].0)
        .unwrap_or(STOPS.len() - 2);
    let ((a, ca), (b, cb)) = (STOPS[k], STOPS[k + 1]);
    let f = ((t - a) / (b - a)).clamp(0.0, 1.0);
    let mix = |x: f64, y: f64| (x + f * (y - x)).round().clamp(0.0, 255.0) as u8;
    RGBColor(mix(ca.0, cb.0), mix(ca.1, cb.1), mix(ca.2, cb.2))
}

/// Colour of a cell without a value.
const NO_VALUE: RGBColor = RGBColor(215, 215, 215);

impl GapMapPlot {
    fn cell(&self) -> (u32, u32) {
        let cols = self.columns.len().max(1) as f64;
        let rows = self.rows.len().max(1) as f64;
        (
            (760.0 / cols).clamp(8.0, 24.0) as u32,
            (640.0 / rows).clamp(9.0, 24.0) as u32,
        )
    }

    fn label_px(labels: &[String], cap: usize) -> u32 {
        let chars = labels
            .iter()
            .map(|l| l.chars().count().min(cap))
            .max()
            .unwrap_or(0);
        (chars as f64 * 0.6 * f64::from(TICK_PX)) as u32 + 16
    }

    fn layout(&self) -> (u32, u32, u32, u32) {
        let (cw, ch) = self.cell();
        let left = Self::label_px(&self.rows, 40);
        let top = Self::label_px(&self.columns, 60);
        (cw, ch, left, top)
    }
}

impl Figure for GapMapPlot {
    fn size(&self) -> (u32, u32) {
        let (cw, ch, left, top) = self.layout();
        let lines = self.subtitle.lines().filter(|l| !l.is_empty()).count() as u32;
        let grid_h = (ch * self.rows.len() as u32).max(220);
        (
            (left + cw * self.columns.len() as u32 + 150).max(700),
            60 + 22 * lines + top + grid_h + 30,
        )
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        if self.rows.is_empty() || self.columns.is_empty() {
            return Err(RenderError::Empty("no run or no statistic"));
        }
        let body = titled(root, &self.title, &self.subtitle)?;
        let grid = self.grid();
        self.draw_cells(&body, grid)?;
        self.draw_row_labels(&body, grid)?;
        self.draw_column_labels(&body, grid)?;
        self.draw_colour_bar(&body, grid)
    }
}

/// Where the gap map's grid lies in its body (px): the top-left corner and a cell's size.
#[derive(Clone, Copy, Debug)]
struct Grid {
    x0: i32,
    y0: i32,
    cell_w: i32,
    cell_h: i32,
}

/// Ink text of `size_px`, anchored at its vertical centre and horizontally at `h`.
fn ink(size_px: u32, h: HPos) -> TextStyle<'static> {
    TextStyle::from(("sans-serif", size_px).into_font())
        .color(&colour::INK)
        .pos(Pos::new(h, VPos::Center))
}

/// The colour bar's label of `v` in [-1, 1] (a fraction of the clip `clip`): the z, with
/// "≥"/"≤" at the ends where colours saturate.
fn bar_label(v: f64, clip: f64) -> String {
    let z = v * clip;
    let value = if z == z.round() {
        format!("{z:.0}")
    } else {
        sig(z, 2)
    };
    if v == 1.0 {
        format!("≥ {value}")
    } else if v == -1.0 {
        format!("≤ {value}")
    } else {
        value
    }
}

impl GapMapPlot {
    fn grid(&self) -> Grid {
        let (cw, ch, left, top) = self.layout();
        Grid {
            x0: left as i32,
            y0: top as i32 + 6,
            cell_w: cw as i32,
            cell_h: ch as i32,
        }
    }

    /// One cell per run and statistic, coloured by z (grey without a value).
    fn draw_cells<DB: DrawingBackend>(&self, body: &DrawingArea<DB, Shift>, g: Grid) -> DrawResult {
        for (r, row) in self.z.iter().enumerate().take(self.rows.len()) {
            for c in 0..self.columns.len() {
                let z = row.get(c).copied().unwrap_or(f64::NAN);
                let fill = if z.is_finite() {
                    diverging(z / self.clip)
                } else {
                    NO_VALUE
                };
                let (cx, cy) = (g.x0 + g.cell_w * c as i32, g.y0 + g.cell_h * r as i32);
                body.draw(&Rectangle::new(
                    [(cx, cy), (cx + g.cell_w - 1, cy + g.cell_h - 1)],
                    fill.filled(),
                ))
                .map_err(draw_err)?;
            }
        }
        Ok(())
    }

    /// Row labels, and the line between training and held-out runs.
    fn draw_row_labels<DB: DrawingBackend>(
        &self,
        body: &DrawingArea<DB, Shift>,
        g: Grid,
    ) -> DrawResult {
        let row_style = ink(TICK_PX, HPos::Right);
        for (r, label) in self.rows.iter().enumerate() {
            body.draw_text(
                &short_name(label),
                &row_style,
                (g.x0 - 6, g.y0 + g.cell_h * r as i32 + g.cell_h / 2),
            )
            .map_err(draw_err)?;
        }
        let grid_w = g.cell_w * self.columns.len() as i32;
        if self.holdout_from > 0 && self.holdout_from < self.rows.len() {
            let y = g.y0 + g.cell_h * self.holdout_from as i32 - 1;
            body.draw(&PathElement::new(
                vec![(g.x0 - 4, y), (g.x0 + grid_w + 4, y)],
                colour::INK.stroke_width(2),
            ))
            .map_err(draw_err)?;
        }
        Ok(())
    }

    /// Column labels, rotated, above the grid (shortened from the left past 60 characters).
    fn draw_column_labels<DB: DrawingBackend>(
        &self,
        body: &DrawingArea<DB, Shift>,
        g: Grid,
    ) -> DrawResult {
        let col_style = TextStyle::from(
            ("sans-serif", TICK_PX)
                .into_font()
                .transform(FontTransform::Rotate270),
        )
        .color(&colour::INK)
        .pos(Pos::new(HPos::Left, VPos::Center));
        for (c, label) in self.columns.iter().enumerate() {
            let text: String = if label.chars().count() > 60 {
                let tail: String = label.chars().skip(label.chars().count() - 59).collect();
                format!("…{tail}")
            } else {
                label.clone()
            };
            let x = g.x0 + g.cell_w * c as i32 + g.cell_w / 2;
            body.draw_text(&text, &col_style, (x, g.y0 - 4))
                .map_err(draw_err)?;
        }
        Ok(())
    }

    /// The colour bar right of the grid, with its ticks and the swatch of "no value".
    fn draw_colour_bar<DB: DrawingBackend>(
        &self,
        body: &DrawingArea<DB, Shift>,
        g: Grid,
    ) -> DrawResult {
        let (bar_x, y0) = (g.x0 + g.cell_w * self.columns.len() as i32 + 40, g.y0);
        let bar_h = (g.cell_h * self.rows.len() as i32).clamp(200, 400);
        let steps = 80;
        for k in 0..steps {
            let t = 1.0 - 2.0 * (k as f64 + 0.5) / steps as f64;
            let ya = y0 + bar_h * k / steps;
            let yb = y0 + bar_h * (k + 1) / steps;
            body.draw(&Rectangle::new(
                [(bar_x, ya), (bar_x + 16, yb)],
                diverging(t).filled(),
            ))
            .map_err(draw_err)?;
        }
        body.draw(&Rectangle::new(
            [(bar_x, y0), (bar_x + 16, y0 + bar_h)],
            colour::INK.stroke_width(1),
        ))
        .map_err(draw_err)?;
        let label_style = ink(TICK_PX, HPos::Left);
        for v in [-1.0, -0.5, -0.2, 0.0, 0.2, 0.5, 1.0] {
            let y = y0 + ((1.0 - v) * 0.5 * f64::from(bar_h)).round() as i32;
            body.draw(&PathElement::new(
                vec![(bar_x + 16, y), (bar_x + 20, y)],
                colour::INK.stroke_width(1),
            ))
            .map_err(draw_err)?;
            body.draw_text(&bar_label(v, self.clip), &label_style, (bar_x + 24, y))
                .map_err(draw_err)?;
        }
        body.draw_text("z", &ink(LABEL_PX, HPos::Left), (bar_x, y0 - 14))
            .map_err(draw_err)?;
        let ny = y0 + bar_h + 18;
        body.draw(&Rectangle::new(
            [(bar_x, ny), (bar_x + 16, ny + 12)],
            NO_VALUE.filled(),
        ))
        .map_err(draw_err)?;
        body.draw_text("no value", &label_style, (bar_x + 24, ny + 6))
            .map_err(draw_err)
    }
}

/// One run's max abs angle error without and with compensation (deg).
#[derive(Clone, Debug, PartialEq)]
pub struct AngleErrorRow {
    /// Run name.
    pub name: String,
    /// Without compensation.
    pub before_deg: f64,
    /// With compensation.
    pub after_deg: f64,
}

/// Grouped bars of the angle error per run, before and after compensation.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AngleErrorPlot {
    /// Title.
    pub title: String,
    /// Subtitle lines.
    pub subtitle: String,
    /// The runs, top to bottom.
    pub rows: Vec<AngleErrorRow>,
    /// Legend of the "before" bars.
    pub before_label: String,
    /// Legend of the "after" bars.
    pub after_label: String,
}

/// Pixels per run of the bar chart: compact, so that the figure of 15 runs fits the
/// report's first screen beside the verdict.
const BAR_ROW_PX: u32 = 26;

impl Figure for AngleErrorPlot {
    fn size(&self) -> (u32, u32) {
        let lines = self.subtitle.lines().filter(|l| !l.is_empty()).count() as u32;
        (
            WIDTH_PX,
            (150 + 22 * lines + BAR_ROW_PX * self.rows.len() as u32).max(300),
        )
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        if self.rows.is_empty() {
            return Err(RenderError::Empty("no run"));
        }
        let hi_deg = self.axis_max_deg();
        let names: Vec<String> = self.rows.iter().map(|r| short_name(&r.name)).collect();
        let body = titled(root, &self.title, &self.subtitle)?;
        let mut chart = bar_chart(&body, &names, hi_deg)?;
        self.draw_bars(&mut chart, Bar::Before, hi_deg)?;
        self.draw_bars(&mut chart, Bar::After, hi_deg)?;
        legend_at(&mut chart, SeriesLabelPosition::LowerRight, 0.9)
    }
}

/// Run k (from the top) of the bar chart spans y in [n-1-k, n-k] × `BAR_UNIT`; its name
/// at the middle.
const BAR_UNIT: i32 = 100;

/// The bar chart: error across (deg), runs down (units of [`BAR_UNIT`] per run).
type BarChart<'a, DB> =
    ChartContext<'a, DB, Cartesian2d<RangedCoordf64, WithKeyPoints<RangedCoordi32>>>;

/// The bottom of run `k`'s row (from the top) of `n`.
fn row_bottom(n: usize, k: usize) -> i32 {
    (n as i32 - 1 - k as i32) * BAR_UNIT
}

/// The chart with its mesh: errors up to `hi_deg` across, one row per name, the first at
/// the top.
fn bar_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    names: &[String],
    hi_deg: f64,
) -> Result<BarChart<'a, DB>, RenderError> {
    let n = names.len();
    let name_px = (names.iter().map(|s| s.chars().count()).max().unwrap_or(0) as f64
        * 0.6
        * f64::from(TICK_PX)) as u32;
    let n_i = n as i32;
    let centres: Vec<i32> = (0..n).map(|k| row_bottom(n, k) + BAR_UNIT / 2).collect();
    let mut chart = ChartBuilder::on(area)
        .margin_left(10)
        .margin_right(30)
        .margin_top(10)
        .x_label_area_size(50)
        .y_label_area_size(name_px + 24)
        .build_cartesian_2d(0.0..hi_deg, (0..n_i * BAR_UNIT).with_key_points(centres))
        .map_err(draw_err)?;
    let y_label = |v: &i32| {
        let from_top = n_i - 1 - (v - BAR_UNIT / 2) / BAR_UNIT;
        if (v - BAR_UNIT / 2) % BAR_UNIT == 0 && from_top >= 0 {
            usize::try_from(from_top)
                .ok()
                .and_then(|k| names.get(k).cloned())
                .unwrap_or_default()
        } else {
            String::new()
        }
    };
    chart
        .configure_mesh()
        .disable_y_mesh()
        .x_labels(10)
        .x_label_formatter(&tick)
        .y_label_formatter(&y_label)
        .light_line_style(BLACK.mix(0.04))
        .bold_line_style(BLACK.mix(0.12))
        .label_style(("sans-serif", TICK_PX))
        .axis_desc_style(("sans-serif", LABEL_PX))
        .x_desc("max abs angle error over the run (deg)")
        .draw()
        .map_err(draw_err)?;
    Ok(chart)
}

/// Which of a run's two bars: without or with compensation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Bar {
    Before,
    After,
}

impl Bar {
    fn colour(self) -> RGBColor {
        match self {
            Bar::Before => colour::GREY,
            Bar::After => colour::BLUE,
        }
    }

    /// Where the bar lies in its run's row (from, to; of [`BAR_UNIT`]): before above
    /// after.
    fn span(self) -> (i32, i32) {
        match self {
            Bar::Before => (52, 88),
            Bar::After => (12, 48),
        }
    }

    /// The run's error this bar shows (deg).
    fn value_deg(self, r: &AngleErrorRow) -> f64 {
        match self {
            Bar::Before => r.before_deg,
            Bar::After => r.after_deg,
        }
    }
}

impl AngleErrorPlot {
    /// The error axis' end (deg): room on the right for the values' labels and the legend.
    fn axis_max_deg(&self) -> f64 {
        let hi = self
            .rows
            .iter()
            .flat_map(|r| [r.before_deg, r.after_deg])
            .filter(|v| v.is_finite())
            .fold(0.0, f64::max);
        if hi > 0.0 {
            hi * 1.45
        } else {
            1.0
        }
    }

    /// `bar` of every run (with its legend entry), then each bar's value beside it.
    fn draw_bars<'a, DB: DrawingBackend + 'a>(
        &self,
        chart: &mut BarChart<'a, DB>,
        bar: Bar,
        hi_deg: f64,
    ) -> DrawResult {
        let label = match bar {
            Bar::Before => &self.before_label,
            Bar::After => &self.after_label,
        };
        let (c, (a, b)) = (bar.colour(), bar.span());
        let value = |r: &AngleErrorRow| bar.value_deg(r);
        let n = self.rows.len();
        chart
            .draw_series(self.rows.iter().enumerate().filter_map(|(k, r)| {
                let v = value(r);
                v.is_finite().then(|| {
                    Rectangle::new(
                        [
                            (0.0, row_bottom(n, k) + a),
                            (v.min(hi_deg), row_bottom(n, k) + b),
                        ],
                        c.mix(0.85).filled(),
                    )
                })
            }))
            .map_err(draw_err)?
            .label(label.clone())
            .legend(move |(x, y)| Rectangle::new([(x, y - 6), (x + 22, y + 6)], c.filled()));
        let value_style = TextStyle::from(("sans-serif", TICK_PX - 2).into_font())
            .color(&colour::INK)
            .pos(Pos::new(HPos::Left, VPos::Center));
        chart
            .draw_series(self.rows.iter().enumerate().map(|(k, r)| {
                let v = value(r);
                let text = if v.is_finite() {
                    format!("{} deg", sig(v, 3))
                } else {
                    "-".to_string()
                };
                let at = if v.is_finite() { v.min(hi_deg) } else { 0.0 };
                EmptyElement::at((at, row_bottom(n, k) + (a + b) / 2))
                    + Text::new(text, (5, 0), value_style.clone())
            }))
            .map_err(draw_err)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::{render, ImageFormat};

    #[test]
    fn small_ticks_without_float_noise() {
        assert_eq!(linear_tick(&1.000000000001e-6), "1e-6");
        assert_eq!(linear_tick(&-2.5e-5), "-2.5e-5");
        assert_eq!(linear_tick(&0.25), "0.25");
        assert_eq!(linear_tick(&0.0), "0");
    }

    #[test]
    fn diverging_ends_and_middle() {
        assert_eq!(diverging(-1.0), RGBColor(33, 102, 172));
        assert_eq!(diverging(0.0), RGBColor(247, 247, 247));
        assert_eq!(diverging(1.0), RGBColor(178, 24, 43));
        assert_eq!(diverging(7.0), diverging(1.0));
        assert_eq!(diverging(f64::NAN), diverging(0.0));
    }

    fn band(x: &[f64], f: impl Fn(f64) -> f64) -> Band {
        Band {
            label: "simulated".into(),
            x: x.to_vec(),
            lo: x.iter().map(|v| 0.8 * f(*v)).collect(),
            mid: x.iter().map(|v| f(*v)).collect(),
            hi: x.iter().map(|v| 1.2 * f(*v)).collect(),
        }
    }

    #[test]
    fn envelope_panels_render_as_svg_and_png() {
        let x: Vec<f64> = (0..20).map(|i| 0.01 * 1.5f64.powi(i)).collect();
        let plot = EnvelopePlot {
            title: "t".into(),
            subtitle: "s".into(),
            panels: vec![
                Panel {
                    x_desc: "τ (s)".into(),
                    y_desc: "σ".into(),
                    log: true,
                    measured: Some(Measured {
                        label: "real".into(),
                        x: x.clone(),
                        y: x.iter().map(|t| 0.1 / t.sqrt()).collect(),
                        bars: None,
                        markers: false,
                    }),
                    bands: vec![band(&x, |t| 0.1 / t.sqrt())],
                    ..Panel::default()
                },
                Panel {
                    x_desc: "rate".into(),
                    y_desc: "residual".into(),
                    measured: Some(Measured {
                        label: "real".into(),
                        x: vec![-1.0, 0.0, 1.0],
                        y: vec![-0.1, 0.0, 0.1],
                        bars: Some((vec![-0.2, -0.1, 0.0], vec![0.0, 0.1, 0.2])),
                        markers: true,
                    }),
                    bands: vec![
                        band(&[-1.0, 0.0, 1.0], |v| v),
                        band(&[-1.0, 0.0, 1.0], |v| 0.5 * v),
                    ],
                    zero_lines: true,
                    ..Panel::default()
                },
                Panel {
                    empty: Some("no temperature".into()),
                    ..Panel::default()
                },
            ],
        };
        let svg = String::from_utf8(render(&plot, ImageFormat::Svg).unwrap()).unwrap();
        assert!(svg.contains("<polygon"), "bands are polygons");
        assert!(svg.contains("no temperature"));
        let png = render(&plot, ImageFormat::Png).unwrap();
        assert!(png.starts_with(b"\x89PNG"));
    }

    #[test]
    fn gap_map_and_bars_render() {
        let map = GapMapPlot {
            title: "gap map".into(),
            subtitle: String::new(),
            rows: vec!["a.csv".into(), "b.csv".into(), "c.csv".into()],
            holdout_from: 2,
            columns: vec!["static/residual_mean".into(), "all/xcorr_peak_lag_s".into()],
            z: vec![vec![0.0, 12.0], vec![-3.0, f64::NAN], vec![1.0, 2.0]],
            clip: 10.0,
        };
        let svg = String::from_utf8(render(&map, ImageFormat::Svg).unwrap()).unwrap();
        assert!(svg.contains("static/residual_mean") && svg.contains("rotate(270"));
        assert!(svg.contains("no value"));
        let bars = AngleErrorPlot {
            title: "angle error".into(),
            subtitle: String::new(),
            rows: vec![
                AngleErrorRow {
                    name: "h1.csv".into(),
                    before_deg: 2.0,
                    after_deg: 0.4,
                },
                AngleErrorRow {
                    name: "h2.csv".into(),
                    before_deg: 1.5,
                    after_deg: f64::NAN,
                },
            ],
            before_label: "before".into(),
            after_label: "after".into(),
        };
        let svg = String::from_utf8(render(&bars, ImageFormat::Svg).unwrap()).unwrap();
        assert!(svg.contains("h1.csv") && svg.contains("h2.csv") && svg.contains("0.400 deg"));
        assert!(render(&bars, ImageFormat::Png).is_ok());
    }
}
