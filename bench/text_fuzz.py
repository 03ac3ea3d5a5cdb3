#!/usr/bin/env python3
"""Random OpenSCAD text() calls, outlined by `pic eval` and by OpenSCAD, compared as 2D drawings.

    python3 bench/text_fuzz.py FIRST_SEED COUNT [OUTDIR]     (default /tmp/pic_text_fuzz)

Each case is one text() with a random string (accents, punctuation, a tab, ligature pairs), size,
font among the installed Liberation and DejaVu faces, spacing, halign, valign, direction
(horizontal and vertical) and $fn/$fa/$fs. OpenSCAD exports the outline as DXF LINEs and the
.csg; `pic eval x.csg -o pic.dxf --json` gives PIC's area and rings. A case is reported BAD when
the areas differ by more than 2e-3 (relative) or the drawings' boxes by more than 2e-3 of the
drawing's extent (or the text's size, if larger); the two agree to about 3e-4 otherwise (OpenSCAD's curves and advances are rounded
in 26.6 fixed point). Every case is replayable: OUTDIR/N/m.scad, ref.dxf, pic.dxf.
"""
import json
import os
import random
import subprocess
import sys

from fuzz_tools import PIC

STRINGS = ["Hello", "og8", "PIC 0.1", "Ångström", "(x+y)=z!", "WAVE", "fi fl", "ÄÖÜ äöü ß", "a\\tb", "123",
           "i.j,k;", "@#%&", "Qq", "mm"]
FONTS = ["", "Liberation Sans", "Liberation Serif", "Liberation Mono", "DejaVu Sans", "DejaVu Serif:style=Bold",
         "Liberation Sans:style=Bold Italic", "DejaVu Sans Mono"]


def dxf_pairs(path):
    lines = [l.strip() for l in open(path).read().split("\n")]
    return lines[lines.index("ENTITIES") + 1:]


def ref_outline(path):
    """OpenSCAD's export: LINE entities. Returns (signed area, box)."""
    lines = dxf_pairs(path)
    segments, i = [], 0
    while i < len(lines) - 1:
        if lines[i] == "0" and lines[i + 1] == "LINE":
            codes, j = {}, i + 2
            while j < len(lines) - 1 and lines[j] != "0":
                codes[lines[j]] = lines[j + 1]
                j += 2
            segments.append(((float(codes["10"]), float(codes["20"])), (float(codes["11"]), float(codes["21"]))))
            i = j
        else:
            i += 2
    area = sum(p[0] * q[1] - q[0] * p[1] for p, q in segments) / 2
    points = [p for s in segments for p in s]
    return area, box(points)


def pic_box(path):
    """PIC's export: LWPOLYLINE vertices (10/20 pairs)."""
    lines = dxf_pairs(path)
    points = [(float(lines[i + 1]), float(lines[i + 3])) for i in range(len(lines) - 3)
              if lines[i] == "10" and lines[i + 2] == "20"]
    return box(points)


def box(points):
    if not points:
        return None
    xs, ys = [p[0] for p in points], [p[1] for p in points]
    return (min(xs), min(ys), max(xs), max(ys))


def random_text(r):
    size = r.choice([0.7, 2.1, 3, 5, 10, 25])
    args = ['"%s"' % r.choice(STRINGS), "size=%g" % size]
    font = r.choice(FONTS)
    if font:
        args.append('font="%s"' % font)
    if r.random() < 0.4:
        args.append("spacing=%g" % r.choice([0.8, 1.2, 2]))
    if r.random() < 0.4:
        args.append('halign="%s"' % r.choice(["left", "center", "right"]))
    if r.random() < 0.4:
        args.append('valign="%s"' % r.choice(["top", "center", "baseline", "bottom"]))
    if r.random() < 0.2:
        args.append('direction="%s"' % r.choice(["ltr", "rtl", "ttb", "btt"]))
    if r.random() < 0.4:
        args.append(r.choice(["$fn=%d" % r.choice([3, 6, 12, 30, 64]), "$fa=%d" % r.choice([5, 30]),
                              "$fs=%g" % r.choice([0.2, 1, 5])]))
    return "text(%s);" % ", ".join(args), size


def main():
    first, count = int(sys.argv[1]), int(sys.argv[2])
    out = sys.argv[3] if len(sys.argv) > 3 else "/tmp/pic_text_fuzz"
    bad = 0
    for seed in range(first, first + count):
        scad, size = random_text(random.Random(seed))
        d = os.path.join(out, str(seed))
        os.makedirs(d, exist_ok=True)
        with open(os.path.join(d, "m.scad"), "w") as f:
            f.write(scad + "\n")
        for target in ("ref.dxf", "m.csg"):
            subprocess.run(["openscad", "-o", os.path.join(d, target), os.path.join(d, "m.scad")], capture_output=True)
        run = subprocess.run([PIC, "eval", os.path.join(d, "m.csg"), "-o", os.path.join(d, "pic.dxf"), "--json"],
                             capture_output=True, text=True)
        try:
            ref_area, ref_box = ref_outline(os.path.join(d, "ref.dxf"))
            pic_area = json.loads(run.stdout)["area"]
            box_pic = pic_box(os.path.join(d, "pic.dxf"))
        except (OSError, ValueError, KeyError) as e:
            print(seed, "ERROR", scad, (run.stderr.strip() or str(e))[:120])
            bad += 1
            continue
        rel = abs(pic_area - ref_area) / max(abs(ref_area), 1e-12)
        if ref_box is None or box_pic is None:  # an empty drawing: both must be
            off = 0 if ref_box == box_pic else float("inf")
        else:  # relative to the drawing: a long column's advances add up
            extent = max(size, ref_box[2] - ref_box[0], ref_box[3] - ref_box[1])
            off = max(abs(a - b) for a, b in zip(ref_box, box_pic)) / extent
        verdict = "BAD" if rel > 2e-3 or off > 2e-3 else "ok"
        bad += verdict == "BAD"
        print(seed, verdict, "area %.2e box %.2e" % (rel, off), scad, flush=True)
    print("%d of %d reported" % (bad, count))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
