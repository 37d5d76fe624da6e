#!/usr/bin/env python3
"""Compares two result directories numerically (standard library only).

    python3 scripts/compare_results.py REFERENCE CANDIDATE [--tolerance 1e-9] [--glob 'meshes/*.ply']

Every PLY file matching the globs (default: meshes/*.ply, control/*/*.ply, hull/*.ply,
base_mesh.ply) in REFERENCE must exist in CANDIDATE with the same vertex and face counts,
the same vertex properties and the same faces; the script prints, per glob, the largest
absolute difference of any vertex property and how many values differ at all, and exits
1 when a file is missing, a structure differs, or a difference exceeds the tolerance.
Binary little-endian and ASCII PLY with float/double/int vertex properties are read.
"""
import argparse
import glob
import os
import struct
import sys

TYPES = {"char": "b", "int8": "b", "uchar": "B", "uint8": "B", "short": "h", "int16": "h",
         "ushort": "H", "uint16": "H", "int": "i", "int32": "i", "uint": "I", "uint32": "I",
         "float": "f", "float32": "f", "double": "d", "float64": "d"}


def read_ply(path):
    with open(path, "rb") as stream:
        data = stream.read()
    end = data.index(b"end_header") + len(b"end_header")
    end = data.index(b"\n", end) + 1
    header = data[:end].decode("ascii").splitlines()
    fmt, elements = None, []
    for line in header:
        words = line.split()
        if not words:
            continue
        if words[0] == "format":
            fmt = words[1]
        elif words[0] == "element":
            elements.append({"name": words[1], "count": int(words[2]), "properties": []})
        elif words[0] == "property":
            elements[-1]["properties"].append(words[1:])
    body = data[end:]
    result = {}
    if fmt == "ascii":
        tokens = body.split()
        at = 0
        for element in elements:
            rows = []
            for _ in range(element["count"]):
                row = []
                for prop in element["properties"]:
                    if prop[0] == "list":
                        n = int(tokens[at]); at += 1
                        row.append(tuple(int(t) for t in tokens[at:at + n])); at += n
                    else:
                        row.append(float(tokens[at])); at += 1
                rows.append(row)
            result[element["name"]] = (element["properties"], rows)
        return result
    if fmt != "binary_little_endian":
        raise ValueError(f"{path}: format {fmt} not supported")
    at = 0
    for element in elements:
        props = element["properties"]
        rows = []
        if all(p[0] != "list" for p in props):
            record = struct.Struct("<" + "".join(TYPES[p[0]] for p in props))
            for values in record.iter_unpack(body[at:at + record.size * element["count"]]):
                rows.append(list(values))
            at += record.size * element["count"]
        else:
            for _ in range(element["count"]):
                row = []
                for prop in props:
                    if prop[0] == "list":
                        count_type, item_type = TYPES[prop[1]], TYPES[prop[2]]
                        (n,) = struct.unpack_from("<" + count_type, body, at)
                        at += struct.calcsize(count_type)
                        row.append(struct.unpack_from("<%d%s" % (n, item_type), body, at))
                        at += n * struct.calcsize(item_type)
                    else:
                        (value,) = struct.unpack_from("<" + TYPES[prop[0]], body, at)
                        at += struct.calcsize(TYPES[prop[0]])
                        row.append(value)
                rows.append(row)
        result[element["name"]] = (props, rows)
    return result


def compare(reference, candidate):
    """(max |difference|, differing values) of the vertex properties; raises on structure."""
    a, b = read_ply(reference), read_ply(candidate)
    if set(a) != set(b):
        raise ValueError(f"elements {sorted(a)} vs {sorted(b)}")
    props_a, rows_a = a["vertex"]
    props_b, rows_b = b["vertex"]
    names_a, names_b = [p[-1] for p in props_a], [p[-1] for p in props_b]
    if sorted(names_a) != sorted(names_b) or len(rows_a) != len(rows_b):
        raise ValueError(f"vertex properties {names_a} ({len(rows_a)}) vs {names_b} ({len(rows_b)})")
    order = [names_b.index(n) for n in names_a]
    worst, differing = 0.0, 0
    for ra, rb in zip(rows_a, rows_b):
        for i, j in enumerate(order):
            d = abs(ra[i] - rb[j])
            if d > 0:
                differing += 1
                worst = max(worst, d)
    if "face" in a and a["face"][1] != b["face"][1]:
        raise ValueError("faces differ")
    return worst, differing


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("reference")
    parser.add_argument("candidate")
    parser.add_argument("--tolerance", type=float, default=1e-9)
    parser.add_argument("--glob", action="append",
                        help="file pattern relative to the directories (repeatable)")
    args = parser.parse_args()
    patterns = args.glob or ["meshes/*.ply", "control/*/*.ply", "hull/*.ply", "base_mesh.ply"]
    failed = False
    for pattern in patterns:
        files = sorted(glob.glob(os.path.join(args.reference, pattern)))
        worst, differing, values = 0.0, 0, 0
        for path in files:
            relative = os.path.relpath(path, args.reference)
            other = os.path.join(args.candidate, relative)
            if not os.path.exists(other):
                print(f"{relative}: missing in {args.candidate}")
                failed = True
                continue
            try:
                w, d = compare(path, other)
            except ValueError as error:
                print(f"{relative}: {error}")
                failed = True
                continue
            worst, differing = max(worst, w), differing + d
        status = "ok" if worst <= args.tolerance else "DIFFERENT"
        failed = failed or worst > args.tolerance
        print(f"{pattern}: {len(files)} files, max |difference| {worst:.3g}, "
              f"{differing} differing values: {status}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
