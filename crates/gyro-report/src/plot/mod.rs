//! Plots of a run, a noise characterisation and a calibration, as SVG or PNG (chosen by
//! the file's extension), drawn with pure-Rust `plotters` and an embedded font (DejaVu
//! Sans), so no system library is needed.
//!
//! ```no_run
//! use gyro_log as log;
//! use gyro_report::plot;
//! use gyro_analysis::replay;
//! let raw = log::read_csv("fixtures/logs/bench_run.csv".as_ref(), &log::ColumnOptions::default())?;
//! let regular = log::regularize(&raw, &log::GridOptions::default())?;
//! let report = replay::replay(&regular, &gyro_core::Config::default())?;
//! plot::run_plot("run.png".as_ref(), "bench_run.csv", &report)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Each plot is a [`Figure`]: [`RunPlot`], [`NoisePlot`], [`CalibrationPlot`], and the
//! diagnosis report's figures in [`diagnose_plot`]. [`save`] writes one to a file,
//! [`render`] returns the file's bytes (e.g. for an HTML report).

mod calibrate_plot;
pub mod diagnose_plot;
mod noise_plot;
mod run_plot;

pub use calibrate_plot::{calibrate_plot, CalibrationPlot};
pub use noise_plot::{noise_plot, NoisePlot};
pub use run_plot::{run_plot, RunPlot};

use plotters::coord::{CoordTranslate, Shift};
use plotters::element::{DashedPathElement, IntoDynElement};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{FontStyle, RGBColor};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The image formats a plot can be written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// Scalable vector graphics (`.svg`).
    Svg,
    /// Portable network graphics, 8-bit RGB (`.png`).
    Png,
}

impl ImageFormat {
    /// The format named by `path`'s extension (`.svg` or `.png`, any case).
    pub fn from_path(path: &Path) -> Result<Self, PlotError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("svg") => Ok(ImageFormat::Svg),
            Some("png") => Ok(ImageFormat::Png),
            _ => Err(PlotError::UnknownFormat {
                path: path.to_path_buf(),
            }),
        }
    }
}

/// A command-line value parser for a plot file: the path, if its extension names a
/// format (so a typo fails before any work is done).
pub fn parse_plot_path(value: &str) -> Result<PathBuf, PlotError> {
    let path = PathBuf::from(value);
    ImageFormat::from_path(&path)?;
    Ok(path)
}

/// Why a figure could not be rendered.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The data holds nothing to draw.
    #[error("nothing to plot: {0}")]
    Empty(&'static str),
    /// The embedded font could not be loaded.
    #[error("the embedded font could not be loaded")]
    Font,
    /// The drawing library failed.
    #[error("drawing failed: {0}")]
    Draw(String),
    /// PNG encoding failed.
    #[error("PNG encoding failed")]
    Encode(#[from] png::EncodingError),
}

/// Why a plot could not be written; every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The extension names no supported format.
    #[error("{}: unknown plot format (the file name must end in .svg or .png)", path.display())]
    UnknownFormat {
        /// The file.
        path: PathBuf,
    },
    /// The figure could not be drawn.
    #[error("cannot plot {}", path.display())]
    Render {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        #[source]
        source: RenderError,
    },
    /// The file could not be written.
    #[error("cannot write {}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
}

/// What a figure's drawing code returns.
pub type DrawResult = Result<(), RenderError>;

/// A plot: its size in pixels and how to draw it on any `plotters` backend.
pub trait Figure {
    /// Width and height (px).
    fn size(&self) -> (u32, u32);
    /// Draw on `root` (already filled white, of [`Figure::size`]).
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult;
}

/// Convert a `plotters` error.
pub(crate) fn draw_err<E: std::error::Error + Send + Sync>(
    e: DrawingAreaErrorKind<E>,
) -> RenderError {
    RenderError::Draw(e.to_string())
}

/// Register the embedded DejaVu Sans as `sans-serif` (once per process).
fn fonts() -> Result<(), RenderError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular())
            .is_ok()
            && plotters::style::register_font("sans-serif", FontStyle::Bold, dejavu::sans::bold())
                .is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(RenderError::Font)
    }
}

/// The bytes of `figure` as a file of `format`.
pub fn render(figure: &impl Figure, format: ImageFormat) -> Result<Vec<u8>, RenderError> {
    fonts()?;
    let (w, h) = figure.size();
    match format {
        ImageFormat::Svg => {
            let mut svg = String::new();
            {
                let root = SVGBackend::with_string(&mut svg, (w, h)).into_drawing_area();
                root.fill(&WHITE).map_err(draw_err)?;
                figure.draw(&root)?;
                root.present().map_err(draw_err)?;
            }
            Ok(svg.into_bytes())
        }
        ImageFormat::Png => {
            let mut rgb = vec![0_u8; w as usize * h as usize * 3];
            {
                let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
                root.fill(&WHITE).map_err(draw_err)?;
                figure.draw(&root)?;
                root.present().map_err(draw_err)?;
            }
            let mut out = Vec::new();
            {
                let mut encoder = png::Encoder::new(&mut out, w, h);
                encoder.set_color(png::ColorType::Rgb);
                encoder.set_depth(png::BitDepth::Eight);
                let mut writer = encoder.write_header()?;
                writer.write_image_data(&rgb)?;
                writer.finish()?;
            }
            Ok(out)
        }
    }
}

/// Write `figure` to `path`, as SVG or PNG by its extension. Nothing is written unless the
/// figure was drawn completely, and then whole ([`gyro_log::whole`]).
pub fn save(path: &Path, figure: &impl Figure) -> Result<(), PlotError> {
    let format = ImageFormat::from_path(path)?;
    let bytes = render(figure, format).map_err(|source| PlotError::Render {
        path: path.to_path_buf(),
        source,
    })?;
    let write = |w: &mut _| std::io::Write::write_all(w, &bytes);
    gyro_log::whole::write(path, write).map_err(|source| PlotError::Write {
        path: path.to_path_buf(),
        source,
    })
}

/// Colour-blind-safe palette (Okabe & Ito).
pub(crate) mod colour {
    use super::RGBColor;
    /// Blue.
    pub const BLUE: RGBColor = RGBColor(0, 114, 178);
    /// Orange.
    pub const ORANGE: RGBColor = RGBColor(230, 159, 0);
    /// Sky blue.
    pub const SKY: RGBColor = RGBColor(86, 180, 233);
    /// Bluish green.
    pub const GREEN: RGBColor = RGBColor(0, 158, 115);
    /// Vermillion.
    pub const VERMILLION: RGBColor = RGBColor(213, 94, 0);
    /// Reddish purple.
    pub const PURPLE: RGBColor = RGBColor(204, 121, 167);
    /// Near-black for data and text.
    pub const INK: RGBColor = RGBColor(30, 30, 30);
    /// Grey.
    pub const GREY: RGBColor = RGBColor(120, 120, 120);
}

/// Font sizes (px).
pub(crate) const TITLE_PX: u32 = 22;
pub(crate) const SUBTITLE_PX: u32 = 16;
pub(crate) const LABEL_PX: u32 = 15;
pub(crate) const TICK_PX: u32 = 13;

/// Draw a bold title and the subtitle's lines (none if empty) at the top of `area`;
/// return the area below them.
pub(crate) fn titled<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
    subtitle: &str,
) -> Result<DrawingArea<DB, Shift>, RenderError> {
    let (w, _) = area.dim_in_pixel();
    let centre = Pos::new(HPos::Center, VPos::Top);
    let title_style = ("sans-serif", TITLE_PX)
        .into_font()
        .style(FontStyle::Bold)
        .color(&colour::INK)
        .pos(centre);
    let x = (w / 2) as i32;
    area.draw_text(&fit_text(title, w, TITLE_PX), &title_style, (x, 10))
        .map_err(draw_err)?;
    let mut used = 10 + TITLE_PX as i32 + 8;
    let style = ("sans-serif", SUBTITLE_PX)
        .into_font()
        .color(&colour::INK)
        .pos(centre);
    for line in subtitle.lines().filter(|l| !l.is_empty()) {
        area.draw_text(&fit_text(line, w, SUBTITLE_PX), &style, (x, used))
            .map_err(draw_err)?;
        used += SUBTITLE_PX as i32 + 6;
    }
    used += 2;
    Ok(area.margin(used, 0, 0, 0))
}

/// `text` shortened from the left (with "…") to fit about `width_px` at `size_px`.
pub(crate) fn fit_text(text: &str, width_px: u32, size_px: u32) -> String {
    // DejaVu Sans averages about 0.55 em per character.
    let max_chars = ((f64::from(width_px) - 20.0) / (0.55 * f64::from(size_px))).max(4.0) as usize;
    let n = text.chars().count();
    if n <= max_chars {
        text.to_string()
    } else {
        let tail: String = text.chars().skip(n - (max_chars - 1)).collect();
        format!("…{tail}")
    }
}

/// A number with about `digits` significant digits, without exponent between 1e-3 and
/// 1e5.
pub(crate) fn sig(value: f64, digits: usize) -> String {
    if value == 0.0 || !value.is_finite() {
        return format!("{value}");
    }
    let magnitude = value.abs().log10().floor() as i32;
    if (-3..5).contains(&magnitude) {
        let decimals = (digits as i32 - 1 - magnitude).max(0) as usize;
        format!("{value:.decimals$}")
    } else {
        format!("{value:.prec$e}", prec = digits.saturating_sub(1))
    }
}

/// Tick label for a log axis: decades as `10^k` written plainly where short (0.01, 100),
/// in `1e-5` form otherwise; other ticks as a short number.
pub(crate) fn log_tick(value: f64) -> String {
    if !(value.is_finite() && value > 0.0) {
        return String::new();
    }
    let exp = value.log10();
    if (exp - exp.round()).abs() < 1e-9 {
        let k = exp.round() as i32;
        if (-3..=4).contains(&k) {
            sig(value, 1)
        } else {
            format!("1e{k}")
        }
    } else {
        let k = exp.floor() as i32;
        if (-3..=4).contains(&k) {
            sig(value, 1)
        } else {
            format!("{value:.0e}")
        }
    }
}

/// Tick label for a linear axis: the shortest of a few decimals, no "-0".
pub(crate) fn tick(value: &f64) -> String {
    let v = if value.abs() < 1e-12 { 0.0 } else { *value };
    if v != 0.0 && (v.abs() >= 1e5 || v.abs() < 1e-3) {
        return format!("{v:e}");
    }
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}

/// The legend corner covering the fewest data: `lines` in plot coordinates normalised to
/// [0, 1] (x right, y up), legend of `size` as fractions of the plotting area. Lines
/// are sampled between their points, so sparse lines count too. Ties go to the upper
/// left, then upper right, lower left, lower right.
pub(crate) fn legend_corner<'a>(
    lines: impl Iterator<Item = &'a [(f64, f64)]>,
    size: (f64, f64),
) -> SeriesLabelPosition {
    let (w, h) = (size.0 + 0.03, size.1 + 0.04);
    let boxes = [
        (SeriesLabelPosition::UpperLeft, (0.0, w), (1.0 - h, 1.0)),
        (
            SeriesLabelPosition::UpperRight,
            (1.0 - w, 1.0),
            (1.0 - h, 1.0),
        ),
        (SeriesLabelPosition::LowerLeft, (0.0, w), (0.0, h)),
        (SeriesLabelPosition::LowerRight, (1.0 - w, 1.0), (0.0, h)),
    ];
    let mut counts = [0_usize; 4];
    for line in lines {
        let samples = line.windows(2).flat_map(|p| {
            (0..8).map(move |k| {
                let f = f64::from(k) / 8.0;
                (
                    p[0].0 + f * (p[1].0 - p[0].0),
                    p[0].1 + f * (p[1].1 - p[0].1),
                )
            })
        });
        for (x, y) in samples.chain(line.last().copied()) {
            for (count, (_, bx, by)) in counts.iter_mut().zip(&boxes) {
                if x >= bx.0 && x <= bx.1 && y >= by.0 && y <= by.1 {
                    *count += 1;
                }
            }
        }
    }
    let mut best = 0;
    for k in 1..4 {
        if counts[k] < counts[best] {
            best = k;
        }
    }
    boxes[best].0.clone()
}

/// Draw `chart`'s legend at `position`, on white of `background_opacity`.
pub(crate) fn legend_at<'a, DB: DrawingBackend + 'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
    background_opacity: f64,
) -> DrawResult {
    chart
        .configure_series_labels()
        .position(position)
        .label_font(("sans-serif", TICK_PX))
        .background_style(WHITE.mix(background_opacity))
        .border_style(BLACK.mix(0.3))
        .draw()
        .map_err(draw_err)
}

/// Draw the legend of `labels` in the corner where `normalised` lines (as for
/// [`legend_corner`]) leave the most room, on white of `background_opacity`.
pub(crate) fn corner_legend<'a, DB: DrawingBackend + 'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
    normalised: &[Vec<(f64, f64)>],
    labels: &[&str],
    background_opacity: f64,
) -> DrawResult {
    let size = legend_size(labels, chart.plotting_area().dim_in_pixel());
    let position = legend_corner(normalised.iter().map(Vec::as_slice), size);
    legend_at(chart, position, background_opacity)
}

/// How a line is stroked: solid, or dashed with dashes and gaps of these lengths (px).
#[derive(Clone, Copy, Debug)]
pub(crate) enum Stroke {
    Solid,
    Dashed(i32, i32),
}

/// Draw each of `segments` as a line of `style`; only the first carries the legend
/// entry, `label` with its `swatch`.
pub(crate) fn draw_segments<'a, DB, CT, E>(
    chart: &mut ChartContext<'a, DB, CT>,
    segments: &[Vec<(f64, f64)>],
    (style, stroke): (ShapeStyle, Stroke),
    label: &str,
    swatch: impl Fn((i32, i32)) -> E + 'a,
) -> DrawResult
where
    DB: DrawingBackend + 'a,
    CT: CoordTranslate<From = (f64, f64)>,
    E: IntoDynElement<'a, DB, (i32, i32)>,
{
    let mut swatch = Some(swatch);
    for line in segments {
        let points = line.iter().copied();
        let drawn = match stroke {
            Stroke::Solid => chart.draw_series(LineSeries::new(points, style)),
            Stroke::Dashed(dash, gap) => {
                chart.draw_series(DashedLineSeries::new(points, dash, gap, style))
            }
        }
        .map_err(draw_err)?;
        if let Some(swatch) = swatch.take() {
            drawn.label(label).legend(swatch);
        }
    }
    Ok(())
}

/// A legend swatch: a short line of colour `c`, `width` px wide.
pub(crate) fn line_swatch(
    c: RGBColor,
    width: u32,
) -> impl Fn((i32, i32)) -> PathElement<(i32, i32)> {
    move |(x, y)| PathElement::new(vec![(x, y), (x + 22, y)], c.stroke_width(width))
}

/// A legend swatch: a short dashed line of colour `c`, `width` px wide.
pub(crate) fn dashed_swatch(
    c: RGBColor,
    width: u32,
) -> impl Fn((i32, i32)) -> DashedPathElement<std::array::IntoIter<(i32, i32), 2>, i32> {
    move |(x, y)| DashedPathElement::new([(x, y), (x + 22, y)], 6, 3, c.stroke_width(width))
}

/// Size of a legend with `labels` in `area_px` (plotting area), as fractions.
pub(crate) fn legend_size(labels: &[&str], area_px: (u32, u32)) -> (f64, f64) {
    let chars = labels.iter().map(|l| l.chars().count()).max().unwrap_or(0);
    let w = 0.56 * f64::from(TICK_PX) * chars as f64 + 50.0;
    let h = 20.0 * labels.len() as f64 + 12.0;
    (
        w / f64::from(area_px.0.max(1)),
        h / f64::from(area_px.1.max(1)),
    )
}

/// Thin `points` (sorted by x) to about `max_points`, keeping the minimum and maximum of
/// each bucket in order, so peaks survive.
pub(crate) fn thin(points: &[(f64, f64)], max_points: usize) -> Vec<(f64, f64)> {
    let buckets = (max_points / 2).max(1);
    if points.len() <= max_points {
        return points.to_vec();
    }
    let per = points.len().div_ceil(buckets);
    let mut out = Vec::with_capacity(2 * buckets + 1);
    for chunk in points.chunks(per) {
        let (mut lo, mut hi) = (0, 0);
        for (i, p) in chunk.iter().enumerate() {
            if p.1 < chunk[lo].1 {
                lo = i;
            }
            if p.1 > chunk[hi].1 {
                hi = i;
            }
        }
        let (a, b) = if lo <= hi { (lo, hi) } else { (hi, lo) };
        out.push(chunk[a]);
        if b != a {
            out.push(chunk[b]);
        }
    }
    out
}

/// Thin `points` (sorted by x) to at most `max_points`: the largest value of each
/// bucket, at the bucket's middle point; an upper envelope without notches.
pub(crate) fn envelope(points: &[(f64, f64)], max_points: usize) -> Vec<(f64, f64)> {
    if points.len() <= max_points.max(2) {
        return points.to_vec();
    }
    let per = points.len().div_ceil(max_points.max(2));
    let mut out: Vec<(f64, f64)> = points
        .chunks(per)
        .map(|chunk| {
            let hi = chunk.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
            (chunk[chunk.len() / 2].0, hi)
        })
        .collect();
    // Keep the ends where they were.
    if let (Some(first), Some(o)) = (points.first(), out.first_mut()) {
        o.0 = first.0;
    }
    if let (Some(last), Some(o)) = (points.last(), out.last_mut()) {
        o.0 = last.0;
    }
    out
}

/// `(lo, hi)` widened by `pad` of its span on both sides (and to a non-zero span).
pub(crate) fn padded(lo: f64, hi: f64, pad: f64) -> (f64, f64) {
    let (lo, hi) = if lo.is_finite() && hi.is_finite() && lo <= hi {
        (lo, hi)
    } else {
        (0.0, 1.0)
    };
    let span = hi - lo;
    if span <= f64::EPSILON * hi.abs().max(lo.abs()).max(1e-12) {
        let half = (lo.abs() * 0.1).max(1e-3);
        return (lo - half, hi + half);
    }
    (lo - pad * span, hi + pad * span)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn format_from_extension() {
        assert_eq!(
            ImageFormat::from_path(Path::new("a/b.SVG")).ok(),
            Some(ImageFormat::Svg)
        );
        assert_eq!(
            ImageFormat::from_path(Path::new("b.png")).ok(),
            Some(ImageFormat::Png)
        );
        for bad in ["b.jpg", "b", "b.svg.txt"] {
            let e = ImageFormat::from_path(Path::new(bad)).unwrap_err();
            assert!(e.to_string().contains(bad), "{e}");
        }
    }

    #[test]
    fn thinning_keeps_extremes() {
        let points: Vec<(f64, f64)> = (0..10_000)
            .map(|i| (f64::from(i), if i == 5_003 { 9.0 } else { 0.0 }))
            .collect();
        let thin = thin(&points, 100);
        assert!(thin.len() <= 101);
        assert!(thin.iter().any(|p| p.1 == 9.0));
        assert!(thin.windows(2).all(|w| w[0].0 < w[1].0));
    }

    #[test]
    fn numbers() {
        assert_eq!(sig(0.0674, 2), "0.067");
        assert_eq!(sig(123.4, 3), "123");
        assert_eq!(sig(1.5e-6, 2), "1.5e-6");
        assert_eq!(log_tick(0.01), "0.01");
        assert_eq!(log_tick(1e-5), "1e-5");
        assert_eq!(log_tick(100.0), "100");
        assert_eq!(fit_text("short", 800, 16), "short");
        assert!(fit_text(&"x".repeat(500), 200, 16).starts_with('…'));
    }
}
