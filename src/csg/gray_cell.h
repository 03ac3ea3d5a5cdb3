// GraycellCSG's predicates (paper section 5.2.3, Figure 3), each a question about one cell of
// the paired recursion: what its edges say, whether the two surfaces meet in it, whether the
// summed QEF's feature is local, whether the result's finer signs are simple, the sign hints
// for the clean-up.
#pragma once

#include <optional>
#include <vector>

#include "csg/operand.h"

namespace pic::detail {

/// A finest leaf whose corner signs make more than one component (corners of one sign meeting
/// only diagonally): the result's sign half-way between such corners says whether the solid
/// (or the gap) joins them; when it joins all the corners of one sign, the hint asks the
/// clean-up to flip a corner of the other sign. Nothing when it joins neither.
std::optional<SignHint> sign_hint(CsgOp op, Operand& xa, Operand& xb, const Cell& cell, uint8_t sr);

/// A capped cell's edges whose ends agree in the result but which cross it twice, through
/// faces turning by more than kThinFeatureTurn (a wall between A's face and B's, a blade, a
/// slot thinner than the cell): both ends of each are hinted to the feature's sign, which
/// keeps the feature about a cell thick where the plain signs would drop it. Edges crossed
/// twice through faces turning by less give BesideThin hints (junctions of thin walls). Features
/// narrower than the operands' own accuracy (sqrt of the QEF threshold `error`) are left out.
void thin_feature_hints(CsgOp op, const Operand& xa, const Side& a, const Operand& xb, const Side& b, const Cell& cell,
                        uint8_t sr, double error, std::vector<SignHint>& out);

/// What the cell's edges say: whether either operand's surface is visible in the result
/// there, and whether the cell must split.
struct EdgeVerdict {
  bool must_split = false;
  bool vis_a = false, vis_b = false;
};
/// Directed distances on each edge and the 1D CSG of the two crossings (paper 5.2.3, Table 1).
EdgeVerdict edge_verdict(CsgOp op, const Operand& xa, const Side& a, const Operand& xb, const Side& b,
                         const Cell& cell);

/// Whether the operands' partial contours in the cell lie on the same planes (coinciding
/// faces, edges or corners, such as a box minus a box that shares its faces): the result there
/// is one operand's surface or none, with no new feature to refine toward.
bool surfaces_coincide(const Operand& xa, const Side& a, const Operand& xb, const Side& b, const Cell& cell);
/// Whether the operands' partial contours over the cell are the same triangles. A leaf's signs
/// and vertex alone do not fix the surface in its cell: its polygons also run to the
/// neighbours' vertices, so two solids can share a leaf's data there and still differ (two
/// boxes with a common corner, each with a vertex on it).
bool same_surface(const Operand& xa, const Side& a, const Operand& xb, const Side& b);
/// Whether the two operands' partial contours meet inside the cell.
bool surfaces_meet(const Operand& xa, const Side& a, const Operand& xb, const Side& b, const Cell& cell);

/// Whether the new feature (where the surfaces meet) fits one point or line over the cell
/// grown by half its size on every side.
bool feature_is_local(const Operand& xa, const Operand& xb, const Cell& cell, const Vec3& x, double error,
                      std::vector<uint32_t>& scratch);

/// Whether the result's signs on the cell's child grid (op of the operands' sign_grid) are
/// simple (grid_is_simple).
bool refinement_is_simple(CsgOp op, const SignGrid& a, const SignGrid& b);

/// The two operands' QEFs over the cell, and their sum.
struct CellQefs {
  Qef a, b, sum;
};
CellQefs cell_qefs(const Operand& xa, const Side& a, const Operand& xb, const Side& b, const Cell& cell);

/// An operand's own vertex in the cell: the leaf's stored one, or the minimizer of its QEF in
/// a virtual cell.
Vec3 operand_vertex(const Operand& x, const Side& s, const Qef& q, const Cell& cell);

}  // namespace pic::detail
