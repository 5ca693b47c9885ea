#!/usr/bin/env python3
"""Read an MCAP log that gyro-cli wrote with the official MCAP readers, not ours.

The file is read with the `mcap` package's indexed reader (summary, chunk indexes, lz4
chunks) and its `/gyro` and `/reference` messages decoded by `mcap-ros2-support` from the
`ros2msg` definitions the file carries, as Foxglove and ROS 2 tooling decode them. Each
decoded value is compared, bit for bit, with the CSV the file was converted from: time
(log_time in ns), rate_dps, temperature_c and reference_deg (NaN where the CSV field is
empty), and status −1 (unknown) in every row.

Usage:
    pip install mcap mcap-ros2-support
    gyro-cli convert LOG.csv LOG.mcap
    python3 scripts/mcap_reference_check.py LOG.csv LOG.mcap

Prints the channels and the count of rows compared; exits 1 at the first difference.
"""
import csv
import math
import sys
from decimal import ROUND_HALF_EVEN, Decimal

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory


def csv_rows(path):
    """(time_ns, rate, temperature, reference) per data row, NaN for an empty field."""
    with open(path, newline="") as f:
        lines = (line for line in f if not line.startswith("#"))
        reader = csv.DictReader(lines)
        for row in reader:
            value = lambda key: float(row[key]) if row.get(key, "") != "" else math.nan
            # gyro-cli rounds a time to whole ns (its decimal digits, exactly).
            ns = int(Decimal(row["time_s"]).scaleb(9).quantize(Decimal(1), ROUND_HALF_EVEN))
            yield ns, value("rate_dps"), value("temperature_c"), value("reference_deg")


def same(a, b):
    return (math.isnan(a) and math.isnan(b)) or a == b


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    csv_path, mcap_path = sys.argv[1:]
    gyro, reference = [], []
    with open(mcap_path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        summary = reader.get_summary()
        for channel in summary.channels.values():
            schema = summary.schemas[channel.schema_id]
            print(
                f"{channel.topic}: {schema.name} ({schema.encoding}, {channel.message_encoding})"
                f" {dict(channel.metadata)}"
            )
        compressions = {c.compression for c in summary.chunk_indexes}
        print(f"{len(summary.chunk_indexes)} chunks, compression {sorted(compressions)}")
        for _, channel, message, decoded in reader.iter_decoded_messages(
            topics=["/gyro", "/reference"]
        ):
            if channel.topic == "/gyro":
                gyro.append((message.log_time, decoded))
            else:
                reference.append((message.log_time, decoded))
    rows = list(csv_rows(csv_path))
    if len(gyro) != len(rows) or (reference and len(reference) != len(rows)):
        sys.exit(f"{len(rows)} CSV rows, {len(gyro)} /gyro and {len(reference)} /reference")
    for i, (time_ns, rate, temperature, angle) in enumerate(rows):
        log_time, sample = gyro[i]
        checks = [
            ("time", log_time, time_ns),
            ("rate_dps", sample.rate_dps, rate),
            ("temperature_c", sample.temperature_c, temperature),
            ("status", sample.status, -1),
        ]
        if reference:
            checks.append(("reference_deg", reference[i][1].angle_deg, angle))
        for name, got, want in checks:
            if not same(got, want):
                sys.exit(f"row {i + 1}: {name} {got!r} in the MCAP, {want!r} in the CSV")
    print(f"{len(rows)} rows: every value equal, bit for bit")


if __name__ == "__main__":
    main()
