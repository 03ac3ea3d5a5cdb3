#!/usr/bin/env python3
"""Overhead of the Python binding: sample + contour of one mesh from Python against the C++ CLI.

  PYTHONPATH=build/python /usr/bin/python3 bench/python_overhead.py build/pic data/fandisk.obj [--depth 12] [--runs 5]

Per run, the CLI's library time is its --json "seconds" (`pic sample`: pic::sample only;
`pic mesh`: pic::contour only). From Python, the wall time of pic.sample(vertices, faces) and
of tree.contour(split=False) around the call, next to the library's own seconds for the same
call (tree.stats / the contour stats): the difference is the binding (argument conversion,
copies into and out of numpy, GIL hand-over). Medians of --runs.
"""
import argparse
import json
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import pic

ap = argparse.ArgumentParser()
ap.add_argument("cli")
ap.add_argument("mesh")
ap.add_argument("--depth", type=int, default=12)
ap.add_argument("--runs", type=int, default=5)
a = ap.parse_args()

tmp = Path(tempfile.mkdtemp())
cli_sample, cli_contour = [], []
for _ in range(a.runs):
    s = json.loads(subprocess.run([a.cli, "sample", a.mesh, "-o", tmp / "x.pic", "--depth", str(a.depth), "--json"],
                                  check=True, capture_output=True, text=True).stdout)
    m = json.loads(subprocess.run([a.cli, "mesh", tmp / "x.pic", "-o", tmp / "x.obj", "--json", "--no-split",
                                   "--no-check"], check=True, capture_output=True, text=True).stdout)
    cli_sample.append(s["seconds"])
    cli_contour.append(m["seconds"])

vertices, faces = pic.read_mesh(a.mesh)
py_sample, lib_sample, py_contour, lib_contour = [], [], [], []
for _ in range(a.runs):
    t0 = time.perf_counter()
    tree = pic.sample(vertices, faces, depth=a.depth)
    py_sample.append(time.perf_counter() - t0)
    lib_sample.append(tree.stats["seconds"])
    stats = {}
    t0 = time.perf_counter()
    tree.contour(split=False, stats=stats)
    py_contour.append(time.perf_counter() - t0)
    lib_contour.append(stats["seconds"])

med = statistics.median
ms = lambda x: f"{med(x) * 1e3:.1f}"
over = lambda py, lib: f"{med([p - l for p, l in zip(py, lib)]) * 1e3:.2f}"
print(f"{Path(a.mesh).name}, depth {a.depth}, {len(faces)} triangles, {tree.pics} PICs, median of {a.runs} runs (ms)")
print("| step | CLI library | Python wall | library inside Python | binding overhead |")
print("|---|---:|---:|---:|---:|")
print(f"| sample | {ms(cli_sample)} | {ms(py_sample)} | {ms(lib_sample)} | {over(py_sample, lib_sample)} |")
print(f"| contour | {ms(cli_contour)} | {ms(py_contour)} | {ms(lib_contour)} | {over(py_contour, lib_contour)} |")
