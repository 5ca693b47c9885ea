#!/usr/bin/env python3
"""Bytes of each kind of top-level record in MCAP files: how much of a file is chunks
(and how much those hold uncompressed), message indexes, the summary. Standard library
only; docs/log-formats.md ("Compression") quotes its figures.

Usage: python3 scripts/mcap_sizes.py FILE.mcap [FILE.mcap ...]
"""
import struct
import sys
from collections import Counter

NAMES = {
    1: "header", 2: "footer", 3: "schema", 4: "channel", 5: "message", 6: "chunk",
    7: "message_index", 8: "chunk_index", 9: "attachment", 10: "attachment_index",
    11: "statistics", 12: "metadata", 13: "metadata_index", 14: "summary_offset",
    15: "data_end",
}
MAGIC = b"\x89MCAP0\r\n"


def sizes(path):
    data = open(path, "rb").read()
    if not data.startswith(MAGIC):
        raise SystemExit(f"{path}: not an MCAP file")
    total, count, codecs = Counter(), Counter(), Counter()
    i = len(MAGIC)
    while i + 9 <= len(data):
        opcode = data[i]
        (length,) = struct.unpack_from("<Q", data, i + 1)
        name = NAMES.get(opcode, f"opcode_{opcode}")
        total[name] += 9 + length
        count[name] += 1
        if opcode == 6:  # chunk: start, end, uncompressed size, crc, compression, ...
            body = data[i + 9 : i + 9 + length]
            (uncompressed,) = struct.unpack_from("<Q", body, 16)
            (name_len,) = struct.unpack_from("<I", body, 28)
            codecs[body[32 : 32 + name_len].decode() or "none"] += 1
            total["chunk data uncompressed"] += uncompressed
        i += 9 + length
        if opcode == 2:
            break
    return len(data), total, count, codecs


for path in sys.argv[1:]:
    size, total, count, codecs = sizes(path)
    print(f"{path}: {size} bytes; chunks: {dict(codecs)}")
    for name in ["chunk", "message_index", "chunk_index"]:
        print(f"  {name:<24} {total[name]:>12} B  ({count[name]} records)")
    print(f"  {'(chunk data unpacked)':<24} {total['chunk data uncompressed']:>12} B")
    rest = size - total["chunk"] - total["message_index"] - total["chunk_index"]
    print(f"  {'everything else':<24} {rest:>12} B")
