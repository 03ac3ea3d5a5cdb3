#!/usr/bin/env python3
"""Writes the small seed files of fuzz/corpus/ (run once; the output is committed).
Usage: fuzz/make_seeds.py PIC_CLI   (the CLI writes the .pic and GLB seeds)"""
import base64, json, os, struct, subprocess, sys, tempfile

root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus")
pic = sys.argv[1]
V = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
T = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
CUBE_V = [(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)]
CUBE_Q = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]


def put(kind, name, data):
    with open(os.path.join(root, kind, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


def normal(p):
    c = (0.25, 0.25, 0.25)
    return tuple(a - b for a, b in zip(p, c))


# PLY
head = "ply\nformat {}\nelement vertex {}\nproperty {t} x\nproperty {t} y\nproperty {t} z\n"
put("ply", "tet_ascii.ply", head.format("ascii 1.0", 4, t="float") +
    "element face 4\nproperty list uchar int vertex_indices\nend_header\n" +
    "".join("%g %g %g\n" % v for v in V) + "".join("3 %d %d %d\n" % t for t in T))
put("ply", "cube_quads_ascii.ply", head.format("ascii 1.0", 8, t="double") +
    "element face 6\nproperty list uchar uint vertex_index\nelement edge 1\nproperty int a\nproperty int b\n"
    "end_header\n" + "".join("%g %g %g\n" % v for v in CUBE_V) + "".join("4 %d %d %d %d\n" % q for q in CUBE_Q) +
    "0 1\n")
b = (head.format("binary_little_endian 1.0", 4, t="float") + "property uchar red\n"
     "element face 4\nproperty list uchar int vertex_indices\nproperty list uchar float texcoord\nend_header\n").encode()
b += b"".join(struct.pack("<3fB", *v, 200) for v in V)
b += b"".join(struct.pack("<B3iB", 3, *t, 0) for t in T)
put("ply", "tet_binary_le.ply", b)
b = (head.format("binary_big_endian 1.0", 4, t="double") +
     "element face 4\nproperty list ushort uint vertex_indices\nend_header\n").encode()
b += b"".join(struct.pack(">3d", *v) for v in V) + b"".join(struct.pack(">H3I", 3, *t) for t in T)
put("ply", "tet_binary_be.ply", b)
pc = head.format("ascii 1.0", 4, t="float") + "property float nx\nproperty float ny\nproperty float nz\nend_header\n"
put("ply", "points_ascii.ply", pc + "".join("%g %g %g %g %g %g\n" % (v + normal(v)) for v in V))
b = (head.format("binary_little_endian 1.0", 4, t="float") +
     "property float nx\nproperty float ny\nproperty float nz\nelement face 0\n"
     "property list uchar int vertex_indices\nend_header\n").encode()
put("ply", "points_binary.ply", b + b"".join(struct.pack("<6f", *(v + normal(v))) for v in V))

# OBJ
put("obj", "tet.obj", "# tetrahedron\n" + "".join("v %g %g %g\n" % v for v in V) +
    "".join("f %d %d %d\n" % tuple(i + 1 for i in t) for t in T))
put("obj", "cube_forms.obj", "o cube\n" + "".join("v %g %g %g\n" % v for v in CUBE_V) +
    "vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\ng faces\ns off\nusemtl none\n" +
    "f 1/1/1 3/2/1 4/3/1 2/1/1\nf 5//1 6//1 8//1 7//1\nf 1/1 2/2 6/3 5/1\nf -6 -2 -1 -5\n"
    "f 1 5 7 3 # comment\nf 2 4 8 6\nl 1 2\n")

# OFF
put("off", "tet.off", "OFF\n4 4 0\n" + "".join("%g %g %g\n" % v for v in V) + "".join("3 %d %d %d\n" % t for t in T))
put("off", "cube_coff.off", "COFF\n# a cube with colors\n8 6 12\n" +
    "".join("%g %g %g 255 0 0 255\n" % v for v in CUBE_V) + "".join("4 %d %d %d %d 0 0 255\n" % q for q in CUBE_Q))
put("off", "tet_noff.off", "NOFF 4 4 0\n" + "".join("%g %g %g 0 0 1\n" % v for v in V) +
    "".join("3 %d %d %d\n" % t for t in T))

# STL
facets = "".join("facet normal 0 0 0\n outer loop\n" + "".join("  vertex %g %g %g\n" % V[i] for i in t) +
                 " endloop\nendfacet\n" for t in T)
put("stl", "tet_ascii.stl", "solid tet\n" + facets + "endsolid tet\n")
b = b"solid but binary".ljust(80, b" ") + struct.pack("<I", 4)
for t in T:
    b += struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *V[i]) for i in t) + b"\0\0"
put("stl", "tet_binary.stl", b)

# glTF (first byte: even = .gltf, odd = .glb; see fuzz_gltf.cpp)
pos = b"".join(struct.pack("<3f", *v) for v in V)
idx = b"".join(struct.pack("<3H", *t) for t in T)
buf = pos + idx
doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
       "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
       "buffers": [{"byteLength": len(buf), "uri": "data:application/octet-stream;base64," +
                    base64.b64encode(buf).decode()}],
       "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(pos)},
                       {"buffer": 0, "byteOffset": len(pos), "byteLength": len(idx)}],
       "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                      "min": [0, 0, 0], "max": [1, 1, 1]},
                     {"bufferView": 1, "componentType": 5123, "count": 12, "type": "SCALAR"}]}
put("gltf", "tet.gltf", b"\0" + json.dumps(doc).encode())
with tempfile.TemporaryDirectory() as d:
    obj = os.path.join(root, "obj", "tet.obj")
    subprocess.run([pic, "sample", obj, "--depth", "4", "-o", os.path.join(d, "t.pic")], check=True,
                   stdout=subprocess.DEVNULL)
    subprocess.run([pic, "mesh", os.path.join(d, "t.pic"), "-o", os.path.join(d, "t.glb")], check=True,
                   stdout=subprocess.DEVNULL)
    put("gltf", "tet.glb", b"\1" + open(os.path.join(d, "t.glb"), "rb").read())
    put("pic", "tet_d4.pic", open(os.path.join(d, "t.pic"), "rb").read())
    subprocess.run([pic, "prim", "sphere", "--depth", "3", "--segments", "16", "-o", os.path.join(d, "s.pic")],
                   check=True, stdout=subprocess.DEVNULL)
    put("pic", "sphere_d3.pic", open(os.path.join(d, "s.pic"), "rb").read())
    subprocess.run([pic, "mesh", os.path.join(d, "s.pic"), "-o", os.path.join(d, "s.ply")], check=True,
                   stdout=subprocess.DEVNULL)
    put("ply", "sphere_pic_written.ply", open(os.path.join(d, "s.ply"), "rb").read())
