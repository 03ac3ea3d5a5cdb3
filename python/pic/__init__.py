"""PIC: solids as points with implicit connectivity.

Sample meshes and oriented point clouds into adaptive octrees, combine them with Booleans
computed on the octrees, contour them back to closed meshes, render them. Arrays in and out
are numpy arrays. See the type stubs (__init__.pyi) and help(pic.sample) for signatures.
"""
from ._pic import *  # noqa: F401,F403
from ._pic import Octree, MAX_LEVEL  # noqa: F401

__version__ = "0.1.0"
