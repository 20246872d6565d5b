#!/usr/bin/env python3
"""Summary tables for docs/results.md from a scripts/results.sh output directory.

Usage: scripts/results_summary.py OUT_DIR

Reads OUT_DIR/<run>/{bend,qiu}.eval{50,200}.json (written by `curbtrace eval --json`),
OUT_DIR/<run>/<method>.summary.txt (the extract summary) and OUT_DIR/<run>.simulate.txt,
and prints two markdown tables: totals per run and method at both buffers with throughput,
and quality per side and category at 50 mm (and at 200 mm for Qiu's buffer).
"""
import json
import re
import sys
from pathlib import Path

RUNS = ["tiny", "curvy", "sapporo", "kawasaki", "kawasaki-40kmh"]
METHODS = ["bend", "qiu"]
CATS = ["curb", "curb_cut", "intersection", "bus_bay"]


def fmt(v, digits=1):
    return "–" if v is None else f"{v:.{digits}f}"


def load(out, run, method, buf):
    p = out / run / f"{method}.eval{buf}.json"
    return json.loads(p.read_text()) if p.exists() else None


def throughput(out, run, method):
    """(points/s wall as printed by extract, CPU ms per metre driven)."""
    summ = out / run / f"{method}.summary.txt"
    sim = out / f"{run}.simulate.txt"
    if not summ.exists() or not sim.exists():
        return None, None
    s = summ.read_text()
    rate = re.search(r"\(([\d.]+) M points/s\)", s)
    cpu = re.search(r"^cpu\s+([\d.]+) s", s, re.M)
    driven = re.search(r"([\d.]+) m driven", sim.read_text())
    pts = float(rate.group(1)) if rate else None
    ms_per_m = (
        1000.0 * float(cpu.group(1)) / float(driven.group(1))
        if cpu and driven
        else None
    )
    return pts, ms_per_m


def main():
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "results-out")
    print("| scene | method | C (50 mm) | P (50 mm) | Q (50 mm) | RMS (50 mm) "
          "| C (200 mm) | P (200 mm) | Q (200 mm) | RMS (200 mm) "
          "| points/s (wall) | CPU ms per m of road |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for run in RUNS:
        for m in METHODS:
            e50, e200 = load(out, run, m, 50), load(out, run, m, 200)
            if e50 is None or e200 is None:
                continue
            t50, t200 = e50["total"], e200["total"]
            pts, msm = throughput(out, run, m)
            print(f"| {run} | {m} | {fmt(t50['completeness_pct'])} | "
                  f"{fmt(t50['correctness_pct'])} | {fmt(t50['quality_pct'])} | "
                  f"{fmt(t50['rms_mm'])} | {fmt(t200['completeness_pct'])} | "
                  f"{fmt(t200['correctness_pct'])} | {fmt(t200['quality_pct'])} | "
                  f"{fmt(t200['rms_mm'])} | {fmt(pts, 2)} M | {fmt(msm, 0)} |")
    for buf in (50, 200):
        print()
        print(f"Quality % per side and category, {buf} mm buffer:")
        print()
        print("| scene | method | side | curb | curb cut | intersection | bus bay |")
        print("|---|---|---|---:|---:|---:|---:|")
        for run in RUNS:
            for m in METHODS:
                e = load(out, run, m, buf)
                if e is None:
                    continue
                for side in e["sides"]:
                    q = {c["category"]: c["metrics"]["quality_pct"]
                         for c in side["categories"]}
                    cells = " | ".join(fmt(q.get(c)) for c in CATS)
                    print(f"| {run} | {m} | {side['side']} | {cells} |")


if __name__ == "__main__":
    main()
