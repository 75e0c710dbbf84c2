#!/usr/bin/env python3
"""Times every calibration method on the shipped UR5 laser-tracker data, one
method a run, and prints each one's time relative to SKCM's: the figures the
`weight` column of the methods table (core/src/calibrate/identify/methods/
mod.rs) is set from, so that the progress bar's planned work, and with it the
time left, follows where the time goes.

Each run is

    robocal calibrate --model ur5 --identify data/.../3D_UR5_uncalibrated_grid_cleaned.csv
        --validate data/.../3D_UR5_uncalibrated_random_cleaned.csv
        --method M --cv-folds 5 --threads 1 --seed 1

with its progress lines on standard error read as they arrive: the method's
time is the processor time (user and system, /proc and wait4) the process
spends from its first progress line (the registration and the
identifiability before it are left out, as they are outside the methods' share
of the bar) to its end; on one thread that is its work whatever else the
machine runs, so the methods run side by side. Methods shorter than `--short`
seconds run `--repeat` times and keep the mean (the clock ticks in 10 ms).
With `--deadline S` a run still going after S seconds is stopped and its time
extrapolated from its last progress line: its processor time in the method
over the share of the method's bar done (the method runs from 10 to 100 %).

    scripts/method_weights.py [--robocal target/release/robocal] [--methods km,skcm,...]
    scripts/method_weights.py --eta auto [--robocal ...]

`--eta M1,M2,...` runs that job once instead and prints every progress line that
states a time left beside the time that was actually left (the process's end
less the line's arrival), then the first line at or past 5, 10, 25, 50 and
75 % with its stated and actual time left and their ratio: how right the
estimate is, early and late. The time left is wall-clock time, so unlike the
weights it depends on what else the machine runs; beside it the same
estimator on the process's processor time (from the methods' first line) and
the processor time actually left, which judge the plan's weights alone.
`--threads N` runs that job on N threads (1 by default, as the weights).

The weight of a method is its time over SKCM's, except `skcm-tlbo`'s, from which
KM's warm start is taken off (the plan counts KM's fit apart,
core/src/calibrate/identify/methods/plan.rs).
"""
import argparse
import os
import pathlib
import re
import signal
import statistics
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor

ROOT = pathlib.Path(__file__).resolve().parent.parent
DATA = ROOT / "data/ur5-wam-laser-tracker/UR5"
GRID = DATA / "3D_UR5_uncalibrated_grid_cleaned.csv"
RANDOM = DATA / "3D_UR5_uncalibrated_random_cleaned.csv"
# Every method but `auto`, in the table's order; `auto` on request.
METHODS = ("km,skcm,skcm-tlbo,skcm-payload,km-maps,skcm-maps,km-rbf,skcm-nn,"
           "skcm-iwonn,skcm-tlbonn,km-gp,skcm-gp,km-maps-gp,skcm-maps-gp")


# A plain progress line: `[ 31.4%] auto · skcm-nn · fold 3/9 · ... · 1 min 20 s left`.
LINE = re.compile(r"^\[\s*([0-9.]+)%\] (\S+)(.*)$")
LEFT = re.compile(r"· (?:(\d+) h (\d+) min|(\d+) min (\d+) s|(\d+) s) left$")


def seconds_left(text):
    """The seconds of `42 s`, `3 min 05 s`, `1 h 02 min` left, or None."""
    m = LEFT.search(text)
    if not m:
        return None
    h, hm, mi, ms, s = (int(g) if g else 0 for g in m.groups())
    return h * 3600 + hm * 60 + mi * 60 + ms + s


def cpu_s(pid):
    """Processor seconds (user and system) process `pid` has used so far."""
    fields = pathlib.Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def run(robocal, methods, threads=1):
    """Runs one calibration; (start, end, lines) with each progress line as
    (arrival, percent, phase, rest, processor seconds so far); `start` and
    `end` as (wall, processor) seconds."""
    cmd = [robocal, "calibrate", "--model", "ur5", "--identify", str(GRID),
           "--validate", str(RANDOM), "--method", methods, "--cv-folds", "5",
           "--threads", str(threads), "--seed", "1"]
    start = time.monotonic()
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if deadline is not None:
        threading.Timer(max(0.0, deadline - time.monotonic()), stop, (p,)).start()
    lines = []
    for line in p.stderr:
        m = LINE.match(line.rstrip("\n"))
        if m:
            lines.append((time.monotonic(), float(m.group(1)), m.group(2), m.group(3), cpu_s(p.pid)))
    _, status, usage = os.wait4(p.pid, 0)
    end = time.monotonic()
    if status != 0 and not (deadline is not None and end >= deadline):
        raise SystemExit(f"{' '.join(cmd)} exited with status {status}")
    return (start, 0.0), (end, usage.ru_utime + usage.ru_stime), lines, status == 0


# With --deadline: the monotonic time at which runs still going are stopped.
deadline = None


def stop(p):
    """Stops a run at the deadline (its last progress line is then used)."""
    if p.poll() is None:
        p.send_signal(signal.SIGTERM)


def timed(robocal, method):
    """Processor seconds from the method's first progress line to the end,
    and before it: the work, whatever else the machine runs."""
    _, (_, cpu_end), lines, finished = run(robocal, method)
    began = next((cpu for _, _, phase, _, cpu in lines if phase == method), None)
    if began is None:
        raise SystemExit(f"{method}: no progress line of the method on standard error")
    if finished:
        return cpu_end - began, began, None
    # Stopped at the deadline: the method's processor time so far over the
    # share of its bar (10-100 %) its last progress line reached.
    _, percent, _, _, cpu = lines[-1]
    share = (percent - 10.0) / 90.0
    if share <= 0.0:
        raise SystemExit(f"{method}: stopped before any of its work was reported")
    return (cpu - began) / share, began, percent


# Where `--eta` sets the stated time left beside the actual one.
MILESTONES = (5.0, 10.0, 25.0, 50.0, 75.0)


def eta(robocal, methods, threads):
    """Every stated time left of one job beside the time actually left, then
    the first report at or past each of `MILESTONES` percent: its stated and
    actual time left and their ratio; and the same in processor time, where
    the estimator (the program's, on processor seconds from the first line of
    a method) is judged on the planned work alone, whatever else the machine
    runs."""
    (start, _), (end, cpu_end), lines, finished = run(robocal, methods, threads)
    if not finished:
        raise SystemExit(f"{methods}: stopped before its end")
    print(f"{methods}: {end - start:.1f} s in all, {cpu_end:.1f} processor s, {threads} thread(s)")
    print(f"{'elapsed s':>9} {'cpu s':>7} {'percent':>7} {'stated s':>8} {'actual s':>8}  where")
    for t, percent, phase, rest, cpu in lines:
        left = seconds_left(rest)
        if left is not None:
            print(f"{t - start:9.1f} {cpu:7.1f} {percent:7.1f} {left:8d} {end - t:8.1f}  "
                  f"{phase}{LEFT.sub('', rest).split(' · iteration')[0]}")
    # The methods' first line: the anchor of the estimate.
    anchor = next(((cpu, percent) for _, percent, phase, _, cpu in lines
                   if phase not in ("registration", "identifiability")), None)
    print()
    print(f"{'at':>4} {'report':>7} {'elapsed s':>9} {'stated s':>8} {'actual s':>8} {'ratio':>6}"
          f" {'cpu est s':>9} {'cpu left s':>10} {'ratio':>6}")
    for at in MILESTONES:
        first = next(((t, percent, seconds_left(rest), cpu) for t, percent, _, rest, cpu in lines
                      if percent >= at), None)
        if first is None:
            print(f"{at:3.0f}% {'none':>7}")
            continue
        t, percent, left, cpu = first
        actual = end - t
        stated = "none" if left is None else f"{left:d}"
        ratio = "" if left is None or actual <= 0 else f"{left / actual:.2f}"
        cpu_est, cpu_ratio = "none", ""
        if anchor is not None and percent - anchor[1] >= 0.01 * (100.0 - anchor[1]):
            est = (cpu - anchor[0]) * (100.0 - percent) / (percent - anchor[1])
            cpu_est = f"{est:.1f}"
            if cpu_end - cpu > 0:
                cpu_ratio = f"{est / (cpu_end - cpu):.2f}"
        print(f"{at:3.0f}% {percent:6.1f}% {t - start:9.1f} {stated:>8} {actual:8.1f} {ratio:>6}"
              f" {cpu_est:>9} {cpu_end - cpu:10.1f} {cpu_ratio:>6}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--robocal", default=str(ROOT / "target/release/robocal"))
    ap.add_argument("--methods", default=METHODS)
    ap.add_argument("--short", type=float, default=5.0)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--jobs", type=int, default=len(METHODS.split(",")),
                    help="methods measured side by side")
    ap.add_argument("--eta", help="a method list to run once, printing its stated and actual time left")
    ap.add_argument("--threads", type=int, default=1, help="threads of the `--eta` run")
    ap.add_argument("--deadline", type=float,
                    help="seconds after which runs still going stop; their time is extrapolated "
                         "from the share of their bar done")
    args = ap.parse_args()
    global deadline
    if args.deadline is not None:
        deadline = time.monotonic() + args.deadline
    if args.eta:
        eta(args.robocal, args.eta, args.threads)
        return
    methods = args.methods.split(",")
    for needed in ("km", "skcm"):
        if needed not in methods:
            methods.insert(0, needed)
    seconds = {}

    extrapolated = {}

    def measure(m):
        runs = [timed(args.robocal, m)]
        while runs[0][0] < args.short and runs[0][2] is None and len(runs) < args.repeat:
            runs.append(timed(args.robocal, m))
        # The mean: the processor clock counts in ticks of 10 ms.
        seconds[m] = statistics.mean(r[0] for r in runs)
        before = statistics.mean(r[1] for r in runs)
        how = f"mean of {len(runs)}"
        if runs[0][2] is not None:
            extrapolated[m] = runs[0][2]
            how = f"extrapolated from {runs[0][2]:.1f} % at the deadline"
        print(f"{m}: {seconds[m]:.3f} s ({how}; {before:.3f} s before it)",
              file=sys.stderr, flush=True)

    # Processor time does not depend on what else runs: the methods run side
    # by side, each on one thread.
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        list(pool.map(measure, methods))
    unit = seconds["skcm"]
    print(f"{'method':<14} {'seconds':>9} {'/ skcm':>9}")
    for m in methods:
        ratio = seconds[m] / unit
        if m == "skcm-tlbo":
            ratio -= seconds["km"] / unit
        note = f"  extrapolated from {extrapolated[m]:.1f} %" if m in extrapolated else ""
        print(f"{m:<14} {seconds[m]:9.3f} {ratio:9.2f}{note}")


if __name__ == "__main__":
    main()
