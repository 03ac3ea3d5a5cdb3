#!/usr/bin/env python3
"""Drill a hole through a mesh with PIC: load a mesh, subtract a cylinder, render a PNG, write an STL.

    PYTHONPATH=build/python python3 examples/subtract_cylinder.py [--mesh data/fandisk.obj] [--out out/]

The cylinder runs along z through the middle of the mesh's bounding box, with a radius of a
tenth of its smallest side. Both solids are sampled into one root cube around the two of
them, so the Boolean needs no resampling; `part -= hole` edits the part in place.
"""
import argparse
from pathlib import Path

import numpy as np

import pic

ROOT = Path(__file__).resolve().parents[1]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh", type=Path, default=ROOT / "data" / "fandisk.obj")
    ap.add_argument("--out", type=Path, default=Path("out"))
    ap.add_argument("--depth", type=int, default=10)
    args = ap.parse_args()

    vertices, faces = pic.read_mesh(args.mesh)
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    center = (lo + hi) / 2
    radius = 0.1 * float((hi - lo).min())
    height = 1.2 * float(hi[2] - lo[2])  # pokes out at the top and bottom
    cyl_vertices, cyl_faces = pic.make_cylinder(center, radius, height, axis=2, segments=128)

    cube = pic.bounding_cube(np.vstack([vertices, cyl_vertices]))
    part = pic.sample(vertices, faces, depth=args.depth, cube=cube)
    hole = pic.sample(cyl_vertices, cyl_faces, depth=args.depth, cube=cube)
    part -= hole  # in place: only the cells around the hole are rebuilt
    print(f"{part.pics} PICs; subtract took {part.stats['seconds'] * 1e3:.1f} ms")

    args.out.mkdir(parents=True, exist_ok=True)
    name = args.mesh.stem + "_drilled"
    pic.write_png(pic.render(part, size=(640, 480)), args.out / f"{name}.png")
    out_vertices, out_faces = part.contour()
    pic.write_mesh(out_vertices, out_faces, args.out / f"{name}.stl")
    print(f"{len(out_faces)} triangles, volume {pic.volume(out_vertices, out_faces):.4g} "
          f"(was {pic.volume(vertices, faces):.4g}) -> {args.out / name}.{{png,stl}}")


if __name__ == "__main__":
    main()
