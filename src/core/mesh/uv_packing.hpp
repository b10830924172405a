#pragma once
// unwrapUvs' pieces and their packing: each chart projected onto a plane and split where its
// projection would overlap itself, each piece turned to its minimum-area bounding rectangle,
// and all pieces packed at one common scale on a skyline. Private to the core (src/core/mesh/).

#include <array>
#include <vector>

#include "mesh/uv_adjacency.hpp"
#include "mesh/uv_charts.hpp"
#include "mesh/uv_geometry.hpp"
#include "norm2tex/mesh/uv_unwrap.hpp"

namespace norm2tex {
namespace uv_unwrap_detail {

/// Texels kept in addition to the padding against float rounding of UVs (a chart edge exactly on
/// a texel centre would otherwise claim that texel or not by luck). packPieces keeps
/// padding_texels + kMarginTexels texels to the border and padding_texels + 1 + kMarginTexels
/// between pieces (padding_texels texel centres between them stay empty).
constexpr double kMarginTexels = 0.01;

/// A chart ready for packing: its faces, its welded vertices and their coordinates in metres in
/// [0, size.x] x [0, size.y] (u right, v up).
struct Piece {
  std::vector<int> faces;
  std::vector<int> vertices;
  std::vector<Vec2> local;
  Vec2 size = Vec2::Zero();
};

/// Turns the piece so its minimum-area bounding rectangle is axis-aligned (the optimum has a
/// side on a hull edge), then moves it to the origin and sets its size. Only `local` and `size`
/// change; a rotation, never a mirroring.
void alignPiece(Piece& piece);

/// Projects every chart onto its plane and splits it where its projection would overlap itself:
/// the pieces to pack, each turned to its minimum-area bounding rectangle. Pieces follow the
/// order of their charts; merged (empty) charts give none.
std::vector<Piece> makePieces(const Charts& charts, const std::vector<Face>& faces,
                              const Adjacency& adjacency, const PlanarUnits& units,
                              const std::vector<Vec3>& positions,
                              const std::array<Vec3, 26>& directions);

/// Where a box lies in the packing.
struct Placement {
  double x = 0, y = 0;   ///< top-left corner of the box in texels, image coordinates (row down)
  bool rotated = false;  ///< turned by 90 deg: the box's width is its size's y
};

/// Skyline bottom-left packing of boxes (already including their trailing gap) into
/// width x height, in the given order, each tried in both orientations. False when one does not
/// fit. Boxes are stacked from y = 0 down; each goes where its far edge (y + height) is
/// smallest, then leftmost, unturned on ties. A box may exceed the width or height, and reach
/// into a neighbour, by up to 1e-9 * max(width, height) (rounding of sizes that fit exactly).
bool packSkyline(const std::vector<Vec2>& boxes, const std::vector<int>& order, double width,
                 double height, std::vector<Placement>& placements);

/// Where the packed pieces go in the texture.
struct Packing {
  double scale = 0.0;                 ///< texels per metre, common to all pieces
  double border = 0.0;                ///< texels kept empty along the texture's border
  std::vector<Placement> placements;  ///< per piece
};

/// Packing order: largest pieces first (by longer side, then shorter side), ties kept in order.
std::vector<int> packingOrder(const std::vector<Piece>& pieces);

/// Upper bound of the scale that fits: the pieces' total area may not exceed the container's,
/// nor may the longest piece (plus its gap) exceed its side. Infinite without any extent.
double scaleUpperBound(const std::vector<Piece>& pieces, double container, double gap);

/// Packs all pieces at one scale, with padding between them and to the border: the largest
/// texels-per-metre that fits, by bisection. Throws when not even their padding fits.
/// Piece i covers the texels [border + x, border + x + w * scale] x [border + y, border + y +
/// h * scale] of placements[i] (w, h its size, swapped when rotated).
Packing packPieces(const std::vector<Piece>& pieces, const UnwrapOptions& options);

}  // namespace uv_unwrap_detail
}  // namespace norm2tex
