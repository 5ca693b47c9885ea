/*
 * The C API from C: built with the system `cc` against the host libgyro_ffi.a and run by
 * tests/all/c_api.rs. Exit status 0 when every check passes; each failed check is printed.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "gyro.h"

static int passed, failed;

#define CHECK(cond)                                                                  \
    do {                                                                             \
        if (cond) {                                                                  \
            passed++;                                                                \
        } else {                                                                     \
            failed++;                                                                \
            printf("FAILED %s:%d: %s\n", __FILE__, __LINE__, #cond);                 \
        }                                                                            \
    } while (0)

#define CHECK_STATUS(call, expected)                                                 \
    do {                                                                             \
        GyroStatus status_ = (call);                                                 \
        if (status_ == (expected)) {                                                 \
            passed++;                                                                \
        } else {                                                                     \
            failed++;                                                                \
            printf("FAILED %s:%d: %s gave %s, expected %s\n", __FILE__, __LINE__, #call, \
                   gyro_status_name(status_), gyro_status_name(expected));            \
        }                                                                            \
    } while (0)

/* Room for two pipelines, so that a misaligned or overlapping one can be tried. */
static _Alignas(GYRO_PIPELINE_ALIGN) unsigned char storage[2 * GYRO_PIPELINE_SIZE];

/* What a run of the synthetic turn gives. */
typedef struct {
    int started, ended, outputs;
    GyroMovement movement; /* the last that ended */
    GyroOutput last;
} Run;

/*
 * 1 s of rest, a turn of `angle_deg` in 1 s (raised-cosine rate, peak 2 * angle_deg deg/s),
 * then 3 s of rest, at 1 kHz; sample `nan_at` (if >= 0) is NaN. With `temperature` the
 * samples go through gyro_pipeline_push_with_temperature at 25 °C.
 */
static Run turn(GyroPipeline *pipeline, float angle_deg, int nan_at, int temperature) {
    const double pi = 3.14159265358979323846;
    Run run;
    memset(&run, 0, sizeof run);
    for (int i = 0; i < 5000; i++) {
        double time_s = i * 1e-3;
        float rate_dps = 0.0f;
        if (time_s >= 1.0 && time_s < 2.0) {
            rate_dps = (float)(angle_deg * (1.0 - cos(2.0 * pi * (time_s - 1.0))));
        }
        if (i == nan_at) {
            rate_dps = NAN;
        }
        GyroOutput out;
        GyroStatus status = temperature
            ? gyro_pipeline_push_with_temperature(pipeline, time_s, rate_dps, 25.0f, &out)
            : gyro_pipeline_push(pipeline, time_s, rate_dps, &out);
        if (status == GYRO_STATUS_OK) {
            continue;
        }
        CHECK_STATUS(status, GYRO_STATUS_OUTPUT);
        if (status != GYRO_STATUS_OUTPUT) {
            break;
        }
        CHECK(out.index == (uint32_t)run.outputs);
        run.outputs++;
        run.last = out;
        if (out.event == GYRO_EVENT_STARTED) {
            run.started++;
            CHECK(out.movement.start_time_s > 0.9 && out.movement.start_time_s < 1.1);
            CHECK(out.movement.verdict == GYRO_VERDICT_NONE);
        } else if (out.event == GYRO_EVENT_ENDED) {
            run.ended++;
            run.movement = out.movement;
        }
    }
    return run;
}

static GyroPipeline *setup(const GyroConfig *config) {
    GyroPipeline *pipeline = NULL;
    GyroField field = GYRO_FIELD_UNKNOWN;
    CHECK_STATUS(gyro_pipeline_init(storage, sizeof storage, config, &pipeline, &field),
                 GYRO_STATUS_OK);
    CHECK(field == GYRO_FIELD_NONE);
    CHECK(pipeline == (GyroPipeline *)storage);
    return pipeline;
}

static void default_config(void) {
    GyroConfig config;
    memset(&config, 0xAB, sizeof config);
    CHECK_STATUS(gyro_config_default(&config), GYRO_STATUS_OK);
    CHECK(config.sample_rate_hz == 1000.0f);
    CHECK(config.output_rate_hz == 50.0f);
    CHECK(config.filter.order == 2 && config.filter.cutoff_hz == 12.5f);
    CHECK(config.compensation == GYRO_COMPENSATION_KALMAN);
    CHECK(config.has_range_dps == 0);
    CHECK(config.correction.scale_k == 0.0f && config.correction.has_temperature_ref_c == 0);
    CHECK(config.tightening.enabled == 0);
    CHECK(config.tightening.k_sigma == 2.0f);
    CHECK(config.tightening.direction == GYRO_DIRECTION_POSITIVE);
    CHECK_STATUS(gyro_config_default(NULL), GYRO_STATUS_NULL_POINTER);
}

/* Each invalid setting gives its own status and field, and leaves the pipeline as it was. */
static void invalid_configs(void) {
    GyroConfig valid;
    gyro_config_default(&valid);
    GyroPipeline *pipeline = setup(&valid);

    struct {
        GyroConfig config;
        GyroStatus status;
        GyroField field;
        const char *name;
    } cases[8];
    int n = 0;
    cases[n].config = valid;
    cases[n].config.motion.exit_dps = -1.0f;
    cases[n].status = GYRO_STATUS_CONFIG_OUT_OF_RANGE;
    cases[n].field = GYRO_FIELD_MOTION_EXIT_DPS;
    cases[n++].name = "motion.exit_dps";
    cases[n].config = valid;
    cases[n].config.filter.cutoff_hz = NAN;
    cases[n].status = GYRO_STATUS_CONFIG_NON_FINITE;
    cases[n].field = GYRO_FIELD_FILTER_CUTOFF_HZ;
    cases[n++].name = "filter.cutoff_hz";
    cases[n].config = valid;
    cases[n].config.kalman.rate_noise_dps = INFINITY;
    cases[n].status = GYRO_STATUS_CONFIG_NON_FINITE;
    cases[n].field = GYRO_FIELD_KALMAN_RATE_NOISE_DPS;
    cases[n++].name = "kalman.rate_noise_dps";
    cases[n].config = valid;
    cases[n].config.compensation = 7;
    cases[n].status = GYRO_STATUS_CONFIG_OUT_OF_RANGE;
    cases[n].field = GYRO_FIELD_COMPENSATION;
    cases[n++].name = "compensation";
    cases[n].config = valid;
    cases[n].config.has_range_dps = 1;
    cases[n].config.range_dps = 0.0f;
    cases[n].status = GYRO_STATUS_CONFIG_OUT_OF_RANGE;
    cases[n].field = GYRO_FIELD_RANGE_DPS;
    cases[n++].name = "range_dps";
    cases[n].config = valid;
    cases[n].config.tightening.enabled = 1;
    cases[n].config.tightening.target_deg = 90.0f;
    cases[n].config.tightening.tolerance_deg = 91.0f;
    cases[n].status = GYRO_STATUS_CONFIG_OUT_OF_RANGE;
    cases[n].field = GYRO_FIELD_TIGHTENING_TOLERANCE_DEG;
    cases[n++].name = "tightening.tolerance_deg";
    cases[n].config = valid;
    cases[n].config.tightening.enabled = 2;
    cases[n].status = GYRO_STATUS_CONFIG_OUT_OF_RANGE;
    cases[n].field = GYRO_FIELD_TIGHTENING_ENABLED;
    cases[n++].name = "tightening.enabled";
    cases[n].config = valid;
    cases[n].config.sample_rate_hz = 100.0f;
    cases[n].config.output_rate_hz = 200.0f;
    cases[n].status = GYRO_STATUS_CONFIG_OUT_OF_RANGE;
    cases[n].field = GYRO_FIELD_OUTPUT_RATE_HZ;
    cases[n++].name = "output_rate_hz";

    for (int i = 0; i < n; i++) {
        GyroPipeline *untouched = NULL;
        GyroField field = GYRO_FIELD_NONE;
        GyroStatus status =
            gyro_pipeline_init(storage, sizeof storage, &cases[i].config, &untouched, &field);
        if (status != cases[i].status || field != cases[i].field) {
            printf("FAILED: %s gave %s and field %s\n", cases[i].name, gyro_status_name(status),
                   gyro_field_name(field));
            failed++;
        } else {
            passed++;
        }
        CHECK(strcmp(gyro_field_name(field), cases[i].name) == 0);
        CHECK(untouched == NULL);
        /* A NULL field pointer is allowed. */
        CHECK_STATUS(gyro_pipeline_init(storage, sizeof storage, &cases[i].config, &untouched,
                                        NULL),
                     cases[i].status);
    }
    /* The pipeline set up before is still there and works. */
    Run run = turn(pipeline, 90.0f, -1, 0);
    CHECK(run.ended == 1);
}

/* Every pointer is checked: NULL, misaligned, not set up, overlapping. */
static void bad_pointers(void) {
    GyroConfig config;
    gyro_config_default(&config);
    GyroPipeline *pipeline = NULL;
    GyroField field;
    GyroOutput out;
    GyroPipelineInfo info;

    CHECK_STATUS(gyro_pipeline_init(NULL, sizeof storage, &config, &pipeline, &field),
                 GYRO_STATUS_NULL_POINTER);
    CHECK_STATUS(gyro_pipeline_init(storage, sizeof storage, NULL, &pipeline, &field),
                 GYRO_STATUS_NULL_POINTER);
    CHECK_STATUS(gyro_pipeline_init(storage, sizeof storage, &config, NULL, &field),
                 GYRO_STATUS_NULL_POINTER);
    CHECK(field == GYRO_FIELD_NONE);
    CHECK_STATUS(gyro_pipeline_init(storage + 4, GYRO_PIPELINE_SIZE, &config, &pipeline, &field),
                 GYRO_STATUS_MISALIGNED);
    CHECK_STATUS(gyro_pipeline_init(storage, GYRO_PIPELINE_SIZE - 1, &config, &pipeline, &field),
                 GYRO_STATUS_STORAGE_TOO_SMALL);
    CHECK_STATUS(gyro_pipeline_init(storage, sizeof storage, &config,
                                    (GyroPipeline **)(storage + 8), &field),
                 GYRO_STATUS_OVERLAP);
    CHECK(pipeline == NULL);

    /* Storage never set up. */
    memset(storage, 0, sizeof storage);
    CHECK_STATUS(gyro_pipeline_push((GyroPipeline *)storage, 0.0, 0.0f, &out),
                 GYRO_STATUS_NOT_INITIALIZED);
    CHECK_STATUS(gyro_pipeline_info((GyroPipeline *)storage, &info), GYRO_STATUS_NOT_INITIALIZED);

    pipeline = setup(&config);
    CHECK_STATUS(gyro_pipeline_push(NULL, 0.0, 0.0f, &out), GYRO_STATUS_NULL_POINTER);
    CHECK_STATUS(gyro_pipeline_push(pipeline, 0.0, 0.0f, NULL), GYRO_STATUS_NULL_POINTER);
    CHECK_STATUS(gyro_pipeline_push_with_temperature(NULL, 0.0, 0.0f, 20.0f, &out),
                 GYRO_STATUS_NULL_POINTER);
    CHECK_STATUS(gyro_pipeline_push_with_temperature(pipeline, 0.0, 0.0f, 20.0f, NULL),
                 GYRO_STATUS_NULL_POINTER);
    CHECK_STATUS(gyro_pipeline_push((GyroPipeline *)(storage + 4), 0.0, 0.0f, &out),
                 GYRO_STATUS_MISALIGNED);
    CHECK_STATUS(gyro_pipeline_push(pipeline, 0.0, 0.0f, (GyroOutput *)(storage + 1)),
                 GYRO_STATUS_MISALIGNED);
    CHECK_STATUS(gyro_pipeline_push(pipeline, 0.0, 0.0f, (GyroOutput *)(storage + 64)),
                 GYRO_STATUS_OVERLAP);
    CHECK_STATUS(gyro_pipeline_info(NULL, &info), GYRO_STATUS_NULL_POINTER);
    CHECK_STATUS(gyro_pipeline_info(pipeline, NULL), GYRO_STATUS_NULL_POINTER);

    /* None of the refused pushes took a sample. */
    CHECK_STATUS(gyro_pipeline_info(pipeline, &info), GYRO_STATUS_OK);
    CHECK(info.outputs == 0);
    int taken = 0;
    while (gyro_pipeline_push(pipeline, taken * 1e-3, 0.0f, &out) == GYRO_STATUS_OK) {
        taken++;
    }
    CHECK(taken == 19); /* the 20th sample completes the first output */
}

/* A 90° turn: the angle, σ, the events, the verdict, the counters. */
static void synthetic_turn(void) {
    GyroConfig config;
    gyro_config_default(&config);
    config.tightening.enabled = 1;
    config.tightening.target_deg = 90.0f;
    config.tightening.tolerance_deg = 5.0f;
    GyroPipeline *pipeline = setup(&config);
    Run run = turn(pipeline, 90.0f, -1, 0);
    printf("90 deg turn: angle %.4f deg, sigma %.4f deg, %d outputs\n",
           (double)run.movement.angle_deg, (double)run.movement.angle_std_deg, run.outputs);
    CHECK(run.outputs == 250);
    CHECK(run.started == 1 && run.ended == 1);
    CHECK(fabsf(run.movement.angle_deg - 90.0f) < 0.05f);
    CHECK(fabsf(run.movement.raw_angle_deg - 90.0f) < 0.05f);
    CHECK(run.movement.has_angle_std);
    CHECK(run.movement.angle_std_deg > 0.0f && run.movement.angle_std_deg < 1.0f);
    CHECK(run.movement.start_time_s > 0.9 && run.movement.start_time_s < 1.1);
    CHECK(run.movement.end_time_s > 1.9 && run.movement.end_time_s < 2.1);
    CHECK(run.movement.end_index > run.movement.start_index);
    CHECK(!run.movement.saturated && !run.movement.rejected_samples);
    CHECK(run.movement.verdict == GYRO_VERDICT_OK);
    CHECK(run.last.motion == GYRO_MOTION_STATIC);
    CHECK(run.last.has_angle_std && fabsf(run.last.angle_deg - 90.0f) < 0.05f);
    CHECK(fabsf(run.last.bias_dps) < 0.01f);

    GyroPipelineInfo info;
    CHECK_STATUS(gyro_pipeline_info(pipeline, &info), GYRO_STATUS_OK);
    CHECK(info.outputs == 250 && info.rejected_samples == 0 && info.finite);
    CHECK(info.output_period_s == 0.02f);
    CHECK(info.filter_delay_s > 0.0 && info.filter_delay_s < 0.1);
    CHECK(!info.movement_saturated && !info.range_contradicted);

    /* With the temperature (and the identity correction): the same, bit for bit. */
    pipeline = setup(&config);
    Run warm = turn(pipeline, 90.0f, -1, 1);
    CHECK(memcmp(&warm.movement.angle_deg, &run.movement.angle_deg, sizeof(float)) == 0);
    CHECK(memcmp(&warm.movement.angle_std_deg, &run.movement.angle_std_deg, sizeof(float)) == 0);
    CHECK(warm.movement.end_time_s == run.movement.end_time_s);

    /* Paper compensation: no σ. */
    config.compensation = GYRO_COMPENSATION_PAPER;
    pipeline = setup(&config);
    Run paper = turn(pipeline, 90.0f, -1, 0);
    CHECK(paper.ended == 1 && !paper.movement.has_angle_std && isnan(paper.movement.angle_std_deg));
    CHECK(paper.movement.verdict == GYRO_VERDICT_OK);
}

/* The verdicts: a short turn is NOK, a turn the other way none, saturation and a
 * rejected sample make it invalid. */
static void verdicts(void) {
    GyroConfig config;
    gyro_config_default(&config);
    config.tightening.enabled = 1;
    config.tightening.target_deg = 90.0f;
    config.tightening.tolerance_deg = 5.0f;

    Run run = turn(setup(&config), 80.0f, -1, 0);
    CHECK(run.ended == 1 && run.movement.verdict == GYRO_VERDICT_NOK);
    run = turn(setup(&config), 94.97f, -1, 0); /* within 2 sigma (about 0.06 deg) of the limit */
    CHECK(run.ended == 1 && run.movement.verdict == GYRO_VERDICT_RECHECK);
    run = turn(setup(&config), -90.0f, -1, 0);
    CHECK(run.ended == 1 && run.movement.verdict == GYRO_VERDICT_NONE);
    config.tightening.direction = GYRO_DIRECTION_NEGATIVE;
    run = turn(setup(&config), -90.0f, -1, 0);
    CHECK(run.ended == 1 && run.movement.verdict == GYRO_VERDICT_OK);
    config.tightening.direction = GYRO_DIRECTION_POSITIVE;

    /* The turn peaks at 180 deg/s, the full scale of a ±180 deg/s sensor: saturated. */
    config.has_range_dps = 1;
    config.range_dps = 180.0f;
    run = turn(setup(&config), 90.0f, -1, 0);
    CHECK(run.ended == 1 && run.movement.saturated);
    CHECK(run.movement.verdict == GYRO_VERDICT_INVALID);
    /* Told ±150 deg/s, the readings go beyond it: not that sensor's range, and without a
     * clip plateau the turn is not flagged. */
    config.range_dps = 150.0f;
    GyroPipeline *told = setup(&config);
    run = turn(told, 90.0f, -1, 0);
    CHECK(run.ended == 1 && !run.movement.saturated);
    CHECK(run.movement.verdict == GYRO_VERDICT_OK);
    GyroPipelineInfo told_info;
    CHECK_STATUS(gyro_pipeline_info(told, &told_info), GYRO_STATUS_OK);
    CHECK(told_info.range_contradicted);
    config.has_range_dps = 0;

    /* A NaN in the middle of the turn: taken as the last rate, counted, judged invalid. */
    GyroPipeline *pipeline = setup(&config);
    run = turn(pipeline, 90.0f, 1500, 0);
    CHECK(run.ended == 1 && run.movement.rejected_samples && !run.movement.saturated);
    CHECK(run.movement.verdict == GYRO_VERDICT_INVALID);
    CHECK(fabsf(run.movement.angle_deg - 90.0f) < 0.5f);
    GyroPipelineInfo info;
    CHECK_STATUS(gyro_pipeline_info(pipeline, &info), GYRO_STATUS_OK);
    CHECK(info.rejected_samples == 1);

    /* A NaN long before the turn does not touch its verdict. */
    run = turn(setup(&config), 90.0f, 100, 0);
    CHECK(run.ended == 1 && !run.movement.rejected_samples);
    CHECK(run.movement.verdict == GYRO_VERDICT_OK);

    /* No window: no verdict. */
    config.tightening.enabled = 0;
    run = turn(setup(&config), 90.0f, -1, 0);
    CHECK(run.ended == 1 && run.movement.verdict == GYRO_VERDICT_NONE);
}

int main(void) {
    default_config();
    invalid_configs();
    bad_pointers();
    synthetic_turn();
    verdicts();
    printf("%d passed, %d failed\n", passed, failed);
    return failed == 0 && passed > 0 ? 0 : 1;
}
