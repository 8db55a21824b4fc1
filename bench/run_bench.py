#!/usr/bin/env python3
"""Runs the Google Benchmark suite, one benchmark per process so each row's
peak memory (max RSS) is its own, and prints a table.

usage: run_bench.py --build BUILD_DIR [--filter REGEX] [--repetitions N]
"""
import argparse
import json
import os
import subprocess
import sys


def list_benchmarks(exe, regex):
    out = subprocess.run([exe, "--benchmark_list_tests", f"--benchmark_filter={regex}"],
                         check=True, capture_output=True, text=True).stdout
    return [line.strip() for line in out.splitlines() if line.strip()]


def run_one(exe, name, repetitions):
    """Returns (benchmark json rows, peak RSS in MiB) for one benchmark."""
    cmd = [exe, f"--benchmark_filter=^{name}$", "--benchmark_format=json",
           f"--benchmark_repetitions={repetitions}"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    stdout = proc.stdout.read()
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        raise SystemExit(f"benchmark {name} failed with exit code {proc.returncode}")
    return json.loads(stdout), usage.ru_maxrss / 1024.0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--build", required=True)
    ap.add_argument("--filter", default=".")
    ap.add_argument("--repetitions", type=int, default=3)
    args = ap.parse_args(argv)
    exe = os.path.join(args.build, "exsynth_bench")
    print(f"machine: {os.cpu_count()} cores; median of {args.repetitions} runs; one process per row")
    header = f"{'benchmark':<56} {'median':>10} {'min':>10} {'peak RSS':>10}  counters"
    print(header)
    print("-" * len(header))
    for name in list_benchmarks(exe, args.filter):
        data, rss = run_one(exe, name, args.repetitions)
        runs = [b for b in data["benchmarks"] if b.get("run_type") == "iteration"]
        times = sorted(b["real_time"] for b in runs)
        med = runs[0] | {"real_time": times[len(times) // 2]}
        unit = med.get("time_unit", "ns")
        skip = {"name", "run_name", "run_type", "repetitions", "repetition_index", "threads", "iterations",
                "real_time", "cpu_time", "time_unit", "aggregate_name", "aggregate_unit", "family_index",
                "per_family_instance_index"}
        counters = ", ".join(f"{k}={v:.4g}" for k, v in med.items() if k not in skip and isinstance(v, (int, float)))
        print(f"{name:<56} {med['real_time']:>8.1f}{unit:>2} {times[0]:>8.1f}{unit:>2} "
              f"{rss:>7.0f}MiB  {counters}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
