//! `noise --plot`: the Allan deviation (log-log) with its confidence bounds, the fitted
//! model and each significant term; below it the Welch PSD with the white-noise density.

use super::{
    colour, corner_legend, dashed_swatch, draw_err, draw_segments, line_swatch, log_tick, save,
    sig, tick, titled, DrawResult, Figure, PlotError, RenderError, Stroke, LABEL_PX, TICK_PX,
};
use gyro_analysis::noise::{
    AllanDeviation, AllanPoint, Characterization, FitTerm, GaussMarkovFit, NoiseFit, Psd,
};
use plotters::coord::Shift;
use plotters::element::IntoDynElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::cell::Cell;
use std::path::Path;

/// The plot of a noise characterisation.
#[derive(Clone, Copy, Debug)]
pub struct NoisePlot<'a> {
    /// Shown in the title (the log, or "all logs pooled").
    pub title: &'a str,
    /// The characterisation.
    pub result: &'a Characterization,
}

/// Write the plot of `result` to `path` (SVG or PNG by the extension).
pub fn noise_plot(path: &Path, title: &str, result: &Characterization) -> Result<(), PlotError> {
    save(path, &NoisePlot { title, result })
}

pub(super) type LogChart<'a, DB> = ChartContext<'a, DB, Cartesian2d<LogCoord<f64>, LogCoord<f64>>>;

/// Points of model curves per decade of τ.
const CURVE_PER_DECADE: f64 = 40.0;

/// One significant term of the fit: a label and the fit with only that term.
fn terms(fit: &NoiseFit) -> Vec<(String, NoiseFit, RGBColor)> {
    let only = |f: &dyn Fn(&mut NoiseFit)| {
        let mut one = NoiseFit {
            tau0_s: fit.tau0_s,
            ..NoiseFit::default()
        };
        f(&mut one);
        one
    };
    let keep = |t: &FitTerm| FitTerm {
        value: t.value,
        significant: true,
        delta_cost: 0.0,
    };
    let mut out = Vec::new();
    let q = &fit.quantization_deg;
    if q.significant && q.value > 0.0 {
        out.push((
            format!("quantisation Q = {} deg", sig(q.value, 2)),
            only(&|n| n.quantization_deg = keep(q)),
            colour::PURPLE,
        ));
    }
    let n = &fit.arw_dps_per_rt_hz;
    if n.significant && n.value > 0.0 {
        out.push((
            format!(
                "angle random walk N = {} deg/√h ({} deg/s/√Hz)",
                sig(fit.arw_deg_per_rt_h, 2),
                sig(n.value, 2)
            ),
            only(&|m| m.arw_dps_per_rt_hz = keep(n)),
            colour::GREEN,
        ));
    }
    let b = &fit.bias_instability_dps;
    if b.significant && b.value > 0.0 {
        out.push((
            format!(
                "bias instability B = {} deg/s ({} deg/h)",
                sig(b.value, 2),
                sig(b.value * 3600.0, 2)
            ),
            only(&|m| m.bias_instability_dps = keep(b)),
            colour::ORANGE,
        ));
    }
    let k = &fit.rate_random_walk_dps_per_rt_s;
    if k.significant && k.value > 0.0 {
        out.push((
            format!("rate random walk K = {} deg/s/√s", sig(k.value, 2)),
            only(&|m| m.rate_random_walk_dps_per_rt_s = keep(k)),
            colour::VERMILLION,
        ));
    }
    let gm = &fit.gauss_markov;
    if let (true, Some(t)) = (gm.significant && gm.sigma_dps > 0.0, gm.corr_time_s) {
        out.push((
            format!(
                "Gauss-Markov σ = {} deg/s, T = {} s",
                sig(gm.sigma_dps, 2),
                sig(t, 2)
            ),
            only(&|m| {
                m.gauss_markov = GaussMarkovFit {
                    sigma_dps: gm.sigma_dps,
                    corr_time_s: Some(t),
                    significant: true,
                    delta_cost: 0.0,
                }
            }),
            colour::SKY,
        ));
    }
    out
}

/// `f` on a log grid over `x`, split where it leaves `y` (or is not finite).
fn curve(x: (f64, f64), y: (f64, f64), f: impl Fn(f64) -> f64) -> Vec<Vec<(f64, f64)>> {
    let decades = (x.1 / x.0).log10();
    let n = (decades * CURVE_PER_DECADE).ceil().max(2.0) as usize;
    let mut out: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut current = Vec::new();
    for i in 0..=n {
        let t = x.0 * 10f64.powf(decades * i as f64 / n as f64);
        let v = f(t);
        if v.is_finite() && v >= y.0 && v <= y.1 {
            current.push((t, v));
        } else if !current.is_empty() {
            out.push(std::mem::take(&mut current));
        }
    }
    if current.len() >= 2 {
        out.push(current);
    }
    out.retain(|c| c.len() >= 2);
    out
}

/// Log range covering `lo..hi` with a margin of `factor` on both sides.
pub(super) fn log_range(lo: f64, hi: f64, factor: f64) -> (f64, f64) {
    if !(lo > 0.0 && hi >= lo && hi.is_finite()) {
        return (1e-3, 1.0);
    }
    let (lo, hi) = if hi / lo < 1.5 {
        (lo / 1.5, hi * 1.5)
    } else {
        (lo, hi)
    };
    let (lo, hi) = (lo / factor, hi * factor);
    // plotters labels a log axis from its first whole decade up: over a short range,
    // start at a decade so that the bottom is labelled too.
    if (hi / lo).log10() < 2.5 {
        // (A hair below it: plotters finds the first decade by a rounded logarithm.)
        (10f64.powf(lo.log10().floor()) * 0.999, hi)
    } else {
        (lo, hi)
    }
}

pub(super) fn log_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    x: (f64, f64),
    y: (f64, f64),
    (x_desc, y_desc): (&str, &str),
) -> Result<LogChart<'a, DB>, RenderError> {
    let mut chart = ChartBuilder::on(area)
        .margin_left(10)
        .margin_right(30)
        .margin_top(10)
        .x_label_area_size(50)
        .y_label_area_size(90)
        .build_cartesian_2d((x.0..x.1).log_scale(), (y.0..y.1).log_scale())
        .map_err(draw_err)?;
    // Over a short range plotters puts a key point at every 1..9 × 10^k: label only 1, 2
    // and 5 there, and draw no extra light lines.
    let short = |r: (f64, f64)| (r.1 / r.0).log10() < 2.5;
    // Enough key points for 1..9 in every decade of a short range.
    let labels = |r: (f64, f64)| {
        if short(r) {
            10 * (r.1 / r.0).log10().ceil().max(1.0) as usize + 1
        } else {
            12
        }
    };
    // Each key point once: plotters may repeat a decade as the last light point below it.
    let (last_x, last_y) = (Cell::new(0.0), Cell::new(0.0));
    let once = |v: f64, last: &Cell<f64>, label: String| {
        let repeated = (v - last.get()).abs() <= 1e-9 * v.abs();
        last.set(v);
        if repeated {
            String::new()
        } else {
            label
        }
    };
    let fmt_x = |v: &f64| once(*v, &last_x, log_label(*v, short(x)));
    let fmt_y = |v: &f64| once(*v, &last_y, log_label(*v, short(y)));
    chart
        .configure_mesh()
        .x_labels(labels(x))
        .y_labels(labels(y))
        .x_label_formatter(&fmt_x)
        .y_label_formatter(&fmt_y)
        .x_max_light_lines(if short(x) { 0 } else { 10 })
        .y_max_light_lines(if short(y) { 0 } else { 10 })
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

/// A log-axis tick label; with `only_125`, none unless the value is 1, 2 or 5 × 10^k.
fn log_label(value: f64, only_125: bool) -> String {
    if only_125 && value > 0.0 {
        let mantissa = value / 10f64.powf(value.log10().floor());
        let near = |m: f64| (mantissa - m).abs() < 1e-6 * m || (mantissa - 10.0 * m).abs() < 1e-5;
        if !(near(1.0) || near(2.0) || near(5.0)) {
            return String::new();
        }
    }
    log_tick(value)
}

/// Legend placed where the lines (in log coordinates) leave the most room.
fn log_legend<'a, DB: DrawingBackend + 'a>(
    chart: &mut LogChart<'a, DB>,
    lines: &[Vec<(f64, f64)>],
    (x, y): ((f64, f64), (f64, f64)),
    labels: &[&str],
) -> DrawResult {
    let norm = |v: f64, r: (f64, f64)| (v / r.0).ln() / (r.1 / r.0).ln();
    let normalised: Vec<Vec<(f64, f64)>> = lines
        .iter()
        .map(|l| l.iter().map(|&(a, b)| (norm(a, x), norm(b, y))).collect())
        .collect();
    corner_legend(chart, &normalised, labels, 0.9)
}

/// A message in the middle of `area`, in place of a panel.
pub(super) fn note<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, text: &str) -> DrawResult {
    let (w, h) = area.dim_in_pixel();
    let style = TextStyle::from(("sans-serif", LABEL_PX).into_font())
        .color(&colour::GREY)
        .pos(Pos::new(HPos::Center, VPos::Center));
    area.draw_text(text, &style, ((w / 2) as i32, (h / 2) as i32))
        .map_err(draw_err)
}

/// Positive and finite: drawable on a log axis.
fn positive(v: f64) -> bool {
    v.is_finite() && v > 0.0
}

/// A log-log panel being drawn: its chart and ranges, and what its legend needs (every
/// line, for the legend's placement, and every label).
struct LogPanel<'a, DB: DrawingBackend> {
    chart: LogChart<'a, DB>,
    x: (f64, f64),
    y: (f64, f64),
    lines: Vec<Vec<(f64, f64)>>,
    labels: Vec<String>,
}

impl<'a, DB: DrawingBackend + 'a> LogPanel<'a, DB> {
    fn new(chart: LogChart<'a, DB>, x: (f64, f64), y: (f64, f64)) -> Self {
        LogPanel {
            chart,
            x,
            y,
            lines: Vec::new(),
            labels: Vec::new(),
        }
    }

    /// Draw `segments` with `label` in the legend (nothing, and no label, if empty).
    fn segments<E: IntoDynElement<'a, DB, (i32, i32)>>(
        &mut self,
        segments: Vec<Vec<(f64, f64)>>,
        line: (ShapeStyle, Stroke),
        label: String,
        swatch: impl Fn((i32, i32)) -> E + 'a,
    ) -> DrawResult {
        draw_segments(&mut self.chart, &segments, line, &label, swatch)?;
        if !segments.is_empty() {
            self.labels.push(label);
        }
        self.lines.extend(segments);
        Ok(())
    }

    /// Draw the legend in the corner the lines leave emptiest.
    fn legend(mut self) -> DrawResult {
        let labels: Vec<&str> = self.labels.iter().map(String::as_str).collect();
        log_legend(&mut self.chart, &self.lines, (self.x, self.y), &labels)
    }

    /// The measured Allan deviation: a dot with its confidence bounds per τ.
    fn measured_allan(&mut self, allan: &AllanDeviation) -> DrawResult {
        let y = self.y;
        let conf = format!(
            "measured (overlapping), {:.0}% bounds",
            100.0 * allan.confidence
        );
        let measured: Vec<_> = allan
            .points
            .iter()
            .filter(|p| positive(p.adev_dps))
            .collect();
        self.chart
            .draw_series(measured.iter().map(|p| {
                ErrorBar::new_vertical(
                    p.tau_s,
                    p.lower_dps.max(y.0),
                    p.adev_dps,
                    p.upper_dps.min(y.1),
                    colour::INK.stroke_width(1),
                    6,
                )
            }))
            .map_err(draw_err)?;
        self.chart
            .draw_series(
                measured
                    .iter()
                    .map(|p| Circle::new((p.tau_s, p.adev_dps), 3, colour::INK.filled())),
            )
            .map_err(draw_err)?
            .label(conf.clone())
            .legend(|(x, y)| {
                EmptyElement::at((x + 11, y))
                    + Circle::new((0, 0), 3, colour::INK.filled())
                    + PathElement::new(vec![(0, -7), (0, 7)], colour::INK.stroke_width(1))
            });
        self.labels.push(conf);
        self.lines
            .push(measured.iter().map(|p| (p.tau_s, p.adev_dps)).collect());
        Ok(())
    }

    /// The band the white density is read over, shaded (nothing if empty).
    fn white_band(&mut self, (band_lo, band_hi): (f64, f64)) -> DrawResult {
        if !(band_hi > band_lo && band_lo > 0.0) {
            return Ok(());
        }
        let (x, y) = (self.x, self.y);
        let band_label = format!("white band {}–{} Hz", sig(band_lo, 2), sig(band_hi, 2));
        self.chart
            .draw_series(std::iter::once(Rectangle::new(
                [(band_lo.max(x.0), y.0), (band_hi.min(x.1), y.1)],
                colour::GREEN.mix(0.08).filled(),
            )))
            .map_err(draw_err)?
            .label(band_label.clone())
            .legend(|(x, y)| {
                Rectangle::new(
                    [(x, y - 6), (x + 22, y + 6)],
                    colour::GREEN.mix(0.15).filled(),
                )
            });
        self.labels.push(band_label);
        Ok(())
    }
}

/// The Allan panel's ranges (τ, σ): the measured points with their bounds, with some
/// room above for the legend.
fn allan_ranges(points: &[AllanPoint]) -> ((f64, f64), (f64, f64)) {
    let tau_lo = points.iter().map(|p| p.tau_s).fold(f64::INFINITY, f64::min);
    let tau_hi = points.iter().map(|p| p.tau_s).fold(0.0, f64::max);
    let y_lo = points
        .iter()
        .flat_map(|p| [p.lower_dps, p.adev_dps])
        .filter(|v| positive(*v))
        .fold(f64::INFINITY, f64::min);
    let y_hi = points
        .iter()
        .flat_map(|p| [p.upper_dps, p.adev_dps])
        .filter(|v| positive(*v))
        .fold(0.0, f64::max);
    (
        log_range(tau_lo, tau_hi, 1.4),
        log_range(y_lo, y_hi * 2.5, 1.6),
    )
}

/// The PSD's positive bins `(frequency_hz, psd)`, the zero frequency left out.
fn psd_bins(psd: &Psd) -> Vec<(f64, f64)> {
    psd.frequency_hz
        .iter()
        .zip(&psd.psd_dps2_per_hz)
        .filter(|(f, p)| **f > 0.0 && p.is_finite() && **p > 0.0)
        .map(|(f, p)| (*f, *p))
        .collect()
}

/// The PSD panel's vertical range: the bins and the white level `white` (if positive),
/// with room above for the legend.
fn psd_range(bins: &[(f64, f64)], white: f64) -> (f64, f64) {
    let y_lo = bins.iter().map(|b| b.1).fold(f64::INFINITY, f64::min);
    let y_hi = bins.iter().map(|b| b.1).fold(0.0, f64::max);
    let y_lo = if white > 0.0 { y_lo.min(white) } else { y_lo };
    log_range(y_lo, y_hi.max(white) * 8.0, 1.5)
}

/// The label of the white density line.
fn white_label(psd: &Psd) -> String {
    format!(
        "white density 2N², N = {} deg/s/√Hz ({} deg/√h)",
        sig(psd.white_density_dps_per_rt_hz, 2),
        sig(psd.white_arw_deg_per_rt_h, 2)
    )
}

impl NoisePlot<'_> {
    fn has_psd(&self) -> bool {
        self.result
            .psd
            .as_ref()
            .is_some_and(|p| p.frequency_hz.iter().skip(1).any(|f| *f > 0.0))
    }

    /// The Allan deviation: each significant term dashed, the fitted total, then the
    /// measured points with their bounds.
    fn draw_allan<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult {
        let r = self.result;
        let fit = &r.fit;
        if !r.allan.points.iter().any(|p| positive(p.adev_dps)) {
            return note(
                area,
                "The Allan deviation is zero at every τ: the rate is constant.",
            );
        }
        let (x, y) = allan_ranges(&r.allan.points);
        let descs = ("averaging time τ (s)", "Allan deviation σ(τ) (deg/s)");
        let mut panel = LogPanel::new(log_chart(area, x, y, descs)?, x, y);
        // Terms, dashed, under the total.
        for (label, one, c) in terms(fit) {
            let dashed = (c.stroke_width(2), Stroke::Dashed(9, 5));
            let segments = curve(x, y, |t| one.adev(t));
            panel.segments(segments, dashed, label, dashed_swatch(c, 2))?;
        }
        let total = curve(x, y, |t| fit.adev(t));
        let solid = (colour::BLUE.stroke_width(3), Stroke::Solid);
        let label = "fitted model (sum of the terms)".to_string();
        panel.segments(total, solid, label, line_swatch(colour::BLUE, 3))?;
        panel.measured_allan(&r.allan)?;
        panel.legend()
    }

    /// The Welch PSD over the white band, its band averages and the white density.
    fn draw_psd<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>, psd: &Psd) -> DrawResult {
        let bins = psd_bins(psd);
        let (Some(first), Some(last)) = (bins.first(), bins.last()) else {
            return note(
                area,
                "The PSD is zero at every frequency: the rate is constant.",
            );
        };
        let x = (first.0, last.0 * 1.05);
        let white = 2.0 * psd.white_density_dps_per_rt_hz.powi(2);
        let y = psd_range(&bins, white);
        let descs = ("frequency (Hz)", "PSD ((deg/s)²/Hz)");
        let mut panel = LogPanel::new(log_chart(area, x, y, descs)?, x, y);
        panel.white_band(psd.white_band_hz)?;
        let raw_label = format!(
            "Welch PSD ({} samples × {} windows)",
            psd.segment_len, psd.segments
        );
        let raw = (colour::SKY.stroke_width(1), Stroke::Solid);
        panel.segments(vec![bins], raw, raw_label, line_swatch(colour::SKY, 2))?;
        let bands: Vec<(f64, f64)> = psd
            .bands
            .iter()
            .filter(|b| b.bins > 0 && b.psd_dps2_per_hz > 0.0)
            .map(|b| ((b.low_hz * b.high_hz).sqrt(), b.psd_dps2_per_hz))
            .collect();
        if bands.len() >= 2 {
            let solid = (colour::BLUE.stroke_width(2), Stroke::Solid);
            let label = "band average (10 per decade)".to_string();
            panel.segments(vec![bands], solid, label, line_swatch(colour::BLUE, 2))?;
        } else {
            // Not drawn, but a lone band still counts where the legend goes.
            panel.lines.push(bands);
        }
        if white > 0.0 {
            let line = vec![(x.0, white), (x.1, white)];
            let dashed = (colour::GREEN.stroke_width(2), Stroke::Dashed(9, 5));
            let swatch = dashed_swatch(colour::GREEN, 2);
            panel.segments(vec![line], dashed, white_label(psd), swatch)?;
        }
        panel.legend()
    }
}

impl Figure for NoisePlot<'_> {
    fn size(&self) -> (u32, u32) {
        if self.has_psd() {
            (1100, 1200)
        } else {
            (1100, 750)
        }
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        let r = self.result;
        if r.allan.points.is_empty() {
            return Err(RenderError::Empty("no Allan deviation points"));
        }
        let floor = &r.fit.floor;
        let subtitle = format!(
            "{} samples at {} Hz ({} s in {} segment{}), mean rate {} deg/s\nARW {} deg/√h   ·   Allan floor {} deg/s at τ = {} s{}",
            r.samples,
            tick(&r.sample_rate_hz),
            sig(r.duration_s, 3),
            r.segments,
            if r.segments == 1 { "" } else { "s" },
            sig(r.mean_rate_dps, 3),
            sig(r.fit.arw_deg_per_rt_h, 2),
            sig(floor.adev_dps, 2),
            sig(floor.tau_s, 2),
            if floor.at_longest_tau { " (not reached)" } else { "" }
        );
        let body = titled(root, &format!("noise: {}", self.title), &subtitle)?;
        match (&r.psd, self.has_psd()) {
            (Some(psd), true) => {
                let (_, h) = body.dim_in_pixel();
                let (top, bottom) = body.split_vertically(h * 60 / 100);
                self.draw_allan(&top)?;
                self.draw_psd(&bottom, psd)
            }
            _ => self.draw_allan(&body),
        }
    }
}
