// PIC — Points with Implicit Connectivity.
//
// A PIC object is an adaptive octree over a root cube. Leaves are white (outside), black
// (inside) or gray; a gray leaf holds one representative vertex and the in/out signs of its
// eight corners. The surface is recovered by dual contouring (SurfaceNets) of the octree.
// Reference: Zhang, Qu, Kaufman, "CSG Operations on Point Models with Implicit Connectivity".
//
// This umbrella header includes the whole public API; each concern has its own header:
//   types.h    points, meshes, point clouds, the root cube, errors
//   octree.h   the PIC object (Octree) and its leaves
//   sample.h   mesh / point cloud -> PIC object
//   contour.h  PIC object -> closed triangle mesh
//   csg.h      Booleans on PIC objects
//   volume.h   offsets, shells, rounds, thickened surfaces
//   io.h       .pic files, mesh and point cloud files
//   measure.h  topology, validity, volume, distances
//   primitives.h, scad.h, render.h, viewer.h: primitives, OpenSCAD, pictures
#pragma once

#include "pic/contour.h"
#include "pic/csg.h"
#include "pic/io.h"
#include "pic/measure.h"
#include "pic/octree.h"
#include "pic/primitives.h"
#include "pic/sample.h"
#include "pic/scad.h"
#include "pic/types.h"
#include "pic/volume.h"
