#!/usr/bin/env python3
"""The table of compositors in docs/parallel.md "Direct-send beside IceT"
from tools/bench/icet_compare.sh's JSON lines, run with ICET_COMPARE_BASE set to an
icet_compare built before the sparse direct-send: per P and image size, the busiest rank's
bytes sent and the median composite time of the old (dense) direct-send, the sparse one, IceT
radix-k called by splat (--compositor icet) and IceT radix-k called directly.
Usage: /usr/bin/python3 tools/bench/icet_table.py build/icet_compare.jsonl"""
import json
import sys

rows = [json.loads(l) for l in open(sys.argv[1]) if l.startswith("{")]
by = {(r["P"], r["size"], r["method"]): r for r in rows}
cols = [("splat direct-send (base)", "direct-send, old (dense)"),
        ("splat direct-send", "direct-send, sparse"),
        ("splat --compositor icet", "--compositor icet"),
        ("IceT sequential + radix-k", "IceT radix-k alone")]
print("| P | image | " + " | ".join(f"{c[1]}: MB sent, ms" for c in cols) + " |")
print("|---|---|" + "---|" * len(cols))
for p, n in sorted({(r["P"], r["size"]) for r in rows}):
    cells = []
    for key, _ in cols:
        r = by.get((p, n, key))
        cells.append(f"{r['bytes_sent_max'] / 1e6:.2f}, {r['median_ms']:.1f}" if r else "—")
    print(f"| {p} | {n}² | " + " | ".join(cells) + " |")
