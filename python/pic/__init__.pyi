"""PIC: solids as points with implicit connectivity (type stubs for the `pic` module)."""
import os
from typing import Any, Iterable, NamedTuple, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

__version__: str
MAX_LEVEL: int
"""Deepest octree level any PIC object may reach."""

PathLike = Union[str, "os.PathLike[str]"]
Cube = Tuple[float, float, float, float]
"""Root cube (x, y, z, size): minimum corner and side, in the input's coordinates."""
Vertices = npt.NDArray[np.float64]
"""(n, 3) float64 positions."""
Faces = npt.NDArray[np.int64]
"""(m, 3) int64 vertex indices, counter-clockwise seen from outside."""
class Mesh(NamedTuple):
    """A triangle mesh (vertices, faces): a tuple, so ``v, f = pic.read_mesh(p)`` works, and
    ``mesh.vertices`` too. pic.sample and pic.csg_meshes take it as one argument."""
    vertices: Vertices
    faces: Faces

MeshLike = Any
"""A Mesh, a (vertices, faces) tuple with integer faces, or anything with .vertices and .faces."""
ArrayLike = npt.ArrayLike
"""Inputs: (n, 3) arrays of float32/float64 (vertices) or int32/int64 (faces), or nested lists."""

class Octree:
    """A PIC object: an adaptive octree whose gray leaves each hold one representative vertex
    and the in/out signs of the cell's corners.

    Made by sample, load, deserialize, eval_scad or CSG. ``a | b`` (union), ``a & b``
    (intersect), ``a - b`` (subtract) return new objects; ``a |= b``, ``a &= b``, ``a -= b``
    edit ``a`` in place (the library's sculpting path: only the overlap is rebuilt). Pickles
    through its .pic bytes.
    """

    @property
    def pics(self) -> int:
        """Number of PICs (gray leaves, one representative vertex each)."""
    @property
    def nodes(self) -> int:
        """Number of octree nodes."""
    @property
    def depth(self) -> int:
        """Maximum octree level."""
    @property
    def cube(self) -> Cube:
        """Root cube (x, y, z, size)."""
    @property
    def stats(self) -> dict[str, Any]:
        """Statistics of the operation that made or last changed this object (sample, csg, eval);
        empty after load."""
    def contour(self, intersection_free: bool = True, split: bool = True,
                stats: Optional[dict[str, Any]] = None) -> Mesh:
        """The closed surface by dual contouring: (vertices (n, 3) float64, faces (m, 3) int64).

        intersection_free: re-triangulate so no two triangles cross (False: `pic mesh --fast`).
        split: give touching sheets their own vertex copies, as `pic mesh` writes.
        stats: a dict to fill with the contour's counts and seconds.
        """
    def info(self, check: bool = True) -> dict[str, Any]:
        """The dict `pic info --json` prints: cells per level, PICs, bytes, bounding box, and
        the contour's topology and validity. check=False skips the exact self-intersection test."""
    def save(self, path: PathLike) -> None:
        """Writes the .pic file atomically. Raises OSError."""
    def serialize(self) -> bytes:
        """The .pic file's bytes."""
    def copy(self) -> Octree:
        """An independent copy."""
    def __copy__(self) -> Octree: ...
    def __deepcopy__(self, memo: Any) -> Octree: ...
    def __or__(self, other: Octree) -> Octree:
        """Union, a new object."""
    def __and__(self, other: Octree) -> Octree:
        """Intersection, a new object."""
    def __sub__(self, other: Octree) -> Octree:
        """Difference, a new object."""
    def __ior__(self, other: Octree) -> Octree:
        """Union in place (pic::csg_inplace)."""
    def __iand__(self, other: Octree) -> Octree:
        """Intersection in place (pic::csg_inplace)."""
    def __isub__(self, other: Octree) -> Octree:
        """Difference in place (pic::csg_inplace): the sculpting path."""
    def __getstate__(self) -> tuple[bytes]: ...
    def __setstate__(self, state: tuple[bytes]) -> None: ...

@overload
def sample(input: PathLike, *, depth: int = 12, error: float = 1e-8, cube: Optional[Sequence[float]] = None,
           inside: str = "auto", parallel: bool = True, margin: float = 1 / 16) -> Octree: ...
@overload
def sample(input: MeshLike, *, depth: int = 12, error: float = 1e-8,
           cube: Optional[Sequence[float]] = None, inside: str = "auto", parallel: bool = True,
           margin: float = 1 / 16) -> Octree: ...
@overload
def sample(input: ArrayLike, faces: ArrayLike, depth: int = 12, error: float = 1e-8,
           cube: Optional[Sequence[float]] = None, inside: str = "auto", parallel: bool = True,
           margin: float = 1 / 16) -> Octree: ...
def sample(input: Any, faces: Any = None, depth: int = 12, error: float = 1e-8,
           cube: Optional[Sequence[float]] = None, inside: str = "auto", parallel: bool = True,
           margin: float = 1 / 16) -> Octree:
    """Adaptively samples a solid into a PIC object (pic::sample).

    input: (n, 3) vertices with faces (m, 3); or one mesh (pic.Mesh as read_mesh returns it,
    a (vertices, faces) tuple, anything with .vertices and .faces); or a path to a mesh (obj,
    stl, ply, off, gltf, glb) or point cloud (ply with normals, xyz). Arrays of points go
    through sample_points (a (points, normals) tuple still works, deprecated). depth: maximum level (1..MAX_LEVEL). error: QEF residual threshold in
    root-cube units squared. cube: (x, y, z, size), default the bounding cube plus `margin`
    of the extent; share one between CSG operands. inside: 'auto', 'parity', 'winding'.
    Raises ValueError for bad input, OSError for an unreadable file. The GIL is released.
    """

def sample_points(points: ArrayLike, normals: ArrayLike, depth: int = 12, error: float = 1e-8,
                  cube: Optional[Sequence[float]] = None, parallel: bool = True,
                  margin: float = 1 / 16) -> Octree:
    """Samples an oriented point cloud (normals pointing out of the solid) into a PIC object.
    The depth stops where a cell is half the points' spacing (stats['depth_used'])."""

def csg_meshes(*args: Any, depth: int = 12, error: float = 1e-8, parallel: bool = True,
               cube: Optional[Sequence[float]] = None) -> Octree:
    """Booleans left to right: csg_meshes(a, 'subtract', b [, 'union', c ...]). Operands are
    meshes (MeshLike), mesh paths or Octrees; meshes are sampled into one cube around all of
    them, as `pic csg` does. stats['steps'] hold each Boolean's statistics."""

def bounding_cube(vertices: ArrayLike, margin: float = 1 / 16) -> Cube:
    """The automatic root cube around points (bounding cube plus margin of the extent)."""

def union(solids: Iterable[Any], *, depth: int = 12, error: float = 1e-8, parallel: bool = True) -> Octree:
    """The union of PIC objects and meshes, combined in a balanced order (halves in parallel);
    three combine as a | (b | c)."""
    ...

def intersection(solids: Iterable[Any], *, depth: int = 12, error: float = 1e-8, parallel: bool = True) -> Octree:
    """The intersection of PIC objects and meshes, combined as union() combines them."""
    ...

def difference(a: Any, solids: Iterable[Any], *, depth: int = 12, error: float = 1e-8,
               parallel: bool = True) -> Octree:
    """a minus the union of the others."""
    ...

def offset(solid: Any, distance: float, *, depth: int = 12, error: float = 1e-8, cube: Any = None,
           parallel: bool = True, mesh: bool = False) -> Any:
    """The solid grown by distance (> 0) or shrunk (< 0); solid: an Octree or a mesh. With
    mesh=True: (Octree, (vertices, faces)), the mesh's points on the exact offset surface (as
    every volume operation below takes it)."""
    ...

def minkowski_round(solid: Any, body: Any, *, depth: int = 12, error: float = 1e-8, cube: Any = None,
                    parallel: bool = True, mesh: bool = False) -> Any:
    """The Minkowski sum of a solid with a round convex body (its (n, 3) vertices: a faceted sphere)."""
    ...

def shell(solid: Any, thickness: float, *, outward: bool = False, depth: int = 12, error: float = 1e-8,
          cube: Any = None, parallel: bool = True, mesh: bool = False) -> Any:
    """The solid hollowed to walls `thickness` thick (outward: a skin around it)."""
    ...

def round(solid: Any, radius: float, *, concave: bool = False, depth: int = 12, error: float = 1e-8,
          cube: Any = None, parallel: bool = True, mesh: bool = False) -> Any:
    """Convex edges rounded to `radius` (concave=True: concave edges filled)."""
    ...

def thicken(surface: Any, thickness: float, *, depth: int = 12, error: float = 1e-8, cube: Any = None,
            parallel: bool = True, mesh: bool = False) -> Any:
    """The solid within thickness / 2 of a surface, open or closed."""
    ...

def sample_function(f: Any, cube: Any, *, depth: int = 8, error: float = 1e-8, gradient: Any = None,
                    lipschitz: float = 1.0) -> Octree:
    """The solid f < 0 for f a function of an (n, 3) array of points returning n values."""
    ...

def csg(a: Octree, b: Octree, op: str, error: float = 1e-8, parallel: bool = True) -> Octree:
    """Boolean on the octrees as a new object (pic::csg). op: 'union', 'intersect'
    ('intersection'), 'subtract' ('difference'). The result's .stats hold the statistics."""

def csg_inplace(a: Octree, b: Octree, op: str, error: float = 1e-8, parallel: bool = True) -> None:
    """a := a op b (pic::csg_inplace): only the overlap is rebuilt. a.stats become the operation's."""

def contour(tree: Octree, intersection_free: bool = True, split: bool = True,
            stats: Optional[dict[str, Any]] = None) -> Mesh:
    """Same as tree.contour(...)."""

def load(path: PathLike) -> Octree:
    """Reads a .pic file. Raises OSError for a missing, truncated, corrupted or foreign file."""

def save(tree: Octree, path: PathLike) -> None:
    """Same as tree.save(path)."""

def deserialize(data: bytes) -> Octree:
    """A PIC object from .pic bytes (Octree.serialize()). Raises OSError for corrupted bytes."""

def eval_scad(path: PathLike, depth: int = 12, error: float = 1e-8, smooth: bool = False,
              parallel: bool = True) -> Octree:
    """Evaluates an OpenSCAD model (.scad through `openscad`, or its .csg export) on octrees."""

def eval_csg(text: str, depth: int = 12, error: float = 1e-8, smooth: bool = False,
             parallel: bool = True) -> Octree:
    """Evaluates OpenSCAD CSG-tree text (the .csg format) on octrees."""

def read_mesh(path: PathLike) -> Mesh:
    """Reads OBJ, STL, PLY, OFF, glTF/GLB, duplicate vertices welded. Raises OSError, ValueError."""

def write_mesh(mesh_or_vertices: Any, faces_or_path: Any, path: Optional[PathLike] = None) -> None:
    """write_mesh(mesh, path) or write_mesh(vertices, faces, path); format from the extension,
    written atomically. Raises OSError."""

def volume(mesh_or_vertices: Any, faces: Optional[ArrayLike] = None) -> float:
    """volume(mesh) or volume(vertices, faces): signed volume (positive for outward orientation)."""

def check_validity(vertices: ArrayLike, faces: ArrayLike, self_intersections: bool = True) -> dict[str, Any]:
    """Validity as a solid's boundary (pic::check_validity): 'valid' and the counts."""

def make_box(lo: Sequence[float], hi: Sequence[float]) -> Mesh:
    """Closed mesh of the axis-aligned box [lo, hi]."""

def make_sphere(center: Sequence[float], radius: float, segments: int = 64) -> Mesh:
    """Closed UV sphere mesh."""

def make_cylinder(center: Sequence[float], radius: float, height: float, axis: int = 2,
                  segments: int = 64) -> Mesh:
    """Closed cylinder mesh along axis 0, 1 or 2, centred at center."""

def make_cone(center: Sequence[float], radius: float, height: float, axis: int = 2,
              segments: int = 64) -> Mesh:
    """Closed cone mesh: base at center - height/2, apex at center + height/2."""

def make_torus(center: Sequence[float], major: float, minor: float, axis: int = 2, segments: int = 64,
               tube_segments: int = 32) -> Mesh:
    """Closed torus mesh around axis."""

def render(obj: Union[Octree, Tuple[ArrayLike, ArrayLike]], size: Tuple[int, int] = (640, 480),
           octree: bool = False, points: bool = False, view: str = "iso",
           camera: Optional[Sequence[float]] = None, perspective: bool = False,
           supersample: int = 2) -> npt.NDArray[np.uint8]:
    """Renders an Octree (its contour) or a mesh (vertices, faces) to an (h, w, 3) uint8 array.

    size: (width, height). octree: draw the gray leaves' cells; points: the representative
    vertices. view: iso, front, back, left, right, top, bottom (+Z up). camera: eye xyz,
    target xyz, up xyz (9 numbers)."""

def write_png(image: npt.ArrayLike, path: PathLike) -> None:
    """Writes an (h, w, 3) uint8 array as a PNG, atomically. Raises OSError."""
