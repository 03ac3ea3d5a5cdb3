"""PIC: solids as points with implicit connectivity.

Sample meshes and oriented point clouds into adaptive octrees, combine them with Booleans
computed on the octrees, contour them back to closed meshes, render them. Arrays in and out
are numpy arrays. See the type stubs (__init__.pyi) and help(pic.sample) for signatures.
"""
from typing import Any as _Any, NamedTuple as _NamedTuple


class Mesh(_NamedTuple):
    """A triangle mesh: vertices float64 (n, 3), faces int64 (m, 3), counter-clockwise seen from
    outside. A tuple, so ``vertices, faces = pic.read_mesh(path)`` works as well as
    ``mesh.vertices``; pic.sample and pic.csg_meshes take it (or anything with .vertices and
    .faces, such as a trimesh.Trimesh) as one argument."""
    vertices: _Any
    faces: _Any


from ._pic import *  # noqa: F401,F403,E402
from ._pic import Octree, MAX_LEVEL  # noqa: F401

__version__ = "0.1.0"
