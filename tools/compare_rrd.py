#!/usr/bin/env python3
"""Compares two physlab recordings value by value, bit for bit.

For every entity and component, collects the rows (timeline values, the component's value) of
the temporal data, sorts them, and compares them exactly (floats by their bit patterns). Static
data (styles, texts) is compared the same way but reported separately. Chunking and row ids are
ignored: two recordings that log the same values at the same times compare equal.

Usage: tools/compare_rrd.py A.rrd B.rrd [--ignore-entity PREFIX ...]
Exit code 0 when every temporal series is identical, 1 otherwise.
Needs: pip install rerun-sdk==0.36.3
"""
import struct
import sys
from collections import defaultdict

from rerun.experimental import RrdReader


def key(v):
    """A hashable, bit-exact form of a cell."""
    if isinstance(v, float):
        return ("f", struct.pack("<d", v))
    if isinstance(v, list):
        return ("l",) + tuple(key(x) for x in v)
    if isinstance(v, dict):
        return ("d",) + tuple((k, key(x)) for k, x in sorted(v.items()))
    return ("v", v)


def load(path):
    temporal = defaultdict(list)
    static = defaultdict(list)
    for chunk in RrdReader(path).stream():
        entity = str(chunk.entity_path)
        if entity.startswith("/__properties"):
            continue
        rb = chunk.to_record_batch()
        names = rb.schema.names
        times = [n for n in names if n in ("sim_time", "frame")]
        comps = [n for n in names if ":" in n]
        cols = {n: rb.column(n).to_pylist() for n in times + comps}
        for c in comps:
            for r in range(rb.num_rows):
                cell = cols[c][r]
                if cell is None:
                    continue
                t = tuple(str(cols[n][r]) for n in times)
                (static if chunk.is_static else temporal)[(entity, c)].append((t, key(cell)))
    return temporal, static


def main():
    args = sys.argv[1:]
    ignore = []
    while "--ignore-entity" in args:
        i = args.index("--ignore-entity")
        ignore.append(args[i + 1])
        del args[i : i + 2]
    a, b = args
    ta, sa = load(a)
    tb, sb = load(b)
    bad = 0
    same = 0
    for kind, da, db in (("temporal", ta, tb), ("static", sa, sb)):
        for k in sorted(set(da) | set(db)):
            if any(k[0].startswith(p) for p in ignore):
                continue
            ra, rb_ = sorted(da.get(k, [])), sorted(db.get(k, []))
            if ra == rb_:
                same += kind == "temporal"
                continue
            if kind == "temporal":
                bad += 1
            print(f"{kind} differs: {k[0]} {k[1]}: {len(ra)} vs {len(rb_)} rows"
                  + (" (only in A)" if k not in db else " (only in B)" if k not in da else ""))
    print(f"{same} temporal columns identical, {bad} differ")
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
