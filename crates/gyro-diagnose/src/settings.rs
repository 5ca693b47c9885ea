//! Every number that decides a diagnosis, in one place ([`Settings`]), apart from the
//! diagnosis's state: thresholds, p-values, z-limits, windows, bounds and quantiles.
//! [`Settings::DEFAULT`] is the one place the defaults live ([`Default`] returns it);
//! [`Settings::validate`] refuses a setting out of its range, naming it.
//! [`Settings::markdown_table`] renders the table in `docs/diagnose.md#settings`.
//!
//! Mathematical constants that decide nothing (π, the 0.5 of a centred difference, unit
//! conversions, the t-table) stay where they are used.

/// Why a setting was refused: the name of the setting (as in [`Settings::entries`], e.g.
/// `tests.z_critical`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SettingsError {
    /// The setting is NaN or infinite.
    #[error("setting `{0}` is not a finite number")]
    NonFinite(&'static str),
    /// The setting is finite but outside its valid range.
    #[error("setting `{0}` is out of its valid range")]
    OutOfRange(&'static str),
}

/// Every number that decides a diagnosis, grouped by stage.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// The statistical tests every stage shares.
    pub tests: Tests,
    /// Where: the unexplained statistics (`locate`).
    pub locate: Locate,
    /// Which: fitting the effects (`fit`).
    pub fit: Fit,
    /// Which: the forward selection (`select`).
    pub select: Select,
    /// The reference trajectory a run is re-simulated from (`ensemble`).
    pub reference: Reference,
    /// The report's figure data (`envelopes`).
    pub envelopes: Envelopes,
    /// The statistics and features every run, real or simulated, goes through (`stats`,
    /// `features`, `line`, `low_band`).
    pub statistics: Statistics,
    /// Scores, floor and posterior checks (`score`, `posterior`).
    pub score: Score,
    /// The turns, rest to rest (`turns`), and the effective noise (`effective`).
    pub turns: Turns,
}

/// The statistical tests every stage shares.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tests {
    /// |z| at or above which a test passes: an effect's parameter test, the rests'
    /// whiteness check (`fit::whiteness_tests`), the short-τ check (`short_white`), the
    /// turns' scale, and a statistic left unexplained by the selected model (`locate`).
    /// Unit 1, valid (0, 100]. 4.0 is a Bonferroni bound over the 17 effects at a
    /// family-wise 0.1%; over the ~65 statistics it leaves a well-fitting model's list
    /// of unexplained statistics empty with probability above 99%.
    pub z_critical: f64,
    /// Smallest z on the held-out runs with which an effect's test replicates its
    /// training fit (`fit::replicates`). Unit 1, valid (0, 100]. 2.0: one-sided 2.3%.
    pub replication_z: f64,
    /// Half width of a 95% interval in standard errors (normal): every parameter
    /// interval and the posterior checks' bands. Unit 1, valid (0, 10]. 1.96: the
    /// normal's 97.5% quantile.
    pub interval_z: f64,
    /// Bootstrap P (over held-out runs) under which an improvement is significant: an
    /// effect's held-out ΔBIC, a swap in the selection, a correction written (`compensate`,
    /// `turns`). Unit 1, valid (0, 1). 0.05: the conventional 5%.
    pub p_value: f64,
}

/// Where: the unexplained statistics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Locate {
    /// Relative tolerance of the unexplained test: each run's z is taken against at least
    /// this share of the statistic's size (max(|real|, |simulated|), and for a segment's
    /// mean residual the residual's spread there, what the mean is left of) as its spread. Unit 1,
    /// valid [0, 1). 0.02: a model is judged at the precision its parameters are known to
    /// (the regression parameters carry a 2% systematic uncertainty,
    /// [`Fit::systematic_rel`]); a correct model fitted to a long run leaves a z of 5 to 10
    /// in its statistics' last percent.
    pub unexplained_tolerance: f64,
}

/// Which: fitting the effects.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fit {
    /// Quantisation is named when the output grid is this many times coarser than the
    /// nominal step. Unit 1 (a ratio of steps), valid (1, 100]. 1.5: halfway to a step
    /// twice the nominal one.
    pub quant_ratio: f64,
    /// The output step the training runs' rates lie on counts as the prior's within this
    /// relative difference (`fit::runs_output_step`). Unit 1, valid (0, 1). 0.01: the step is
    /// a least-squares fit over many grid values (`gyro_analysis::noise::rate_step`), which
    /// rounding to a few decimals moves by far less; the LSBs of other sensors differ by
    /// tens of percent (1/131 against 1/24 °/s).
    pub step_match_rel: f64,
    /// Fewest clipped samples over the training runs for saturation. Unit samples, valid
    /// [1, 10⁶]. 10: a clip holds for several samples; fewer is a single peak.
    pub min_clipped: usize,
    /// Relative systematic uncertainty added in quadrature to the intervals of the
    /// regression-based parameters. Unit 1, valid [0, 1). 0.02: re-simulating a run from
    /// its sampled reference, and the gain calibrated by simulation, leave errors of about
    /// 1% (measured by the self-test on large effects).
    pub systematic_rel: f64,
    /// Fewest gaps over the training runs for dropouts. Unit gaps, valid [1, 10⁶]. 3: one
    /// or two gaps are a logger's accident, not a rate of them.
    pub min_gaps: u64,
    /// Smallest relative difference of the rests' two white variances (Allan blocks
    /// against first differences) that counts as colour. Unit 1, valid [0, 10]. 0.1: under
    /// it the first differences stand, however many rests measure it.
    pub white_check_min: f64,
    /// Fewest block differences over the training runs for the whiteness check. Unit
    /// block differences, valid [2, 10⁶]. 20: the z's √(3/n) spread is then under 0.4.
    pub min_white_check_diffs: usize,
    /// A delay shorter than this share of a sample period is negligible: it moves no
    /// sample by more than that share of its step. Unit samples, valid [0, 1]. 0.1: below
    /// what the log's timing resolves.
    pub negligible_delay_samples: f64,
    /// Beside another effect, an effect whose whole 95% interval lies under this share of
    /// the smallest size of its realistic range (`gyro_sim::EffectInfo::range`, from the
    /// datasheets) is negligible, and is not named. Unit 1, valid [0, 1]. 0.1: a tenth of
    /// the smallest size any of those parts shows.
    pub negligible_range_share: f64,
    /// Beside another effect, an effect whose whole 95% interval lies under this share of
    /// the smallest size of its realistic range and whose addition closed none of the
    /// held-out gap G is not named: smaller than the parts show, and no closer to the runs
    /// with it. Unit 1, valid [0, 1]. 1: the smallest size itself.
    pub idle_range_share: f64,
    /// Share of the null's chi-square above which the real runs' scatter of a regression
    /// coefficient is larger than the null's, and its own error is used. Unit 1, valid
    /// (0, 1). 0.99: one-sided 1%.
    pub scatter_p: f64,
    /// Largest ratio of the fitted wander's Allan variance to the runs' at any τ of the
    /// wander statistic for a wander to pass. Unit 1, valid [1, 10⁶]. 3.0: the sampling
    /// spread of a 16 s Allan variance from five one-minute runs (about 15 windows).
    pub wander_overshoot: f64,
    /// The prior's Gauss-Markov wander is set aside (σ 0) when the bound the training
    /// residual allows (its random walk coefficient at τ = 3 s) is under this share of the
    /// prior's: the wander the runs do show is then the vocabulary's to name; never raised
    /// (a larger wander is an effect to name). Unit 1,
    /// valid (0, 1]. 0.5: a bound that close to the prior is the prior's own wander drawn
    /// low in five one-minute runs, not a quieter sensor (nearer 1, a null case of the
    /// self-check names a random walk).
    pub wander_prior_floor: f64,
    /// A regression effect's gain (coefficient change per unit of the coefficient's own
    /// parameter, by simulation) is used when it lies in (1/r, r), r this; the calibration
    /// steps stay within r times the raw coefficient. Unit 1, valid (1, 10⁶]. 5.0: a gain
    /// beyond it is a simulation that does not respond, not a calibration.
    pub gain_ratio_max: f64,
    /// The same bound for a wander effect's gain (Allan variance per unit of its variance
    /// parameter), in (1/r, r). Unit 1, valid (1, 10⁶]. 10.0: the wander's gain from 8
    /// members per run scatters more than a regression's.
    pub wander_gain_ratio_max: f64,
    /// Members per training run simulated with a wander to calibrate its gain. Unit
    /// members, valid [1, 10⁴]. 8: the gain's mean over runs × members is then within a
    /// few percent.
    pub wander_gain_members: usize,
}

/// Which: the forward selection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Select {
    /// Most effects the forward selection adds. Unit effects, valid [1, 17]. 6: beyond
    /// it the held-out runs no longer tell the effects apart.
    pub max_effects: usize,
    /// Cosine similarity of two effects' shifts of the held-out z-scores above which one
    /// that is not selected is reported as confounded with the selected one. Unit 1,
    /// valid [0, 1]. 0.8: the two move the statistics nearly alike.
    pub confound_cosine: f64,
}

/// The reference trajectory a run is re-simulated from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reference {
    /// Smoothing of the reference trajectory when it is quantised (an encoder's steps).
    /// Unit s, valid (0, 1]. 0.02: the encoder's steps would otherwise be rate spikes in
    /// the simulated gyro; 20 ms passes a wrench's turns.
    pub quantised_smooth_s: f64,
    /// A value lies on the encoder's grid when it is within this share of a step of a
    /// grid point. Unit steps, valid (0, 0.5]. 0.15: well inside the half step that
    /// separates two grid points.
    pub grid_tolerance_steps: f64,
    /// Share of the distinct reference values on the grid for the reference to be
    /// quantised. Unit 1, valid (0, 1]. 0.9: a few values off the grid (interpolated
    /// gaps) do not undo it.
    pub grid_share: f64,
    /// Standard deviation of the rounding noise that a reference printed on a decimal
    /// grid puts into a re-simulated rate, below which the print is taken as exact. Unit
    /// deg/s, valid [0, 10]. 0.005: under the output step of common MEMS gyros (an
    /// MPU6050's 0.0076 °/s at ±250 °/s).
    pub print_rounding_floor_dps: f64,
    /// Finest decimal grid looked for, 10⁻ᵈ°. Unit decimals, valid [0, 12]. 6: finer
    /// prints are exact at any sample rate a gyro logs at.
    pub print_max_decimals: i32,
    /// Longest half width of a print's smoothing. Unit s, valid (0, 1]. 0.08: a quintic
    /// smoothing of ±80 ms passes a wrench's turns (rate gain 0.9995 at 3 Hz, 0.992 at
    /// 5 Hz) and brings a 0.001° print at 100 Hz to 0.006 °/s of rounding.
    pub print_max_half_width_s: f64,
}

/// The report's figure data.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Envelopes {
    /// Quantile of the |reference rate| over the runs that spans the rate axis of the
    /// binned figures. Unit 1, valid (0, 1]. 0.995: a few spikes do not stretch the axis.
    pub rate_quantile: f64,
    /// Quantile of the moving |reference acceleration| that spans the acceleration axis.
    /// Unit 1, valid (0, 1]. 0.99: the acceleration's tails are longer than the rate's.
    pub acceleration_quantile: f64,
}

/// The statistics and features every run goes through.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Statistics {
    /// A sample is still when |reference rate| is below this. Unit deg/s, valid (0, 100].
    /// 1.0: above a rest's reference noise, below any turn of a wrench.
    pub static_rate_dps: f64,
    /// Shortest still run counted as static. Unit s, valid (0, 60]. 0.5: long enough for
    /// the white-noise features, short enough for a wrench's pauses.
    pub static_min_s: f64,
    /// Averaging window of the gyro's stillness check. Unit s, valid (0, 10]. 0.05: a
    /// mean over it stays within 1 deg/s of the rest's median on a still gyro.
    pub gyro_still_window_s: f64,
    /// Left out at each end of a rest for the white-noise features. Unit s, valid [0, 10].
    /// 0.1: the turns' first and last ramps, under the static threshold.
    pub rest_edge_s: f64,
    /// Largest lag searched by the per-sample cross-correlation statistic. Unit s, valid
    /// (0, 10]. 0.05: a gyro's own latency and filter delay.
    pub max_lag_s: f64,
    /// Averaging time of the whiteness check on static samples. Unit s, valid (0, 10].
    /// 0.05: the Allan variance at it, beside the first differences, tells white rest
    /// noise from noise a low-pass inside the band has coloured.
    pub white_check_tau_s: f64,
    /// A run's temperature varies when its range exceeds this. Unit °C, valid [0, 100].
    /// 0.5: above a sensor's temperature resolution.
    pub min_temperature_range_c: f64,
    /// Smallest range of the reference's |rate| over a run's plateau samples, as a share
    /// of the plateau's level, for them to be a clip. Unit 1, valid [0, 1]. 0.01: a clip
    /// ranges over tens of deg/s, a smooth turn's peak held on one code over 0.07–0.27.
    pub plateau_reference_share: f64,
    /// Length of the line spectrum's Welch segments (rounded to a power of two samples).
    /// Unit s, valid (0, 60]. 2.0: 0.5 Hz bins over a one-minute run's 30 segments.
    pub line_segment_s: f64,
    /// A line must stand this many times above its local floor. Unit 1, valid [1, 10⁶].
    /// 3.0: the null replicas' spectra are smooth, a real sensor's have texture.
    pub line_min_ratio: f64,
    /// A line of the motion is reported when it stands this many times above its floor.
    /// Unit 1, valid [1, 10⁶]. 20.0: only lines that stand out of the motion's spectrum.
    pub motion_line_ratio: f64,
    /// Lowest frequency searched for a line. Unit Hz, valid (0, 10⁴]. 2.0: above the
    /// turns' own band.
    pub min_line_hz: f64,
    /// Bins on either side of a line that belong to it. Unit bins, valid [0, 100]. 2: the
    /// Hann window's main lobe.
    pub guard_bins: usize,
    /// Bins on either side whose median is the local floor. Unit bins, valid [1, 1000].
    /// 10: a floor from 16 bins outside the guard.
    pub floor_bins: usize,
    /// Cut-off of the low band. Unit Hz, valid (0, 10⁴]. 2.0: the band of a wrench's
    /// turns, where the angle is integrated.
    pub low_band_hz: f64,
    /// Window over which the gyro–reference lag is read, one point of the lag line
    /// (`lag_line`, the statistic `xcorr_lag_trend`): a sensor clock stamped by its own count makes the lag grow through the
    /// run. Unit s, valid (0, 3600]. 4.0: a bench movement or two, and 22 points in 90 s
    /// with windows overlapping by half.
    pub lag_window_s: f64,
    /// Least RMS reference rate in a window for its lag to be read. Unit deg/s, valid
    /// (0, 10⁴]. 5.0: below it a window is mostly rest and its cross-correlation is noise.
    pub lag_min_motion_dps: f64,
    /// Largest sample-clock error the lag line searches for (1 = 100%): the first windows
    /// are searched within ±([`Statistics::max_lag_s`] + this × their time). Unit 1, valid
    /// (0, 0.5]. 0.05: beyond the ±1–3% of a MEMS gyro's internal oscillator (MPU-6050,
    /// BMI160 datasheets) with a margin.
    pub lag_max_clock: f64,
    /// Rate the rates are block-averaged to before the lag line reads them. Unit Hz,
    /// valid (0, 10⁶]. 200.0: a wrench's motion lies below 20 Hz, and the peak is placed
    /// between samples by a parabola; at 1 kHz it cuts the search 25-fold.
    pub lag_line_hz: f64,
    /// Least share of the run the windows of a lag line must span from first to last: a
    /// line through a few neighbouring windows (the track lost after them) says little of
    /// the slope. Unit 1, valid (0, 1]. 0.5.
    pub lag_min_span_share: f64,
}

/// Scores, floor and posterior checks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Score {
    /// Members taken out in turn per run for the floor. Unit members, valid [1, 10⁴].
    /// 10: the floor's spread over members is then under its own size.
    pub floor_members: usize,
    /// Degrees of freedom of the Student-t likelihood of one statistic. Unit 1, valid
    /// (0, 10⁶]. 4.0: heavy tails, so one outlying statistic does not decide a step.
    pub likelihood_dof: f64,
    /// Share of the nominal discrepancy of a signature statistic an effect may leave and
    /// still pass its posterior check. Unit 1, valid [0, 1]. 0.5: it explains most of it.
    pub remaining_share: f64,
    /// A gap G above the floor of at most this share of the floor is no gap: the share of
    /// it an effect closes is then 0 (`summarise`), not a ratio of two small differences.
    /// Unit 1, valid [0, 10]. 0.1: a tenth of the floor is within the floor's own spread.
    pub no_gap_share: f64,
}

/// The turns, rest to rest, and the effective noise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Turns {
    /// Smallest scale error named from the turns (1 = 100%). Unit 1, valid [0, 1]. 0.001:
    /// 0.09° on a 90° turn, below what real turns' totals resolve.
    pub min_k: f64,
    /// Shortest stretch of residual the effective noise uses. Unit s, valid (0, 3600].
    /// 2.0: shorter ones add no τ worth reading.
    pub min_stretch_s: f64,
    /// Shortest averaging time the effective noise characterises. Unit s, valid (0, 100].
    /// 0.1: below it the residual is shaped by the reference derivative's window.
    pub min_tau_s: f64,
}

/// One setting: its name, value, unit, valid range and why it has its value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Entry {
    /// Dotted name, as the field path (`tests.z_critical`).
    pub name: &'static str,
    /// The value.
    pub value: f64,
    /// Whether the value is a count (shown without decimals).
    pub integer: bool,
    /// Unit.
    pub unit: &'static str,
    /// Smallest valid value.
    pub min: f64,
    /// Largest valid value.
    pub max: f64,
    /// Whether `min` itself is valid.
    pub min_inclusive: bool,
    /// Whether `max` itself is valid.
    pub max_inclusive: bool,
    /// What it decides, and why it has its value.
    pub why: &'static str,
}

const fn entry(
    name: &'static str,
    value: f64,
    unit: &'static str,
    (min_inclusive, min, max, max_inclusive): (bool, f64, f64, bool),
    why: &'static str,
) -> Entry {
    Entry {
        name,
        value,
        integer: false,
        unit,
        min,
        max,
        min_inclusive,
        max_inclusive,
        why,
    }
}

const fn count(
    name: &'static str,
    value: f64,
    unit: &'static str,
    min: f64,
    max: f64,
    why: &'static str,
) -> Entry {
    Entry {
        name,
        value,
        integer: true,
        unit,
        min,
        max,
        min_inclusive: true,
        max_inclusive: true,
        why,
    }
}

/// `[min, max]`.
const CLOSED: bool = true;
/// `(min, max)`.
const OPEN: bool = false;

impl Settings {
    /// The defaults: the one place they live.
    pub const DEFAULT: Settings = Settings {
        tests: Tests {
            z_critical: 4.0,
            replication_z: 2.0,
            interval_z: 1.96,
            p_value: 0.05,
        },
        locate: Locate {
            unexplained_tolerance: 0.02,
        },
        fit: Fit {
            quant_ratio: 1.5,
            step_match_rel: 0.01,
            min_clipped: 10,
            systematic_rel: 0.02,
            min_gaps: 3,
            white_check_min: 0.1,
            min_white_check_diffs: 20,
            negligible_delay_samples: 0.1,
            negligible_range_share: 0.1,
            idle_range_share: 1.0,
            scatter_p: 0.99,
            wander_overshoot: 3.0,
            wander_prior_floor: 0.5,
            gain_ratio_max: 5.0,
            wander_gain_ratio_max: 10.0,
            wander_gain_members: 8,
        },
        select: Select {
            max_effects: 6,
            confound_cosine: 0.8,
        },
        reference: Reference {
            quantised_smooth_s: 0.02,
            grid_tolerance_steps: 0.15,
            grid_share: 0.9,
            print_rounding_floor_dps: 0.005,
            print_max_decimals: 6,
            print_max_half_width_s: 0.08,
        },
        envelopes: Envelopes {
            rate_quantile: 0.995,
            acceleration_quantile: 0.99,
        },
        statistics: Statistics {
            static_rate_dps: 1.0,
            static_min_s: 0.5,
            gyro_still_window_s: 0.05,
            rest_edge_s: 0.1,
            max_lag_s: 0.05,
            white_check_tau_s: 0.05,
            min_temperature_range_c: 0.5,
            plateau_reference_share: 0.01,
            line_segment_s: 2.0,
            line_min_ratio: 3.0,
            motion_line_ratio: 20.0,
            min_line_hz: 2.0,
            guard_bins: 2,
            floor_bins: 10,
            low_band_hz: 2.0,
            lag_window_s: 4.0,
            lag_min_motion_dps: 5.0,
            lag_max_clock: 0.05,
            lag_line_hz: 200.0,
            lag_min_span_share: 0.5,
        },
        score: Score {
            floor_members: 10,
            likelihood_dof: 4.0,
            remaining_share: 0.5,
            no_gap_share: 0.1,
        },
        turns: Turns {
            min_k: 1e-3,
            min_stretch_s: 2.0,
            min_tau_s: 0.1,
        },
    };

    /// Every setting with its unit, valid range and reason, in the order of the table.
    // Longer than a screen because it is the table itself: one row per setting, in order.
    pub fn entries(&self) -> Vec<Entry> {
        let (t, l, f, s, r, e) = (
            &self.tests,
            &self.locate,
            &self.fit,
            &self.select,
            &self.reference,
            &self.envelopes,
        );
        let (st, sc, tu) = (&self.statistics, &self.score, &self.turns);
        vec![
            entry("tests.z_critical", t.z_critical, "1", (OPEN, 0.0, 100.0, CLOSED),
                "\\|z\\| at which a test passes (parameter tests, whiteness checks, the turns' scale) and a statistic is unexplained: Bonferroni over the 17 effects at a family-wise 0.1%"),
            entry("tests.replication_z", t.replication_z, "1", (OPEN, 0.0, 100.0, CLOSED),
                "z on the held-out runs with which a test replicates its training fit: one-sided 2.3%"),
            entry("tests.interval_z", t.interval_z, "1", (OPEN, 0.0, 10.0, CLOSED),
                "half width of a 95% interval in standard errors: the normal's 97.5% quantile"),
            entry("tests.p_value", t.p_value, "1", (OPEN, 0.0, 1.0, OPEN),
                "bootstrap P over held-out runs under which an improvement (held-out ΔBIC, a swap, a correction) is significant"),
            entry("locate.unexplained_tolerance", l.unexplained_tolerance, "1", (CLOSED, 0.0, 1.0, OPEN),
                "least spread of a statistic in the unexplained test, as a share of its size (a mean residual's: its segment's spread): the parameters' 2% systematic uncertainty"),
            entry("fit.quant_ratio", f.quant_ratio, "1", (OPEN, 1.0, 100.0, CLOSED),
                "output grid over the nominal step at which quantisation is named"),
            entry("fit.step_match_rel", f.step_match_rel, "1", (OPEN, 0.0, 1.0, OPEN),
                "relative difference within which the runs' output step is the prior's"),
            count("fit.min_clipped", f.min_clipped as f64, "samples", 1.0, 1e6,
                "fewest clipped samples over the training runs for saturation"),
            entry("fit.systematic_rel", f.systematic_rel, "1", (CLOSED, 0.0, 1.0, OPEN),
                "relative systematic uncertainty of the regression parameters: re-simulation and gain calibration leave about 1%"),
            count("fit.min_gaps", f.min_gaps as f64, "gaps", 1.0, 1e6,
                "fewest gaps over the training runs for dropouts"),
            entry("fit.white_check_min", f.white_check_min, "1", (CLOSED, 0.0, 10.0, CLOSED),
                "relative difference of the rests' two white variances that counts as colour"),
            count("fit.min_white_check_diffs", f.min_white_check_diffs as f64, "block differences", 2.0, 1e6,
                "fewest block differences for the whiteness check"),
            entry("fit.negligible_delay_samples", f.negligible_delay_samples, "samples", (CLOSED, 0.0, 1.0, CLOSED),
                "a delay under this share of a sample period is negligible"),
            entry("fit.negligible_range_share", f.negligible_range_share, "1", (CLOSED, 0.0, 1.0, CLOSED),
                "beside another, an effect whose 95% interval lies under this share of its range's smallest size is negligible"),
            entry("fit.idle_range_share", f.idle_range_share, "1", (CLOSED, 0.0, 1.0, CLOSED),
                "beside another, an effect under this share of its range's smallest size that closes no held-out gap is not named"),
            entry("fit.scatter_p", f.scatter_p, "1", (OPEN, 0.0, 1.0, OPEN),
                "null chi-square share above which the runs' own scatter of a coefficient is used: one-sided 1%"),
            entry("fit.wander_overshoot", f.wander_overshoot, "1", (CLOSED, 1.0, 1e6, CLOSED),
                "largest fitted-over-real Allan variance of a wander at any τ: the spread of a 16 s Allan variance from five one-minute runs"),
            entry("fit.wander_prior_floor", f.wander_prior_floor, "1", (OPEN, 0.0, 1.0, CLOSED),
                "the prior's wander is set aside when the runs' bound is under this share of it"),
            entry("fit.gain_ratio_max", f.gain_ratio_max, "1", (OPEN, 1.0, 1e6, CLOSED),
                "a regression effect's simulated gain is used within (1/r, r)"),
            entry("fit.wander_gain_ratio_max", f.wander_gain_ratio_max, "1", (OPEN, 1.0, 1e6, CLOSED),
                "a wander effect's simulated gain is used within (1/r, r)"),
            count("fit.wander_gain_members", f.wander_gain_members as f64, "members", 1.0, 1e4,
                "members per training run that calibrate a wander's gain"),
            count("select.max_effects", s.max_effects as f64, "effects", 1.0, 17.0,
                "most effects the forward selection adds"),
            entry("select.confound_cosine", s.confound_cosine, "1", (CLOSED, 0.0, 1.0, CLOSED),
                "cosine of two effects' shifts of the held-out z-scores above which they are confounded"),
            entry("reference.quantised_smooth_s", r.quantised_smooth_s, "s", (OPEN, 0.0, 1.0, CLOSED),
                "smoothing of a quantised (encoder) reference: its steps would be rate spikes"),
            entry("reference.grid_tolerance_steps", r.grid_tolerance_steps, "steps", (OPEN, 0.0, 0.5, CLOSED),
                "a reference value within this share of a step of a grid point lies on the encoder's grid"),
            entry("reference.grid_share", r.grid_share, "1", (OPEN, 0.0, 1.0, CLOSED),
                "share of the distinct reference values on the grid for the reference to be quantised"),
            entry("reference.print_rounding_floor_dps", r.print_rounding_floor_dps, "deg/s", (CLOSED, 0.0, 10.0, CLOSED),
                "rounding noise of a printed reference below which the print is exact: under common MEMS output steps"),
            count("reference.print_max_decimals", f64::from(r.print_max_decimals), "decimals", 0.0, 12.0,
                "finest decimal grid a printed reference is looked for on"),
            entry("reference.print_max_half_width_s", r.print_max_half_width_s, "s", (OPEN, 0.0, 1.0, CLOSED),
                "longest half width of a print's smoothing: ±80 ms (quintic) passes a wrench's turns"),
            entry("envelopes.rate_quantile", e.rate_quantile, "1", (OPEN, 0.0, 1.0, CLOSED),
                "quantile of the \\|reference rate\\| that spans the figures' rate axis"),
            entry("envelopes.acceleration_quantile", e.acceleration_quantile, "1", (OPEN, 0.0, 1.0, CLOSED),
                "quantile of the moving \\|reference acceleration\\| that spans the acceleration axis"),
            entry("statistics.static_rate_dps", st.static_rate_dps, "deg/s", (OPEN, 0.0, 100.0, CLOSED),
                "a sample is still when \\|reference rate\\| is below this"),
            entry("statistics.static_min_s", st.static_min_s, "s", (OPEN, 0.0, 60.0, CLOSED),
                "shortest still run counted as static"),
            entry("statistics.gyro_still_window_s", st.gyro_still_window_s, "s", (OPEN, 0.0, 10.0, CLOSED),
                "averaging window of the gyro's stillness check"),
            entry("statistics.rest_edge_s", st.rest_edge_s, "s", (CLOSED, 0.0, 10.0, CLOSED),
                "left out at each end of a rest for the white-noise features: the turns' first and last ramps"),
            entry("statistics.max_lag_s", st.max_lag_s, "s", (OPEN, 0.0, 10.0, CLOSED),
                "largest lag searched by the per-sample cross-correlation statistic"),
            entry("statistics.white_check_tau_s", st.white_check_tau_s, "s", (OPEN, 0.0, 10.0, CLOSED),
                "averaging time of the rests' whiteness check (Allan variance against first differences)"),
            entry("statistics.min_temperature_range_c", st.min_temperature_range_c, "°C", (CLOSED, 0.0, 100.0, CLOSED),
                "a run's temperature varies when its range exceeds this"),
            entry("statistics.plateau_reference_share", st.plateau_reference_share, "1", (CLOSED, 0.0, 1.0, CLOSED),
                "least range of the reference's \\|rate\\| over a plateau, as a share of its level, for a clip"),
            entry("statistics.line_segment_s", st.line_segment_s, "s", (OPEN, 0.0, 60.0, CLOSED),
                "length of the line spectrum's Welch segments"),
            entry("statistics.line_min_ratio", st.line_min_ratio, "1", (CLOSED, 1.0, 1e6, CLOSED),
                "a line stands at least this many times above its local floor: real spectra have texture"),
            entry("statistics.motion_line_ratio", st.motion_line_ratio, "1", (CLOSED, 1.0, 1e6, CLOSED),
                "a line of the motion is reported at this many times its floor"),
            entry("statistics.min_line_hz", st.min_line_hz, "Hz", (OPEN, 0.0, 1e4, CLOSED),
                "lowest frequency searched for a line"),
            count("statistics.guard_bins", st.guard_bins as f64, "bins", 0.0, 100.0,
                "bins on either side of a line that belong to it: the Hann main lobe"),
            count("statistics.floor_bins", st.floor_bins as f64, "bins", 1.0, 1000.0,
                "bins on either side whose median is a line's local floor"),
            entry("statistics.low_band_hz", st.low_band_hz, "Hz", (OPEN, 0.0, 1e4, CLOSED),
                "cut-off of the low band: the band of the turns"),
            entry("statistics.lag_window_s", st.lag_window_s, "s", (OPEN, 0.0, 3600.0, CLOSED),
                "window of one point of the lag line, whose growth through the run is a count-stamped clock"),
            entry("statistics.lag_min_motion_dps", st.lag_min_motion_dps, "deg/s", (OPEN, 0.0, 1e4, CLOSED),
                "least RMS reference rate in a window for its lag to be read"),
            entry("statistics.lag_max_clock", st.lag_max_clock, "1", (OPEN, 0.0, 0.5, CLOSED),
                "largest clock error the lag line searches for: beyond the ±1–3% of an internal oscillator"),
            entry("statistics.lag_line_hz", st.lag_line_hz, "Hz", (OPEN, 0.0, 1e6, CLOSED),
                "rate the lag line block-averages the rates to: the motion lies below 20 Hz"),
            entry("statistics.lag_min_span_share", st.lag_min_span_share, "1", (OPEN, 0.0, 1.0, CLOSED),
                "least share of the run a lag line's windows span: a few neighbouring windows say little of the slope"),
            count("score.floor_members", sc.floor_members as f64, "members", 1.0, 1e4,
                "members taken out in turn per run for the floor"),
            entry("score.likelihood_dof", sc.likelihood_dof, "1", (OPEN, 0.0, 1e6, CLOSED),
                "degrees of freedom of the Student-t likelihood of one statistic: heavy tails"),
            entry("score.remaining_share", sc.remaining_share, "1", (CLOSED, 0.0, 1.0, CLOSED),
                "share of a signature statistic's nominal discrepancy an effect may leave and pass its posterior check"),
            entry("score.no_gap_share", sc.no_gap_share, "1", (CLOSED, 0.0, 10.0, CLOSED),
                "gap above the floor, as a share of the floor, that counts as no gap (nothing to close)"),
            entry("turns.min_k", tu.min_k, "1", (CLOSED, 0.0, 1.0, CLOSED),
                "smallest scale error named from the turns: 0.09° on a 90° turn"),
            entry("turns.min_stretch_s", tu.min_stretch_s, "s", (OPEN, 0.0, 3600.0, CLOSED),
                "shortest stretch of residual the effective noise uses"),
            entry("turns.min_tau_s", tu.min_tau_s, "s", (OPEN, 0.0, 100.0, CLOSED),
                "shortest averaging time the effective noise characterises"),
        ]
    }

    /// `Ok` when every setting is finite and within its range, else the first that is
    /// not, by name.
    pub fn validate(&self) -> Result<(), SettingsError> {
        for e in self.entries() {
            if !e.value.is_finite() {
                return Err(SettingsError::NonFinite(e.name));
            }
            let above = if e.min_inclusive {
                e.value >= e.min
            } else {
                e.value > e.min
            };
            let below = if e.max_inclusive {
                e.value <= e.max
            } else {
                e.value < e.max
            };
            if !(above && below) {
                return Err(SettingsError::OutOfRange(e.name));
            }
        }
        Ok(())
    }

    /// The settings as the markdown table of `docs/diagnose.md#settings`.
    pub fn markdown_table(&self) -> String {
        let mut out =
            String::from("| setting | default | unit | valid | why |\n|---|---|---|---|---|\n");
        for e in self.entries() {
            let value = if e.integer {
                format!("{}", e.value as i64)
            } else {
                format!("{}", e.value)
            };
            let range = format!(
                "{}{}, {}{}",
                if e.min_inclusive { "[" } else { "(" },
                e.min,
                e.max,
                if e.max_inclusive { "]" } else { ")" },
            );
            out.push_str(&format!(
                "| `{}` | {} | {} | {} | {} |\n",
                e.name, value, e.unit, range, e.why
            ));
        }
        out
    }
}

impl Default for Settings {
    fn default() -> Self {
        Self::DEFAULT
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_defaults_are_valid() {
        assert_eq!(Settings::default().validate(), Ok(()));
    }

    #[test]
    fn a_setting_out_of_range_is_named() {
        let mut s = Settings::default();
        s.tests.p_value = 1.0;
        assert_eq!(
            s.validate(),
            Err(SettingsError::OutOfRange("tests.p_value"))
        );
        let mut s = Settings::default();
        s.reference.quantised_smooth_s = f64::NAN;
        assert_eq!(
            s.validate(),
            Err(SettingsError::NonFinite("reference.quantised_smooth_s"))
        );
    }

    #[test]
    fn every_field_has_one_entry() {
        let names: Vec<_> = Settings::DEFAULT.entries().iter().map(|e| e.name).collect();
        let mut unique = names.clone();
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(unique.len(), names.len());
        // One entry per field: a field added without an entry changes the Debug output's
        // count of `: ` pairs but not this.
        let debug = format!("{:?}", Settings::DEFAULT);
        let fields = debug.matches(": ").count() - 9;
        assert_eq!(fields, names.len(), "{debug}");
    }
}
