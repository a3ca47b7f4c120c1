#!/usr/bin/env python3
"""Specular AA swept: flicker against accuracy for σ² (specular_aa_variance), κ
(specular_aa_threshold) and the derivative source (shading=compute: neighbouring pixels' rays;
shading=fragment: the hardware quads), on the temporal suite's scenes (issue 28).

Each configuration of harness/suites/temporal.json (bumpy_sphere under sky_sun and studio, 32
frames; sphere_field under sky_sun through both paths, 16 frames) is rendered with specular_aa=off
and each variant at each (σ², κ) of the grid, and scored against the quadrature truth of every
frame (goldens/reference/*__frames=N.exr): mean LDR-FLIP and flicker (frame-to-frame change the
truth does not have). One table per configuration, each row marked '*' when it is on the Pareto
front (no other row has both less flicker and less FLIP), plus a verdict line: the rows that
reduce flicker against off without costing accuracy (FLIP no worse than off's + --flip-slack).

    nice scripts/specular_aa_sweep.py                  # the default grid (about 10 min of CPU on 2 cores)
    nice scripts/specular_aa_sweep.py --filter '*sphere_field*' --variance 0.02,0.25 --threshold 0.18
    scripts/specular_aa_sweep.py --results OLD/results.json    # tables from a stored run

Not part of CTest: it measures, it does not judge (measure_only tests). Exit: 0; 2 when the tool,
the suite or the run fails (the message says which).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
VARIANTS = ("tokuyoshi", "rjump", "toksvig")


def fail(msg):
    print(f"specular_aa_sweep: {msg}", file=sys.stderr)
    sys.exit(2)


def floats(text):
    try:
        return [float(v) for v in text.split(",") if v]
    except ValueError:
        fail(f"'{text}': not a comma-separated list of numbers")


def sweep_suite(temporal_path, variances, thresholds):
    """The temporal suite's configurations (one per scene, env and options), each with off and the grid."""
    try:
        with open(temporal_path) as f:
            temporal = json.load(f)
    except (OSError, json.JSONDecodeError) as e:
        fail(f"{temporal_path}: {e}")
    configs = {}
    for t in temporal.get("tests", []):
        key = json.dumps([t["scene"], t["env"], t.get("options", {}), t["temporal"].get("reference_options", {})])
        configs.setdefault(key, t)
    grid = [{"specular_aa": "off"}]
    for v in VARIANTS:
        for s in variances:
            for k in thresholds:
                grid.append({"specular_aa": v, "specular_aa_variance": s, "specular_aa_threshold": k})
    tests = []
    for t in configs.values():
        temporal_spec = {k: v for k, v in t["temporal"].items() if k != "checks"}
        tests.append({"scene": t["scene"], "method": t["method"], "env": t["env"], "options": t.get("options", {}),
                      "variants": grid, "baseline": False, "reference": False, "temporal": temporal_spec,
                      "measure_only": True})
    return {"suite": "specular_aa_sweep", "description": "scripts/specular_aa_sweep.py",
            "defaults": {"jobs": 2}, "tests": tests}


def run_sweep(tool, goldens, temporal_path, variances, thresholds, filt, keep):
    tmp = keep or tempfile.mkdtemp(prefix="specular_aa_sweep.")
    os.makedirs(tmp, exist_ok=True)
    suite_path = os.path.join(tmp, "specular_aa_sweep.json")
    with open(suite_path, "w") as f:
        json.dump(sweep_suite(temporal_path, variances, thresholds), f, indent=1)
    out = os.path.join(tmp, "out")
    cmd = [tool, "run", "--suite", suite_path, "--out", out, "--goldens", goldens, "-q", "--force"]
    if filt:
        cmd += ["--filter", filt]
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if r.returncode not in (0, 1):
        fail(f"{' '.join(cmd)} exited {r.returncode}:\n{r.stdout[-2000:]}")
    print(f"# results: {os.path.join(out, 'results.json')}")
    return os.path.join(out, "results.json")


def rows_by_config(results_path):
    """(scene, env, shading) -> rows of (label, flicker, flip) against the truth; off first."""
    with open(results_path) as f:
        results = json.load(f)
    configs = {}
    for t in results["tests"]:
        if t.get("verdict") == "error":
            fail(f"{t['name']}: {t.get('message', '')}")
        truth = t.get("temporal", {}).get("truth", {})
        if "flip_mean" not in truth:
            fail(f"{t['name']}: no temporal truth ({truth.get('missing', 'not in results')})")
        opts = t.get("options", {})
        key = (t["scene"], t["env"], opts.get("shading", "compute"))
        rows = configs.setdefault(key, [("off", truth["off"]["flicker"], truth["off"]["flip_mean"])])
        if opts.get("specular_aa", "off") == "off":
            continue
        label = f"{opts['specular_aa']} s2={float(opts['specular_aa_variance']):g} k={float(opts['specular_aa_threshold']):g}"
        rows.append((label, truth["flicker"], truth["flip_mean"]))
    return configs


def front(rows):
    """Labels of the rows no other row beats in both flicker and FLIP."""
    return {r[0] for r in rows if not any(o[1] <= r[1] and o[2] <= r[2] and (o[1] < r[1] or o[2] < r[2]) for o in rows)}


def print_tables(configs, flip_slack):
    for (scene, env, shading), rows in configs.items():
        off = rows[0]
        on_front = front(rows)
        print(f"\n## {scene}, {env}, shading={shading} (against the truth; change against off)")
        print(f"{'variant':34}{'flicker':>9}{'Δflicker':>10}{'FLIP':>8}{'ΔFLIP':>9}  front")
        for label, flick, flip in rows:
            df, dp = (flick / off[1] - 1) * 100, (flip / off[2] - 1) * 100
            print(f"{label:34}{flick:9.5f}{df:+9.0f}%{flip:8.4f}{dp:+8.0f}%  {'*' if label in on_front else ''}")
        helps = [r[0] for r in rows[1:] if r[1] < off[1] and r[2] <= off[2] + flip_slack]
        print(f"less flicker at FLIP <= off + {flip_slack}: {', '.join(helps) if helps else 'none'}")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--iblcheck", default=os.path.join(ROOT, "build", "iblcheck"))
    ap.add_argument("--goldens", default=os.path.join(ROOT, "goldens"))
    ap.add_argument("--suite", default=os.path.join(ROOT, "harness", "suites", "temporal.json"))
    ap.add_argument("--variance", default="0.02,0.0625,0.25", help="σ² values (comma-separated)")
    ap.add_argument("--threshold", default="0.02,0.18", help="κ values (comma-separated)")
    ap.add_argument("--filter", help="glob on test names (a subset)")
    ap.add_argument("--keep", help="write the suite and the run into this folder (kept)")
    ap.add_argument("--results", help="print the tables of a stored run's results.json instead of running")
    ap.add_argument("--flip-slack", type=float, default=0.002, help="FLIP above off's that still counts as no cost")
    args = ap.parse_args()
    results = args.results
    if not results:
        if not os.access(args.iblcheck, os.X_OK):
            fail(f"{args.iblcheck}: not an executable (build it: scripts/build.sh)")
        results = run_sweep(args.iblcheck, args.goldens, args.suite, floats(args.variance), floats(args.threshold),
                            args.filter, args.keep)
    print_tables(rows_by_config(results), args.flip_slack)


if __name__ == "__main__":
    main()
