/*
 * Example C firmware: CRM100 rate words -> gyro-core through its C API (gyro.h,
 * libgyro_ffi.a), the way a wrench written in C wires them.
 *
 * Built with arm-none-eabi-gcc for a Cortex-M4F (no C library: startup.c has the vector
 * table, the reset handler and semihosting), it boots on QEMU's mps2-an386 board. There is
 * no gyroscope on that board, so the samples are the rate words of the first 20 s of
 * fixtures/logs/bench_run.csv (three 90 degree turns: +, -, +), linked in by fixture.S;
 * everything after the rate word is what a wrench runs: the scaling by the range (what the
 * CRM100 driver does), then gyro_pipeline_push_with_temperature and the movement events with
 * their tightening verdicts. Results go to the host console over semihosting, and the exit
 * status says whether the run was clean. run-qemu.sh checks the figures against
 * `gyro-cli run` on the host: they must be the same floats, bit for bit.
 *
 * Figures are printed as their IEEE 754 bits in hex (0x + 8 digits for a float, 16 for a
 * double), which is exact and needs no floating-point formatting; each movement also gets
 * a line with rounded decimals for people.
 */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "gyro.h"
#include "semihosting.h"

/* The recorded rate words (fixture.S). */
extern const uint8_t rate_words[];
extern const uint8_t rate_words_end[];

/* The range the recording was made in: ±300 deg/s, 24 counts per deg/s; a word beyond
 * ±7200 counts is beyond full scale (the sensor saturated). */
#define RANGE_DPS 300
#define LSB_PER_DPS 24
#define FULL_SCALE_COUNTS 7200

/* The sensor's temperature: a wrench reads it from the same frame as the rate. */
#define TEMPERATURE_C 25.0f

/* The tightening window every movement is judged against (run-qemu.sh gives gyro-cli the
 * same: --target-deg 90 --tolerance-deg 0.25). */
#define TARGET_DEG 90.0f
#define TOLERANCE_DEG 0.25f

/* ---- text output without a C library ---------------------------------------------- */

typedef struct {
    char text[256];
    size_t len;
} Line;

static void put(Line *line, const char *text) {
    while (*text != '\0' && line->len + 1 < sizeof line->text) {
        line->text[line->len++] = *text++;
    }
    line->text[line->len] = '\0';
}

static void put_u32(Line *line, uint32_t value) {
    char digits[11];
    size_t n = 0;
    do {
        digits[n++] = (char)('0' + value % 10u);
        value /= 10u;
    } while (value != 0u);
    char text[12];
    for (size_t i = 0; i < n; i++) {
        text[i] = digits[n - 1 - i];
    }
    text[n] = '\0';
    put(line, text);
}

static void put_hex(Line *line, uint64_t bits, int digits) {
    static const char hex[] = "0123456789abcdef";
    char text[19] = "0x";
    for (int i = 0; i < digits; i++) {
        text[2 + i] = hex[(bits >> (4 * (digits - 1 - i))) & 0xFu];
    }
    text[2 + digits] = '\0';
    put(line, text);
}

static void put_f32_bits(Line *line, float value) {
    union { float f; uint32_t u; } bits = { .f = value };
    put_hex(line, bits.u, 8);
}

static void put_f64_bits(Line *line, double value) {
    union { double d; uint64_t u; } bits = { .d = value };
    put_hex(line, bits.u, 16);
}

/* `value` rounded to 3 decimals, for people (|value| below 2e6). */
static void put_decimal(Line *line, float value) {
    if (value != value) {
        put(line, "nan");
        return;
    }
    if (value < 0.0f) {
        put(line, "-");
        value = -value;
    }
    uint32_t milli = (uint32_t)(value * 1000.0f + 0.5f);
    put_u32(line, milli / 1000u);
    put(line, ".");
    char frac[4] = { (char)('0' + milli / 100u % 10u), (char)('0' + milli / 10u % 10u),
                     (char)('0' + milli % 10u), '\0' };
    put(line, frac);
}

static void print(Line *line) {
    put(line, "\n");
    semihosting_write(line->text);
    line->len = 0;
    line->text[0] = '\0';
}

static const char *verdict_name(GyroVerdict verdict) {
    switch (verdict) {
    case GYRO_VERDICT_OK:
        return "ok";
    case GYRO_VERDICT_NOK:
        return "nok";
    case GYRO_VERDICT_RECHECK:
        return "recheck";
    case GYRO_VERDICT_INVALID:
        return "invalid";
    default:
        return "none";
    }
}

/* ---- the pipelines ----------------------------------------------------------------- */

/* One pipeline and what we report about it. */
typedef struct {
    const char *name;
    uint8_t compensation;
    GyroPipeline *pipeline;
    uint32_t outputs;
    uint32_t movements;
    GyroOutput last;
    bool failed;
} Channel;

/* The pipelines' state: storage this program owns (no heap). */
static _Alignas(GYRO_PIPELINE_ALIGN) uint8_t storage[2][GYRO_PIPELINE_SIZE];

/* Both compensations run side by side, so the host check covers both; a wrench runs one. */
static Channel channels[2] = {
    { .name = "paper", .compensation = GYRO_COMPENSATION_PAPER },
    { .name = "kalman", .compensation = GYRO_COMPENSATION_KALMAN },
};

static bool setup(Channel *channel, uint8_t *state, size_t state_size) {
    GyroConfig config;
    gyro_config_default(&config); /* 1 kHz in, 50 Hz out; on the wrench: the calibrated model */
    config.compensation = channel->compensation;
    config.has_range_dps = 1; /* a movement whose readings reach the range is flagged */
    config.range_dps = (float)RANGE_DPS;
    config.tightening.enabled = 1;
    config.tightening.target_deg = TARGET_DEG;
    config.tightening.tolerance_deg = TOLERANCE_DEG;

    GyroField field = GYRO_FIELD_NONE;
    GyroStatus status =
        gyro_pipeline_init(state, state_size, &config, &channel->pipeline, &field);
    if (status != GYRO_STATUS_OK) {
        Line line = { .len = 0 };
        put(&line, "error: pipeline configuration: ");
        put(&line, gyro_status_name(status));
        put(&line, " (setting ");
        put(&line, gyro_field_name(field));
        put(&line, ")");
        print(&line);
        return false;
    }
    return true;
}

/* Feeds one sample; prints movement events as they are confirmed. */
static void push(Channel *channel, double time_s, float rate_dps) {
    GyroOutput out;
    GyroStatus status = gyro_pipeline_push_with_temperature(channel->pipeline, time_s, rate_dps,
                                                            TEMPERATURE_C, &out);
    if (status == GYRO_STATUS_OK) {
        return; /* no output this sample: 19 of 20 */
    }
    if (status != GYRO_STATUS_OUTPUT) {
        if (!channel->failed) {
            Line line = { .len = 0 };
            put(&line, "error: push: ");
            put(&line, gyro_status_name(status));
            print(&line);
        }
        channel->failed = true;
        return;
    }
    channel->outputs++;
    channel->last = out;
    Line line = { .len = 0 };
    if (out.event == GYRO_EVENT_STARTED) {
        /* Confirmed 60 ms or so after it began; the start is back-dated. */
        put(&line, "started  compensation=");
        put(&line, channel->name);
        put(&line, " index=");
        put_u32(&line, channel->movements + 1);
        put(&line, " start_time_s=");
        put_f64_bits(&line, out.movement.start_time_s);
        put(&line, " confirmed_at_s=");
        put_f64_bits(&line, out.time_s);
        print(&line);
    } else if (out.event == GYRO_EVENT_ENDED) {
        /* On the wrench: this is where the turned angle and its verdict go to the
         * tightening logic. */
        const GyroMovement *m = &out.movement;
        channel->movements++;
        put(&line, "movement compensation=");
        put(&line, channel->name);
        put(&line, " index=");
        put_u32(&line, channel->movements);
        put(&line, " start_time_s=");
        put_f64_bits(&line, m->start_time_s);
        put(&line, " end_time_s=");
        put_f64_bits(&line, m->end_time_s);
        put(&line, " angle_deg=");
        put_f32_bits(&line, m->angle_deg);
        put(&line, " raw_angle_deg=");
        put_f32_bits(&line, m->raw_angle_deg);
        put(&line, " angle_std_deg=");
        if (m->has_angle_std) {
            put_f32_bits(&line, m->angle_std_deg);
        } else {
            put(&line, "none");
        }
        put(&line, " saturated=");
        put_u32(&line, m->saturated ? 1u : 0u);
        put(&line, " verdict=");
        put(&line, verdict_name(m->verdict));
        print(&line);

        put(&line, "         ");
        put(&line, channel->name);
        put(&line, " movement ");
        put_u32(&line, channel->movements);
        put(&line, ": ");
        put_decimal(&line, m->angle_deg);
        put(&line, " deg");
        if (m->has_angle_std) {
            put(&line, " +/- ");
            put_decimal(&line, m->angle_std_deg);
        }
        put(&line, " (uncompensated ");
        put_decimal(&line, m->raw_angle_deg);
        put(&line, "), ");
        put(&line, verdict_name(m->verdict));
        if (m->saturated) {
            put(&line, ", SATURATED");
        }
        print(&line);
    }
}

/* Prints the summary line; true if the pipeline ran clean. */
static bool report(const Channel *channel, uint32_t samples) {
    GyroPipelineInfo info;
    GyroStatus status = gyro_pipeline_info(channel->pipeline, &info);
    Line line = { .len = 0 };
    if (status != GYRO_STATUS_OK) {
        put(&line, "error: info: ");
        put(&line, gyro_status_name(status));
        print(&line);
        return false;
    }
    put(&line, "summary  compensation=");
    put(&line, channel->name);
    put(&line, " samples=");
    put_u32(&line, samples);
    put(&line, " outputs=");
    put_u32(&line, channel->outputs);
    put(&line, " rejected_samples=");
    put_u32(&line, info.rejected_samples);
    put(&line, " movements=");
    put_u32(&line, channel->movements);
    put(&line, " final_angle_deg=");
    put_f32_bits(&line, channel->last.angle_deg);
    put(&line, " final_raw_angle_deg=");
    put_f32_bits(&line, channel->last.raw_angle_deg);
    put(&line, " finite=");
    put(&line, info.finite ? "true" : "false");
    print(&line);
    return !channel->failed && info.rejected_samples == 0 && info.finite &&
           info.outputs == channel->outputs && channel->movements > 0;
}

int main(void) {
    Line line = { .len = 0 };
    bool clean = true;
    for (size_t i = 0; i < 2; i++) {
        clean &= setup(&channels[i], storage[i], sizeof storage[i]);
    }
    if (!clean) {
        return 1;
    }
    uint32_t samples = (uint32_t)(rate_words_end - rate_words) / 2u;
    put(&line, "gyro C firmware example: CRM100 (+/-");
    put_u32(&line, RANGE_DPS);
    put(&line, " deg/s, playback of ");
    put_u32(&line, samples);
    put(&line, " samples) -> gyro-ffi at 1000 Hz in, 50 Hz out; pipeline state ");
    put_u32(&line, GYRO_PIPELINE_SIZE);
    put(&line, " bytes");
    print(&line);

    uint32_t beyond_full_scale = 0;
    for (uint32_t n = 0; n < samples; n++) {
        /* One iteration per sample clock tick. On the wrench a timer fires at 1 kHz and this
         * body runs in its interrupt handler: read the frame, scale, push. Here it runs flat
         * out. Time is the sample count over the nominal rate, as the host grid uses. */
        double time_s = (double)n / 1000.0;
        int16_t counts = (int16_t)((uint16_t)(rate_words[2 * n] << 8) | rate_words[2 * n + 1]);
        float rate_dps;
        if (counts > FULL_SCALE_COUNTS || counts < -FULL_SCALE_COUNTS) {
            /* Beyond full scale: the reading is the range (a lower bound of the rate),
             * which flags the movement saturated. */
            beyond_full_scale++;
            rate_dps = counts < 0 ? -(float)RANGE_DPS : (float)RANGE_DPS;
        } else {
            /* What the CRM100 driver computes: counts / 24, correctly rounded to float. */
            rate_dps = (float)counts / (float)LSB_PER_DPS;
        }
        for (size_t i = 0; i < 2; i++) {
            push(&channels[i], time_s, rate_dps);
        }
    }

    put(&line, "sensor   samples=");
    put_u32(&line, samples);
    put(&line, " beyond_full_scale=");
    put_u32(&line, beyond_full_scale);
    print(&line);
    for (size_t i = 0; i < 2; i++) {
        clean &= report(&channels[i], samples);
    }
    put(&line, "result   ");
    put(&line, clean ? "ok" : "FAILED");
    print(&line);
    return clean ? 0 : 1;
}
