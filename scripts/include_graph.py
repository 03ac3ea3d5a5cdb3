#!/usr/bin/env python3
"""The include graph of src/, folder by folder (docs/layout.md shows it).

    scripts/include_graph.py            print the graph as a markdown table
    scripts/include_graph.py --check    exit 1 if a file-level include cycle exists, a folder
                                        includes one of a later phase than its own, or one
                                        of the APART pairs meets

The phases, lowest first: a folder may include its own files, the public headers
(include/pic/) and folders before it in PHASES.
"""
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src"
PHASES = ["geometry", "mesh", "octree", "signs", "io", "measure", "contour", "sample", "csg", "scad", "render"]
# Pairs of folders that never include one another although the phase order allows it: Booleans
# work on octrees and their contours, never on the sampler's input sources.
APART = [("csg", "sample")]
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)


def file_graph():
    graph = {}
    for f in sorted(SRC.rglob("*")):
        if f.suffix not in (".h", ".cpp"):
            continue
        rel = f.relative_to(SRC).as_posix()
        graph[rel] = [inc for inc in INCLUDE.findall(f.read_text()) if (SRC / inc).exists()]
    return graph


def cycles(graph):
    """File-level include cycles (each as a list of files), by depth-first search."""
    found, state = [], {}

    def visit(node, path):
        state[node] = 1
        for nxt in graph.get(node, []):
            if state.get(nxt) == 1:
                found.append(path[path.index(nxt):] + [nxt])
            elif nxt not in state:
                visit(nxt, path + [nxt])
        state[node] = 2

    for node in graph:
        if node not in state:
            visit(node, [node])
    return found


def folder_edges(graph):
    edges = {}
    for f, incs in graph.items():
        a = f.split("/")[0]
        for inc in incs:
            b = inc.split("/")[0]
            if a != b:
                edges.setdefault(a, set()).add(b)
    return edges


def main():
    graph = file_graph()
    edges = folder_edges(graph)
    if "--check" in sys.argv:
        bad = [" -> ".join(c) for c in cycles(graph)]
        for a, bs in edges.items():
            for b in bs:
                if a not in PHASES or b not in PHASES or PHASES.index(b) > PHASES.index(a):
                    bad.append(f"src/{a}/ includes src/{b}/ (a later phase)")
                if (a, b) in APART:
                    bad.append(f"src/{a}/ includes src/{b}/ (kept apart)")
        for b in bad:
            print("include graph:", b)
        print(f"include graph: {len(graph)} files, {sum(map(len, graph.values()))} includes, "
              f"{'OK' if not bad else str(len(bad)) + ' problems'}")
        sys.exit(1 if bad else 0)
    print("| folder | includes (besides include/pic/) |")
    print("|---|---|")
    for a in PHASES:
        deps = sorted(edges.get(a, ()), key=PHASES.index)
        print(f"| src/{a}/ | {', '.join(d + '/' for d in deps) or '—'} |")


if __name__ == "__main__":
    main()
