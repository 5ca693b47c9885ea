//! `run --plot`: stacked panels over one time axis — angle against the reference, the
//! angle error (with the Kalman ±1σ band), the motion state and the filtered rate.

use super::{
    colour, corner_legend, draw_err, draw_segments, envelope, line_swatch, padded, save, thin,
    tick, titled, DrawResult, Figure, PlotError, RenderError, Stroke, LABEL_PX, TICK_PX,
};
use gyro_analysis::replay::{Mode, RunReport, SeriesPoint, Summary};
use gyro_core::{Compensation, MotionState};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Points kept per line (min/max thinning beyond that).
const MAX_POINTS: usize = 3000;

const REFERENCE_LABEL: &str = "reference (encoder, filtered)";
const ERROR_LABEL: &str = "angle − reference";
const SIGMA_LABEL: &str = "±1σ of the angle";
const RATE_LABEL: &str = "rate (decimated, low-passed)";

/// The plot of one replayed run.
#[derive(Clone, Copy, Debug)]
pub struct RunPlot<'a> {
    /// Shown in the title (the log's file name).
    pub title: &'a str,
    /// The replay.
    pub report: &'a RunReport,
}

/// Write the plot of `report` to `path` (SVG or PNG by the extension).
pub fn run_plot(path: &Path, title: &str, report: &RunReport) -> Result<(), PlotError> {
    save(path, &RunPlot { title, report })
}

/// Time spans (s) during which the pipeline was in the dynamic state.
fn dynamic_spans(series: &[SeriesPoint]) -> Vec<(f64, f64)> {
    let mut spans = Vec::new();
    let mut start: Option<f64> = None;
    for p in series {
        match (p.motion, start) {
            (MotionState::Dynamic, None) => start = Some(p.time_s),
            (MotionState::Static, Some(s)) => {
                spans.push((s, p.time_s));
                start = None;
            }
            _ => {}
        }
    }
    if let (Some(s), Some(last)) = (start, series.last()) {
        spans.push((s, last.time_s));
    }
    spans
}

/// Contiguous stretches of `(time, value)` where `value` is present.
fn segments(
    series: &[SeriesPoint],
    value: impl Fn(&SeriesPoint) -> Option<f64>,
) -> Vec<Vec<(f64, f64)>> {
    let mut out: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut current = Vec::new();
    for p in series {
        match value(p) {
            Some(v) if v.is_finite() => current.push((p.time_s, v)),
            _ => {
                if !current.is_empty() {
                    out.push(std::mem::take(&mut current));
                }
            }
        }
    }
    if !current.is_empty() {
        out.push(current);
    }
    out
}

fn range_of<'a>(lines: impl Iterator<Item = &'a Vec<(f64, f64)>>) -> (f64, f64) {
    lines
        .flat_map(|l| l.iter())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.1), hi.max(p.1))
        })
}

type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// A panel with the shared time axis; tick labels and the axis title only at the bottom.
fn panel<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    time: (f64, f64),
    y: (f64, f64),
    y_desc: &str,
    bottom: bool,
) -> Result<Chart<'a, DB>, RenderError> {
    let mut chart = ChartBuilder::on(area)
        .margin_left(10)
        .margin_right(25)
        .margin_top(8)
        .x_label_area_size(if bottom { 50 } else { 0 })
        .y_label_area_size(85)
        .build_cartesian_2d(time.0..time.1, y.0..y.1)
        .map_err(draw_err)?;
    let mut mesh = chart.configure_mesh();
    mesh.x_labels(12)
        .y_labels(6)
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .light_line_style(WHITE.mix(0.0))
        .bold_line_style(BLACK.mix(0.12))
        .label_style(("sans-serif", TICK_PX))
        .axis_desc_style(("sans-serif", LABEL_PX))
        .y_desc(y_desc);
    if bottom {
        mesh.x_desc("time (s)");
    }
    mesh.draw().map_err(draw_err)?;
    Ok(chart)
}

/// Light shading of the movements across a panel.
fn shade_movements<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    spans: &[(f64, f64)],
    y: (f64, f64),
) -> DrawResult {
    chart
        .draw_series(
            spans.iter().map(|&(a, b)| {
                Rectangle::new([(a, y.0), (b, y.1)], colour::ORANGE.mix(0.10).filled())
            }),
        )
        .map_err(draw_err)?;
    Ok(())
}

/// Draw the legend of `labels` in the corner where `lines` leave the most room.
fn legend<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    lines: &[&[(f64, f64)]],
    (time, y): ((f64, f64), (f64, f64)),
    labels: &[&str],
) -> DrawResult {
    let normalised: Vec<Vec<(f64, f64)>> = lines
        .iter()
        .map(|l| {
            l.iter()
                .map(|&(t, v)| ((t - time.0) / (time.1 - time.0), (v - y.0) / (y.1 - y.0)))
                .collect()
        })
        .collect();
    corner_legend(chart, &normalised, labels, 0.85)
}

/// Several segments of one quantity over time (gaps where it is missing).
type Segments = Vec<Vec<(f64, f64)>>;

/// Each segment thinned to its share of [`MAX_POINTS`] (at least 2 points).
fn thin_all(lines: Segments) -> Segments {
    let total: usize = lines.iter().map(Vec::len).sum::<usize>().max(1);
    lines
        .into_iter()
        .map(|l| {
            let keep = (MAX_POINTS * l.len() / total).max(2);
            thin(&l, keep)
        })
        .collect()
}

/// The run's series as thinned lines, ready to draw.
struct Lines {
    angle_deg: Segments,
    reference_deg: Segments,
    error_deg: Segments,
    /// The upper edge of the Kalman ±1σ band.
    sigma_deg: Segments,
    rate_dps: Segments,
}

impl Lines {
    fn of(series: &[SeriesPoint]) -> Self {
        Lines {
            angle_deg: thin_all(segments(series, |p| Some(f64::from(p.angle_deg)))),
            reference_deg: thin_all(segments(series, |p| p.reference_deg)),
            error_deg: thin_all(segments(series, SeriesPoint::error_deg)),
            // The band's edge: the largest σ per bucket (min/max thinning would notch it).
            sigma_deg: segments(series, |p| p.angle_std_deg.map(f64::from))
                .iter()
                .map(|l| envelope(l, MAX_POINTS / 2))
                .collect(),
            rate_dps: thin_all(segments(series, |p| Some(f64::from(p.rate_dps)))),
        }
    }
}

/// How the angle was compensated, in words; offline said so.
fn mode_text(compensation: Compensation, mode: Mode) -> &'static str {
    match (compensation, mode) {
        (Compensation::None, _) => "no compensation",
        (Compensation::Paper, _) => "paper error model",
        (Compensation::Kalman, Mode::Causal) => "Kalman form",
        (Compensation::Kalman, Mode::Offline) => "Kalman form, offline",
    }
}

/// The subtitle: the compensation, the error figures and the movements.
fn subtitle(s: &Summary, mode: Mode) -> String {
    let errors = match (s.max_abs_error_deg, s.rms_error_deg, s.final_error_deg) {
        (Some(max), Some(rms), Some(fin)) => {
            format!("max |error| {max:.3}°, RMS {rms:.3}°, final {fin:+.3}°")
        }
        _ => "no reference in the log: errors not available".to_string(),
    };
    format!(
        "{}  ·  {errors}  ·  {} movement{} in {:.1} s",
        mode_text(s.compensation, mode),
        s.movements,
        if s.movements == 1 { "" } else { "s" },
        s.duration_s
    )
}

/// Where the body is cut into panels (px from its top): angle, error (if any), motion,
/// rate.
fn panel_cuts(body_h_px: u32, has_error: bool) -> Vec<i32> {
    let h = body_h_px as i32;
    if has_error {
        vec![h * 33 / 100, h * 59 / 100, h * 68 / 100]
    } else {
        vec![h * 50 / 100, h * 60 / 100]
    }
}

/// The stretches of `time_s` outside the movements `moving_s` (sorted, disjoint).
fn static_spans(time_s: (f64, f64), moving_s: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut statics = Vec::new();
    let mut t = time_s.0;
    for &(a, b) in moving_s {
        if a > t {
            statics.push((t, a));
        }
        t = b;
    }
    if t < time_s.1 {
        statics.push((t, time_s.1));
    }
    statics
}

/// One quantity drawn as a line: its segments, stroke and legend entry (swatch colour
/// and width).
struct Trace<'l> {
    segments: &'l Segments,
    style: ShapeStyle,
    label: &'l str,
    swatch: (RGBColor, u32),
}

/// Draw every segment of `trace`; only the first carries the legend entry.
fn draw_trace<'a, DB: DrawingBackend + 'a>(chart: &mut Chart<'a, DB>, trace: &Trace) -> DrawResult {
    let swatch = line_swatch(trace.swatch.0, trace.swatch.1);
    draw_segments(
        chart,
        trace.segments,
        (trace.style, Stroke::Solid),
        trace.label,
        swatch,
    )
}

/// What every panel shares: the time axis, the movements to shade and the line widths.
struct Frame {
    time_s: (f64, f64),
    moving_s: Vec<(f64, f64)>,
    /// Stroke of the data lines (px).
    width_px: u32,
    /// Stroke of the wide reference line (px).
    wide_px: u32,
}

impl Frame {
    /// A panel of `traces` (drawn in order, the last on top) over the shaded movements,
    /// with its legend.
    fn line_panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        y_desc: &str,
        bottom: bool,
        traces: &[Trace],
    ) -> DrawResult {
        // Lines from the topmost (last drawn) trace down.
        let lines: Vec<&Vec<(f64, f64)>> = traces.iter().rev().flat_map(|t| t.segments).collect();
        let (lo, hi) = range_of(lines.iter().copied());
        let y = padded(lo, hi, 0.08);
        let mut chart = panel(area, self.time_s, y, y_desc, bottom)?;
        shade_movements(&mut chart, &self.moving_s, y)?;
        for trace in traces {
            draw_trace(&mut chart, trace)?;
        }
        let lines: Vec<&[(f64, f64)]> = lines.into_iter().map(Vec::as_slice).collect();
        let labels: Vec<&str> = traces.iter().map(|t| t.label).collect();
        legend(&mut chart, &lines, (self.time_s, y), &labels)
    }

    /// The angle against the (wide, grey) reference.
    fn angle_panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        lines: &Lines,
        mode: &str,
    ) -> DrawResult {
        let angle_label = format!("angle ({mode})");
        let traces = [
            Trace {
                segments: &lines.reference_deg,
                style: colour::GREY.mix(0.55).stroke_width(self.wide_px),
                label: REFERENCE_LABEL,
                swatch: (RGBColor(180, 180, 180), self.wide_px),
            },
            Trace {
                segments: &lines.angle_deg,
                style: colour::BLUE.stroke_width(self.width_px),
                label: &angle_label,
                swatch: (colour::BLUE, 2),
            },
        ];
        self.line_panel(area, "angle (deg)", false, &traces)
    }

    /// The angle error, with the Kalman ±1σ band about zero.
    fn error_panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        lines: &Lines,
    ) -> DrawResult {
        let (error, sigma) = (&lines.error_deg, &lines.sigma_deg);
        let y = error_range(error, sigma);
        let mut chart = panel(area, self.time_s, y, "error (deg)", false)?;
        shade_movements(&mut chart, &self.moving_s, y)?;
        draw_sigma_band(&mut chart, sigma)?;
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(self.time_s.0, 0.0), (self.time_s.1, 0.0)],
                BLACK.mix(0.5).stroke_width(1),
            )))
            .map_err(draw_err)?;
        let trace = Trace {
            segments: error,
            style: colour::VERMILLION.stroke_width(self.width_px),
            label: ERROR_LABEL,
            swatch: (colour::VERMILLION, 2),
        };
        draw_trace(&mut chart, &trace)?;
        let negated_sigma: Segments = sigma
            .iter()
            .map(|l| l.iter().map(|&(t, s)| (t, -s)).collect())
            .collect();
        let mut lines: Vec<&[(f64, f64)]> = error.iter().map(Vec::as_slice).collect();
        let mut labels = vec![ERROR_LABEL];
        if !sigma.is_empty() {
            lines.extend(sigma.iter().map(Vec::as_slice));
            lines.extend(negated_sigma.iter().map(Vec::as_slice));
            labels.push(SIGMA_LABEL);
        }
        legend(&mut chart, &lines, (self.time_s, y), &labels)
    }

    /// The motion state as a two-row timeline: static below, dynamic above.
    fn motion_panel<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult {
        let time = self.time_s;
        let mut chart = ChartBuilder::on(area)
            .margin_left(10)
            .margin_right(25)
            .margin_top(8)
            .x_label_area_size(0)
            .y_label_area_size(85)
            .build_cartesian_2d(time.0..time.1, (0..1).into_segmented())
            .map_err(draw_err)?;
        let label = |v: &SegmentValue<i32>| match v {
            SegmentValue::CenterOf(0) => "static".to_string(),
            SegmentValue::CenterOf(1) => "dynamic".to_string(),
            _ => String::new(),
        };
        chart
            .configure_mesh()
            .disable_mesh()
            .y_labels(2)
            .y_label_formatter(&label)
            .label_style(("sans-serif", TICK_PX))
            .axis_desc_style(("sans-serif", LABEL_PX))
            .y_desc("motion")
            .draw()
            .map_err(draw_err)?;
        let statics = static_spans(time, &self.moving_s);
        let row = |row: i32, (a, b): (f64, f64), c: RGBColor| {
            Rectangle::new(
                [
                    (a, SegmentValue::Exact(row)),
                    (b, SegmentValue::Exact(row + 1)),
                ],
                c.filled(),
            )
        };
        chart
            .draw_series(statics.iter().map(|&s| row(0, s, RGBColor(200, 200, 200))))
            .map_err(draw_err)?;
        chart
            .draw_series(self.moving_s.iter().map(|&s| row(1, s, colour::ORANGE)))
            .map_err(draw_err)?;
        Ok(())
    }

    /// The filtered rate, with the time axis below it.
    fn rate_panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        lines: &Lines,
    ) -> DrawResult {
        let trace = Trace {
            segments: &lines.rate_dps,
            style: colour::GREEN.stroke_width(self.width_px),
            label: RATE_LABEL,
            swatch: (colour::GREEN, 2),
        };
        self.line_panel(area, "rate (deg/s)", true, &[trace])
    }
}

/// The error panel's y range: the error and the ±1σ band, with zero, and headroom above
/// for the legend.
fn error_range(error: &Segments, sigma: &Segments) -> (f64, f64) {
    let (mut lo, mut hi) = range_of(error.iter());
    let (_, smax) = range_of(sigma.iter());
    if smax.is_finite() {
        lo = lo.min(-smax);
        hi = hi.max(smax);
    }
    let (a, b) = padded(lo.min(0.0), hi.max(0.0), 0.1);
    (a, b + 0.22 * (b - a))
}

/// The Kalman ±1σ band about zero, one polygon per segment of its upper edge `sigma`.
fn draw_sigma_band<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    sigma: &Segments,
) -> DrawResult {
    for (i, band) in sigma.iter().enumerate() {
        let outline: Vec<(f64, f64)> = band
            .iter()
            .copied()
            .chain(band.iter().rev().map(|&(t, s)| (t, -s)))
            .collect();
        let drawn = chart
            .draw_series(std::iter::once(Polygon::new(
                outline,
                colour::SKY.mix(0.35).filled(),
            )))
            .map_err(draw_err)?;
        if i == 0 {
            drawn.label(SIGMA_LABEL).legend(|(x, y)| {
                Rectangle::new(
                    [(x, y - 6), (x + 22, y + 6)],
                    colour::SKY.mix(0.35).filled(),
                )
            });
        }
    }
    Ok(())
}

impl Figure for RunPlot<'_> {
    fn size(&self) -> (u32, u32) {
        (1200, 1000)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let series = &self.report.series;
        let (Some(first), Some(last)) = (series.first(), series.last()) else {
            return Err(RenderError::Empty("the run has no output samples"));
        };
        let summary = &self.report.summary;
        let title = format!("run: {}", self.title);
        let body = titled(root, &title, &subtitle(summary, self.report.mode))?;
        let lines = Lines::of(series);
        // Thinned lines are drawn thin: plotters' bitmap backend leaves gaps in thick,
        // near-vertical segments.
        let (width_px, wide_px) = if series.len() > MAX_POINTS {
            (1, 3)
        } else {
            (2, 5)
        };
        let frame = Frame {
            time_s: padded(first.time_s, last.time_s, 0.0),
            moving_s: dynamic_spans(series),
            width_px,
            wide_px,
        };
        let has_error = !lines.error_deg.is_empty();
        let cuts = panel_cuts(body.dim_in_pixel().1, has_error);
        let areas = body.split_by_breakpoints::<i32, i32, _, _>([], cuts);
        let mut areas = areas.iter();
        let mut next = || areas.next().ok_or(RenderError::Draw("layout".into()));
        frame.angle_panel(
            next()?,
            &lines,
            mode_text(summary.compensation, self.report.mode),
        )?;
        if has_error {
            frame.error_panel(next()?, &lines)?;
        }
        frame.motion_panel(next()?)?;
        frame.rate_panel(next()?, &lines)
    }
}
