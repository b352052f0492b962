#!/usr/bin/env python3
"""IFC reader benchmark: framewright vs IfcOpenShell on one big generated model.

One run of this script:
  (a) writes a >= 40 MB wood-frame model with `framewright synth building --grid NxM`,
  (b) times `framewright inspect MODEL --json > /dev/null` (reads every member),
  (c) times `ifcopenshell.open(MODEL)` plus `get_local_placement(m.ObjectPlacement)`
      for every IfcMember / IfcColumn / IfcBeam,
each in its own child process, best-of-N wall time and peak RSS (os.wait4 rusage of
the child), and prints MB/s for both, the speed ratio and peak memory as a multiple
of the file size.

    python3 bench/ifc_read_peer.py                      # cargo build --release, then run
    python3 bench/ifc_read_peer.py --binary PATH --grid 27x27 --runs 5
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CRATE = Path(__file__).resolve().parent.parent
MIN_BYTES = 40_000_000
MIN_MEMBERS = 50_000

# The IfcOpenShell side runs in a child so its peak RSS is its own. It times
# open + placements itself (the import is measured separately as a baseline).
PEER = r"""
import sys, time, json
t0 = time.perf_counter()
import ifcopenshell, ifcopenshell.util.placement
t1 = time.perf_counter()
f = ifcopenshell.open(sys.argv[1])
t_open = time.perf_counter()
n = 0
for cls in ("IfcMember", "IfcColumn", "IfcBeam"):
    for m in f.by_type(cls):
        ifcopenshell.util.placement.get_local_placement(m.ObjectPlacement)
        n += 1
t2 = time.perf_counter()
print(json.dumps({"import_s": t1 - t0, "open_s": t_open - t1, "read_s": t2 - t1, "members": n,
                  "version": ifcopenshell.version}))
"""
IMPORT_ONLY = "import ifcopenshell, ifcopenshell.util.placement"
# Counts the members `inspect --json` reports, in a child: Linux carries a parent's RSS
# high-water mark into ru_maxrss of children it forks later, so this script must never
# hold a big document itself.
COUNT_MEMBERS = r"""
import json, subprocess, sys
doc = json.loads(subprocess.run(sys.argv[1:], capture_output=True, check=True).stdout)
print(len(doc["members"]) if isinstance(doc, dict) and "members" in doc else -1)
"""


def run_child(argv, stdout=subprocess.DEVNULL):
    """Run argv; return (wall seconds, peak RSS bytes, exit code, captured stdout or None)."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(argv, stdout=stdout, stderr=subprocess.PIPE)
    out = proc.stdout.read() if stdout == subprocess.PIPE else None
    err = proc.stderr.read()
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    proc.returncode = os.waitstatus_to_exitcode(status)
    # ru_maxrss is in KiB on Linux.
    return wall, usage.ru_maxrss * 1024, proc.returncode, out, err


def best_of(argv, runs, stdout=subprocess.DEVNULL):
    results = [run_child(argv, stdout) for _ in range(runs)]
    for r in results:
        if r[2] != 0:
            return None, results[0]
    best = min(results, key=lambda r: r[0])
    peak = max(r[1] for r in results)
    return (best[0], peak, best[3]), results[0]


def find_binary(args):
    if args.binary:
        return Path(args.binary)
    print("building: cargo build --release", flush=True)
    subprocess.run(["cargo", "build", "--release", "--quiet"], cwd=CRATE, check=True)
    return CRATE / "target" / "release" / "framewright"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--binary", help="framewright binary (default: cargo build --release)")
    ap.add_argument("--grid", default="27x27", help="building grid NxM (default 27x27: ~45 MB, ~103k members)")
    ap.add_argument("--runs", type=int, default=3, help="best-of-N runs per reader (default 3)")
    ap.add_argument("--model", help="where to write the model (default: a temporary directory)")
    ap.add_argument("--results", help="also write the figures as JSON here")
    args = ap.parse_args()

    binary = find_binary(args)
    tmp = tempfile.TemporaryDirectory(prefix="framewright-bench-")
    model = Path(args.model) if args.model else Path(tmp.name) / f"bench_grid_{args.grid}.ifc"

    # (a) generate
    t0 = time.perf_counter()
    gen = subprocess.run([str(binary), "synth", "building", "--grid", args.grid, "-o", str(model)],
                         capture_output=True, text=True)
    gen_s = time.perf_counter() - t0
    if gen.returncode != 0:
        sys.exit(f"generation failed: {gen.stderr.strip()}")
    size = model.stat().st_size
    mb = size / 1e6
    members = int(gen.stdout.split(": ")[1].split(" members")[0])
    print(f"model: {model} ({mb:.1f} MB, {members} members; written in {gen_s:.2f} s, {mb / gen_s:.0f} MB/s)")
    if size < MIN_BYTES or members < MIN_MEMBERS:
        print(f"warning: below the benchmark's minimum ({MIN_BYTES / 1e6:.0f} MB, {MIN_MEMBERS} members); use a bigger --grid")

    figures = {"model_bytes": size, "members": members, "grid": args.grid, "runs": args.runs,
               "generate_s": gen_s}

    # (b) framewright inspect
    rust, first = best_of([str(binary), "inspect", str(model), "--json"], args.runs)
    if rust is None:
        msg = first[4].decode(errors="replace").strip()
        print(f"framewright inspect: not available yet (exit {first[2]}: {msg}); its figures are skipped")
    else:
        figures["framewright"] = {"wall_s": rust[0], "peak_rss_bytes": rust[1]}
    # (c) IfcOpenShell
    py = sys.executable
    base, first = best_of([py, "-c", IMPORT_ONLY], args.runs)
    if base is None:
        print(f"ifcopenshell: not importable ({first[4].decode(errors='replace').strip()[-200:]}); "
              "install it with `pip install ifcopenshell`")
    else:
        runs = []
        for _ in range(args.runs):
            wall, rss, code, out, err = run_child([py, "-c", PEER, str(model)], subprocess.PIPE)
            if code != 0:
                sys.exit(f"ifcopenshell run failed: {err.decode(errors='replace')[-500:]}")
            runs.append((json.loads(out), wall, rss))
        best = min(runs, key=lambda r: r[0]["read_s"])
        figures["ifcopenshell"] = {
            "version": best[0]["version"],
            "read_s": best[0]["read_s"],
            "open_s": best[0]["open_s"],
            "process_wall_s": min(r[1] for r in runs),
            "peak_rss_bytes": max(r[2] for r in runs),
            "import_baseline_rss_bytes": base[1],
            "members_read": best[0]["members"],
        }

    # Not timed, after all measurements: did inspect report every member?
    if "framewright" in figures:
        _, _, code, out, _ = run_child([sys.executable, "-c", COUNT_MEMBERS, str(binary), "inspect", str(model),
                                        "--json"], subprocess.PIPE)
        n = int(out) if code == 0 and int(out) >= 0 else None
        figures["framewright"]["members_reported"] = n
        if n is None:
            print("note: could not count the members in inspect's JSON (no top-level 'members' list)")
        elif n != members:
            print(f"warning: inspect reported {n} members, the model has {members}")

    print()
    print(f"{'reader':<34} {'time s':>8} {'MB/s':>8} {'peak RSS MB':>12} {'RSS/file':>9}")
    fw = figures.get("framewright")
    if fw:
        print(f"{'framewright inspect --json':<34} {fw['wall_s']:>8.3f} {mb / fw['wall_s']:>8.1f} "
              f"{fw['peak_rss_bytes'] / 1e6:>12.1f} {fw['peak_rss_bytes'] / size:>8.2f}x")
        print(f"  (framewright: {fw.get('members_reported')} members reported)")
    ios = figures.get("ifcopenshell")
    if ios:
        label = f"ifcopenshell {ios['version']} open+placements"
        print(f"{label:<34} {ios['read_s']:>8.3f} {mb / ios['read_s']:>8.1f} "
              f"{ios['peak_rss_bytes'] / 1e6:>12.1f} {ios['peak_rss_bytes'] / size:>8.2f}x")
        print(f"  (ifcopenshell: open {ios['open_s']:.3f} s + placements {ios['read_s'] - ios['open_s']:.3f} s; "
              f"whole child process {ios['process_wall_s']:.3f} s incl. import; "
              f"interpreter + import alone peak RSS {ios['import_baseline_rss_bytes'] / 1e6:.1f} MB; "
              f"{ios['members_read']} members read)")
    if fw and ios:
        ratio = ios["read_s"] / fw["wall_s"]
        figures["speed_ratio"] = ratio
        print(f"speed ratio (ifcopenshell time / framewright time): {ratio:.2f}x")
    if args.results:
        Path(args.results).write_text(json.dumps(figures, indent=2) + "\n")


if __name__ == "__main__":
    main()
