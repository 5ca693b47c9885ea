//! Stage 6, summarise: how far the selected effects close the gap on the training and
//! held-out runs, and the [`Diagnosis`] of the JSON contract.

use super::baseline::{evaluate, Baseline, Runs};
use super::fit::Untestable;
use super::score::{gap, RunScore};
use super::select::{Candidate, Selection};
use super::{
    CompensationSummary, Diagnosis, EffectResult, GapSummary, ModelSummary, Options, Progress,
    RealRun, RunSummary, UntestableEntry, Verdict, Where,
};
use gyro_analysis::model::ModelFile;
use gyro_sim::{Effect, SensorModel};

/// The training runs with the selected effects: their scores and G.
pub(crate) fn train_after(
    runs: &Runs,
    baseline: &Baseline,
    selected_model: &SensorModel,
    selected_effects: &[Effect],
    options: &Options,
    progress: &dyn Progress,
) -> (Vec<RunScore>, f64) {
    if selected_effects.is_empty() {
        return (baseline.train.scores.clone(), baseline.train_gap);
    }
    let mc = baseline.candidate_members;
    progress.stage(
        "selected model on training runs",
        (mc * runs.train.len()) as u64,
    );
    let e = evaluate(
        &runs.train,
        &runs.train_ids,
        selected_model,
        selected_effects,
        options,
        mc,
        progress,
    );
    let g = gap(&e.scores);
    (e.scores, g)
}

/// (before − after) / (before − floor); 0 with no gap above the floor (within
/// `no_gap_share` of it: `score.no_gap_share`).
fn closed(floor: f64, no_gap_share: f64, before: f64, after: f64) -> f64 {
    let span = before - floor;
    if span <= no_gap_share * floor {
        0.0
    } else {
        (before - after) / span
    }
}

/// Each candidate's result: the selected ones in the order they were added, then the
/// rest by held-out gap reduction when added alone, then those not scored on the
/// held-out runs (`gap_before`: the nominal model's held-out G with the candidate seeds).
fn effect_results(
    (floor, no_gap_share): (f64, f64),
    gap_before: f64,
    candidates: &[Candidate],
    selection: &Selection,
) -> Vec<EffectResult> {
    let selected = &selection.selected;
    let mut effects: Vec<(Option<usize>, EffectResult)> = candidates
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let info = c.fit.effect.info();
            let values = c.fit.effect.params();
            let params = info.params.iter().map(|p| p.name).zip(values).collect();
            let ci95 = info
                .params
                .iter()
                .map(|p| p.name)
                .zip(c.fit.ci95.iter().map(|(a, b)| [*a, *b]))
                .collect();
            let mut with = selection.partners.get(&i).cloned().unwrap_or_default();
            with.sort_unstable();
            with.dedup();
            let st = c.added.as_ref().or(c.alone.as_ref().map(|a| &a.step));
            let order = selected.iter().position(|&j| j == i);
            (
                order,
                EffectResult {
                    id: info.id,
                    params,
                    delta_bic: st.map(|st| st.delta_bic),
                    holdout_gap_before: st.map_or(gap_before, |st| st.gap_before),
                    holdout_gap_after: st.map(|st| st.gap_after),
                    fraction_closed: st
                        .map(|st| closed(floor, no_gap_share, st.gap_before, st.gap_after)),
                    significant: order.is_some(),
                    ci95,
                    z: c.fit.z.is_finite().then_some(c.fit.z),
                    holdout_z: c.fit.holdout_z,
                    shape_loglik: c.fit.shape_loglik,
                    test: format!(
                        "{}: {}",
                        c.fit.test,
                        if c.fit.passes {
                            "passes"
                        } else {
                            "does not pass"
                        }
                    ),
                    bootstrap_p: st.map(|st| st.p),
                    confounded_with: with,
                    posterior_check: c.posterior.clone(),
                },
            )
        })
        .collect();
    effects.sort_by(|(oa, a), (ob, b)| match (oa, ob) {
        (Some(x), Some(y)) => x.cmp(y),
        (Some(_), None) => std::cmp::Ordering::Less,
        (None, Some(_)) => std::cmp::Ordering::Greater,
        (None, None) => match (a.holdout_gap_after, b.holdout_gap_after) {
            (Some(x), Some(y)) => (x - a.holdout_gap_before).total_cmp(&(y - b.holdout_gap_before)),
            (Some(_), None) => std::cmp::Ordering::Less,
            (None, Some(_)) => std::cmp::Ordering::Greater,
            (None, None) => std::cmp::Ordering::Equal,
        },
    });
    effects.into_iter().map(|(_, e)| e).collect()
}

/// Each run's gap before and after, training runs first.
fn run_summaries(
    runs: &Runs,
    train: (&[RunScore], &[RunScore]),
    holdout: (&[RunScore], &[RunScore]),
) -> Vec<RunSummary> {
    runs.train
        .iter()
        .zip(train.0.iter().zip(train.1))
        .map(|(r, (b, a))| (r, "train", b, a))
        .chain(
            runs.holdout
                .iter()
                .zip(holdout.0.iter().zip(holdout.1))
                .map(|(r, (b, a))| (r, "holdout", b, a)),
        )
        .map(|(r, role, b, a)| RunSummary {
            name: r.name.clone(),
            role,
            duration_s: r.duration_s,
            gap_before: gap(std::slice::from_ref(b)),
            gap_after: gap(std::slice::from_ref(a)),
            reference_grid: r.reference_grid,
            z: b.z
                .iter()
                .map(|(s, z)| (format!("{}/{}", s.segment, s.statistic), *z))
                .collect(),
        })
        .collect()
}

/// Everything the diagnosis reports, from the stages before.
pub(crate) struct Findings<'a> {
    pub(crate) runs: &'a Runs<'a>,
    pub(crate) baseline: Baseline,
    pub(crate) r#where: Vec<Where>,
    pub(crate) untestable: Vec<Untestable>,
    /// Held-out scores of the nominal model with the candidate members.
    pub(crate) holdout_before: Vec<RunScore>,
    pub(crate) candidates: Vec<Candidate>,
    pub(crate) selection: Selection,
    pub(crate) selected_effects: Vec<Effect>,
    pub(crate) selected_sensor: SensorModel,
    pub(crate) train_after: (Vec<RunScore>, f64),
    pub(crate) compensation: Option<CompensationSummary>,
    pub(crate) corrected_model: Option<ModelFile>,
    pub(crate) turns: Option<super::turns::TurnEvidence>,
    pub(crate) settings: &'a crate::Settings,
}

/// Stage 6: the diagnosis.
pub(crate) fn summarise(f: Findings) -> Diagnosis {
    let floor = f.baseline.floor;
    let effects = effect_results(
        (floor, f.settings.score.no_gap_share),
        gap(&f.holdout_before),
        &f.candidates,
        &f.selection,
    );
    let unmodelled: Vec<&'static str> = effects
        .iter()
        .filter(|e| e.significant)
        .map(|e| e.id)
        .collect();
    let closed_holdout = closed(
        floor,
        f.settings.score.no_gap_share,
        gap(&f.holdout_before),
        gap(&f.selection.holdout_scores),
    );
    let holdout_after = gap(&f.selection.holdout_scores);
    let unexplained = super::locate::unexplained(
        &f.baseline.train.scores,
        &f.train_after.0,
        &f.selection.holdout_scores,
        f.settings,
    );
    let (reference_warnings, doubts, warnings) = warnings(&f);
    let effective_noise = effective_noise(&f);
    let runs = run_summaries(
        f.runs,
        (&f.baseline.train.scores, &f.train_after.0),
        (&f.holdout_before, &f.selection.holdout_scores),
    );
    Diagnosis {
        gap: GapSummary {
            train_before: f.baseline.train_gap,
            train_after: f.train_after.1,
            holdout_before: f.baseline.holdout_gap,
            holdout_after,
            floor,
        },
        r#where: f.r#where,
        effects,
        verdict: Verdict {
            unmodelled: unmodelled.clone(),
            fraction_closed_holdout: closed_holdout,
            model_fits: unexplained.is_empty(),
        },
        not_seen: super::detection::not_seen(&unmodelled),
        unexplained,
        untestable: f
            .untestable
            .into_iter()
            .map(|Untestable { id, reason }| UntestableEntry { id, reason })
            .collect(),
        model: ModelSummary {
            sensor: f.baseline.nominal,
            notes: f.baseline.notes,
            rest_noise: f.baseline.whiteness.clone(),
            effects: f.selected_effects,
        },
        runs,
        compensation: f.compensation,
        reference_warnings,
        doubts,
        warnings,
        effective_noise,
        motion_lines: [
            super::line::motion_line(&f.runs.train, "training"),
            super::line::motion_line(&f.runs.holdout, "held-out"),
        ]
        .into_iter()
        .flatten()
        .collect(),
        inputs: Vec::new(),
        turns: f.turns,
        corrected_model: f.corrected_model,
        selected_sensor: f.selected_sensor,
    }
}

/// What the diagnosis says beside its findings, one sentence each: a reference that does
/// not measure the gyro's motion ([`sense_warnings`]), the doubts on a named effect
/// ([`delay_doubt`]), and what makes part of the diagnosis unreliable (a lag beyond the
/// search, [`lag_warnings`]; coloured rests, [`colour_warning`]).
fn warnings(f: &Findings) -> (Vec<String>, Vec<String>, Vec<String>) {
    let growing = f.selected_effects.iter().any(is_count_clock);
    let doubts = delay_doubt(
        &f.selected_effects,
        f.baseline.whiteness.as_ref(),
        f.baseline.nominal.sample_rate_hz,
    );
    let warnings = lag_warnings(f.runs, growing)
        .into_iter()
        .chain(f.baseline.whiteness.as_ref().and_then(colour_warning))
        .collect();
    (
        sense_warnings(f.runs),
        doubts.into_iter().collect(),
        warnings,
    )
}

/// The effective noise on moving data: the training runs' (measured with the baseline)
/// and the held-out runs', each against the rests' own.
fn effective_noise(f: &Findings) -> super::effective::EffectiveNoise {
    super::effective::EffectiveNoise {
        training: f.baseline.moving_noise.clone(),
        holdout: super::effective::measure(&f.runs.holdout, "held-out", &f.settings.turns)
            .map(|m| m.compared_to(f.baseline.own_noise.0, f.baseline.own_noise.1)),
    }
}

/// A warning when the reference of some runs turns against the gyro, or by more than a
/// factor of [`gyro_log::sense::GAIN_LIMIT`] ([`gyro_log::sense`]): every statistic of
/// gyro against reference then measures the mismatch, not the sensor.
fn sense_warnings(runs: &Runs) -> Vec<String> {
    let all: Vec<&RealRun> = runs.train.iter().chain(&runs.holdout).copied().collect();
    use gyro_log::sense::{mismatch, Mismatch};
    // Each measured run's correlation and gain, with the mismatch they show.
    let measured: Vec<(f64, f64, Mismatch)> = all
        .iter()
        .filter_map(|r| {
            let q = &r.log.quality;
            let (c, g) = q.reference_correlation.zip(q.reference_gain)?;
            Some((c, g, mismatch(c, g)?))
        })
        .collect();
    let opposed: Vec<f64> = measured
        .iter()
        .filter(|m| m.2 == Mismatch::Opposed)
        .map(|m| m.0)
        .collect();
    let scaled: Vec<f64> = measured
        .iter()
        .filter(|m| m.2 == Mismatch::Scaled)
        .map(|m| m.1)
        .collect();
    let range = |v: &[f64], digits: usize| {
        let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        format!("{lo:.digits$} to {hi:.digits$}")
    };
    let mut out = Vec::new();
    if !opposed.is_empty() {
        out.push(format!(
            "on {} of {} runs the reference turns against the gyro (correlation of their turns over {} s: {}): one of them counts the other way, and every effect fitted or checked against it measures that, not the sensor; negate one of them",
            opposed.len(),
            all.len(),
            gyro_log::sense::BLOCK_S,
            range(&opposed, 2)
        ));
    }
    if !scaled.is_empty() {
        out.push(format!(
            "on {} of {} runs the reference turns {} times as far as the gyro: their units or scales differ (a rate in rad/s read as deg/s makes 57.3: --rate-unit rads), and every effect fitted or checked against it measures that, not the sensor",
            scaled.len(),
            all.len(),
            range(&scaled, 3)
        ));
    }
    out
}

/// The doubt when a `latency` is named although the rests' noise is low-passed, which
/// points to the gyro's own filter ([`super::select::rests_delay`]): selection keeps the
/// bandwidth when it qualifies, so a latency named beside such rests is one the bandwidth
/// effect could not match, most often because a two-pole low-pass of that delay has its
/// cutoff above the Nyquist frequency, where the effect cannot reach.
fn delay_doubt(
    selected: &[Effect],
    whiteness: Option<&super::fit::RestWhiteness>,
    sample_rate_hz: f64,
) -> Option<String> {
    let delay_s = selected.iter().find_map(|e| match e {
        Effect::Latency { delay_s } if *delay_s > 0.0 => Some(*delay_s),
        _ => None,
    })?;
    let w = whiteness?;
    if super::select::rests_delay(Some(w)) != Some("bandwidth") {
        return None;
    }
    let cutoff_hz = gyro_sim::low_pass_cutoff_hz(delay_s);
    let nyquist_hz = 0.5 * sample_rate_hz;
    let why = if cutoff_hz > nyquist_hz {
        format!(
            ": a two-pole low-pass with this lag has its cutoff at {cutoff_hz:.0} Hz, above the {nyquist_hz:.0} Hz this sample rate allows"
        )
    } else {
        String::new()
    };
    Some(format!(
        "The {:.1} ms lag may be the gyro's own low-pass filter, not a delay: its noise at rest is low-passed too, which a delay does not do (the training rests' {:.2} s blocks read {:.3} deg/sqrt(h), their first differences {:.3}; z {:.0}), and the bandwidth effect could not match the lag{why}",
        delay_s * 1e3,
        w.tau_s,
        w.block_arw_deg_per_rt_h,
        w.first_difference_arw_deg_per_rt_h,
        w.z
    ))
}

/// The warning a coloured rest noise gives: the nominal model's white noise cannot be the
/// rests' at every frequency.
fn colour_warning(w: &super::fit::RestWhiteness) -> Option<String> {
    w.coloured.then(|| {
        format!(
            "the training rests' noise is not white: their first differences read {:.3} deg/sqrt(h), their {:.2} s blocks {:.3} (z {:.0}); the baseline takes the blocks' figure, and its simulated noise, white, does not reproduce the rests' high band (the static statistics that show it are left unexplained)",
            w.first_difference_arw_deg_per_rt_h, w.tau_s, w.block_arw_deg_per_rt_h, w.z
        )
    })
}

/// A warning when the gyro–reference lag of some runs lies beyond the cross-correlation's
/// search: their `xcorr_peak_lag_s` is cut at its edge, and the latency's fit and
/// posterior check read a cut value. Beside a named count-stamped clock (`growing`) the
/// lag grows there by the clock's doing, which the lag line follows.
/// A count-stamped clock: the lag grows through the run.
pub(crate) fn is_count_clock(effect: &gyro_sim::Effect) -> bool {
    matches!(effect, gyro_sim::Effect::ClockErrorCountStamped { .. })
}

fn lag_warnings(runs: &Runs, growing: bool) -> Vec<String> {
    let all: Vec<&RealRun> = runs.train.iter().chain(&runs.holdout).copied().collect();
    // The runs cut at the edge, with the edge.
    let cut: Vec<(&RealRun, f64)> = all
        .iter()
        .filter_map(|r| {
            Some((
                *r,
                super::stats::lag_at_search_edge(
                    &r.stats,
                    r.sample_rate_hz,
                    r.statistics.max_lag_s,
                )?,
            ))
        })
        .collect();
    let Some(&(_, edge)) = cut.first() else {
        return Vec::new();
    };
    // What the lag is, searched wider on those runs.
    let measured: Vec<f64> = cut
        .iter()
        .filter_map(|(r, _)| gyro_analysis::lag::log_lag_s(&r.log))
        .collect();
    let wider = match (
        measured.iter().copied().reduce(f64::min),
        measured.iter().copied().reduce(f64::max),
    ) {
        (Some(lo), Some(hi)) => format!(
            "; searched within ±{:.0} ms, those runs give {:+.0} to {:+.0} ms (+: the gyro lags)",
            1e3 * gyro_analysis::lag::SEARCH_S,
            1e3 * lo,
            1e3 * hi
        ),
        _ => String::new(),
    };
    if growing {
        return vec![format!(
            "on {} of {} runs the gyro-reference lag reaches beyond the edge of the cross-correlation's search, ±{:.0} ms{wider}: it grows through each run with the count-stamped clock named above, which the lag line follows window by window (xcorr_lag_trend); the latency is read at the line's start, not from the cut statistic",
            cut.len(),
            all.len(),
            1e3 * edge.abs()
        )];
    }
    vec![format!(
        "on {} of {} runs the gyro-reference lag lies at or beyond the edge of the cross-correlation's search, ±{:.0} ms{wider}: their lag statistic is cut there, not measured, and a latency fitted or checked on it is not to be trusted (a logger that buffers, over a wireless link or USB, can put 100 ms between the two)",
        cut.len(),
        all.len(),
        1e3 * edge.abs()
    )]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::RestWhiteness;
    use crate::settings::Settings;

    fn rests(z: f64) -> RestWhiteness {
        RestWhiteness {
            tau_s: 0.05,
            first_difference_arw_deg_per_rt_h: 1.405,
            block_arw_deg_per_rt_h: 1.762,
            block_differences: 4000,
            z,
            coloured: z.abs() >= Settings::DEFAULT.tests.z_critical,
        }
    }

    #[test]
    fn a_latency_beside_low_passed_rests_is_doubted() {
        let latency = [Effect::Latency { delay_s: 0.0023 }];
        // At 100 Hz: a 2.3 ms two-pole delay is a cutoff near 89 Hz, above Nyquist.
        let w = delay_doubt(&latency, Some(&rests(19.0)), 100.0).expect("a warning");
        assert!(
            w.contains("The 2.3 ms lag may be the gyro's own low-pass filter"),
            "{w}"
        );
        assert!(w.contains("above the 50 Hz"), "{w}");
        // At 1 kHz the cutoff is below Nyquist: the warning without that clause.
        let w = delay_doubt(&latency, Some(&rests(19.0)), 1000.0).expect("a warning");
        assert!(!w.contains("Nyquist") && !w.contains("above the"), "{w}");
        // White rests, rests not checked, a negative latency, or no latency: none.
        assert_eq!(delay_doubt(&latency, Some(&rests(0.5)), 100.0), None);
        assert_eq!(delay_doubt(&latency, None, 100.0), None);
        let ahead = [Effect::Latency { delay_s: -0.01 }];
        assert_eq!(delay_doubt(&ahead, Some(&rests(19.0)), 100.0), None);
        assert_eq!(delay_doubt(&[], Some(&rests(19.0)), 100.0), None);
    }
}
