//! `calibrate --plot`: per run, the max abs angle error without compensation, with the
//! paper's error model and with the Kalman form — a dot plot on a log axis, one row per
//! run, training runs above the hold-out runs.

use super::{
    colour, draw_err, log_tick, save, sig, titled, DrawResult, Figure, PlotError, RenderError,
    LABEL_PX, TICK_PX,
};
use gyro_analysis::calibrate::{Calibration, Objective, RunScore};
use plotters::coord::ranged1d::SegmentedCoord;
use plotters::coord::types::RangedCoordi32;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// The plot of a calibration's per-run scores.
#[derive(Clone, Copy, Debug)]
pub struct CalibrationPlot<'a> {
    /// The calibration.
    pub calibration: &'a Calibration,
}

/// Write the plot of `calibration` to `path` (SVG or PNG by the extension).
pub fn calibrate_plot(path: &Path, calibration: &Calibration) -> Result<(), PlotError> {
    save(path, &CalibrationPlot { calibration })
}

/// Pixels per run row.
const ROW_PX: u32 = 34;
/// Longest run name shown (characters).
const NAME_CHARS: usize = 36;

const NONE_LABEL: &str = "no compensation";
const PAPER_LABEL: &str = "paper error model";
const KALMAN_LABEL: &str = "Kalman form";

/// The run's name as shown: its file name, shortened from the left.
pub(super) fn short_name(name: &str) -> String {
    let file = Path::new(name)
        .file_name()
        .and_then(|f| f.to_str())
        .unwrap_or(name);
    let n = file.chars().count();
    if n <= NAME_CHARS {
        file.to_string()
    } else {
        let tail: String = file.chars().skip(n - (NAME_CHARS - 1)).collect();
        format!("…{tail}")
    }
}

fn objective_text(objective: Objective) -> &'static str {
    match objective {
        Objective::MeanMaxAbs => "mean max |error|",
        Objective::MeanRms => "mean RMS error",
        Objective::WorstMaxAbs => "worst max |error|",
        Objective::MovementRms => "RMS movement error",
    }
}

/// A one-line legend of the three markers, centred at the top of `area`; returns the
/// area below it.
fn legend_row<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
) -> Result<DrawingArea<DB, Shift>, RenderError> {
    let (w, _) = area.dim_in_pixel();
    let style = TextStyle::from(("sans-serif", LABEL_PX).into_font())
        .color(&colour::INK)
        .pos(Pos::new(HPos::Left, VPos::Center));
    let entry_px = |label: &str| 30 + (0.58 * f64::from(LABEL_PX) * label.len() as f64) as i32 + 30;
    let labels = [NONE_LABEL, PAPER_LABEL, KALMAN_LABEL];
    let total: i32 = labels.iter().map(|l| entry_px(l)).sum();
    let y = 14;
    let mut x = (w as i32 - total) / 2;
    for (i, label) in labels.iter().enumerate() {
        let c = (x + 10, y);
        match i {
            0 => area.draw(&Circle::new(c, 7, colour::GREY.filled())),
            1 => area.draw(&Rectangle::new(
                [(c.0 - 6, c.1 - 6), (c.0 + 6, c.1 + 6)],
                colour::ORANGE.filled(),
            )),
            _ => area.draw(&TriangleMarker::new(c, 8, colour::BLUE.filled())),
        }
        .map_err(draw_err)?;
        area.draw_text(label, &style, (x + 24, y))
            .map_err(draw_err)?;
        x += entry_px(label);
    }
    Ok(area.margin(2 * y, 0, 0, 0))
}

impl CalibrationPlot<'_> {
    fn rows(&self) -> Vec<(&RunScore, bool)> {
        let c = self.calibration;
        c.train
            .iter()
            .map(|r| (r, false))
            .chain(c.holdout.iter().map(|r| (r, true)))
            .collect()
    }
}

/// The chart: log error axis across, one segment per run down.
type RowChart<'a, DB> =
    ChartContext<'a, DB, Cartesian2d<LogCoord<f64>, SegmentedCoord<RangedCoordi32>>>;

/// The three errors of a run (deg): without compensation, paper model, Kalman form.
fn errors_deg(r: &RunScore) -> [f64; 3] {
    [
        r.none_max_abs_deg,
        r.paper_max_abs_deg,
        r.kalman_max_abs_deg,
    ]
}

/// Drawable on the log axis.
fn positive(v: &f64) -> bool {
    v.is_finite() && *v > 0.0
}

/// The error axis (deg): every positive error with a margin, and room on the right for
/// the section labels.
fn error_range_deg(rows: &[(&RunScore, bool)]) -> Result<(f64, f64), RenderError> {
    let values = || rows.iter().flat_map(|(r, _)| errors_deg(r));
    let lo = values().filter(positive).fold(f64::INFINITY, f64::min);
    let hi = values().filter(positive).fold(0.0, f64::max);
    if !(lo.is_finite() && hi > 0.0) {
        return Err(RenderError::Empty("no finite, non-zero error to plot"));
    }
    let (lo, hi) = if hi / lo < 3.0 {
        (lo / 1.8, hi * 1.8)
    } else {
        (lo / 1.4, hi * 1.4)
    };
    Ok((lo, hi * (hi / lo).powf(0.3)))
}

/// The fitted paper model, the objective and what the model file uses.
fn subtitle(c: &Calibration) -> String {
    let p = &c.fitted.paper;
    format!(
        "paper model β = {} 1/s (T = {} s), b0 = {} deg/s, o0 = {} deg; objective: {} = {} deg\nthe model file uses: {}",
        sig(f64::from(p.beta_per_s), 3),
        sig(1.0 / f64::from(p.beta_per_s), 3),
        sig(f64::from(p.b0_dps), 3),
        sig(f64::from(p.o0_deg), 3),
        objective_text(c.objective),
        sig(c.objective_deg, 3),
        crate::calibrate::choice_text(c),
    )
}

/// The chart on `area` with its mesh: the error axis `x_deg` (log) and a row per name,
/// the first at the top.
fn row_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    names: &[String],
    x_deg: (f64, f64),
) -> Result<RowChart<'a, DB>, RenderError> {
    let n = names.len() as i32;
    let longest = names.iter().map(|s| s.chars().count()).max().unwrap_or(0);
    let name_px = (longest as f64 * 0.6 * f64::from(TICK_PX)) as u32;
    let mut chart = ChartBuilder::on(area)
        .margin_left(10)
        .margin_right(30)
        .margin_top(10)
        .x_label_area_size(50)
        .y_label_area_size(name_px + 30)
        .build_cartesian_2d((x_deg.0..x_deg.1).log_scale(), (0..n - 1).into_segmented())
        .map_err(draw_err)?;
    let y_label = |v: &SegmentValue<i32>| match v {
        SegmentValue::CenterOf(y) => usize::try_from(n - 1 - y)
            .ok()
            .and_then(|k| names.get(k).cloned())
            .unwrap_or_default(),
        _ => String::new(),
    };
    let x_label = |v: &f64| log_tick(*v);
    chart
        .configure_mesh()
        .disable_y_mesh()
        .y_labels(names.len())
        .y_label_formatter(&y_label)
        .x_labels(12)
        .x_label_formatter(&x_label)
        .light_line_style(BLACK.mix(0.04))
        .bold_line_style(BLACK.mix(0.14))
        .label_style(("sans-serif", TICK_PX))
        .axis_desc_style(("sans-serif", LABEL_PX))
        .x_desc("max abs angle error over the run (deg, log scale)")
        .draw()
        .map_err(draw_err)?;
    Ok(chart)
}

/// The hold-out rows (at the bottom) on a tinted band, and each section's label at the
/// right.
fn draw_sections<'a, DB: DrawingBackend + 'a>(
    chart: &mut RowChart<'a, DB>,
    (train_n, holdout_n): (i32, i32),
    (lo, hi): (f64, f64),
) -> DrawResult {
    let n = train_n + holdout_n;
    if holdout_n > 0 {
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [
                    (lo, SegmentValue::Exact(0)),
                    (hi, SegmentValue::Exact(holdout_n)),
                ],
                colour::PURPLE.mix(0.10).filled(),
            )))
            .map_err(draw_err)?;
    }
    let section = TextStyle::from(("sans-serif", LABEL_PX).into_font())
        .color(&colour::GREY)
        .pos(Pos::new(HPos::Right, VPos::Center));
    let right = hi / 1.08;
    if train_n > 0 {
        chart
            .draw_series(std::iter::once(Text::new(
                format!("training ({train_n})"),
                (right, SegmentValue::CenterOf(n - 1)),
                section.clone(),
            )))
            .map_err(draw_err)?;
    }
    if holdout_n > 0 {
        chart
            .draw_series(std::iter::once(Text::new(
                format!("hold-out ({holdout_n}, not fitted)"),
                (right, SegmentValue::CenterOf(holdout_n - 1)),
                section,
            )))
            .map_err(draw_err)?;
    }
    Ok(())
}

/// Per run (row k from the top), a thin line across its three errors, then their
/// markers: grey circle, orange square, blue triangle.
fn draw_runs<'a, DB: DrawingBackend + 'a>(
    chart: &mut RowChart<'a, DB>,
    rows: &[(&RunScore, bool)],
    (lo, hi): (f64, f64),
) -> DrawResult {
    // Row k from the top has y segment n-1-k.
    let n = rows.len() as i32;
    let row_y = |k: usize| SegmentValue::CenterOf(n - 1 - k as i32);
    chart
        .draw_series(rows.iter().enumerate().map(|(k, (r, _))| {
            let vals = errors_deg(r);
            let a = vals.iter().copied().filter(positive).fold(hi, f64::min);
            let b = vals.iter().copied().filter(positive).fold(lo, f64::max);
            let y = row_y(k);
            PathElement::new(
                vec![(a, y.clone()), (b, y)],
                colour::GREY.mix(0.6).stroke_width(2),
            )
        }))
        .map_err(draw_err)?;
    // The markers of one of the three errors, at the runs where it is drawable.
    let at = |k: usize, v: f64| (v.clamp(lo, hi), row_y(k));
    let drawable = |which: usize| {
        rows.iter()
            .enumerate()
            .map(move |(k, (r, _))| (k, errors_deg(r)[which]))
            .filter(|(_, v)| positive(v))
    };
    chart
        .draw_series(drawable(0).map(|(k, v)| Circle::new(at(k, v), 7, colour::GREY.filled())))
        .map_err(draw_err)?;
    chart
        .draw_series(drawable(1).map(|(k, v)| {
            EmptyElement::at(at(k, v)) + Rectangle::new([(-6, -6), (6, 6)], colour::ORANGE.filled())
        }))
        .map_err(draw_err)?;
    chart
        .draw_series(
            drawable(2).map(|(k, v)| TriangleMarker::new(at(k, v), 8, colour::BLUE.filled())),
        )
        .map_err(draw_err)?;
    Ok(())
}

impl Figure for CalibrationPlot<'_> {
    fn size(&self) -> (u32, u32) {
        let n = self.rows().len() as u32;
        (1100, (230 + ROW_PX * n).max(420))
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let c = self.calibration;
        let rows = self.rows();
        if rows.is_empty() {
            return Err(RenderError::Empty("the calibration scored no run"));
        }
        let x_deg = error_range_deg(&rows)?;
        let body = titled(
            root,
            "calibration: max abs angle error per run",
            &subtitle(c),
        )?;
        let body = legend_row(&body)?;
        let names: Vec<String> = rows.iter().map(|(r, _)| short_name(&r.name)).collect();
        let mut chart = row_chart(&body, &names, x_deg)?;
        let sections = (c.train.len() as i32, c.holdout.len() as i32);
        draw_sections(&mut chart, sections, x_deg)?;
        draw_runs(&mut chart, &rows, x_deg)
    }
}
