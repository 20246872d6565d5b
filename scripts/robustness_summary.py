#!/usr/bin/env python3
"""docs/robustness-accuracy.md from a scripts/robustness.sh output directory.

Usage: scripts/robustness_summary.py OUT_DIR FIRST_SEED N ELAPSED_S BIN

Reads OUT_DIR/seed-S/{simulate.txt, bend.json, qiu.json, *.strict.json, *.extract.txt},
prints the page
on stdout and draws the worst place of the worst streets with `BIN eval --picture` into
docs/robustness/.
"""
import json
import os
import re
import subprocess
import sys
from pathlib import Path

CATS = ["curb", "curb_cut", "intersection", "bus_bay"]
WORST_BEND = 5
WORST_QIU = 3
PICTURES = Path("docs/robustness")


def fmt(v, digits=1):
    return "–" if v is None else f"{v:.{digits}f}"


def percentile(values, q):
    """Linear interpolation between closest ranks (numpy's default)."""
    v = sorted(values)
    if not v:
        return None
    k = (len(v) - 1) * q
    lo = int(k)
    hi = min(lo + 1, len(v) - 1)
    return v[lo] + (v[hi] - v[lo]) * (k - lo)


def ratios(tp, ext, ref, matched):
    fn = max(ref - matched, 0.0)
    return {
        "completeness": 100.0 * matched / ref if ref > 0 else None,
        "correctness": 100.0 * tp / ext if ext > 0 else None,
        "quality": 100.0 * tp / (ext + fn) if ext + fn > 0 else None,
        "reference_m": ref,
    }


def combine(metrics):
    """Completeness, correctness, quality of several columns taken together."""
    s = {k: sum(m[k] for m in metrics) for k in ["tp_m", "extracted_m", "reference_m", "matched_m"]}
    return ratios(s["tp_m"], s["extracted_m"], s["reference_m"], s["matched_m"])


def street(out, seed, suffix=""):
    d = out / f"seed-{seed}"
    sim = (d / "simulate.txt").read_text().splitlines()
    desc = sim[0] if sim else ""
    r = {"seed": seed, "dir": d, "description": desc}
    m = re.search(r"\(([0-9.]+) m between lines\)", desc)
    r["spacing_m"] = float(m.group(1)) if m else None
    m = re.search(r"far side (left|right)", desc)
    r["far"] = m.group(1) if m else None
    m = re.search(r"yaw (-?\d+)° pitch (\d+)°", desc)
    r["yaw"], r["pitch"] = (int(m.group(1)), int(m.group(2))) if m else (None, None)
    m = re.search(r"(\d+) parked", desc)
    r["parked"] = int(m.group(1)) if m else None
    m = re.search(r": (\d+) points", sim[1] if len(sim) > 1 else "")
    r["points"] = int(m.group(1)) if m else None
    for method in ["bend", "qiu"]:
        p = d / f"{method}{suffix}.json"
        if not p.exists():
            r[method] = None
            continue
        j = json.loads(p.read_text())
        t = j["total"]
        e = {
            "total": ratios(t["tp_m"], t["extracted_m"], t["reference_m"], t["matched_m"]),
            "rms_mm": t["rms_mm"],
        }
        for c in CATS:
            cols = [cm["metrics"] for s in j["sides"] for cm in s["categories"] if cm["category"] == c]
            e[c] = combine(cols) if cols and sum(x["reference_m"] for x in cols) > 0 else None
        for s in j["sides"]:
            e["side_" + s["side"]] = combine([s["total"]])
        e["unattributed_m"] = j["extracted_unattributed_m"]
        sv = j.get("survey") or {}
        e["class_checked_m"] = sv.get("class_checked_m") or 0.0
        e["class_right_m"] = sv.get("class_right_m") or 0.0
        e["class_pct"] = 100 * e["class_right_m"] / e["class_checked_m"] if e["class_checked_m"] > 0 else None
        r[method] = e
        w = re.search(r"wall_ms (\d+)", (d / f"{method}.extract.txt").read_text())
        r[method + "_ms"] = int(w.group(1)) if w else None
    return r


def dist_row(name, values, n_all):
    values = [v for v in values if v is not None]
    if not values:
        return f"| {name} | 0 | – | – | – | – |"
    return (
        f"| {name} | {len(values)} of {n_all} | {fmt(min(values))} | {fmt(percentile(values, 0.1))} "
        f"| {fmt(percentile(values, 0.5))} | {fmt(sum(values) / len(values))} |"
    )


def picture(bin_path, s, method, buffer):
    PICTURES.mkdir(parents=True, exist_ok=True)
    png = PICTURES / f"seed-{s['seed']}-{method}.png"
    d = s["dir"]
    res = subprocess.run(
        [bin_path, "eval", "--reference", str(d / "reference.geojson"), "--extracted",
         str(d / f"{method}.geojson"), "--buffer", str(buffer), "--picture", str(png),
         "--points", str(d / "points.laz"), "--title", f"seed {s['seed']}, {method}"],
        capture_output=True, text=True)
    line = [l for l in res.stdout.splitlines() if l.startswith("worst place") or l.startswith("no worst")]
    return (png if png.exists() else None), (line[0] if line else res.stderr.strip())


def main():
    out, first, n, elapsed, bin_path = Path(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]), sys.argv[5]
    seeds = range(first, first + n)
    streets = [street(out, s) for s in seeds if (out / f"seed-{s}" / "simulate.txt").exists()]
    n_all = len(streets)
    bend = [s for s in streets if s["bend"]]
    qiu = [s for s in streets if s["qiu"]]
    p = print
    p("# Robustness: random streets")
    p()
    p("Both methods with their default parameters on random streets of `curbtrace simulate")
    p("--scene random` (the distributions are in [simulator.md](simulator.md)). Evaluation seeds")
    p(f"{first}–{first + n - 1} are kept apart from the tuning seeds 1–100. Produced by")
    p()
    p("```sh")
    methods = os.environ.get("METHODS", "bend qiu")
    prefix = "" if methods.split() == ["bend", "qiu"] else f'ROBUSTNESS_METHODS="{methods}" '
    p(f"{prefix}scripts/robustness.sh {n} {first}")
    p("```")
    p()
    jobs = int(os.environ.get("ROBUSTNESS_JOBS", "2"))
    at_a_time = {1: "one street", 2: "two streets"}.get(jobs, f"{jobs} streets")
    p(f"({n_all} streets, {elapsed} s wall on the shared 2-core build machine, {at_a_time} at a time;")
    p("bend scored at the 50 mm buffer, qiu at 200 mm, by `curbtrace eval`.) Per-category figures")
    p("take both sides together and count only the streets that have the category in their")
    p("reference.")
    p()
    med = lambda xs: percentile([x for x in xs if x is not None], 0.5)
    cat_q = lambda m, c: [s[m][c]["quality"] if s[m][c] else None for s in (bend if m == "bend" else qiu)]
    close_q = [s["bend"]["total"]["quality"] for s in bend if s["spacing_m"] is not None and s["spacing_m"] <= 0.15]
    checked = sum(s["bend"]["class_checked_m"] for s in bend)
    class_all = 100 * sum(s["bend"]["class_right_m"] for s in bend) / checked if checked > 0 else None
    targets = [
        ("bend median total quality", med([s["bend"]["total"]["quality"] for s in bend]), ">= 96"),
        ("bend 10th percentile total quality", percentile([s["bend"]["total"]["quality"] for s in bend], 0.1), ">= 93"),
        ("bend lowest total quality, lines ≤ 0.15 m apart", min(close_q) if close_q else None, ">= 90"),
        ("bend median curb-cut quality", med(cat_q("bend", "curb_cut")), ">= 90"),
        ("bend median intersection quality", med(cat_q("bend", "intersection")), ">= 85"),
        ("bend largest RMS [mm]", max(s["bend"]["rms_mm"] or 0.0 for s in bend) if bend else None, "<= 15"),
        ("bend extracted length in the right class, all streets [%]", class_all, ">= 95"),
        ("qiu median completeness", med([s["qiu"]["total"]["completeness"] for s in qiu]), ">= 92"),
        ("qiu median correctness", med([s["qiu"]["total"]["correctness"] for s in qiu]), ">= 97"),
        ("qiu median far-side completeness", med([s["qiu"].get("side_" + (s["far"] or ""), {}).get("completeness") for s in qiu]), ">= 88"),
    ]
    p("## Targets")
    p()
    p("| what | measured | target | met |")
    p("|---|---:|---:|:---:|")
    for name, v, t in targets:
        op, bound = t.split()
        ok = v is not None and (v >= float(bound) if op == ">=" else v <= float(bound))
        met = "not run" if v is None else ("yes" if ok else "no")
        p(f"| {name} | {fmt(v)} | {t.replace('>=', '≥').replace('<=', '≤')} | {met} |")
    p()
    strict = [street(out, s["seed"], ".strict") for s in streets]
    if any(s["bend"] or s["qiu"] for s in strict):
        p("The reference joins two observed stretches of one toe at most 1 m apart")
        p("([simulator.md](simulator.md), *Reference lines*). Against the strict reference, which")
        p("keeps each observed stretch alone (`reference_strict.geojson`), the same extracted edges")
        p("score:")
        p()
        p("| what | reference | strict reference |")
        p("|---|---:|---:|")
        sb = [s for s in strict if s["bend"]]
        sq = [s for s in strict if s["qiu"]]
        both = lambda f, a, b: f"| {f[0]} | {fmt(f[1](a))} | {fmt(f[1](b))} |"
        rows = [
            ("bend median total quality", lambda xs: med([s["bend"]["total"]["quality"] for s in xs])),
            ("bend 10th percentile total quality", lambda xs: percentile([s["bend"]["total"]["quality"] for s in xs], 0.1)),
            ("bend lowest total quality", lambda xs: min([s["bend"]["total"]["quality"] or 0.0 for s in xs], default=None)),
            ("bend median completeness", lambda xs: med([s["bend"]["total"]["completeness"] for s in xs])),
            ("bend 10th percentile correctness", lambda xs: percentile([s["bend"]["total"]["correctness"] for s in xs], 0.1)),
            ("bend median curb-cut quality", lambda xs: med([s["bend"]["curb_cut"]["quality"] if s["bend"]["curb_cut"] else None for s in xs])),
            ("bend median intersection quality", lambda xs: med([s["bend"]["intersection"]["quality"] if s["bend"]["intersection"] else None for s in xs])),
        ]
        for r in rows:
            p(both(r, bend, sb))
        qrows = [
            ("qiu median completeness", lambda xs: med([s["qiu"]["total"]["completeness"] for s in xs])),
            ("qiu median correctness", lambda xs: med([s["qiu"]["total"]["correctness"] for s in xs])),
            ("qiu median far-side completeness", lambda xs: med([s["qiu"].get("side_" + (s["far"] or ""), {}).get("completeness") for s in xs])),
        ]
        if qiu and sq:
            for r in qrows:
                p(both(r, qiu, sq))
        p()
    p("## bend, 50 mm buffer")
    p()
    p("| quality [%] | streets | min | 10th pct | median | mean |")
    p("|---|---:|---:|---:|---:|---:|")
    p(dist_row("total", [s["bend"]["total"]["quality"] for s in bend], n_all))
    for c in CATS:
        p(dist_row(c, [s["bend"][c]["quality"] if s["bend"][c] else None for s in bend], n_all))
    p()
    p("| total [%] | streets | min | 10th pct | median | mean |")
    p("|---|---:|---:|---:|---:|---:|")
    p(dist_row("completeness", [s["bend"]["total"]["completeness"] for s in bend], n_all))
    p(dist_row("correctness", [s["bend"]["total"]["correctness"] for s in bend], n_all))
    p(dist_row("RMS [mm]", [s["bend"]["rms_mm"] for s in bend], n_all))
    p(dist_row("length in the right class", [s["bend"]["class_pct"] for s in bend], n_all))
    for c in CATS:
        p(dist_row(f"{c} completeness", [s["bend"][c]["completeness"] if s["bend"][c] else None for s in bend], n_all))
    close = [s for s in bend if s["spacing_m"] is not None and s["spacing_m"] <= 0.15]
    p()
    p(f"Streets whose scanlines are at most 0.15 m apart on the road: {len(close)} of {n_all}; their total")
    p("quality:")
    p()
    p("| quality [%] | streets | min | 10th pct | median | mean |")
    p("|---|---:|---:|---:|---:|---:|")
    p(dist_row("total, lines ≤ 0.15 m apart", [s["bend"]["total"]["quality"] for s in close], n_all))
    below90 = sorted((s["bend"]["total"]["quality"] or 0.0, s["seed"]) for s in close if (s["bend"]["total"]["quality"] or 0.0) < 90.0)
    p()
    p("Below 90 % among them: " + (", ".join(f"seed {sd} ({q:.1f} %)" for q, sd in below90) or "none") + ".")
    p()
    p("### By condition")
    p()
    near = lambda s: s["bend"].get("side_" + ("right" if s["far"] == "left" else "left"), {}).get("quality")
    far = lambda s: s["bend"].get("side_" + (s["far"] or ""), {}).get("quality")
    gap = [s for s in bend if s["pitch"] is not None and s["pitch"] < 10 and abs(s["yaw"]) >= 45]
    rest = [s for s in bend if s not in gap]
    many = [s for s in bend if (s["parked"] or 0) >= 8]
    none = [s for s in bend if s["parked"] == 0]
    p("| bend quality [%] | streets | min | 10th pct | median | mean |")
    p("|---|---:|---:|---:|---:|---:|")
    p(dist_row("near side (the vehicle's lane side)", [near(s) for s in bend], n_all))
    p(dist_row("far side", [far(s) for s in bend], n_all))
    p(dist_row("total, mount pitch < 10° and \\|yaw\\| ≥ 45°", [s["bend"]["total"]["quality"] for s in gap], n_all))
    p(dist_row("total, the other mounts", [s["bend"]["total"]["quality"] for s in rest], n_all))
    p(dist_row("curb completeness, ≥ 8 parked vehicles", [s["bend"]["curb"]["completeness"] if s["bend"]["curb"] else None for s in many], n_all))
    p(dist_row("curb completeness, no parked vehicle", [s["bend"]["curb"]["completeness"] if s["bend"]["curb"] else None for s in none], n_all))
    p()
    p("Extracted length farther than 2 m from every reference line (phantom edges), bend: "
      f"{sum(s['bend']['unattributed_m'] for s in gap):.0f} m on the {len(gap)} streets with pitch < 10° and |yaw| ≥ 45° "
      f"({', '.join(str(s['seed']) for s in gap) or 'none'}), "
      f"{sum(s['bend']['unattributed_m'] for s in rest):.0f} m on the other {len(rest)}.")
    p()
    p("## qiu, 200 mm buffer")
    p()
    if not qiu:
        p("qiu was not run for this page (`ROBUSTNESS_METHODS`); its figures on these seeds are in")
        p("the page's git history, from the last run that included it.")
        p()
    p("| [%] | streets | min | 10th pct | median | mean |")
    p("|---|---:|---:|---:|---:|---:|")
    p(dist_row("completeness", [s["qiu"]["total"]["completeness"] for s in qiu], n_all))
    p(dist_row("correctness", [s["qiu"]["total"]["correctness"] for s in qiu], n_all))
    p(dist_row("quality", [s["qiu"]["total"]["quality"] for s in qiu], n_all))
    p(dist_row("far side completeness", [s["qiu"].get("side_" + (s["far"] or ""), {}).get("completeness") for s in qiu], n_all))
    for c in CATS:
        p(dist_row(f"{c} quality", [s["qiu"][c]["quality"] if s["qiu"][c] else None for s in qiu], n_all))
    p()
    p("## Every street")
    p()
    p("| seed | points | line spacing [m] | bend Q | bend C / P | curb | curb cut | intersection | bus bay | bend RMS [mm] | qiu C / P | qiu far C |")
    p("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for s in streets:
        b, q = s["bend"], s["qiu"]
        cat = lambda c: fmt(b[c]["quality"]) if b and b[c] else "–"
        p(f"| {s['seed']} | {s['points'] or '–'} | {fmt(s['spacing_m'], 3)} "
          f"| {fmt(b['total']['quality']) if b else '–'} "
          f"| {fmt(b['total']['completeness']) if b else '–'} / {fmt(b['total']['correctness']) if b else '–'} "
          f"| {cat('curb')} | {cat('curb_cut')} | {cat('intersection')} | {cat('bus_bay')} "
          f"| {fmt(b['rms_mm']) if b else '–'} "
          f"| {fmt(q['total']['completeness']) if q else '–'} / {fmt(q['total']['correctness']) if q else '–'} "
          f"| {fmt(q.get('side_' + (s['far'] or ''), {}).get('completeness')) if q else '–'} |")
    p()
    p("## The worst streets")
    p()
    p("Each picture is a top view around the street's worst place: the longest stretch of")
    p("reference no extracted edge comes within the buffer of, or the longest extracted piece")
    p("outside it, whichever is longer (`curbtrace eval --picture`). Red: reference; black:")
    p("extracted; colour: height above the local ground.")
    p()
    worst_b = sorted(bend, key=lambda s: s["bend"]["total"]["quality"] or 0.0)[:WORST_BEND]
    worst_q = sorted(qiu, key=lambda s: s["qiu"]["total"]["completeness"] or 0.0)[:WORST_QIU]
    for method, buffer, worst, key in [("bend", 0.05, worst_b, "quality"), ("qiu", 0.2, worst_q, "completeness")]:
        for s in worst:
            png, what = picture(bin_path, s, method, buffer)
            p(f"### seed {s['seed']}, {method}: total {key} {fmt(s[method]['total'][key])} %")
            p()
            p(s["description"].replace("seed {}: ".format(s["seed"]), "") + ".")
            p()
            p(f"{what}.")
            p()
            if png:
                p(f"![seed {s['seed']} {method}](robustness/{png.name})")
                p()


if __name__ == "__main__":
    main()
