//! What a push gives back: the output sample, its movement event and the verdict.

use gyro_core::{Event, MotionState, Movement, Output, Verdict};

/// The confirmed motion state of an output sample.
#[repr(u8)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GyroMotion {
    /// At rest: the angle is held.
    Static = 0,
    /// Moving: the rate is integrated.
    Dynamic = 1,
}

/// The movement event confirmed at an output sample.
#[repr(u8)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GyroEvent {
    /// None.
    None = 0,
    /// A movement was confirmed; `GyroOutput.movement` has its start (`start_time_s`,
    /// `start_index`; the other fields are 0).
    Started = 1,
    /// A rest was confirmed after a movement; `GyroOutput.movement` has all of it.
    Ended = 2,
}

/// The tightening decision on a movement (guard-banded by k·σ).
#[repr(u8)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GyroVerdict {
    /// No verdict: no tightening window is configured, or the movement turned the other way
    /// (not a tightening), or the movement has not ended.
    None = 0,
    /// Inside the window by more than k·σ.
    Ok = 1,
    /// Outside the window by more than k·σ.
    Nok = 2,
    /// Within k·σ of a limit: measure again (or by another means).
    Recheck = 3,
    /// The angle cannot be trusted: the sensor saturated, or samples were rejected.
    Invalid = 4,
}

/// One movement, from its last quiet sample before to its first quiet sample after.
///
/// Times are on the input's time line (the filter's delay taken off); indices count output
/// samples from 0 at the pipeline's first output.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GyroMovement {
    /// Start time (s).
    pub start_time_s: f64,
    /// End time (s).
    pub end_time_s: f64,
    /// Index of the output sample the movement starts at (its last quiet sample).
    pub start_index: u32,
    /// Index of the output sample the movement ends at (its first quiet sample).
    pub end_index: u32,
    /// Angle turned, with the configured compensation (deg).
    pub angle_deg: f32,
    /// Angle turned, uncompensated (deg).
    pub raw_angle_deg: f32,
    /// Standard deviation of `angle_deg` (deg) if `has_angle_std`, else NaN.
    pub angle_std_deg: f32,
    /// `angle_std_deg` is known (Kalman compensation).
    pub has_angle_std: bool,
    /// A reading during the movement reached the sensor's range (while none had gone
    /// beyond it: see `GyroPipelineInfo::range_contradicted`) or sat on a clip plateau:
    /// the angle is a lower bound of the turn.
    pub saturated: bool,
    /// An input sample was rejected (not finite, or beyond `max_abs_rate_dps`) between the
    /// movement's start and the end's confirmation: its rate was a guess.
    pub rejected_samples: bool,
    /// The tightening decision (`GYRO_VERDICT_NONE` without a tightening window): invalid
    /// if `saturated` or `rejected_samples`.
    pub verdict: GyroVerdict,
}

/// One output sample, at the decimated rate.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GyroOutput {
    /// Centre of the input block this sample averages (s).
    pub time_s: f64,
    /// Index of this output sample, from 0 at the pipeline's first output.
    pub index: u32,
    /// Decimated, filtered rate (deg/s).
    pub rate_dps: f32,
    /// Angle with the configured compensation (deg).
    pub angle_deg: f32,
    /// Angle without compensation (deg).
    pub raw_angle_deg: f32,
    /// Standard deviation of `angle_deg` (deg) if `has_angle_std`, else NaN.
    pub angle_std_deg: f32,
    /// Current bias estimate (deg/s): the Kalman estimate, or the rest mean otherwise.
    pub bias_dps: f32,
    /// `angle_std_deg` is known (Kalman compensation).
    pub has_angle_std: bool,
    /// The confirmed motion state.
    pub motion: GyroMotion,
    /// The movement event confirmed at this sample, if any.
    pub event: GyroEvent,
    /// The movement of `event` (all 0 when `event` is `GYRO_EVENT_NONE`).
    pub movement: GyroMovement,
}

impl GyroMovement {
    /// Nothing: the movement of an output without an event.
    const NONE: Self = Self {
        start_time_s: 0.0,
        end_time_s: 0.0,
        start_index: 0,
        end_index: 0,
        angle_deg: 0.0,
        raw_angle_deg: 0.0,
        angle_std_deg: 0.0,
        has_angle_std: false,
        saturated: false,
        rejected_samples: false,
        verdict: GyroVerdict::None,
    };

    /// A movement that ended, with its verdict.
    pub(crate) fn ended(
        movement: &Movement,
        rejected_samples: bool,
        verdict: Option<Verdict>,
    ) -> Self {
        Self {
            start_time_s: movement.start_time_s,
            end_time_s: movement.end_time_s,
            start_index: movement.start_index,
            end_index: movement.end_index,
            angle_deg: movement.angle_deg,
            raw_angle_deg: movement.raw_angle_deg,
            angle_std_deg: movement.angle_std_deg.unwrap_or(f32::NAN),
            has_angle_std: movement.angle_std_deg.is_some(),
            saturated: movement.saturated,
            rejected_samples,
            verdict: match verdict {
                None => GyroVerdict::None,
                Some(Verdict::Ok) => GyroVerdict::Ok,
                Some(Verdict::Nok) => GyroVerdict::Nok,
                Some(Verdict::Recheck) => GyroVerdict::Recheck,
                Some(Verdict::Invalid) => GyroVerdict::Invalid,
            },
        }
    }
}

impl GyroOutput {
    /// The C struct of `output`, output sample number `index`; `ended` is the movement of a
    /// [`Event::MovementEnded`] with what only the caller of the core knows.
    pub(crate) fn new(output: &Output, index: u32, ended: Option<GyroMovement>) -> Self {
        let (event, movement) = match (output.event, ended) {
            (Some(Event::MovementEnded(_)), Some(movement)) => (GyroEvent::Ended, movement),
            (
                Some(Event::MovementStarted {
                    start_time_s,
                    start_index,
                }),
                _,
            ) => (
                GyroEvent::Started,
                GyroMovement {
                    start_time_s,
                    start_index,
                    ..GyroMovement::NONE
                },
            ),
            _ => (GyroEvent::None, GyroMovement::NONE),
        };
        Self {
            time_s: output.time_s,
            index,
            rate_dps: output.rate_dps,
            angle_deg: output.angle_deg,
            raw_angle_deg: output.raw_angle_deg,
            angle_std_deg: output.angle_std_deg.unwrap_or(f32::NAN),
            bias_dps: output.bias_dps,
            has_angle_std: output.angle_std_deg.is_some(),
            motion: match output.motion {
                MotionState::Static => GyroMotion::Static,
                MotionState::Dynamic => GyroMotion::Dynamic,
            },
            event,
            movement,
        }
    }
}

/// The pipeline's counters and state, for diagnostics (`gyro_pipeline_info`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GyroPipelineInfo {
    /// Group delay of the low-pass filter at DC (s): how far movement boundaries found on
    /// the filtered rate lag the input (movement times are corrected by it).
    pub filter_delay_s: f64,
    /// Output sample period (s).
    pub output_period_s: f32,
    /// Input samples rejected so far (not finite, or beyond `max_abs_rate_dps`), each
    /// replaced by the last valid rate.
    pub rejected_samples: u32,
    /// Output samples produced so far.
    pub outputs: u32,
    /// All internal state is finite (it always should be).
    pub finite: bool,
    /// The movement in progress is saturated so far (`false` at rest): for a caller whose
    /// recording ends while moving.
    pub movement_saturated: bool,
    /// A reading went beyond `range_dps` by more than 0.5%: that range is not the
    /// sensor's, and from then on only a clip plateau flags a movement saturated.
    pub range_contradicted: bool,
}
