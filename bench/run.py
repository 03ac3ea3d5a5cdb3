#!/usr/bin/env python3
"""Benchmark driver behind bench/run.sh (see there for usage and knobs).

Every command runs as a child process; its peak RSS comes from wait4() (ru_maxrss of that
child alone). Timings are the programs' own JSON fields (file I/O excluded), medians over
PIC_BENCH_REPS runs unless stated otherwise.
"""
import datetime
import json
import math
import os
import platform
import shlex
import signal
import statistics
import subprocess
import sys
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BUILD = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 and not sys.argv[1].startswith("--") else "build")
OUT = os.path.join("out", "bench")
IN = os.path.join(OUT, "in")
RES = os.path.join(OUT, "res")
PIC = os.path.join(BUILD, "pic")
TOOL = os.path.join(BUILD, "bench", "pic_bench_tool")
SCULPT = os.path.join(BUILD, "bench", "pic_sculpt")
MICRO = os.path.join(BUILD, "bench", "pic_bench")
VDB = os.path.join(BUILD, "bench", "pic_vdb_peer")
MANIFOLD = os.path.join("bench", "manifold_peer.mjs")
# Native Manifold's `mfbench` (built from a Manifold source snapshot by the shared tools'
# manifold-native/build.sh), and the Thingi10K difference pair (A - B, already in one frame).
MFBENCH = os.environ.get("PIC_MFBENCH") or os.path.expanduser("~/.cache/pic-peers/manifold/mfbench")
THINGI_DIR = os.environ.get("THINGI_DIR") or os.path.join(os.path.dirname(ROOT), "shared", "data")
THINGI_PAIR = ("thingi10k-1706459.obj", "thingi10k-1514499.obj")

REPS = int(os.environ.get("PIC_BENCH_REPS", "5"))
STROKES = int(os.environ.get("PIC_BENCH_STROKES", "1000"))
CHECK_STROKES = int(os.environ.get("PIC_BENCH_CHECK_STROKES", "300"))
VOXELS = os.environ.get("PIC_BENCH_VDB_VOXELS", "1/1024 1/2048").split()
SUBDIV = int(os.environ.get("PIC_BENCH_SUBDIV", "4"))
RUN_MICRO = os.environ.get("PIC_BENCH_MICRO", "1") != "0"
TIMEOUT = float(os.environ.get("PIC_BENCH_TIMEOUT", "600"))
CUBE = "0,0,0,1"

os.chdir(ROOT)
for d in (OUT, IN, RES):
    os.makedirs(d, exist_ok=True)

results = {"meta": {}, "skipped": {}, "failed": [], "commands": []}


def log(msg=""):
    print(msg, flush=True)


def loadavg():
    try:
        return [round(x, 2) for x in os.getloadavg()]
    except OSError:
        return None


class Failed(Exception):
    pass


_counter = [0]


def run(cmd, name=None, timeout=TIMEOUT, want_json=True):
    """Runs cmd; returns (parsed stdout JSON or text, peak RSS bytes, wall seconds)."""
    _counter[0] += 1
    name = name or os.path.basename(cmd[0])
    base = os.path.join(RES, "%03d_%s" % (_counter[0], name))
    with open(base + ".out", "w") as fo, open(base + ".err", "w") as fe:
        t0 = time.monotonic()
        p = subprocess.Popen(cmd, stdout=fo, stderr=fe)
    timed_out = []

    def kill():
        timed_out.append(True)
        try:
            os.kill(p.pid, signal.SIGKILL)
        except OSError:
            pass

    timer = threading.Timer(timeout, kill)
    timer.start()
    _, status, ru = os.wait4(p.pid, 0)
    timer.cancel()
    wall = time.monotonic() - t0
    p.returncode = os.waitstatus_to_exitcode(status)
    results["commands"].append(" ".join(shlex.quote(c) for c in cmd))
    text = open(base + ".out").read()
    if timed_out:
        raise Failed("timed out after %.0f s: %s" % (timeout, " ".join(cmd)))
    if p.returncode != 0:
        err = open(base + ".err").read().strip().splitlines()
        raise Failed("exit %d: %s: %s" % (p.returncode, " ".join(cmd), err[-1] if err else ""))
    out = text
    if want_json:
        lines = [l for l in text.splitlines() if l.strip().startswith("{")]
        if not lines:
            raise Failed("no JSON from: " + " ".join(cmd))
        out = json.loads(lines[-1])
    return out, ru.ru_maxrss * 1024, wall


def med(xs):
    xs = [x for x in xs if x is not None]
    return statistics.median(xs) if xs else None


def p95(xs):
    xs = sorted(xs)
    if not xs:
        return None
    pos = 0.95 * (len(xs) - 1)
    i = int(pos)
    return xs[i] if i + 1 >= len(xs) else xs[i] * (1 - (pos - i)) + xs[i + 1] * (pos - i)


def section(name, fn):
    log("\n== %s ==" % name)
    t0 = time.monotonic()
    try:
        fn()
    except Failed as e:
        results["failed"].append({"section": name, "error": str(e)})
        log("FAILED: %s" % e)
    except Exception as e:  # keep going: one broken section must not hide the others
        results["failed"].append({"section": name, "error": repr(e)})
        log("FAILED: %r" % e)
    log("(%s: %.1f s)" % (name, time.monotonic() - t0))


def skip(key, why):
    results["skipped"][key] = why
    log("skipped: %s: %s" % (key, why))


# ---------------------------------------------------------------------------------------------
def meta():
    m = results["meta"]
    m["date"] = datetime.datetime.now().astimezone().isoformat(timespec="seconds")
    m["command"] = "bash bench/run.sh " + os.path.relpath(BUILD, ROOT)
    m["cpus"] = os.cpu_count()
    try:
        m["cpu"] = next(l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name"))
    except Exception:
        m["cpu"] = platform.processor()
    try:
        m["mem_total_gb"] = round(int(next(l.split()[1] for l in open("/proc/meminfo") if l.startswith("MemTotal"))) / 2**20, 1)
    except Exception:
        pass
    m["loadavg_start"] = loadavg()
    try:
        m["git"] = subprocess.run(["git", "describe", "--always", "--dirty"], capture_output=True, text=True).stdout.strip()
    except Exception:
        pass
    m["reps"] = REPS
    log("%s  %s x%s  load %s  git %s" % (m["date"], m.get("cpu"), m["cpus"], m["loadavg_start"], m.get("git")))


# ---------------------------------------------------------------------------------------------
def make_inputs():
    # Table 2 inputs
    _, _, _ = run([PIC, "prim", "cylinder", "-o", os.path.join(IN, "cylinder_prim.pic"),
                   "--mesh", os.path.join(IN, "cylinder.obj"), "--json"], "prim_cylinder")
    sub, _, wall = run([TOOL, "subdivide", "data/spot.obj", os.path.join(IN, "spot_sub.obj"), str(SUBDIV)], "subdivide")
    results["meta"]["spot_sub"] = {"levels": SUBDIV, "triangles": sub["triangles"], "seconds": wall}
    log("spot subdivided %d times: %d triangles -> %s" % (SUBDIV, sub["triangles"], os.path.join(IN, "spot_sub.obj")))
    # CAD tool (paper Table 3) and carved slab (paper Figure 10), as in scripts/demo.sh
    prims = {
        "cube": ["box", "--size", "0.5,0.5,0.5", "--center", "0.5,0.5,0.5"],
        "cyl_z": ["cylinder", "--radius", "0.15", "--height", "0.8", "--axis", "z", "--center", "0.5,0.5,0.5"],
        "cyl_x": ["cylinder", "--radius", "0.1", "--height", "0.8", "--axis", "x", "--center", "0.5,0.5,0.5"],
        "cyl_y": ["cylinder", "--radius", "0.07", "--height", "0.8", "--axis", "y", "--center", "0.5,0.5,0.5"],
        "slab": ["box", "--size", "0.8,0.5,0.16", "--center", "0.5,0.5,0.5"],
        "dimple": ["sphere", "--radius", "0.12", "--center", "0.3,0.5,0.6"],
        "groove": ["cylinder", "--radius", "0.05", "--height", "0.7", "--axis", "x", "--center", "0.5,0.35,0.58"],
        "notch": ["box", "--size", "0.12,0.7,0.12", "--center", "0.72,0.5,0.58", "--rotate", "0,1,0,45"],
    }
    for name, args in prims.items():
        run([PIC, "prim"] + args + ["--cube", CUBE, "-o", os.path.join(IN, name + ".pic"),
                                    "--mesh", os.path.join(IN, name + ".obj"), "--json"], "prim_" + name)
    run([PIC, "csg", os.path.join(IN, "slab.pic"), "subtract", os.path.join(IN, "dimple.pic"), "subtract",
         os.path.join(IN, "groove.pic"), "subtract", os.path.join(IN, "notch.pic"),
         "-o", os.path.join(IN, "slab_carved.pic"), "--json"], "csg_slab")


# ---------------------------------------------------------------------------------------------
TABLE2 = [("fandisk", "data/fandisk.obj"), ("cylinder", os.path.join(IN, "cylinder.obj")),
          ("spot", "data/spot.obj"), ("spot_sub", os.path.join(IN, "spot_sub.obj"))]


def table2():
    rows = results["table2"] = []
    for name, mesh in TABLE2:
        if not os.path.exists(mesh):
            skip("table2/" + name, "input %s missing" % mesh)
            continue
        pic_path = os.path.join(OUT, name + ".pic")
        reps = REPS if name != "spot_sub" else max(1, min(REPS, 3))
        par, ser, rss = [], [], []
        last = None
        for _ in range(reps):
            last, r, _ = run([PIC, "sample", mesh, "-o", pic_path, "--json"], "sample_" + name)
            par.append(last["seconds"])
            rss.append(r)
        for _ in range(reps):
            s, _, _ = run([PIC, "sample", mesh, "-o", pic_path + ".serial", "--json", "--serial"], "sample_serial_" + name)
            ser.append(s["seconds"])
        os.remove(pic_path + ".serial")
        info, _, _ = run([PIC, "info", pic_path, "--json"], "info_" + name)
        mesh_out = os.path.join(OUT, name + "_pic.obj")
        cs, tris, topo = [], 0, None
        for _ in range(reps):
            c, _, _ = run([PIC, "mesh", pic_path, "-o", mesh_out, "--json"], "contour_" + name)
            cs.append(c["seconds"])
            tris, topo = c["triangles"], c["topology"]
        row = {
            "model": name, "input": mesh, "triangles_in": last["triangles_in"], "pics": last["pics"],
            "capped": last["capped"], "depth": last["depth"], "error": last["error"], "runs": reps,
            "sample_seconds_tbb": med(par), "sample_seconds_tbb_all": par,
            "sample_seconds_serial": med(ser), "sample_seconds_serial_all": ser,
            "peak_rss_bytes_sample": max(rss),
            "nodes": info["nodes"], "memory_bytes": info["memory_bytes"], "file_bytes": info["file_bytes"],
            "memory_bytes_per_pic": info["memory_bytes"] / info["pics"], "file_bytes_per_pic": info["file_bytes"] / info["pics"],
            "contour_triangles": tris, "contour_seconds": med(cs), "contour_seconds_all": cs,
            "contour_triangles_per_second": tris / med(cs) if med(cs) else None,
            "contour_manifold": topo["manifold"] if topo else None,
        }
        rows.append(row)
        log("%-9s %9d tris  %8d PICs  sample %8.1f ms (TBB) %8.1f ms (serial)  %5.1f B/PIC mem %5.2f B/PIC file  "
            "contour %d tris %.1f ms = %.1f M tri/s  peak %.0f MB" %
            (name, row["triangles_in"], row["pics"], row["sample_seconds_tbb"] * 1e3, row["sample_seconds_serial"] * 1e3,
             row["memory_bytes_per_pic"], row["file_bytes_per_pic"], tris, row["contour_seconds"] * 1e3,
             (row["contour_triangles_per_second"] or 0) / 1e6, row["peak_rss_bytes_sample"] / 2**20))


# ---------------------------------------------------------------------------------------------
CAD_OPS = [("union", "cyl_z"), ("subtract", "cyl_x"), ("subtract", "cyl_y")]


def cad_pic():
    cad = results["cad_pic"] = {}
    # sampling of the four operands (part of PIC's end-to-end time)
    samp = {}
    rss = []
    for name in ["cube"] + [b for _, b in CAD_OPS]:
        ts = []
        for _ in range(REPS):
            s, r, _ = run([PIC, "sample", os.path.join(IN, name + ".obj"), "--cube", CUBE, "-o",
                           os.path.join(OUT, "cad_" + name + ".pic"), "--json"], "sample_cad_" + name)
            ts.append(s["seconds"])
            rss.append(r)
        samp[name] = {"seconds": med(ts), "pics": s["pics"], "triangles_in": s["triangles_in"]}
    cad["sample"] = samp
    cad["sample_seconds"] = sum(v["seconds"] for v in samp.values())
    args = [PIC, "csg", os.path.join(OUT, "cad_cube.pic")]
    for op, b in CAD_OPS:
        args += [op, os.path.join(OUT, "cad_" + b + ".pic")]
    runs = []
    reps = max(REPS, 7)
    for _ in range(reps):
        j, r, _ = run(args + ["-o", os.path.join(OUT, "cad_tool.pic"), "--json"], "csg_cad")
        runs.append(j)
        rss.append(r)
    ops = []
    for k, (op, b) in enumerate(CAD_OPS):
        o = {"op": op, "operand": b}
        for f in ("seconds", "contour_a_seconds", "contour_b_seconds", "csg_seconds", "cells_visited", "cells_stamped"):
            o[f] = med([rj["ops"][k][f] for rj in runs])
        o["seconds_all"] = [rj["ops"][k]["seconds"] for rj in runs]
        ops.append(o)
    cad["ops"] = ops
    cad["runs"] = reps
    cad["csg_seconds_total"] = med([sum(o["seconds"] for o in rj["ops"]) for rj in runs])
    cad["pics"] = runs[-1]["pics"]
    cs = []
    for _ in range(REPS):
        c, _, _ = run([PIC, "mesh", os.path.join(OUT, "cad_tool.pic"), "-o", os.path.join(OUT, "cad_tool_pic.obj"), "--json"],
                      "contour_cad")
        cs.append(c["seconds"])
    cad["contour_seconds"] = med(cs)
    cad["triangles"] = c["triangles"]
    cad["manifold"] = c["topology"]["manifold"]
    cad["end_to_end_seconds"] = cad["sample_seconds"] + cad["csg_seconds_total"] + cad["contour_seconds"]
    cad["peak_rss_bytes"] = max(rss)
    log("%-9s %12s %12s %10s %10s %14s" % ("op", "contour_A_ms", "contour_B_ms", "csg_ms", "total_ms", "cells_visited"))
    for o in ops:
        log("%-9s %12.2f %12.2f %10.2f %10.2f %14d" % (o["op"] + " " + o["operand"], o["contour_a_seconds"] * 1e3,
                                                        o["contour_b_seconds"] * 1e3, o["csg_seconds"] * 1e3,
                                                        o["seconds"] * 1e3, o["cells_visited"]))
    log("PIC end to end: sample 4 operands %.1f ms + CSG %.1f ms + contour %.1f ms = %.1f ms; %d triangles (%s); peak %.0f MB"
        % (cad["sample_seconds"] * 1e3, cad["csg_seconds_total"] * 1e3, cad["contour_seconds"] * 1e3,
           cad["end_to_end_seconds"] * 1e3, cad["triangles"], "manifold" if cad["manifold"] else "NOT manifold",
           cad["peak_rss_bytes"] / 2**20))


def cad_inputs():
    chain = [os.path.join(IN, "cube.obj")]
    for op, b in CAD_OPS:
        chain += ["union" if op == "union" else "difference", os.path.join(IN, b + ".obj")]
    return chain


def manifold_peer():
    if not shutil_which("node"):
        return skip("manifold", "node not found (apt-get install nodejs npm)")
    if not os.path.isdir("bench/node_modules/manifold-3d"):
        return skip("manifold", "npm package manifold-3d not installed (cd bench && npm ci)")
    ref = os.path.join(OUT, "cad_tool_manifold.obj")
    j, rss, _ = run(["node", MANIFOLD, "--out", ref, "--repeat", "20"] + cad_inputs(), "manifold")
    j["peak_rss_bytes_wait4"] = rss
    results["manifold"] = j
    log("Manifold %s: convert %.1f ms + 3 booleans %.1f ms (warm, best of %d; first run %.1f ms) + export %.1f ms = %.1f ms; "
        "%d triangles, genus %d; peak %.0f MB"
        % (j["manifold_version"], j["convert_ms"], j["chain_ms"], j["repeat"], sum(o["ms_first"] for o in j["ops"]),
           j["export_ms"], j["end_to_end_ms"], j["triangles"], j["genus"], rss / 2**20))
    if "cad_pic" in results and os.path.exists(os.path.join(OUT, "cad_tool_pic.obj")):
        d, _, _ = run([TOOL, "distance", os.path.join(OUT, "cad_tool_pic.obj"), ref], "distance_pic")
        results["cad_pic"]["distance_to_manifold"] = d
        log("PIC result vs Manifold: two-sided Hausdorff %.3g (root cube = 1; finest PIC cell = %.3g)"
            % (d["hausdorff"], 1 / 4096))


def native_manifold_peer():
    """The CAD tool's chain on native Manifold (mfbench), warm best of 20."""
    if not os.path.exists(MFBENCH):
        return skip("manifold_native", "%s not found (build it with the shared tools' manifold-native/build.sh, or set "
                                       "PIC_MFBENCH)" % MFBENCH)
    j, rss, _ = run([MFBENCH, os.path.join(OUT, "cad_tool_mfbench.obj")] + cad_inputs() + ["--repeat", "20"], "mfbench_cad")
    j["peak_rss_bytes_wait4"] = rss
    results["manifold_native_cad"] = j
    log("native Manifold: convert %.2f ms + 3 booleans %.2f ms (best of 20) + export %.2f ms"
        % (sum(j["to_manifold_ms"]), j["boolean_ms"], j["from_manifold_ms"]))


def thingi_pair():
    """A - B of the Thingi10K pair: PIC (both sampled in one cube, the Boolean, the contour) beside
    native Manifold (conversion, difference, export)."""
    a, b = (os.path.join(THINGI_DIR, f) for f in THINGI_PAIR)
    if not (os.path.exists(a) and os.path.exists(b)):
        return skip("thingi_pair", "%s and %s not found (set THINGI_DIR)" % (a, b))
    res = os.path.join(OUT, "thingi_pair.pic")
    runs, contours = [], []
    for _ in range(REPS):
        j, _, _ = run([PIC, "csg", a, "subtract", b, "-o", res, "--json"], "csg_thingi")
        runs.append(j)
    for _ in range(REPS):
        c, _, _ = run([PIC, "mesh", res, "-o", os.path.join(OUT, "thingi_pair_pic.obj"), "--json", "--no-check"],
                      "contour_thingi")
        contours.append(c["seconds"])
    pic = {"csg_step_seconds": med([r["ops"][0]["seconds"] for r in runs]),
           "sample_and_csg_seconds": med([r["seconds"] for r in runs]), "contour_seconds": med(contours),
           "pics": runs[-1]["pics"], "triangles": c["triangles"]}
    pic["end_to_end_seconds"] = pic["sample_and_csg_seconds"] + pic["contour_seconds"]
    results["thingi_pair"] = {"pic": pic}
    log("PIC: sample both + A - B %.3f s (the Boolean %.3f s) + contour %.3f s = %.3f s; %d triangles"
        % (pic["sample_and_csg_seconds"], pic["csg_step_seconds"], pic["contour_seconds"], pic["end_to_end_seconds"],
           pic["triangles"]))
    if not os.path.exists(MFBENCH):
        return skip("thingi_pair_manifold", "%s not found" % MFBENCH)
    m, _, _ = run([MFBENCH, os.path.join(OUT, "thingi_pair_mfbench.obj"), a, "difference", b, "--repeat", str(REPS)],
                  "mfbench_thingi")
    results["thingi_pair"]["manifold_native"] = m
    log("native Manifold: convert %.1f ms + difference %.1f ms (best of %d) + export %.1f ms"
        % (sum(m["to_manifold_ms"]), m["boolean_ms"], REPS, m["from_manifold_ms"]))


def sculpt_peer():
    """The same strokes (pic_sculpt's centres) subtracted from the exact carved slab by Manifold (WASM)."""
    if not os.path.exists(SCULPT_CENTRES):
        return skip("sculpt_manifold", "no stroke centres (the sculpting section did not run)")
    if not shutil_which("node") or not os.path.isdir("bench/node_modules/manifold-3d"):
        return skip("sculpt_manifold", "node or the npm package manifold-3d missing (cd bench && npm ci)")
    chain = [os.path.join(IN, "slab.obj")]
    for cut in ("dimple", "groove", "notch"):
        chain += ["difference", os.path.join(IN, cut + ".obj")]
    j, _, _ = run(["node", MANIFOLD, "--out", os.path.join(OUT, "sculpted_manifold.obj"), "--repeat", "1",
                   "--sculpt", SCULPT_CENTRES, "--segments", "32"] + chain, "sculpt_manifold", timeout=max(TIMEOUT, 900))
    results["sculpt_manifold"] = j["sculpt"]
    log("Manifold (WASM), the same %d strokes: median %.3f ms, p95 %.3f ms per subtraction"
        % (j["sculpt"]["strokes"], j["sculpt"]["stroke_ms"]["median"], j["sculpt"]["stroke_ms"]["p95"]))
    if not os.path.exists(MFBENCH):
        return skip("sculpt_manifold_native", "%s not found" % MFBENCH)
    # Native: every stroke's sphere as an OBJ (a UV sphere, 32 segments around, 16 rings).
    tools = []
    with open(SCULPT_CENTRES) as f:
        for k, line in enumerate(f):
            x, y, z, rad = map(float, line.split())
            path = os.path.join(RES, "stroke%04d.obj" % k)
            write_uv_sphere(path, (x, y, z), rad, 32, 16)
            tools += ["difference", path]
    m, _, _ = run([MFBENCH, os.path.join(OUT, "sculpted_mfbench.obj")] + chain + tools, "sculpt_mfbench",
                  timeout=max(TIMEOUT, 900))
    strokes = [o["ms"] for o in m["ops"][3:]]
    results["sculpt_manifold_native"] = {"strokes": len(strokes), "stroke_ms": {"median": med(strokes), "p95": p95(strokes)}}
    log("Manifold (native), the same %d strokes: median %.3f ms, p95 %.3f ms per subtraction"
        % (len(strokes), med(strokes), p95(strokes)))


def write_uv_sphere(path, c, r, around, rings):
    v = [(c[0], c[1], c[2] - r)]
    for i in range(1, rings):
        t = math.pi * i / rings
        for j in range(around):
            p = 2 * math.pi * j / around
            v.append((c[0] + r * math.sin(t) * math.cos(p), c[1] + r * math.sin(t) * math.sin(p), c[2] - r * math.cos(t)))
    v.append((c[0], c[1], c[2] + r))
    top = len(v)
    ring = lambda i, j: 2 + (i - 1) * around + j % around  # 1-based OBJ index of ring i (1..rings-1)
    f = [(1, ring(1, j + 1), ring(1, j)) for j in range(around)]
    for i in range(1, rings - 1):
        for j in range(around):
            f.append((ring(i, j), ring(i, j + 1), ring(i + 1, j + 1)))
            f.append((ring(i, j), ring(i + 1, j + 1), ring(i + 1, j)))
    f += [(top, ring(rings - 1, j), ring(rings - 1, j + 1)) for j in range(around)]
    with open(path, "w") as out:
        out.write("".join("v %.17g %.17g %.17g\n" % p for p in v))
        out.write("".join("f %d %d %d\n" % t for t in f))


def vdb_peer():
    if not os.path.exists(VDB):
        return skip("openvdb", "%s not built (apt-get install libopenvdb-dev, reconfigure)" % VDB)
    ref = os.path.join(OUT, "cad_tool_manifold.obj")
    results["openvdb"] = []
    for v in VOXELS:
        cmd = [VDB, "--voxel", v]
        if os.path.exists(ref):
            cmd += ["--reference", ref]
        try:
            j, rss, _ = run(cmd + cad_inputs(), "vdb")
        except Failed as e:
            skip("openvdb " + v, str(e))
            continue
        j["peak_rss_bytes_wait4"] = rss
        results["openvdb"].append(j)
        log("OpenVDB voxel %s: level sets %.2f s + CSG %.3f s + volumeToMesh %.2f s = %.2f s; %d active voxels; "
            "%d triangles; peak %.0f MB (in-process, before distance), Hausdorff to Manifold %s"
            % (v, j["levelset_seconds"], j["csg_seconds"], j["mesh_seconds"], j["total_seconds"], j["active_voxels"],
               j["triangles"], j["peak_rss_bytes"] / 2**20, "%.3g" % j["hausdorff"] if "hausdorff" in j else "n/a"))


def shutil_which(x):
    import shutil
    return shutil.which(x)


# ---------------------------------------------------------------------------------------------
SCULPT_CENTRES = os.path.join(OUT, "sculpt_centres.txt")


def sculpt():
    j, rss, _ = run([SCULPT, os.path.join(IN, "slab_carved.pic"), "--strokes", str(STROKES), "--radius", "0.02",
                     "--seed", "1", "--out", os.path.join(OUT, "sculpted.pic"), "--centres", SCULPT_CENTRES], "sculpt",
                    timeout=max(TIMEOUT, 900))
    j["peak_rss_bytes_wait4"] = rss
    results["sculpt"] = j
    # Topology after every stroke (contoured, untimed) over the first CHECK_STROKES strokes.
    c, _, _ = run([SCULPT, os.path.join(IN, "slab_carved.pic"), "--strokes", str(CHECK_STROKES), "--radius", "0.02",
                   "--seed", "1", "--check"], "sculpt_check", timeout=max(TIMEOUT, 900))
    results["sculpt_check"] = dict(c["check"], strokes=c["strokes"])
    log("checked %d strokes one by one: %d left the object open, %d non-manifold (first at stroke %d), "
        "%d still non-manifold after pic::split_nonmanifold"
        % (c["strokes"], c["check"]["open_strokes"], c["check"]["nonmanifold_strokes"], c["check"]["first_nonmanifold"],
           c["check"]["nonmanifold_after_split_strokes"]))
    log("%d strokes (sphere r 0.02, depth %d): stroke (csg_inplace) median %.3f ms, p95 %.3f ms; tool sampling median %.3f ms; "
        "cells visited median %d, p95 %d; PICs %d -> %d; contour after: %s; peak %.0f MB"
        % (j["strokes"], j["depth"], j["stroke_ms"]["median"], j["stroke_ms"]["p95"], j["tool_sample_ms"]["median"],
           j["cells_visited"]["median"], j["cells_visited"]["p95"], j["pics_before"], j["pics_after"],
           "closed manifold" if j["manifold_after"] else ("closed, NOT manifold" if j["closed_after"] else "NOT closed"),
           rss / 2**20))


def micro():
    if not RUN_MICRO:
        return skip("micro", "PIC_BENCH_MICRO=0")
    if not os.path.exists(MICRO):
        return skip("micro", "%s not built (apt-get install libbenchmark-dev, reconfigure)" % MICRO)
    jpath = os.path.join(OUT, "micro.json")
    run([MICRO, "--benchmark_min_time=0.3", "--benchmark_out=" + jpath, "--benchmark_out_format=json"],
        "micro", want_json=False)
    data = json.load(open(jpath))
    rows = []
    skipk = {"name", "run_name", "run_type", "repetitions", "repetition_index", "threads", "iterations", "real_time",
             "cpu_time", "time_unit", "family_index", "per_family_instance_index", "label", "aggregate_name", "error_occurred",
             "error_message"}
    for b in data["benchmarks"]:
        counters = {k: v for k, v in b.items() if k not in skipk}
        rows.append({"name": b["name"], "label": b.get("label", ""), "real_time": b["real_time"], "cpu_time": b["cpu_time"],
                     "unit": b["time_unit"], "iterations": b["iterations"], "counters": counters})
        log("%-40s %10.4g %s  %s %s" % (b["name"], b["real_time"], b["time_unit"], b.get("label", ""),
                                        " ".join("%s=%.4g" % kv for kv in counters.items())))
    results["micro"] = rows


# ---------------------------------------------------------------------------------------------
def mb(x):
    return "%.0f" % (x / 2**20) if x else "—"


def ms(x):
    return "%.2f" % (x * 1e3) if x is not None else "—"


def side_by_side(r):
    """(workload, PIC ms, peer, peer ms) for every pair measured in this run."""
    rows = []
    c, mn = r.get("cad_pic"), r.get("manifold_native_cad")
    if c and mn:
        rows.append(("CAD tool: the 3 Booleans", c["csg_seconds_total"] * 1e3, "Manifold (native)", mn["boolean_ms"]))
        rows.append(("CAD tool: end to end (sample/convert, Booleans, contour/export)", c["end_to_end_seconds"] * 1e3,
                     "Manifold (native)", sum(mn["to_manifold_ms"]) + mn["boolean_ms"] + mn["from_manifold_ms"]))
    mf = r.get("manifold")
    if c and mf:
        rows.append(("CAD tool: the 3 Booleans", c["csg_seconds_total"] * 1e3, "Manifold (WASM)", mf["chain_ms"]))
    t = r.get("thingi_pair") or {}
    if t.get("pic") and t.get("manifold_native"):
        p, m = t["pic"], t["manifold_native"]
        rows.append(("Thingi10K pair A − B: the Boolean", p["csg_step_seconds"] * 1e3, "Manifold (native)", m["boolean_ms"]))
        rows.append(("Thingi10K pair A − B: end to end", p["end_to_end_seconds"] * 1e3, "Manifold (native)",
                     sum(m["to_manifold_ms"]) + m["boolean_ms"] + m["from_manifold_ms"]))
    s, sm, sn = r.get("sculpt"), r.get("sculpt_manifold"), r.get("sculpt_manifold_native")
    if s and sn:
        rows.append(("sculpting: stroke median", s["stroke_ms"]["median"], "Manifold (native)", sn["stroke_ms"]["median"]))
        rows.append(("sculpting: stroke p95", s["stroke_ms"]["p95"], "Manifold (native)", sn["stroke_ms"]["p95"]))
    if s and sm:
        rows.append(("sculpting: stroke median", s["stroke_ms"]["median"], "Manifold (WASM)", sm["stroke_ms"]["median"]))
        rows.append(("sculpting: stroke p95", s["stroke_ms"]["p95"], "Manifold (WASM)", sm["stroke_ms"]["p95"]))
    return rows


def report():
    r = results
    md = []
    m = r["meta"]
    md.append("Measured %s on %s (%s CPUs, %s GB), load average %s at start, %s at end; git %s; `%s`."
              % (m.get("date"), m.get("cpu"), m.get("cpus"), m.get("mem_total_gb"), m.get("loadavg_start"),
                 m.get("loadavg_end"), m.get("git"), m.get("command")))
    md.append("")
    if r.get("table2"):
        md.append("### Sampling (paper Table 2 setting: depth 12, error 1e-8), contouring, bytes per PIC")
        md.append("")
        md.append("| model | triangles in | PICs | sample ms (TBB) | sample ms (1 thread) | peak RSS MB | bytes/PIC memory | bytes/PIC file | contour triangles | contour ms | contour M tri/s |")
        md.append("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
        for x in r["table2"]:
            md.append("| %s | %d | %d | %s | %s | %s | %.2f | %.2f | %d | %s | %.1f |" % (
                x["model"], x["triangles_in"], x["pics"], ms(x["sample_seconds_tbb"]), ms(x["sample_seconds_serial"]),
                mb(x["peak_rss_bytes_sample"]), x["memory_bytes_per_pic"], x["file_bytes_per_pic"], x["contour_triangles"],
                ms(x["contour_seconds"]), (x["contour_triangles_per_second"] or 0) / 1e6))
        md.append("")
        md.append("Medians of %d runs (spot_sub: %d) of `pic sample` / `pic mesh` (library time, file I/O excluded)."
                  % (REPS, max(1, min(REPS, 3))))
        md.append("")
    c = r.get("cad_pic")
    if c:
        md.append("### CAD tool (paper Table 3 setting): cube ∪ cylinder z − cylinder x − cylinder y, depth 12")
        md.append("")
        md.append("| op | contour A ms | contour B ms | csg ms | total ms | cells visited |")
        md.append("|---|---:|---:|---:|---:|---:|")
        for o in c["ops"]:
            md.append("| %s %s | %s | %s | %s | %s | %d |" % (o["op"], o["operand"], ms(o["contour_a_seconds"]),
                                                           ms(o["contour_b_seconds"]), ms(o["csg_seconds"]),
                                                           ms(o["seconds"]), o["cells_visited"]))
        md.append("")
        md.append("Medians of %d runs of `pic csg ... --json` (each a fresh process)." % c["runs"])
        md.append("")
    peers = []
    if c:
        peers.append(("PIC", "depth 12 (cell 1/4096)", c["end_to_end_seconds"], c["csg_seconds_total"],
                      c["peak_rss_bytes"], c["triangles"], (c.get("distance_to_manifold") or {}).get("hausdorff")))
    for v in r.get("openvdb", []):
        peers.append(("OpenVDB %s" % v["openvdb_version"], "voxel %s, half-width %g" % (v["voxel_text"], v["half_width"]),
                      v["total_seconds"], v["csg_seconds"], v["peak_rss_bytes"], v["triangles"], v.get("hausdorff")))
    mf = r.get("manifold")
    if mf:
        peers.append(("Manifold %s" % mf["manifold_version"], "exact (float32), warm best of %d" % mf["repeat"],
                      mf["end_to_end_ms"] / 1e3, mf["chain_ms"] / 1e3, mf["peak_rss_bytes_wait4"], mf["triangles"], 0.0))
    if peers:
        md.append("### Peers on the same input meshes (CAD tool)")
        md.append("")
        md.append("| system | setting | end to end s | CSG step ms | peak RSS MB | triangles out | Hausdorff to Manifold | PIC/peer time | PIC/peer CSG step | PIC/peer memory |")
        md.append("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")
        pic = peers[0] if c else None
        for p in peers:
            ratio = lambda a, b: "%.3g" % (a / b) if (pic and a and b) else "—"
            md.append("| %s | %s | %.4g | %.2f | %s | %d | %s | %s | %s | %s |" % (
                p[0], p[1], p[2], p[3] * 1e3, mb(p[4]), p[5], "%.3g" % p[6] if p[6] is not None else "—",
                ratio(pic[2], p[2]) if pic else "—", ratio(pic[3], p[3]) if pic else "—", ratio(pic[4], p[4]) if pic else "—"))
        md.append("")
        md.append("End to end: PIC = sampling the 4 operand meshes + 3 CSG ops + contouring (medians); OpenVDB = "
                  "mesh→level set + CSG + volumeToMesh (one run); Manifold = mesh→Manifold conversion + 3 booleans "
                  "(best of N) + export. CSG step: the 3 Booleans only. Peak RSS: of the whole process (PIC: the largest "
                  "of its `pic` processes; OpenVDB: taken in-process right after volumeToMesh, before the distance "
                  "computation; Manifold: the node process incl. the WASM heap). Hausdorff: two-sided, root-cube units (finest PIC cell = 1/4096 = 2.44e-4).")
        md.append("")
    s = r.get("sculpt")
    if s:
        md.append("### Sculpting: %d subtractions of a sphere (radius 0.02 of the root cube) on the carved slab" % s["strokes"])
        md.append("")
        md.append("| stroke ms median | stroke ms p95 | tool sampling ms median | cells visited median | cells visited p95 | PICs before → after | contour after | peak RSS MB |")
        md.append("|---:|---:|---:|---:|---:|---:|---|---:|")
        md.append("| %.3f | %.3f | %.3f | %d | %d | %d → %d | %s | %s |" % (
            s["stroke_ms"]["median"], s["stroke_ms"]["p95"], s["tool_sample_ms"]["median"], s["cells_visited"]["median"],
            s["cells_visited"]["p95"], s["pics_before"], s["pics_after"],
            "closed manifold" if s["manifold_after"] else (
                ("closed, NOT manifold; manifold after `split_nonmanifold` (%d vertex copies)" % s.get("split_vertices_after", 0))
                if s.get("manifold_after_split") else ("closed, NOT manifold" if s["closed_after"] else "NOT closed")),
            mb(s["peak_rss_bytes_wait4"])))
        md.append("")
        md.append("Stroke = `pic::csg_inplace(object, tool, Subtract)`; the tool sphere (32 segments) is sampled per stroke "
                  "and timed separately. Centres: random vertices of the current contour, re-extracted every 50 strokes.")
        md.append("")
        chk = r.get("sculpt_check")
        if chk:
            md.append("Checked one by one (`pic_sculpt ... --strokes %d --check`, same seed): %d strokes left the object "
                      "open; %d left its raw contour non-manifold, the first at stroke %s (a defect stays until a later "
                      "stroke carves it away); after `pic::split_nonmanifold` (what `pic mesh` writes) %d were still "
                      "non-manifold." % (chk["strokes"], chk["open_strokes"], chk["nonmanifold_strokes"],
                                         chk["first_nonmanifold"] if chk["first_nonmanifold"] > 0 else "—",
                                         chk.get("nonmanifold_after_split_strokes", -1)))
            md.append("")
    if r.get("micro"):
        md.append("### Micro-benchmarks (`pic_bench`, Google Benchmark)")
        md.append("")
        md.append("| benchmark | time | counters |")
        md.append("|---|---:|---|")
        for b in r["micro"]:
            cs = ", ".join("%s %.4g" % kv for kv in b["counters"].items())
            md.append("| %s %s | %.4g %s | %s |" % (b["name"], b["label"], b["real_time"], b["unit"], cs))
        md.append("")
    side = side_by_side(r)
    if side:
        md.append("### Side by side: each PIC figure beside its peer, measured in this run")
        md.append("")
        md.append("| workload | PIC | peer | peer figure | PIC / peer |")
        md.append("|---|---:|---|---:|---:|")
        for w, p, peer, q in side:
            md.append("| %s | %.2f ms | %s | %.2f ms | %.2f |" % (w, p, peer, q, p / q if q else float("nan")))
        md.append("")
        md.append("PIC: medians of fresh `pic` processes (library time, file I/O excluded; the Thingi pair "
                  "samples both meshes in one cube); sculpting: `pic_sculpt` strokes (`csg_inplace`, tool sampling "
                  "excluded). Native Manifold: `mfbench`, warm best of N, conversion and export timed apart; "
                  "sculpting peer: Manifold's WASM build (about 2x slower than native) subtracting spheres of the "
                  "same centres and radius (32 segments) from the exact carved slab.")
        md.append("")
    # targets
    tg = []
    t2 = {x["model"]: x for x in r.get("table2", [])}
    if "fandisk" in t2:
        tg.append(("fandisk sampling ≤ 21 ms", "%s ms (TBB), %s ms (1 thread)" % (ms(t2["fandisk"]["sample_seconds_tbb"]), ms(t2["fandisk"]["sample_seconds_serial"])),
                   t2["fandisk"]["sample_seconds_tbb"] <= 0.021))
    if t2:
        best = max((x["contour_triangles_per_second"] or 0) for x in t2.values())
        tg.append(("contouring ≥ 50 M tri/s", "%.1f M tri/s (best model)" % (best / 1e6), best >= 50e6))
    if c:
        worst = max(o["seconds"] for o in c["ops"])
        tg.append(("each CAD op ≤ 5 ms", "worst op %s ms" % ms(worst), worst <= 0.005))
    if s:
        tg.append(("sculpt stroke ≤ 1 ms median", "%.3f ms" % s["stroke_ms"]["median"], s["stroke_ms"]["median"] <= 1.0))
    if c and r.get("openvdb"):
        fastest = min(v["total_seconds"] for v in r["openvdb"])
        tg.append(("faster than OpenVDB end to end", "PIC %.3f s vs OpenVDB %.3f s (fastest voxel size run)" % (c["end_to_end_seconds"], fastest),
                   c["end_to_end_seconds"] < fastest))
    if c and mf:
        tg.append(("CSG step faster than Manifold", "PIC %s ms vs Manifold %.2f ms (warm)" % (ms(c["csg_seconds_total"]), mf["chain_ms"]),
                   c["csg_seconds_total"] * 1e3 < mf["chain_ms"]))
    mn, tp = r.get("manifold_native_cad"), (r.get("thingi_pair") or {})
    if c and mn:
        tg.append(("CAD tool: PIC's 3 Booleans faster than native Manifold's", "PIC %s ms vs %.2f ms"
                   % (ms(c["csg_seconds_total"]), mn["boolean_ms"]), c["csg_seconds_total"] * 1e3 < mn["boolean_ms"]))
    if tp.get("pic") and tp.get("manifold_native"):
        p_, m_n = tp["pic"], tp["manifold_native"]
        peer_e2e = sum(m_n["to_manifold_ms"]) + m_n["boolean_ms"] + m_n["from_manifold_ms"]
        tg.append(("Thingi10K pair: the Boolean faster than native Manifold's", "PIC %s ms vs %.1f ms"
                   % (ms(p_["csg_step_seconds"]), m_n["boolean_ms"]), p_["csg_step_seconds"] * 1e3 < m_n["boolean_ms"]))
        tg.append(("Thingi10K pair: end to end within 2x of native Manifold", "PIC %s ms vs %.1f ms"
                   % (ms(p_["end_to_end_seconds"]), peer_e2e), p_["end_to_end_seconds"] * 1e3 <= 2 * peer_e2e))
    if s:
        tg.append(("sculpt stroke median ≤ 2 ms, p95 ≤ 5 ms", "%.3f / %.3f ms" % (s["stroke_ms"]["median"], s["stroke_ms"]["p95"]),
                   s["stroke_ms"]["median"] <= 2.0 and s["stroke_ms"]["p95"] <= 5.0))
    r["targets"] = [{"target": a, "measured": b, "met": bool(m_)} for a, b, m_ in tg]
    if tg:
        md.append("### Targets")
        md.append("")
        md.append("| target | measured | met |")
        md.append("|---|---|---|")
        for a, b, m_ in tg:
            md.append("| %s | %s | %s |" % (a, b, "yes" if m_ else "**no**"))
        md.append("")
    if r["skipped"] or r["failed"]:
        md.append("### Skipped / failed")
        md.append("")
        for k, v in r["skipped"].items():
            md.append("- skipped: %s: %s" % (k, v))
        for f in r["failed"]:
            md.append("- FAILED: %s: %s" % (f["section"], f["error"]))
        md.append("")
    return "\n".join(md)


def main():
    if "--report" in sys.argv:  # rewrite results.md from an existing results.json
        results.update(json.load(open(os.path.join(OUT, "results.json"))))
        md = report()
        with open(os.path.join(OUT, "results.md"), "w") as f:
            f.write(md + "\n")
        log(md)
        return
    t0 = time.monotonic()
    section("machine", meta)
    # PIC_BENCH_ONLY=key,key,... runs only those sections (keys as below; "inputs" is needed by
    # every section but table2).
    only = set(filter(None, os.environ.get("PIC_BENCH_ONLY", "").split(",")))
    for key, name, fn in [
        ("inputs", "inputs", make_inputs),
        ("table2", "sampling and contouring (paper Table 2 setting)", table2),
        ("cad", "CAD tool with PIC (paper Table 3 setting)", cad_pic),
        ("manifold", "peer: Manifold", manifold_peer),
        ("openvdb", "peer: OpenVDB", vdb_peer),
        ("sculpt", "sculpting", sculpt),
        ("manifold_native", "peer: native Manifold (CAD tool)", native_manifold_peer),
        ("thingi", "Thingi10K pair: PIC and native Manifold", thingi_pair),
        ("sculpt_peer", "peer: sculpting with Manifold", sculpt_peer),
        ("micro", "micro-benchmarks", micro),
    ]:
        if not only or key in only:
            section(name, fn)
    results["meta"]["loadavg_end"] = loadavg()
    results["meta"]["total_seconds"] = time.monotonic() - t0
    with open(os.path.join(OUT, "results.json"), "w") as f:  # first: kept even if the report fails
        json.dump(results, f, indent=1)
    md = report()
    with open(os.path.join(OUT, "results.md"), "w") as f:
        f.write(md + "\n")
    log("\n" + md)
    log("wrote %s and %s (%.0f s)" % (os.path.join(OUT, "results.json"), os.path.join(OUT, "results.md"),
                                      results["meta"]["total_seconds"]))


if __name__ == "__main__":
    main()
