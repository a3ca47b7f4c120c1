#!/usr/bin/env python3
"""Every mobile variant's mean FLIP against the truth (goldens/reference/) on the roughness sweep.

The variants and environments are the nightly suite's mobile roughness_sweep entry
(harness/suites/nightly.json), so the table follows the suite. It runs them once (no timing
repeats, no baselines) through `iblcheck run` and prints one row per variant, one column per
environment, plus the row mean:

    scripts/variant_accuracy.py > after.txt
    scripts/variant_accuracy.py --before before.txt      # before -> after, side by side
    scripts/variant_accuracy.py --before before.txt --after after.txt   # the same from two saved tables

With --before, each cell is "before -> after" read from an earlier output of this script (rows are
matched by variant name; a variant that is new or gone shows '-'). Run it with `nice` on a shared
machine: 38 variants x 4 environments, about a minute of CPU per environment on 2 cores.
Exit: 0; 2 when the tool, the suite or the run fails (the message says which).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def fail(msg):
    print(f"variant_accuracy: {msg}", file=sys.stderr)
    sys.exit(2)


def sweep_suite(nightly_path):
    """The nightly's mobile roughness_sweep entry as a one-test suite: one render per test."""
    try:
        with open(nightly_path) as f:
            nightly = json.load(f)
    except (OSError, json.JSONDecodeError) as e:
        fail(f"{nightly_path}: {e}")
    entries = [t for t in nightly.get("tests", []) if t.get("method") == "mobile" and t.get("scene") == "roughness_sweep"]
    if not entries:
        fail(f"{nightly_path}: no mobile roughness_sweep test")
    tests = [dict(t, baseline=False) for t in entries]
    return {"suite": "variant_accuracy", "description": "scripts/variant_accuracy.py",
            "defaults": {"jobs": 1, "timing_repeats": 1}, "tests": tests}


def run_table(tool, goldens, nightly_path, filt):
    with tempfile.TemporaryDirectory(prefix="variant_accuracy.") as tmp:
        suite_path = os.path.join(tmp, "variant_accuracy.json")
        with open(suite_path, "w") as f:
            json.dump(sweep_suite(nightly_path), f)
        out = os.path.join(tmp, "out")
        cmd = [tool, "run", "--suite", suite_path, "--out", out, "--goldens", goldens, "-q"]
        if filt:
            cmd += ["--filter", filt]
        r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if r.returncode not in (0, 1):
            fail(f"{' '.join(cmd)} exited {r.returncode}:\n{r.stdout[-2000:]}")
        with open(os.path.join(out, "results.json")) as f:
            results = json.load(f)
    table, envs = {}, []
    for t in results["tests"]:
        acc = t.get("accuracy")
        if t.get("verdict") == "error":
            fail(f"{t['name']}: {t.get('message', '')}")
        env = t["env"]
        if not isinstance(acc, dict):  # no truth for these options (e.g. ao: its own golden), shown as '-'
            table.setdefault(t.get("variant") or "default", {})
            continue
        if env not in envs:
            envs.append(env)
        table.setdefault(t.get("variant") or "default", {})[env] = acc["flip_mean"]
    return table, envs


def read_table(path):
    """An earlier output of this script: header 'variant ENV... mean', then one row per variant."""
    with open(path) as f:
        lines = [l.split() for l in f if l.strip() and not l.startswith("#")]
    envs = lines[0][1:-1]
    table = {}
    for row in lines[1:]:
        table[row[0]] = {e: float(v) for e, v in zip(envs, row[1:-1]) if v != "-"}
    return table, envs


def mean(values):
    return sum(values) / len(values) if values else None


def print_table(table, envs, before=None):
    width = max(len(v) for v in list(table) + list(before or {})) + 2
    if before is None:
        print("variant".ljust(width) + "".join(e.rjust(17) for e in envs) + "mean".rjust(9))
        for v, row in table.items():
            cells = "".join((f"{row[e]:.4f}" if e in row else "-").rjust(17) for e in envs)
            m = mean([row[e] for e in envs if e in row])
            print(v.ljust(width) + cells + (f"{m:.4f}" if m is not None else "-").rjust(9))
        return
    print("# mean FLIP vs the truth, before -> after")
    print("variant".ljust(width) + "".join(e.rjust(19) for e in envs) + "mean".rjust(19))
    for v in list(before) + [v for v in table if v not in before]:
        b, a = before.get(v, {}), table.get(v, {})
        cells = ""
        for e in envs:
            bs = f"{b[e]:.4f}" if e in b else "-"
            as_ = f"{a[e]:.4f}" if e in a else "-"
            cells += f"{bs} -> {as_}".rjust(19)
        bm, am = mean([b[e] for e in envs if e in b]), mean([a[e] for e in envs if e in a])
        cells += f"{bm:.4f} -> {am:.4f}".rjust(19) if bm is not None and am is not None else "-".rjust(19)
        print(v.ljust(width) + cells)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--iblcheck", default=os.path.join(ROOT, "build", "iblcheck"))
    ap.add_argument("--goldens", default=os.path.join(ROOT, "goldens"))
    ap.add_argument("--suite", default=os.path.join(ROOT, "harness", "suites", "nightly.json"))
    ap.add_argument("--filter", help="glob on test names (a subset)")
    ap.add_argument("--before", help="an earlier output of this script: print before -> after")
    ap.add_argument("--after", help="with --before: a saved output to compare instead of running the table")
    args = ap.parse_args()
    if not args.after and not os.access(args.iblcheck, os.X_OK):
        fail(f"{args.iblcheck}: not an executable (build it: scripts/build.sh)")
    before = None
    if args.before:
        try:
            before, _ = read_table(args.before)
        except (OSError, ValueError, IndexError) as e:
            fail(f"{args.before}: not an output of this script ({e})")
    if args.after:
        if before is None:
            fail("--after needs --before")
        try:
            table, envs = read_table(args.after)
        except (OSError, ValueError, IndexError) as e:
            fail(f"{args.after}: not an output of this script ({e})")
    else:
        table, envs = run_table(args.iblcheck, args.goldens, args.suite, args.filter)
    print_table(table, envs, before)


if __name__ == "__main__":
    main()
