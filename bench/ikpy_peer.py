#!/usr/bin/env python3
"""Time IKPy and framewright on the same robot and the same poses, in one run.

1. Draws N joint vectors inside the URDF limits (fixed seed; joints with more than a full turn
   are drawn in [-pi, pi]) and computes their tool0 poses with IKPy's own FK on framewright's
   URDF, so every target is reachable.
2. Writes the poses to a file, one `x y z qw qx qy qz` per line.
3. Times IKPy's full-pose solve (position + orientation, orientation_mode="all", default zero
   seed) on each pose with time.perf_counter, one call at a time.
4. Runs `framewright robot ik ROBOT --poses FILE --json --stats` on the same file. The --stats
   line gives the in-process time of each Robot::ik call (all solutions within limits, sorted,
   each checked by FK; no parsing or output). The process wall time per pose is shown too.
5. Checks every framewright solution with IKPy's FK (independent of framewright's FK), and
   IKPy's answer the same way, and prints both medians, both success rates and the ratio.

Success: framewright, every returned solution within 1e-6 m and 1e-6 rad; IKPy, the study's
criterion (position < 1 mm and rotation < 0.01 rad) and the strict one (1e-6 m, 1e-6 rad).

Usage: python3 bench/ikpy_peer.py [--robot abb-irb4600-40-255] [--n 200] [--seed 1]
                                  [--bin target/release/framewright] [--json OUT]
                                  [--ikpy-n K] [--runs R]
The issue's figure: --n 10000 --ikpy-n 1000 (IKPy's per-pose median from 1,000 of the poses;
framewright's whole process on all 10,000, best of R runs, with every solution and --closest).
Needs: pip install ikpy (brings numpy and scipy); a release build (cargo build --release).
"""
import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
import warnings

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def rot_angle(ra, rb):
    c = (np.trace(ra.T @ rb) - 1.0) / 2.0
    return math.acos(max(-1.0, min(1.0, c)))


def quat_wxyz(r):
    """Unit quaternion (w, x, y, z) of a rotation matrix (Shepperd's method)."""
    t = np.trace(r)
    if t > 0:
        s = math.sqrt(t + 1.0) * 2
        return ((0.25 * s), (r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s)
    i = int(np.argmax([r[0, 0], r[1, 1], r[2, 2]]))
    if i == 0:
        s = math.sqrt(1.0 + r[0, 0] - r[1, 1] - r[2, 2]) * 2
        return ((r[2, 1] - r[1, 2]) / s, 0.25 * s, (r[0, 1] + r[1, 0]) / s, (r[0, 2] + r[2, 0]) / s)
    if i == 1:
        s = math.sqrt(1.0 + r[1, 1] - r[0, 0] - r[2, 2]) * 2
        return ((r[0, 2] - r[2, 0]) / s, (r[0, 1] + r[1, 0]) / s, 0.25 * s, (r[1, 2] + r[2, 1]) / s)
    s = math.sqrt(1.0 + r[2, 2] - r[0, 0] - r[1, 1]) * 2
    return ((r[1, 0] - r[0, 1]) / s, (r[0, 2] + r[2, 0]) / s, (r[1, 2] + r[2, 1]) / s, 0.25 * s)


def pct(xs, p):
    xs = sorted(xs)
    k = (len(xs) - 1) * p / 100.0
    f = math.floor(k)
    c = min(f + 1, len(xs) - 1)
    return xs[f] + (xs[c] - xs[f]) * (k - f)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--robot", default="abb-irb4600-40-255")
    ap.add_argument("--n", type=int, default=200)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--bin", default=os.path.join(ROOT, "target", "release", "framewright"))
    ap.add_argument("--json", default=None, help="write all figures to this file")
    ap.add_argument("--ikpy-n", type=int, default=None,
                    help="time IKPy on the first K poses only (its per-pose median); default: all")
    ap.add_argument("--runs", type=int, default=3, help="framewright processes timed (best of)")
    args = ap.parse_args()

    import ikpy
    import ikpy.chain

    urdf = os.path.join(ROOT, "robots", args.robot + ".urdf")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        probe = ikpy.chain.Chain.from_urdf_file(urdf, base_elements=["base_link"])
        mask = [link.joint_type == "revolute" for link in probe.links]
        chain = ikpy.chain.Chain.from_urdf_file(urdf, base_elements=["base_link"], active_links_mask=mask)
    active = [i for i, m in enumerate(mask) if m]
    if len(active) != 6:
        sys.exit(f"expected 6 revolute joints in {urdf}, found {len(active)}")

    rng = np.random.default_rng(args.seed)
    targets = []
    for _ in range(args.n):
        full = np.zeros(len(chain.links))
        for i in active:
            lo, hi = chain.links[i].bounds
            lo, hi = max(lo, -math.pi), min(hi, math.pi)
            full[i] = rng.uniform(lo, hi)
        targets.append(chain.forward_kinematics(full))

    tmp = tempfile.mkdtemp(prefix="ikpy_peer_")
    poses_file = os.path.join(tmp, "poses.txt")
    with open(poses_file, "w") as f:
        for t in targets:
            w, x, y, z = quat_wxyz(t[:3, :3])
            f.write(" ".join("%.17g" % v for v in (t[0, 3], t[1, 3], t[2, 3], w, x, y, z)) + "\n")

    def residual(full_q, t):
        fk = chain.forward_kinematics(full_q)
        return float(np.linalg.norm(fk[:3, 3] - t[:3, 3])), rot_angle(fk[:3, :3], t[:3, :3])

    # --- IKPy ---
    load_before = os.getloadavg()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        chain.inverse_kinematics(target_position=targets[0][:3, 3], target_orientation=targets[0][:3, :3],
                                 orientation_mode="all")  # warm-up
        ikpy_times, ikpy_cpu, ikpy_ok, ikpy_strict = [], [], 0, 0
        for t in targets[:args.ikpy_n or len(targets)]:
            c0 = time.thread_time()
            t0 = time.perf_counter()
            sol = chain.inverse_kinematics(target_position=t[:3, 3], target_orientation=t[:3, :3],
                                           orientation_mode="all")
            ikpy_times.append(time.perf_counter() - t0)
            ikpy_cpu.append(time.thread_time() - c0)
            dp, dr = residual(sol, t)
            ikpy_ok += dp < 1e-3 and dr < 0.01
            ikpy_strict += dp <= 1e-6 and dr <= 1e-6
    # Python-side costs that IKPy's figure contains and framewright's does not.
    t0 = time.perf_counter()
    for _ in range(2000):
        chain.forward_kinematics(np.zeros(len(chain.links)))
    fk_us = (time.perf_counter() - t0) / 2000 * 1e6

    # --- framewright, same poses ---
    if not os.path.exists(args.bin):
        sys.exit(f"{args.bin} not found: run `cargo build --release` first")
    def timed(extra):
        """Best whole-process wall time of `args.runs` runs, and the last run."""
        best = math.inf
        for _ in range(max(1, args.runs)):
            t0 = time.perf_counter()
            run = subprocess.run([args.bin, "robot", "ik", args.robot, "--poses", poses_file, "--json",
                                  "--stats"] + extra, capture_output=True, text=True)
            best = min(best, time.perf_counter() - t0)
            if run.returncode != 0:
                sys.exit(f"framewright failed ({run.returncode}): {run.stderr}")
        return best, run

    wall, run = timed([])
    # One answer per pose, as IKPy gives: the closest of all solutions (all are still computed).
    wall_closest, run_closest = timed(["--closest"])
    stats = json.loads(run.stderr.strip().splitlines()[-1])
    answers = [json.loads(line) for line in run.stdout.splitlines()]
    assert len(answers) == len(targets), (len(answers), len(targets))
    fw_ok, n_solutions, worst = 0, 0, 0.0
    for t, a in zip(targets, answers):
        sols = a.get("solutions")
        if not sols:
            continue
        good = True
        for q in sols:
            full = np.zeros(len(chain.links))
            for i, v in zip(active, q):
                full[i] = v
            dp, dr = residual(full, t)
            worst = max(worst, dp)
            good &= dp <= 1e-6 and dr <= 1e-6
        n_solutions += len(sols)
        fw_ok += good
    closest = [json.loads(line) for line in run_closest.stdout.splitlines()]
    assert all(c.get("solutions", [None])[:1] == a.get("solutions", [None])[:1]
               for c, a in zip(closest, answers)), "--closest must print the first of all solutions"
    load_after = os.getloadavg()

    n_ikpy = len(ikpy_times)
    ikpy_med = statistics.median(ikpy_times) * 1e6
    # Thread CPU time is less disturbed by other processes on a shared machine than wall time
    # (a 10 ms call is preempted often, a 3 us call rarely), so its ratio is the conservative one.
    ikpy_cpu_med = statistics.median(ikpy_cpu) * 1e6
    fw_med = stats["median_us"]
    out = {
        "robot": args.robot,
        "n": args.n,
        "seed": args.seed,
        "ikpy_version": getattr(ikpy, "__version__", "?"),
        "ikpy_median_us": ikpy_med,
        "ikpy_p95_us": pct(ikpy_times, 95) * 1e6,
        "ikpy_cpu_median_us": ikpy_cpu_med,
        "ikpy_success_study": ikpy_ok / n_ikpy,
        "ikpy_success_strict": ikpy_strict / n_ikpy,
        "ikpy_fk_call_us": fk_us,
        "framewright_median_us": fw_med,
        "framewright_p95_us": stats["p95_us"],
        "framewright_success_strict": fw_ok / args.n,
        "framewright_solutions_per_pose": n_solutions / args.n,
        "framewright_worst_position_error_m": worst,
        "framewright_cli_wall_per_pose_us": wall / args.n * 1e6,
        "ratio_median": ikpy_med / fw_med,
        "ratio_ikpy_cpu_median": ikpy_cpu_med / fw_med,
        "ratio_cli_wall": ikpy_med / (wall / args.n * 1e6),
        "framewright_cli_closest_wall_per_pose_us": wall_closest / args.n * 1e6,
        "ratio_cli_closest_wall": ikpy_med / (wall_closest / args.n * 1e6),
        "ikpy_poses_timed": n_ikpy,
        "loadavg_before_after": [load_before[0], load_after[0]],
    }
    print(f"robot {args.robot}, {args.n} reachable poses (seed {args.seed}), ikpy {out['ikpy_version']}")
    print(f"IKPy full pose, zero seed: median {ikpy_med:9.1f} us  p95 {out['ikpy_p95_us']:9.1f} us  "
          f"success {100 * out['ikpy_success_study']:.1f} % (1 mm / 0.01 rad), "
          f"{100 * out['ikpy_success_strict']:.1f} % (1e-6)")
    print(f"framewright Robot::ik:     median {fw_med:9.2f} us  p95 {stats['p95_us']:9.2f} us  "
          f"success {100 * out['framewright_success_strict']:.1f} % (every solution within 1e-6 m/rad, "
          f"checked with IKPy's FK), {out['framewright_solutions_per_pose']:.1f} solutions per pose")
    print(f"ratio of medians (IKPy / framewright): {out['ratio_median']:.0f}x wall; "
          f"{out['ratio_ikpy_cpu_median']:.0f}x with IKPy's thread CPU time (median {ikpy_cpu_med:.1f} us)")
    print(f"framewright CLI end to end (process start, parsing, JSON): {out['framewright_cli_wall_per_pose_us']:.1f} "
          f"us per pose -> {out['ratio_cli_wall']:.0f}x (every solution printed, best of {args.runs})")
    print(f"framewright CLI end to end, --closest (one answer per pose, as IKPy): "
          f"{out['framewright_cli_closest_wall_per_pose_us']:.1f} us per pose -> {out['ratio_cli_closest_wall']:.0f}x")
    print(f"note: IKPy's time includes Python/numpy call overhead (one IKPy FK call costs {fk_us:.1f} us here); "
          f"framewright's median is the in-process time of one call. load average {load_before[0]:.2f} -> {load_after[0]:.2f}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=2, sort_keys=True)


if __name__ == "__main__":
    main()
