#!/usr/bin/env python3
"""Puts the Performance tables that tools/bench.sh generated into splat/docs/performance.md.

Usage: python3 tools/bench/update_perf_doc.py PERF.md [DOC.md]

Replaces everything between the marker lines `<!-- perf:begin -->` and `<!-- perf:end -->`
of DOC.md (default: the repository's splat/docs/performance.md) with PERF.md (`bash
tools/bench.sh ... --markdown PERF.md`), verbatim; the hand-written text around the markers
stays. Exit status 1 when the markers are missing or not in order, 2 on a usage error.
"""
import os
import sys

BEGIN = "<!-- perf:begin -->"
END = "<!-- perf:end -->"
DEFAULT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "splat", "docs",
                       "performance.md")


def update(doc, table):
    with open(doc) as f:
        text = f.read()
    b, e = text.find(BEGIN), text.find(END)
    if b < 0 or e < b or text.count(BEGIN) != 1 or text.count(END) != 1:
        sys.exit(f"update_perf_doc: {doc}: needs one '{BEGIN}' line before one '{END}' line")
    new = text[:b + len(BEGIN)] + "\n" + table.rstrip("\n") + "\n" + text[e:]
    tmp = doc + ".tmp"
    with open(tmp, "w") as f:
        f.write(new)
    os.replace(tmp, doc)
    print(f"update_perf_doc: {doc}: generated block replaced ({len(table.splitlines())} lines)",
          file=sys.stderr)


def main():
    if len(sys.argv) not in (2, 3):
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        return 2
    doc = sys.argv[2] if len(sys.argv) == 3 else DEFAULT
    try:
        with open(sys.argv[1]) as f:
            update(doc, f.read())
    except OSError as e:
        sys.exit(f"update_perf_doc: {e.filename}: {e.strerror}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
