//! `run --plot`: stacked panels over one time axis — angle against the reference, the
//! angle error (with the Kalman ±1σ band), the motion state and the filtered rate.

use super::{
    colour, draw_err, envelope, legend_corner, legend_size, padded, save, thin, tick, titled,
    DrawResult, Figure, PlotError, RenderError, LABEL_PX, TICK_PX,
};
use gyro_analysis::replay::{RunReport, SeriesPoint};
use gyro_core::{Compensation, MotionState};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Points kept per line (min/max thinning beyond that).
const MAX_POINTS: usize = 3000;

const REFERENCE_LABEL: &str = "reference (encoder, filtered)";
const ERROR_LABEL: &str = "angle − reference";
const SIGMA_LABEL: &str = "±1σ of the angle (Kalman)";
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
    let size = legend_size(labels, chart.plotting_area().dim_in_pixel());
    let position = legend_corner(normalised.iter().map(Vec::as_slice), size);
    chart
        .configure_series_labels()
        .position(position)
        .label_font(("sans-serif", TICK_PX))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.3))
        .draw()
        .map_err(draw_err)
}

fn line_legend(c: RGBColor, width: u32) -> impl Fn((i32, i32)) -> PathElement<(i32, i32)> {
    move |(x, y)| PathElement::new(vec![(x, y), (x + 22, y)], c.stroke_width(width))
}

impl Figure for RunPlot<'_> {
    fn size(&self) -> (u32, u32) {
        (1200, 1000)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let report = self.report;
        let series = &report.series;
        let (Some(first), Some(last)) = (series.first(), series.last()) else {
            return Err(RenderError::Empty("the run has no output samples"));
        };
        let time = padded(first.time_s, last.time_s, 0.0);
        let s = &report.summary;
        let mode = match s.compensation {
            Compensation::None => "no compensation",
            Compensation::Paper => "paper error model",
            Compensation::Kalman => "Kalman form",
        };
        let errors = match (s.max_abs_error_deg, s.rms_error_deg, s.final_error_deg) {
            (Some(max), Some(rms), Some(fin)) => {
                format!("max |error| {max:.3}°, RMS {rms:.3}°, final {fin:+.3}°")
            }
            _ => "no reference in the log: errors not available".to_string(),
        };
        let subtitle = format!(
            "{mode}  ·  {errors}  ·  {} movement{} in {:.1} s",
            s.movements,
            if s.movements == 1 { "" } else { "s" },
            s.duration_s
        );
        let body = titled(root, &format!("run: {}", self.title), &subtitle)?;

        let spans = dynamic_spans(series);
        let thin_all = |lines: Vec<Vec<(f64, f64)>>| -> Vec<Vec<(f64, f64)>> {
            let total: usize = lines.iter().map(Vec::len).sum::<usize>().max(1);
            lines
                .into_iter()
                .map(|l| {
                    let keep = (MAX_POINTS * l.len() / total).max(2);
                    thin(&l, keep)
                })
                .collect()
        };
        let angle = thin_all(segments(series, |p| Some(f64::from(p.angle_deg))));
        let reference = thin_all(segments(series, |p| p.reference_deg));
        let error = thin_all(segments(series, SeriesPoint::error_deg));
        // The band's edge: the largest σ per bucket (min/max thinning would notch it).
        let sigma: Vec<Vec<(f64, f64)>> = segments(series, |p| p.angle_std_deg.map(f64::from))
            .iter()
            .map(|l| envelope(l, MAX_POINTS / 2))
            .collect();
        let rate = thin_all(segments(series, |p| Some(f64::from(p.rate_dps))));
        let has_error = !error.is_empty();
        // Thinned lines are drawn thin: plotters' bitmap backend leaves gaps in thick,
        // near-vertical segments.
        let (width, wide) = if series.len() > MAX_POINTS {
            (1, 3)
        } else {
            (2, 5)
        };

        // Panel heights (px) of the body.
        let (_, h) = body.dim_in_pixel();
        let h = h as i32;
        let cuts: Vec<i32> = if has_error {
            vec![h * 33 / 100, h * 59 / 100, h * 68 / 100]
        } else {
            vec![h * 50 / 100, h * 60 / 100]
        };
        let areas = body.split_by_breakpoints::<i32, i32, _, _>([], cuts);
        let mut areas = areas.iter();
        let mut next = || areas.next().ok_or(RenderError::Draw("layout".into()));

        // Angle and reference.
        {
            let angle_label = format!("angle ({mode})");
            let (lo, hi) = range_of(angle.iter().chain(&reference));
            let y = padded(lo, hi, 0.08);
            let mut chart = panel(next()?, time, y, "angle (deg)", false)?;
            shade_movements(&mut chart, &spans, y)?;
            for (i, line) in reference.iter().enumerate() {
                let drawn = chart
                    .draw_series(LineSeries::new(
                        line.iter().copied(),
                        colour::GREY.mix(0.55).stroke_width(wide),
                    ))
                    .map_err(draw_err)?;
                if i == 0 {
                    drawn
                        .label(REFERENCE_LABEL)
                        .legend(line_legend(RGBColor(180, 180, 180), wide));
                }
            }
            for (i, line) in angle.iter().enumerate() {
                let drawn = chart
                    .draw_series(LineSeries::new(
                        line.iter().copied(),
                        colour::BLUE.stroke_width(width),
                    ))
                    .map_err(draw_err)?;
                if i == 0 {
                    drawn
                        .label(&angle_label)
                        .legend(line_legend(colour::BLUE, 2));
                }
            }
            let lines: Vec<&[(f64, f64)]> =
                angle.iter().chain(&reference).map(Vec::as_slice).collect();
            legend(
                &mut chart,
                &lines,
                (time, y),
                &[REFERENCE_LABEL, &angle_label],
            )?;
        }

        // Error, with the Kalman ±1σ band about zero.
        if has_error {
            let (mut lo, mut hi) = range_of(error.iter());
            let (_, smax) = range_of(sigma.iter());
            if smax.is_finite() {
                lo = lo.min(-smax);
                hi = hi.max(smax);
            }
            // Headroom above for the legend.
            let (a, b) = padded(lo.min(0.0), hi.max(0.0), 0.1);
            let y = (a, b + 0.22 * (b - a));
            let negated_sigma: Vec<Vec<(f64, f64)>> = sigma
                .iter()
                .map(|l| l.iter().map(|&(t, s)| (t, -s)).collect())
                .collect();
            let mut chart = panel(next()?, time, y, "error (deg)", false)?;
            shade_movements(&mut chart, &spans, y)?;
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
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(time.0, 0.0), (time.1, 0.0)],
                    BLACK.mix(0.5).stroke_width(1),
                )))
                .map_err(draw_err)?;
            for (i, line) in error.iter().enumerate() {
                let drawn = chart
                    .draw_series(LineSeries::new(
                        line.iter().copied(),
                        colour::VERMILLION.stroke_width(width),
                    ))
                    .map_err(draw_err)?;
                if i == 0 {
                    drawn
                        .label(ERROR_LABEL)
                        .legend(line_legend(colour::VERMILLION, 2));
                }
            }
            let mut lines: Vec<&[(f64, f64)]> = error.iter().map(Vec::as_slice).collect();
            let mut labels = vec![ERROR_LABEL];
            if !sigma.is_empty() {
                lines.extend(sigma.iter().map(Vec::as_slice));
                lines.extend(negated_sigma.iter().map(Vec::as_slice));
                labels.push(SIGMA_LABEL);
            }
            legend(&mut chart, &lines, (time, y), &labels)?;
        }

        // Motion state as a two-row timeline.
        {
            let area = next()?;
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
            let mut statics = Vec::new();
            let mut t = time.0;
            for &(a, b) in &spans {
                if a > t {
                    statics.push((t, a));
                }
                t = b;
            }
            if t < time.1 {
                statics.push((t, time.1));
            }
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
                .draw_series(spans.iter().map(|&s| row(1, s, colour::ORANGE)))
                .map_err(draw_err)?;
        }

        // Filtered rate.
        {
            let (lo, hi) = range_of(rate.iter());
            let y = padded(lo, hi, 0.08);
            let mut chart = panel(next()?, time, y, "rate (deg/s)", true)?;
            shade_movements(&mut chart, &spans, y)?;
            for (i, line) in rate.iter().enumerate() {
                let drawn = chart
                    .draw_series(LineSeries::new(
                        line.iter().copied(),
                        colour::GREEN.stroke_width(width),
                    ))
                    .map_err(draw_err)?;
                if i == 0 {
                    drawn
                        .label(RATE_LABEL)
                        .legend(line_legend(colour::GREEN, 2));
                }
            }
            let lines: Vec<&[(f64, f64)]> = rate.iter().map(Vec::as_slice).collect();
            legend(&mut chart, &lines, (time, y), &[RATE_LABEL])?;
        }
        Ok(())
    }
}
