#!/usr/bin/env python3
"""Prints the fidelity baseline table from the runs of scripts/baseline_scenes.sh.

    scripts/baseline_table.py RUNS_DIR SCENE...

Per scene: observed accuracy P90 (mm and px), observed completeness, observed EPE_rel, the
exact-mask hull's observed accuracy / completeness and the ratio hull / result accuracy,
the run's own hull, wall time and peak memory (from /usr/bin/time -v), per frame.
"""
import json
import os
import re
import sys


def load(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def time_figures(path):
    wall, peak = None, None
    try:
        text = open(path).read()
    except OSError:
        return None, None
    m = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (?:(\d+):)?(\d+):([\d.]+)", text)
    if m:
        wall = int(m.group(1) or 0) * 3600 + int(m.group(2)) * 60 + float(m.group(3))
    m = re.search(r"Maximum resident set size \(kbytes\): (\d+)", text)
    if m:
        peak = int(m.group(1)) / 1024.0 / 1024.0
    return wall, peak


def observed(report):
    return report["overall"].get("observed") if report else None


def main():
    runs, scenes = sys.argv[1], sys.argv[2:]
    print("| scene | frames | obs. acc P90 mm | px | px size mm | obs. completeness | obs. EPE_rel "
          "| mask hull acc mm / compl. | hull/result | run's hull acc / compl. | wall s/frame | peak GB |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name in scenes:
        r = os.path.join(runs, name)
        result = load(os.path.join(r, "eval.json"))
        o = observed(result)
        if o is None:
            print(f"| {name} | (no result) |")
            continue
        frames = len(result["frames"])
        flow = o.get("flow") or {}
        mask_hull = observed(load(os.path.join(r, "eval_mask_hull.json")))
        own_hull = observed(load(os.path.join(r, "eval_result_hull.json")))
        wall, peak = time_figures(os.path.join(r, "reconstruct.time"))
        cells = [name, str(frames), f"{o['accuracy'] * 1000:.3f}", f"{o['accuracy_px']:.2f}",
                 f"{o['pixel_footprint'] * 1000:.2f}", f"{o['completeness']:.3f}",
                 f"{flow['epe_relative']:.3f}" if flow else "-"]
        if mask_hull:
            cells += [f"{mask_hull['accuracy'] * 1000:.2f} / {mask_hull['completeness']:.3f}",
                      f"{mask_hull['accuracy'] / o['accuracy']:.1f}x"]
        else:
            cells += ["-", "-"]
        cells.append(f"{own_hull['accuracy'] * 1000:.2f} / {own_hull['completeness']:.3f}" if own_hull else "-")
        cells.append(f"{wall / frames:.1f}" if wall else "-")
        cells.append(f"{peak:.2f}" if peak else "-")
        print("| " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
