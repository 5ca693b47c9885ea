#!/usr/bin/env bash
# The project's bad-input corpus: ~210 bad inputs and mistaken arguments across all eight
# gyro-cli commands, each run with a timeout and classified (see docs/bad-input-corpus.md):
#   clean          non-zero exit with exactly one `error:` line (naming what it must), or
#                  a documented success
#   panic          exit 101 or "panicked" on stderr
#   hang           killed by the timeout
#   crash          killed by another signal
#   silent-accept  exit 0 where the input must be refused
#   rejected       non-zero exit on an input that is valid
#   unhelpful      refused, but not with one `error:` line naming the file/line/option
#   clobber        an input file changed
#   leftover       a refused command left an output file behind
#
# Usage: scripts/bad_input_corpus.sh [TABLE.md]     (default: docs/bad-input-corpus.md)
# The binary is $GYRO_CLI, else target/release/gyro-cli (built if missing).
# Exits 1 if any case is not clean.
set -uo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
TABLE=${1:-docs/bad-input-corpus.md}
TIMEOUT=${CORPUS_TIMEOUT_S:-20}
if [[ -z ${GYRO_CLI:-} ]]; then
    cargo build --release -q -p gyro-cli
    GYRO_CLI=$ROOT/target/release/gyro-cli
fi
G=$(cd "$(dirname "$GYRO_CLI")" && pwd)/$(basename "$GYRO_CLI")
export G
[[ -x $G ]] || { echo "no gyro-cli binary at $G" >&2; exit 2; }
W=$(mktemp -d "${TMPDIR:-/tmp}/gyro-corpus.XXXXXX")
trap 'rm -rf "$W"' EXIT
mkdir -p "$W/in" "$W/out"
cd "$W"

# ---------------------------------------------------------------------------------------
# Inputs (all small, all made here from the fixtures)
BENCH=$ROOT/fixtures/logs/bench_run.csv
head -n 10004 "$BENCH" >in/good.csv # 10 s at 1 kHz, two turns, reference and temperature
cp in/good.csv in/ängle.csv
{ head -n 4 "$BENCH"; tail -n 10000 "$BENCH"; } >in/other.csv # another 10 s of the bench run
"$G" convert in/good.csv in/good.mcap 2>/dev/null
cp "$ROOT/fixtures/mcap/ros2_imu.mcap" in/ros2.mcap
cp "$ROOT/fixtures/mcap/ros2_two_imus.mcap" in/two_imus.mcap
data() { tail -n +5 in/good.csv | head -n "$1"; } # data rows of good.csv
hdr='time_s,rate_dps,temperature_c,reference_deg'

: >in/empty.csv
: >in/empty.mcap
echo "$hdr" >in/header_only.csv
data 50 >in/no_header.csv
{ echo 'time_s,foo'; data 50 | cut -d, -f1,2; } >in/no_rate_column.csv
{ echo 'foo,rate_dps'; data 50 | cut -d, -f1,2; } >in/no_time_column.csv
{ echo 'time_s,rate_dps,rate_dps'; data 50 | cut -d, -f1,2,2; } >in/two_rate_columns.csv
{ echo "$hdr"; data 100; echo '0.100000,abc,25.0,0.0'; data 200 | tail -n 100; } >in/not_a_number.csv
{ echo "$hdr"; data 100; echo '0.100000,0.1'; } >in/short_row.csv
{ echo "$hdr"; data 100; echo '0.100000,0.1,25,0,7,7'; } >in/long_row.csv
{ echo "$hdr"; data 100; echo 'nan,0.1,25,0'; } >in/nan_time.csv
{ echo "$hdr"; data 100; echo 'inf,0.1,25,0'; } >in/inf_time.csv
{ echo "$hdr"; data 100; echo '1e300,0.1,25,0'; } >in/huge_time.csv
{ echo "$hdr"; data 3000; data 100; } >in/time_backwards.csv
{ echo "$hdr"; data 100; data 3000 | tail -n 100; } >in/long_gap.csv
{ echo "$hdr"; data 3000 | awk -F, -v OFS=, '{$2=""; print}'; } >in/no_rates.csv
{ echo "$hdr"; data 3000 | awk -F, -v OFS=, '{$2="1e300"; print}'; } >in/rates_1e300.csv
{ echo "$hdr"; data 1; } >in/one_row.csv
{ echo "$hdr"; data 3000 | awk -F, -v OFS=, '{$1=$1*1e6+1.7e15; print}'; } >in/epoch_us_as_s.csv
{ echo "$hdr"; data 3000 | awk -F, -v OFS=, '{$1=$1*1000; print}'; } >in/ms_as_s.csv
{ echo '# sample_rate_hz: -1000'; echo "$hdr"; data 3000; } >in/meta_rate_negative.csv
{ echo '# sample_rate_hz: 0'; echo "$hdr"; data 3000; } >in/meta_rate_zero.csv
{ echo '# sample_rate_hz: NaN'; echo "$hdr"; data 3000; } >in/meta_rate_nan.csv
{ echo '# sample_rate_hz: fast'; echo "$hdr"; data 3000; } >in/meta_rate_word.csv
{ echo '# sample_rate_hz: 1000 Hz'; echo "$hdr"; data 3000; } >in/meta_rate_unit.csv
{ echo '# sample_rate_hz: 1000'; echo '# sample_rate_hz: 500'; echo "$hdr"; data 3000; } >in/meta_rate_twice.csv
{ echo '# sample_rate_hz: 100'; echo "$hdr"; data 3000; } >in/meta_rate_wrong.csv
{ echo '# sample_rate_hz: 1e9'; echo "$hdr"; data 3000; } >in/meta_rate_1e9.csv
{ printf '# operator: Jos\xe9\n'; echo "$hdr"; data 3000; } >in/latin1_comment.csv
{ printf '\xef\xbb\xbf'; echo "$hdr"; data 3000; } >in/bom.csv
{ echo "$hdr"; data 3000 | sed 's/$/\r/'; } >in/crlf.csv
{ echo "$hdr"; data 100; } | tr ',' '\t' >in/tab_separated.csv
{ echo "$hdr"; data 100; } | sed 's/,/;/g; s/\./,/g' >in/semicolon_separated.csv
iconv -f UTF-8 -t UTF-16 in/good.csv >in/utf16.csv 2>/dev/null || printf '\xff\xfet\x00i\x00' >in/utf16.csv
dd if="$ROOT/fixtures/mcap/ros2_imu.mcap" bs=1 skip=3000 count=4096 status=none >in/binary.csv
head -c 4096 /dev/zero >in/nul_bytes.csv
{ echo "$hdr"; data 100; head -c 1000000 /dev/zero | tr '\0' '7'; echo; } >in/million_char_line.csv
{ echo "$hdr"; data 3000 | awk '{print; if (NR % 100 == 0) print}'; } >in/duplicate_rows.csv
{ echo 'time_s,rate_dps'; data 3000 | cut -d, -f1,2; } >in/no_reference.csv
cp in/good.csv in/good.mcap.csv
cp in/good.csv in/csv_named.mcap
size=$(stat -c %s in/good.mcap)
head -c $((size / 2)) in/good.mcap >in/truncated.mcap
cp in/good.mcap in/corrupt.mcap
printf 'XXXXXXXXXXXXXXXX' | dd of=in/corrupt.mcap bs=1 seek=$((size * 3 / 10)) conv=notrunc status=none
# The same bytes at 60% land in a message index, which the reader does not need (it
# walks the records and reads the chunks, whose CRCs hold): the data are intact.
cp in/good.mcap in/corrupt_index.mcap
printf 'XXXXXXXXXXXXXXXX' | dd of=in/corrupt_index.mcap bs=1 seek=$((size * 6 / 10)) conv=notrunc status=none
{ printf 'NOTMCAP!'; tail -c +9 in/good.mcap; } >in/bad_magic.mcap
head -c 20 in/good.mcap >in/header_only.mcap
# Absurd values (issue 46's classes): a stamp of 1e300 s mid-file, every stamp 0, a field
# of a million digits, a rate too large for a double, inf and nan rates (missing values by
# the contract: counted and named), two data rows.
{ echo "$hdr"; data 3000; echo '1e300,0.1,25,0'; data 6000 | tail -n 3000; } >in/huge_time_mid.csv
{ echo '# sample_rate_hz: 1000'; echo "$hdr"; data 3000 | awk -F, -v OFS=, '{$1=0; print}'; } >in/all_stamps_zero.csv
{ echo '# sample_rate_hz: 1000'; echo "$hdr"; data 3000 | tac; } >in/reverse_order.csv
{ echo "$hdr"; data 1500; printf '1.500000,1'; head -c 1000000 /dev/zero | tr '\0' '0'; echo ',25,0'; data 3000 | tail -n 1499; } >in/million_digit_field.csv
{ echo "$hdr"; data 3000 | awk -F, -v OFS=, 'NR==1500{$2="1e400"} {print}'; } >in/rate_1e400.csv
{ echo "$hdr"; data 10004 | awk -F, -v OFS=, 'NR%7==0{$2="inf"} NR%11==0{$2="nan"} {print}'; } >in/inf_nan_rates.csv
{ echo "$hdr"; data 2; } >in/two_rows.csv
# MCAP files whose messages run backwards in time, or sit at one log time (made from
# reversed and constant-stamp CSVs before the writer refused them).
cp "$ROOT/fixtures/mcap/reverse_time.mcap" in/reverse_time.mcap
cp "$ROOT/fixtures/mcap/one_log_time.mcap" in/one_log_time.mcap
echo '{"format": "gyro-model", "version": 1}' >in/model.json
printf '\xef\xbb\xbf{"format": "gyro-model", "version": 1}\n' >in/model_bom.json
echo '{"format": "gyro-model", "version": 2}' >in/model_v2.json
echo '{"format": "gyro-model", "version": 1, "config": {"sample_rate_hz": -5}}' >in/model_bad_setting.json
echo '{"format": "gyro-model", "version": 1, "colour": "red"}' >in/model_unknown_key.json
echo '{"format": "gyro-model", "version": 1, "config": {' >in/model_truncated.json
echo '{"format": "gyro-model", "version": 1, "reference_delay_s": 5}' >in/model_delay.json
echo '{"format": "gyro-model", "version": 1, "scale_sigma": -0.1}' >in/model_scale_sigma.json
: >in/model_empty.json
iconv -f UTF-8 -t UTF-16 in/model.json >in/model_utf16.json 2>/dev/null || cp in/binary.csv in/model_utf16.json
mkdir -p in/a_directory
ln -s good.csv in/link_to_good.csv
ln in/good.csv in/hardlink_to_good.csv
echo 'placeholder' >in/existing_recording.mcap
# Outputs that exist already (kept unless --force; the inputs' checksum sees any change)
mkdir -p in/existing/report
for f in out.csv plot.svg model.json psd.csv imu.yaml faults.json copy.mcap report/index.html; do
    echo 'an earlier output' >"in/existing/$f"
done

# ---------------------------------------------------------------------------------------
# Cases: `c NAME EXPECT NEEDLE COMMAND`. EXPECT: refuse (one `error:` line containing
# NEEDLE), late (the same, after a complete output file was written), ok (exit 0), quiet
# (non-zero exit, stderr unusable: no panic). COMMAND runs in
# bash from the work folder with $G the binary; outputs go to out/.
declare -a NAMES EXPECTS NEEDLES CMDS
c() { NAMES+=("$1"); EXPECTS+=("$2"); NEEDLES+=("$3"); CMDS+=("$4"); }

# Every command that reads a log, on every bad log
for f in empty header_only no_header no_rate_column no_time_column two_rate_columns \
    not_a_number short_row long_row nan_time inf_time huge_time time_backwards long_gap \
    no_rates one_row meta_rate_negative meta_rate_zero meta_rate_nan meta_rate_word \
    meta_rate_unit meta_rate_twice meta_rate_wrong meta_rate_1e9 utf16 binary nul_bytes \
    million_char_line tab_separated semicolon_separated; do
    c "run $f.csv" refuse "$f.csv" "\$G run in/$f.csv"
done
for f in empty no_rate_column not_a_number meta_rate_wrong utf16 binary rates_1e300; do
    c "noise $f.csv" refuse "$f.csv" "\$G noise in/$f.csv"
done
for f in empty not_a_number time_backwards utf16 no_reference; do
    c "calibrate $f.csv" refuse "$f.csv" "\$G calibrate in/$f.csv -o out/m.json"
done
for f in empty no_rate_column meta_rate_nan binary no_reference; do
    c "diagnose --train $f.csv" refuse "$f.csv" "\$G diagnose --train in/$f.csv --holdout in/other.csv"
done
for f in empty nan_time utf16 no_reference epoch_us_as_s; do
    c "simulate --motion-from $f.csv" refuse "$f.csv" "\$G simulate --motion-from in/$f.csv -o out/s.csv"
done
for f in empty not_a_number utf16 nul_bytes time_backwards; do
    c "convert $f.csv" refuse "$f.csv" "\$G convert in/$f.csv out/c.mcap"
done
c "run ms_as_s.csv (stamps in ms read as s)" refuse "--time-unit ms" "\$G run in/ms_as_s.csv"
for f in empty utf16 not_a_number; do
    c "emulate --log $f.csv" refuse "$f.csv" "\$G emulate --log in/$f.csv --port out/nowhere"
done

# Absurd values: refused naming the file (and the line), or said
for f in huge_time_mid all_stamps_zero reverse_order million_digit_field rate_1e400; do
    c "run $f.csv" refuse "$f.csv" "\$G run in/$f.csv"
    c "noise $f.csv" refuse "$f.csv" "\$G noise in/$f.csv"
    c "convert $f.csv" refuse "$f.csv" "\$G convert in/$f.csv out/c.mcap"
done
for f in million_digit_field rate_1e400 all_stamps_zero; do
    c "calibrate $f.csv" refuse "$f.csv" "\$G calibrate in/$f.csv -o out/m.json"
    c "diagnose --train $f.csv" refuse "$f.csv" "\$G diagnose --train in/$f.csv in/good.csv --holdout in/other.csv"
    c "simulate --motion-from $f.csv" refuse "$f.csv" "\$G simulate --motion-from in/$f.csv -o out/s.csv"
done
for f in reverse_time one_log_time; do
    c "run $f.mcap" refuse "$f.mcap" "\$G run in/$f.mcap"
    c "noise $f.mcap" refuse "$f.mcap" "\$G noise in/$f.mcap"
    c "convert $f.mcap" refuse "$f.mcap" "\$G convert in/$f.mcap out/c.csv"
done
c "run inf_nan_rates.csv (missing values: counted, lines named)" ok "" "\$G run in/inf_nan_rates.csv | grep -q 'missing rates, .* interpolated'"
c "noise inf_nan_rates.csv (interpolated samples said)" ok "" "\$G noise in/inf_nan_rates.csv | grep -q 'samples interpolated'"
c "simulate --motion-from inf_nan_rates.csv (said)" ok "" "\$G simulate --motion-from in/inf_nan_rates.csv -o out/s.csv 2>&1 | grep -q 'missing rates'"
c "run two_rows.csv (short_log said)" ok "" "\$G run in/two_rows.csv --format json | grep -q short_log"
c "simulate --motion-from two_rows.csv (said)" ok "" "\$G simulate --motion-from in/two_rows.csv -o out/s.csv 2>&1 | grep -q 'under 1 s'"
for f in one_row two_rows; do
    c "noise $f.csv" refuse "$f.csv" "\$G noise in/$f.csv"
    c "calibrate $f.csv" refuse "" "\$G calibrate in/$f.csv -o out/m.json"
done
c "diagnose --train one_row.csv" refuse "one_row.csv" "\$G diagnose --train in/one_row.csv in/good.csv --holdout in/other.csv"
c "simulate --motion-from one_row.csv" refuse "one_row.csv" "\$G simulate --motion-from in/one_row.csv -o out/s.csv"

# MCAP damage
for f in empty corrupt bad_magic header_only csv_named; do
    c "run $f.mcap" refuse "$f.mcap" "\$G run in/$f.mcap"
    c "convert $f.mcap" refuse "$f.mcap" "\$G convert in/$f.mcap out/c.csv"
done
c "run truncated.mcap (read up to the cut, warned)" ok "" "\$G run in/truncated.mcap"
c "run corrupt_index.mcap (damage outside the data)" ok "" "\$G run in/corrupt_index.mcap"
c "run two_imus.mcap (two rate channels)" refuse "--topic" "\$G run in/two_imus.mcap"
c "run ros2.mcap --topic /nope" refuse "/nope" "\$G run in/ros2.mcap --topic /nope"
c "noise corrupt.mcap" refuse "corrupt.mcap" "\$G noise in/corrupt.mcap"

# Valid inputs that must be accepted
c "run latin1_comment.csv" ok "" "\$G run in/latin1_comment.csv"
c "run bom.csv" ok "" "\$G run in/bom.csv"
c "run crlf.csv" ok "" "\$G run in/crlf.csv"
c "run duplicate_rows.csv" ok "" "\$G run in/duplicate_rows.csv"
c "run ängle.csv (non-ASCII path)" ok "" "\$G run in/ängle.csv"
c "run good.mcap" ok "" "\$G run in/good.mcap"
c "run ros2.mcap" ok "" "\$G run in/ros2.mcap"
c "run good.mcap.csv (CSV by extension)" ok "" "\$G run in/good.mcap.csv"
c "run --model model_bom.json" ok "" "\$G run in/good.csv --model in/model_bom.json"
c "convert good.csv → ängle.mcap" ok "" "\$G convert in/good.csv out/ängle.mcap"
c "simulate -o s.mcap" ok "" "\$G simulate --duration-s 5 -o out/s.mcap && head -c 5 out/s.mcap | grep -q MCAP"
c "simulate --static -o s.mcap --compression none" ok "" "\$G simulate --static --duration-s 5 -o out/s.mcap --compression none && head -c 5 out/s.mcap | grep -q MCAP"
for z in zstd lz4 none; do
    c "convert good.csv → c.mcap --compression $z, read back" ok "" "\$G convert in/good.csv out/c.mcap --compression $z && \$G run out/c.mcap >/dev/null"
done
c "convert --to mcap c.x --compression lz4" ok "" "\$G convert in/good.csv out/c.x --to mcap --compression lz4 && head -c 5 out/c.x | grep -q MCAP"
c "simulate --list-effects | true" ok "" "\$G simulate --list-effects | true; exit \${PIPESTATUS[0]}"
c "run | head -c1 (closed pipe)" ok "" "\$G run in/good.csv | head -c1 >/dev/null; exit \${PIPESTATUS[0]}"
c "noise --format json | head -c1" ok "" "\$G noise in/good.csv --format json | head -c1 >/dev/null; exit \${PIPESTATUS[0]}"

# Files that are not files
c "run missing.csv" refuse "missing.csv" "\$G run in/missing.csv"
c "run a directory" refuse "a_directory" "\$G run in/a_directory"
c "noise missing.mcap" refuse "missing.mcap" "\$G noise in/missing.mcap"
c "run --model missing.json" refuse "missing.json" "\$G run in/good.csv --model in/missing.json"

# Outputs that are directories: one line naming the path
D=in/a_directory
c "run --out a directory" refuse "a_directory: is a directory" "\$G run in/good.csv --out $D"
c "run --out a directory --force" refuse "a_directory: is a directory" "\$G run in/good.csv --out $D --force"
c "calibrate -o a directory" refuse "a_directory: is a directory" "\$G calibrate in/good.csv -o $D"
c "noise --psd-out a directory" refuse "a_directory: is a directory" "\$G noise in/good.csv --psd-out $D"
c "noise --model-out a directory" refuse "a_directory: is a directory" "\$G noise in/good.csv --model-out $D"
c "noise --noise-yaml a directory" refuse "a_directory: is a directory" "\$G noise in/good.csv --noise-yaml $D"
c "diagnose -o a directory" refuse "a_directory: is a directory" "\$G diagnose --train in/good.csv --holdout in/other.csv -o $D"
c "simulate -o a directory" refuse "a_directory: is a directory" "\$G simulate --duration-s 2 -o $D"
c "convert to a directory" refuse "a_directory: is a directory" "\$G convert in/good.csv $D"
c "emulate --fault-log a directory" refuse "a_directory: is a directory" "\$G emulate --port out/nowhere --fault-log $D"
c "record -o a directory" refuse "a_directory: is a directory" "\$G record --port /dev/null -o $D"

# Model files
for f in model_v2 model_bad_setting model_unknown_key model_truncated model_delay model_scale_sigma model_empty model_utf16; do
    c "run --model $f.json" refuse "$f.json" "\$G run in/good.csv --model in/$f.json"
done
c "simulate --model model_truncated.json" refuse "model_truncated.json" "\$G simulate --model in/model_truncated.json -o out/s.csv"
c "noise --model model_v2.json" refuse "model_v2.json" "\$G noise in/good.csv --model in/model_v2.json"

# Numeric options
for v in -1 0 nan inf 1e400 abc; do
    c "run --sample-rate-hz $v" refuse "--sample-rate-hz" "\$G run in/good.csv --sample-rate-hz=$v"
done
for v in -1 nan inf; do
    c "run --max-gap-s $v" refuse "--max-gap-s" "\$G run in/good.csv --max-gap-s=$v"
done
# A negative number after a flag, with a space: the value, judged by its parser
c "run --sample-rate-hz -1000" refuse "expected a positive" "\$G run in/good.csv --sample-rate-hz -1000"
c "run --max-gap-s -1" refuse "--max-gap-s" "\$G run in/good.csv --max-gap-s -1"
c "noise --margin-s -1" refuse "--margin-s" "\$G noise in/good.csv --margin-s -1"
c "calibrate --tau-s -1" refuse "--tau-s" "\$G calibrate in/good.csv --tau-s -1 -o out/m.json"
c "simulate --duration-s -5" refuse "--duration-s" "\$G simulate --duration-s -5 -o out/s.csv"
c "emulate --rate-hz -5" refuse "--rate-hz" "\$G emulate --port out/nowhere --rate-hz -5"
c "record --duration -1" refuse "--duration" "\$G record --port /dev/null --duration -1 -o out/r.mcap"
c "simulate --temperature-rise-c -1e308" refuse "--temperature-rise-c" "\$G simulate --temperature-rise-c -1e308 -o out/s.csv"
c "simulate --temperature-rise-c 1e6" refuse "--temperature-rise-c" "\$G simulate --temperature-rise-c 1e6 -o out/s.csv"
c "simulate --temperature-rise-c -5 (a cooling run)" ok "" "\$G simulate --temperature-rise-c -5 --duration-s 2 -o out/s.csv"
c "run --sample-rate-hz 100 on a 1 kHz log" refuse "--sample-rate-hz" "\$G run in/good.csv --sample-rate-hz 100"
c "run --sample-rate-hz 1e9" refuse "--sample-rate-hz" "\$G run in/good.csv --sample-rate-hz 1e9"
c "run --range-dps 0" refuse "--range-dps" "\$G run in/good.csv --range-dps 0"
c "run --range-dps -5" refuse "--range-dps" "\$G run in/good.csv --range-dps=-5"
c "run --target-deg nan" refuse "--target-deg" "\$G run in/good.csv --target-deg nan --tolerance-deg 1"
c "run --tolerance-deg -1" refuse "--tolerance-deg" "\$G run in/good.csv --target-deg 90 --tolerance-deg=-1"
c "run --k-sigma -1" refuse "--k-sigma" "\$G run in/good.csv --k-sigma=-1"
c "run --scale-sigma inf" refuse "--scale-sigma" "\$G run in/good.csv --scale-sigma inf"
c "run --format xml" refuse "--format" "\$G run in/good.csv --format xml"
c "run --no-such-flag" refuse "--no-such-flag" "\$G run in/good.csv --no-such-flag"
c "run --reference-delay-s 2" refuse "--reference-delay-s 2" "\$G run in/good.csv --reference-delay-s 2"
c "run --reference-delay-s nan" refuse "--reference-delay-s" "\$G run in/good.csv --reference-delay-s nan"
c "noise --margin-s -1" refuse "--margin-s" "\$G noise in/good.csv --margin-s=-1"
c "noise --min-rest-s nan" refuse "--min-rest-s" "\$G noise in/good.csv --min-rest-s nan"
c "noise --per-decade 0" refuse "--per-decade" "\$G noise in/good.csv --per-decade 0"
c "noise --confidence 2" refuse "--confidence" "\$G noise in/good.csv --confidence 2"
c "noise --psd-segment 0" refuse "--psd-segment" "\$G noise in/good.csv --psd-segment 0"
c "noise --sample-rate-hz 1e9" refuse "--sample-rate-hz" "\$G noise in/good.csv --sample-rate-hz 1e9"
c "calibrate --tau-s -1" refuse "--tau-s" "\$G calibrate in/good.csv --tau-s=-1 -o out/m.json"
c "calibrate --tau-s nan" refuse "--tau-s" "\$G calibrate in/good.csv --tau-s nan -o out/m.json"
c "diagnose --members 0 --holdout in/other.csv" refuse "--members" "\$G diagnose --train in/good.csv --members 0 --holdout in/other.csv"
c "diagnose --seed -1" refuse "--seed" "\$G diagnose --train in/good.csv --seed=-1 --holdout in/other.csv"
c "diagnose --split-s nan --holdout in/other.csv" refuse "--split-s" "\$G diagnose --train in/good.csv --split-s nan --holdout in/other.csv"
c "diagnose --self-test --only no_such_effect" refuse "no_such_effect" "\$G diagnose --self-test --only no_such_effect"
c "diagnose without --train" refuse "required arguments" "\$G diagnose --holdout in/other.csv"
c "simulate --duration-s -1" refuse "--duration-s" "\$G simulate --duration-s=-1 -o out/s.csv"
c "simulate --duration-s nan" refuse "--duration-s" "\$G simulate --duration-s nan -o out/s.csv"
c "simulate --sample-rate-hz 1e6 --duration-s 86400" refuse "samples" "\$G simulate --sample-rate-hz 1e6 --duration-s 86400 -o out/s.csv"
c "simulate --temperature-rise-c nan" refuse "--temperature-rise-c" "\$G simulate --temperature-rise-c nan -o out/s.csv"
c "simulate --encoder-counts 0" refuse "--encoder-counts" "\$G simulate --encoder-counts 0 -o out/s.csv"
c "simulate --effect no_such_effect" refuse "no_such_effect" "\$G simulate --effect no_such_effect -o out/s.csv"
c "simulate --seed abc" refuse "--seed" "\$G simulate --seed abc -o out/s.csv"
c "convert --to xml" refuse "--to" "\$G convert in/good.csv out/c.x --to xml"
c "convert --compression brotli" refuse "--compression" "\$G convert in/good.csv out/c.mcap --compression brotli"
c "convert --compression (no value)" refuse "--compression" "\$G convert in/good.csv out/c.mcap --compression"
c "convert to .csv --compression lz4 (CSV has none)" refuse "--compression lz4" "\$G convert in/good.csv out/c.csv --compression lz4"
c "simulate -o s.csv --compression zstd (CSV has none)" refuse "--compression zstd" "\$G simulate --duration-s 2 -o out/s.csv --compression zstd"
c "simulate --static --motion-from" refuse "--static" "\$G simulate --static --motion-from in/good.csv -o out/s.csv"
c "simulate --static --duration-s 0" refuse "--duration-s" "\$G simulate --static --duration-s 0 -o out/s.csv"
c "record --csv -o r.mcap (two formats)" refuse "--csv" "\$G record --port /dev/null --csv -o out/r.mcap"
c "record -o r.csv --compression lz4 (CSV has none)" refuse "--compression lz4" "\$G record --port /dev/null -o out/r.csv --compression lz4"
c "convert to .txt" refuse "c.txt" "\$G convert in/good.csv out/c.txt"
c "record --baud 0" refuse "--baud" "\$G record --port /dev/null --baud 0 -o out/r.mcap"
c "record --duration -1" refuse "--duration" "\$G record --port /dev/null --duration=-1 -o out/r.mcap"
c "emulate --rate-hz 0" refuse "--rate-hz" "\$G emulate --port out/nowhere --rate-hz 0"
c "emulate --rate-hz nan" refuse "--rate-hz" "\$G emulate --port out/nowhere --rate-hz nan"
c "emulate --duration-s -1" refuse "--duration-s" "\$G emulate --port out/nowhere --duration-s=-1"
c "emulate --faults bogus" refuse "--faults" "\$G emulate --port out/nowhere --faults bogus"

# Options that do not apply, or name what is not there
c "run --reference-column ref_deg (missing)" refuse "ref_deg" "\$G run in/good.csv --reference-column ref_deg"
c "run --temperature-column temp (missing)" refuse "temp" "\$G run in/good.csv --temperature-column temp"
c "run good.mcap --reference-column r" refuse "--reference-column" "\$G run in/good.mcap --reference-column r"
c "run good.mcap --time-unit ms" refuse "--time-unit" "\$G run in/good.mcap --time-unit ms"
c "run good.csv --topic /gyro" refuse "--topic" "\$G run in/good.csv --topic /gyro"
c "run good.csv --axis x" refuse "--axis" "\$G run in/good.csv --axis x"
c "noise good.mcap --rate-column r" refuse "--rate-column" "\$G noise in/good.mcap --rate-column r"
c "noise --temperature-column (noise reads no temperature)" refuse "--temperature-column" "\$G noise in/good.csv --temperature-column temperature_c"
c "noise --reference-column (noise reads no reference)" refuse "--reference-column" "\$G noise in/good.csv --reference-column reference_deg"
c "run no_reference.csv --temperature-column temperature_c (missing)" refuse "temperature_c" "\$G run in/no_reference.csv --temperature-column temperature_c"

# Runs given twice
c "calibrate the same run twice" refuse "twice" "\$G calibrate in/good.csv ./in/good.csv -o out/m.json"
c "calibrate a run in training and hold-out" refuse "hold-out" "\$G calibrate in/good.csv --holdout in/hardlink_to_good.csv -o out/m.json"
c "diagnose the same run twice" refuse "twice" "\$G diagnose --train in/good.csv in/link_to_good.csv --holdout in/other.csv"
c "noise the same log twice" refuse "twice" "\$G noise in/good.csv in/good.csv"

# Outputs over inputs
c "run --out over its input" refuse "good.csv" "\$G run in/good.csv --out in/good.csv"
c "run --out ./ spelling" refuse "good.csv" "\$G run in/good.csv --out ./in/good.csv"
c "run --out absolute path" refuse "good.csv" "\$G run in/good.csv --out \$PWD/in/good.csv"
c "run --out symlink" refuse "link_to_good.csv" "\$G run in/good.csv --out in/link_to_good.csv"
c "run --out hard link" refuse "hardlink_to_good.csv" "\$G run in/good.csv --out in/hardlink_to_good.csv"
c "run --out sub/../" refuse "good.csv" "\$G run in/good.csv --out in/a_directory/../good.csv"
c "run --plot over its input" refuse "good.csv" "\$G run in/good.csv --plot in/good.csv"
c "calibrate -o over its input" refuse "good.csv" "\$G calibrate in/good.csv -o in/good.csv"
c "calibrate -o over --model" refuse "model.json" "\$G calibrate in/good.csv --model in/model.json -o in/model.json"
c "noise --psd-out over input" refuse "good.csv" "\$G noise in/good.csv --psd-out in/good.csv"
c "noise --model-out over input" refuse "good.csv" "\$G noise in/good.csv --model-out in/good.csv"
c "diagnose -o over --train" refuse "good.csv" "\$G diagnose --train in/good.csv --holdout in/other.csv -o in/good.csv"
c "simulate -o over --motion-from" refuse "good.csv" "\$G simulate --motion-from in/good.csv -o in/good.csv"
c "simulate -o over --model" refuse "model.json" "\$G simulate --model in/model.json -o in/model.json"
c "convert in → same file" refuse "good.csv" "\$G convert in/good.csv in/good.csv"
c "convert in → symlink to it" refuse "link_to_good.csv" "\$G convert in/good.csv in/link_to_good.csv"
c "convert corrupt.mcap over existing file --force" refuse "corrupt.mcap" "\$G convert in/corrupt.mcap in/existing_recording.mcap --force"
c "emulate --fault-log over --log" refuse "good.csv" "\$G emulate --log in/good.csv --port out/nowhere --fault-log in/good.csv"
c "record -o existing without --force" refuse "existing_recording.mcap" "\$G record --port /dev/null -o in/existing_recording.mcap"

# Outputs that exist: refused without --force, replaced with it
E=in/existing
c "run --out existing" refuse "out.csv: exists" "\$G run in/good.csv --out $E/out.csv"
c "run --plot existing" refuse "plot.svg: exists" "\$G run in/good.csv --plot $E/plot.svg"
c "calibrate -o existing" refuse "model.json: exists" "\$G calibrate in/good.csv -o $E/model.json"
c "noise --psd-out existing" refuse "psd.csv: exists" "\$G noise in/good.csv --psd-out $E/psd.csv"
c "noise --model-out existing" refuse "model.json: exists" "\$G noise in/good.csv --model-out $E/model.json"
c "noise --noise-yaml existing" refuse "imu.yaml: exists" "\$G noise in/good.csv --noise-yaml $E/imu.yaml"
c "noise --plot existing" refuse "plot.svg: exists" "\$G noise in/good.csv --plot $E/plot.svg"
c "diagnose -o existing" refuse "model.json: exists" "\$G diagnose --train in/good.csv --holdout in/other.csv -o $E/model.json"
c "diagnose --noise-yaml existing" refuse "imu.yaml: exists" "\$G diagnose --train in/good.csv --holdout in/other.csv --noise-yaml $E/imu.yaml"
c "diagnose --report over an earlier report" refuse "index.html: exists" "\$G diagnose --train in/good.csv --holdout in/other.csv --report $E/report"
c "simulate -o existing" refuse "out.csv: exists" "\$G simulate --duration-s 2 -o $E/out.csv"
c "convert to an existing file" refuse "copy.mcap: exists" "\$G convert in/good.csv $E/copy.mcap"
c "emulate --fault-log existing" refuse "faults.json: exists" "\$G emulate --port out/nowhere --fault-log $E/faults.json"
c "noise: one file for two outputs" refuse "named for two outputs" "\$G noise in/good.csv --psd-out out/a.csv --model-out ./out/a.csv"
c "run --out over its input with --force" refuse "good.csv" "\$G run in/good.csv --out in/good.csv --force"
c "run --out existing --force" ok "" "echo old >out/s.csv && \$G run in/good.csv --out out/s.csv --force >/dev/null && ! grep -q old out/s.csv"
c "simulate -o existing --force" ok "" "echo old >out/s.csv && \$G simulate --duration-s 2 -o out/s.csv --force && ! grep -q old out/s.csv"
c "convert to an existing file --force" ok "" "echo old >out/c.mcap && \$G convert in/good.csv out/c.mcap --force && head -c 5 out/c.mcap | grep -q MCAP"
c "run --out /dev/stdout (a device: written, not refused)" ok "" "\$G run in/good.csv --format json --out /dev/stdout >/dev/null"

# Ports, pipes, full disks
c "record --port missing" refuse "/dev/no-such-port" "\$G record --port /dev/no-such-port -o out/r.mcap"
c "emulate --port missing folder" refuse "no-such-dir" "\$G emulate --port /no-such-dir/tty --duration-s 1"
c "emulate --create-pty, nobody reads" refuse "" "\$G emulate --create-pty --duration-s 2 --write-timeout-s 1"
c "emulate --create-pty, nobody reads, default timeout" refuse "is anything reading it?" "\$G emulate --create-pty --duration-s 30"
c "emulate --create-pty, nobody reads: the stalled port said" refuse "is anything reading it?" "\$G emulate --create-pty --duration-s 30 --write-timeout-s 2"
c "run > /dev/full" refuse "stdout" "\$G run in/good.csv >/dev/full"
c "calibrate > /dev/full" late "stdout" "\$G calibrate in/good.csv --no-leave-one-out -o out/m.json >/dev/full"
c "noise > /dev/full" refuse "stdout" "\$G noise in/good.csv >/dev/full"
c "simulate --list-effects > /dev/full" refuse "stdout" "\$G simulate --list-effects >/dev/full"
c "run --out /dev/full" refuse "/dev/full" "\$G run in/good.csv --out /dev/full"
c "run empty.csv 2> /dev/full" quiet "" "\$G run in/empty.csv 2>/dev/full"
c "run --sample-rate-hz -1 2> /dev/full" quiet "" "\$G run in/good.csv --sample-rate-hz -1 2>/dev/full"
c "run meta_rate_wrong.csv 2> /dev/full" quiet "" "\$G run in/meta_rate_wrong.csv 2>/dev/full"
c "convert --help > /dev/full" ok "" "\$G convert --help >/dev/full"
c "run --out missing folder" refuse "no-such-dir" "\$G run in/good.csv --out out/no-such-dir/s.csv"

# ---------------------------------------------------------------------------------------
inputs_sum() { find in -type f -print0 | sort -z | xargs -0 md5sum | md5sum; }
declare -A COUNT
ROWS=()
bad=0
for i in "${!NAMES[@]}"; do
    name=${NAMES[$i]} expect=${EXPECTS[$i]} needle=${NEEDLES[$i]} cmd=${CMDS[$i]}
    before=$(inputs_sum)
    rm -rf out && mkdir out
    timeout -k 2 "$TIMEOUT" bash -c "$cmd" >stdout 2>stderr </dev/null
    rc=$?
    after=$(inputs_sum)
    errors=$(grep -c '^error:' stderr)
    first=$(grep -m1 '^error:' stderr || head -n1 stderr)
    if [[ $rc -eq 124 || $rc -eq 137 ]]; then outcome=hang
    elif [[ $rc -eq 101 ]] || grep -q 'panicked' stderr; then outcome=panic
    elif [[ $rc -gt 128 ]]; then outcome=crash
    elif [[ $before != "$after" ]]; then outcome=clobber
    elif [[ $expect == ok ]]; then
        if [[ $rc -eq 0 ]]; then outcome=clean; else outcome=rejected; fi
    elif [[ $rc -eq 0 ]]; then outcome=silent-accept
    elif [[ -n $(ls -A out) && $expect == refuse ]]; then outcome=leftover
    elif [[ $expect == quiet ]]; then outcome=clean
    elif [[ $expect == late && $errors -eq 1 && $first == *"$needle"* ]]; then outcome=clean
    elif [[ $errors -eq 1 && ( -z $needle || $first == *"$needle"* ) ]]; then outcome=clean
    else outcome=unhelpful
    fi
    COUNT[$outcome]=$(( ${COUNT[$outcome]:-0} + 1 ))
    [[ $outcome == clean ]] || { bad=$((bad + 1)); echo "NOT CLEAN ($outcome, exit $rc): $name: $first" >&2; }
    shown=${first//$W\//}
    shown=${shown//|/\\|}
    [[ ${#shown} -gt 100 ]] && shown="${shown:0:100}…"
    display=${cmd//\$G/gyro-cli}
    display=${display//|/\\|}
    ROWS+=("| $((i + 1)) | $name | \`$display\` | $outcome (exit $rc) | ${shown:-(none)} |")
done
cd "$ROOT"

{
    echo "# Bad-input corpus"
    echo
    echo "Every gyro-cli command fed bad inputs and mistaken arguments, each run with a"
    echo "${TIMEOUT}-second timeout. Regenerate this file with:"
    echo
    echo '```sh'
    echo 'scripts/bad_input_corpus.sh              # builds target/release/gyro-cli; writes docs/bad-input-corpus.md'
    echo 'GYRO_CLI=target/debug/gyro-cli scripts/bad_input_corpus.sh /tmp/table.md   # as CI runs it'
    echo '```'
    echo
    echo "The inputs are made by the script from the fixtures (\`in/\` in a temporary"
    echo "folder; \`good.csv\` is the first 10 s of \`fixtures/logs/bench_run.csv\`). Outcomes:"
    echo "**clean** (a non-zero exit with exactly one \`error:\` line that names the file, line or"
    echo "option, or a documented success), **panic** (exit 101 or \`panicked\`), **hang**"
    echo "(timeout), **crash** (a signal), **silent-accept** (exit 0 where the input must be"
    echo "refused), **rejected** (a valid input refused), **unhelpful** (refused without one"
    echo "\`error:\` line naming what is wrong), **clobber** (an input changed), **leftover** (a"
    echo "refused command left an output behind). The script exits 1 unless every case is clean."
    echo
    echo "The readers are also fuzzed in \`cargo test --workspace\` (proptest over bytes, fixed"
    echo "seeds; fixture files mutated by bit flips, truncation, insertion, duplicated and deleted"
    echo "lines, odd field values, other encodings, plus random bytes): no panic, every error one"
    echo "line naming the file, at most 400 characters beyond the path. \`crates/gyro-log/tests/all/fuzz_csv.rs\`"
    echo "(1600 + 400 cases), \`fuzz_mcap.rs\` (2000 + 500), \`crates/gyro-analysis/tests/all/fuzz_model.rs\`"
    echo "(3000 + 750), \`crates/crm100-driver/tests/all/fuzz_bridge.rs\` (4 × 2048). In debug on two"
    echo "shared cores they took 10.6 s, 8.8 s, 9.7 s and 4.1 s (\`cargo test -p gyro-log --test all"
    echo "fuzz_csv::\` etc., the \`finished in\` figures)."
    echo
    echo "## Summary"
    echo
    echo "| outcome | cases |"
    echo "|---|---|"
    for k in clean panic hang crash silent-accept rejected unhelpful clobber leftover; do
        echo "| $k | ${COUNT[$k]:-0} |"
    done
    echo "| **total** | ${#NAMES[@]} |"
    echo
    echo "## Cases"
    echo
    echo "| # | case | command | outcome | first line of stderr (the \`error:\` line if any) |"
    echo "|---|---|---|---|---|"
    printf '%s\n' "${ROWS[@]}"
} >"$TABLE"

echo "${#NAMES[@]} cases, $bad not clean; table in $TABLE" >&2
[[ $bad -eq 0 ]]
