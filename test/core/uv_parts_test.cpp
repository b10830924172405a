// unwrapUvs' steps, tested directly (src/core/mesh/uv_*.hpp): welding and adjacency, the chart
// segmentation, the splitting of charts into pieces and their skyline packing.
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "mesh/uv_adjacency.hpp"
#include "mesh/uv_charts.hpp"
#include "mesh/uv_geometry.hpp"
#include "mesh/uv_packing.hpp"
#include "norm2tex/mesh/mesh_primitives.hpp"
#include "norm2tex/mesh/uv_unwrap.hpp"
#include "test_helpers.hpp"

namespace norm2tex {
namespace {

using namespace uv_unwrap_detail;  // the steps under test
using test::expectError;

// What unwrapUvs builds before its segmentation: faces on welded vertices and their adjacency.
struct Prepared {
  std::vector<int> welded, representative;
  std::vector<Vec3> positions;
  std::array<Vec3, 26> directions = chartDirections();
  std::vector<Face> faces;
  double total_area = 0.0;
  Adjacency adjacency;
};

Prepared prepare(const TexturedMesh& mesh) {
  Prepared p;
  p.welded = weldVertices(mesh.vertices(), p.representative);
  p.positions = weldedPositions(mesh.vertices(), p.representative);
  p.faces = makeFaces(mesh.triangles(), p.welded, p.positions, p.directions, p.total_area);
  p.adjacency = buildAdjacency(p.faces, p.positions);
  return p;
}

// The unit cube [-0.5, 0.5]^3 on 8 shared vertices (index = 4 x + 2 y + z of its corner bits),
// 12 triangles with outward winding, two per face in the order +x, -x, +y, -y, +z, -z.
TexturedMesh makeSharedCube() {
  std::vector<Eigen::Vector3f> vertices;
  for (int i = 0; i < 8; ++i) {
    vertices.emplace_back((i >> 2 & 1) - 0.5f, (i >> 1 & 1) - 0.5f, (i & 1) - 0.5f);
  }
  const int quads[6][4] = {{4, 6, 7, 5}, {0, 1, 3, 2}, {2, 3, 7, 6},
                           {0, 4, 5, 1}, {1, 5, 7, 3}, {0, 2, 6, 4}};
  std::vector<Eigen::Vector3i> triangles;
  for (const auto& q : quads) {
    triangles.emplace_back(q[0], q[1], q[2]);
    triangles.emplace_back(q[0], q[2], q[3]);
  }
  return TexturedMesh(vertices, triangles);
}

// A closed cylinder around z: `segments` side quads (triangles 0 .. 2 segments - 1), then the
// fanned caps, bottom and top alternating (a centre vertex each). With `duplicate_rims` the caps
// use copies of the rim vertices (as exporters write a hard edge), else the side's.
TexturedMesh makeCylinder(int segments, bool duplicate_rims) {
  const double pi = 3.14159265358979323846;
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> triangles;
  const int n = segments;
  for (float z : {0.0f, 0.03f}) {
    for (int i = 0; i < n; ++i) {
      const double a = 2 * pi * i / n;
      vertices.emplace_back(static_cast<float>(0.01 * std::cos(a)),
                            static_cast<float>(0.01 * std::sin(a)), z);
    }
  }
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    triangles.emplace_back(i, j, j + n);
    triangles.emplace_back(i, j + n, i + n);
  }
  int bottom = 0, top = n;
  if (duplicate_rims) {
    bottom = static_cast<int>(vertices.size());
    top = bottom + n;
    for (int i = 0; i < 2 * n; ++i) vertices.push_back(vertices[i]);
  }
  const int centre = static_cast<int>(vertices.size());
  vertices.emplace_back(0.0f, 0.0f, 0.0f);
  vertices.emplace_back(0.0f, 0.0f, 0.03f);
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    triangles.emplace_back(centre, bottom + j, bottom + i);
    triangles.emplace_back(centre + 1, top + i, top + j);
  }
  return TexturedMesh(vertices, triangles);
}

// ---------------------------------------------------------------------------------------------
// Welding, faces and adjacency

TEST(UvWeld, EqualPositionsShareAnIdAndMinusZeroIsZero) {
  const float above_one = std::nextafter(1.0f, 2.0f);
  const std::vector<Eigen::Vector3f> vertices = {
      {0, 0, 0}, {1, 0, 0}, {0, 0, 0}, {-0.0f, 0, -0.0f}, {1, 0, 0}, {above_one, 0, 0}, {0, 1, 0}};
  std::vector<int> representative = {99};  // cleared
  const std::vector<int> welded = weldVertices(vertices, representative);
  EXPECT_EQ(welded, (std::vector<int>{0, 1, 0, 0, 1, 2, 3}));
  EXPECT_EQ(representative, (std::vector<int>{0, 1, 5, 6}));
  const std::vector<Vec3> positions = weldedPositions(vertices, representative);
  ASSERT_EQ(positions.size(), 4u);
  EXPECT_EQ(positions[2], Vec3(static_cast<double>(above_one), 0, 0));
  EXPECT_EQ(positions[3], Vec3(0, 1, 0));
}

TEST(UvWeld, DuplicatedCubeCornersWeldToEight) {
  // makeBox gives every face its own 4 vertices: 24 vertices on 8 positions.
  const TexturedMesh box = makeBox(Eigen::Vector3d(0.02, 0.01, 0.005));
  ASSERT_EQ(box.vertices().size(), 24u);
  const Prepared p = prepare(box);
  EXPECT_EQ(p.representative.size(), 8u);
  for (size_t i = 0; i < box.vertices().size(); ++i) {
    EXPECT_EQ(box.vertices()[p.representative[p.welded[i]]], box.vertices()[i]) << "vertex " << i;
  }
  // Welded, the box is closed: every face has its three edges shared with one face each.
  EXPECT_EQ(p.adjacency.offset.back(), 36);
  for (int f = 0; f < 12; ++f) EXPECT_EQ(p.adjacency.offset[f + 1] - p.adjacency.offset[f], 3);
}

TEST(UvAdjacency, CountsTheSharedEdgesOfAStrip) {
  // 0 -- 1 -- 2 along x, 3 -- 4 -- 5 one above; triangles T0 (0 1 4), T1 (0 4 3), T2 (1 2 5),
  // T3 (1 5 4): shared edges 0-4 (T0 T1, length sqrt 2), 1-4 (T0 T3, 1), 1-5 (T2 T3, sqrt 2).
  const TexturedMesh strip({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 1, 0}},
                           {{0, 1, 4}, {0, 4, 3}, {1, 2, 5}, {1, 5, 4}});
  const Prepared p = prepare(strip);
  EXPECT_EQ(p.total_area, 2.0);
  for (const Face& face : p.faces) {
    EXPECT_EQ(face.area, 0.5);
    EXPECT_EQ(face.normal, Vec3::UnitZ());
    EXPECT_EQ(p.directions[face.cls], Vec3::UnitZ());
  }
  EXPECT_EQ(p.adjacency.offset, (std::vector<int>{0, 2, 3, 4, 6}));
  EXPECT_EQ(p.adjacency.neighbour, (std::vector<int>{1, 3, 0, 3, 0, 2}));
  const double root2 = std::sqrt(2.0);
  EXPECT_EQ(p.adjacency.length, (std::vector<double>{root2, 1.0, root2, root2, 1.0, root2}));
}

// `count` triangles on the edge 0-1 (vertex 0 at the origin, 1 above it), fanned around it.
TexturedMesh makeFan(int count) {
  const double pi = 3.14159265358979323846;
  std::vector<Eigen::Vector3f> vertices = {{0, 0, 0}, {0, 0, 1}};
  std::vector<Eigen::Vector3i> triangles;
  for (int i = 0; i < count; ++i) {
    const double a = 2 * pi * i / count;
    vertices.emplace_back(static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a)), 0.5f);
    triangles.emplace_back(0, 1, 2 + i);
  }
  return TexturedMesh(vertices, triangles);
}

TEST(UvAdjacency, NonManifoldFansLinkAllPairsUpToTheLimitThenAChain) {
  const int n = kMaxEdgeFan;
  const Prepared all = prepare(makeFan(n));
  EXPECT_EQ(all.adjacency.offset.back(), n * (n - 1));
  for (int f = 0; f < n; ++f) {
    std::vector<int> expected;
    for (int g = 0; g < n; ++g) {
      if (g != f) expected.push_back(g);
    }
    const std::vector<int> got(all.adjacency.neighbour.begin() + all.adjacency.offset[f],
                               all.adjacency.neighbour.begin() + all.adjacency.offset[f + 1]);
    EXPECT_EQ(got, expected) << "face " << f;
  }
  const int m = kMaxEdgeFan + 1;
  const Prepared chain = prepare(makeFan(m));
  EXPECT_EQ(chain.adjacency.offset.back(), 2 * (m - 1));
  for (int f = 0; f < m; ++f) {
    std::vector<int> expected;
    if (f > 0) expected.push_back(f - 1);
    if (f + 1 < m) expected.push_back(f + 1);
    const std::vector<int> got(chain.adjacency.neighbour.begin() + chain.adjacency.offset[f],
                               chain.adjacency.neighbour.begin() + chain.adjacency.offset[f + 1]);
    EXPECT_EQ(got, expected) << "face " << f;
  }
  for (double length : chain.adjacency.length) EXPECT_EQ(length, 1.0);
}

TEST(UvFaces, DegenerateFacesHaveNoNormalAndAllDegenerateThrows) {
  // A real triangle, one with a repeated vertex and one with three corners on a line.
  const TexturedMesh mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}},
                          {{0, 1, 2}, {0, 1, 1}, {0, 1, 3}});
  const Prepared p = prepare(mesh);
  EXPECT_EQ(p.total_area, 0.5);
  EXPECT_EQ(p.faces[0].normal, Vec3::UnitZ());
  for (int f : {1, 2}) {
    EXPECT_EQ(p.faces[f].area, 0.0) << "face " << f;
    EXPECT_EQ(p.faces[f].normal, Vec3::Zero()) << "face " << f;
    EXPECT_EQ(p.faces[f].cls, -1) << "face " << f;
  }
  // They take their neighbour's class in the segmentation, and its chart.
  Prepared q = prepare(mesh);
  const Segmentation s = segmentCharts(q.faces, q.adjacency, q.directions, q.total_area);
  for (const Face& face : q.faces) EXPECT_EQ(face.cls, q.faces[0].cls);
  EXPECT_EQ(s.charts.chart_of, (std::vector<int>{0, 0, 0}));

  const TexturedMesh line({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, {{0, 1, 2}});
  std::vector<int> representative;
  const std::vector<int> welded = weldVertices(line.vertices(), representative);
  const std::vector<Vec3> positions = weldedPositions(line.vertices(), representative);
  double total_area = -1.0;
  expectError(
      [&] { makeFaces(line.triangles(), welded, positions, chartDirections(), total_area); },
      {"unwrapUvs", "1 triangles", "degenerate"});
}

// ---------------------------------------------------------------------------------------------
// Segmentation

TEST(UvCharts, DirectionsAreTheCubesFacesEdgesAndCorners) {
  const std::array<Vec3, 26> directions = chartDirections();
  EXPECT_EQ(directions[12], -Vec3::UnitZ());
  EXPECT_EQ(directions[13], Vec3::UnitZ());
  EXPECT_EQ(directions[0], Vec3(-1, -1, -1).normalized());
  EXPECT_EQ(directions[25], Vec3(1, 1, 1).normalized());
  for (const Vec3& d : directions) EXPECT_NEAR(d.norm(), 1.0, 1e-15);
}

// Checks that the cube's charts are its faces: chart c holds triangles 2c and 2c + 1 (the mesh's
// face order), its class the face's normal, its area the face's.
void expectOneChartPerCubeFace(const TexturedMesh& cube, double face_area) {
  Prepared p = prepare(cube);
  const Segmentation s = segmentCharts(p.faces, p.adjacency, p.directions, p.total_area);
  ASSERT_EQ(s.charts.faces.size(), 6u);
  for (int c = 0; c < 6; ++c) {
    EXPECT_EQ(s.charts.faces[c], (std::vector<int>{2 * c, 2 * c + 1})) << "chart " << c;
    EXPECT_EQ(p.directions[s.charts.cls[c]], p.faces[2 * c].normal) << "chart " << c;
    EXPECT_EQ(s.charts.area[c], face_area) << "chart " << c;
  }
  EXPECT_EQ(s.charts.chart_of, (std::vector<int>{0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5}));
  // Each face is one planar unit of its two triangles.
  EXPECT_EQ(s.units.offset, (std::vector<int>{0, 2, 4, 6, 8, 10, 12}));
}

TEST(UvCharts, CubeGivesOneChartPerFace) {
  const TexturedMesh cube = makeSharedCube();
  const Prepared p = prepare(cube);
  EXPECT_EQ(p.total_area, 6.0);
  const std::array<Vec3, 6> normals = {Vec3::UnitX(),  -Vec3::UnitX(), Vec3::UnitY(),
                                       -Vec3::UnitY(), Vec3::UnitZ(),  -Vec3::UnitZ()};
  for (int f = 0; f < 12; ++f) EXPECT_EQ(p.faces[f].normal, normals[f / 2]) << "face " << f;
  expectOneChartPerCubeFace(cube, 1.0);
  // The same on makeBox's 24 vertices (4 per face, two triangles per face in a row too).
  const TexturedMesh box = makeBox(Eigen::Vector3d::Constant(1.0));
  expectOneChartPerCubeFace(box, 1.0);
}

// The cylinder's charts: none mixes caps and side, each cap is one chart of all its triangles,
// and the side (normals spread evenly over the 8 horizontal directions) splits into 8 charts
// of 2 segments / 8 quads each.
void expectCapsAndSideApart(const TexturedMesh& cylinder, int segments) {
  Prepared p = prepare(cylinder);
  const Segmentation s = segmentCharts(p.faces, p.adjacency, p.directions, p.total_area);
  const int side_faces = 2 * segments;
  int cap_charts = 0, side_charts = 0;
  for (size_t c = 0; c < s.charts.faces.size(); ++c) {
    const std::vector<int>& members = s.charts.faces[c];
    ASSERT_FALSE(members.empty());
    const bool cap = members.front() >= side_faces;
    for (int f : members) EXPECT_EQ(f >= side_faces, cap) << "chart " << c << " mixes";
    if (cap) {
      ++cap_charts;
      // Caps alternate bottom (even) and top (odd) after the side.
      const int parity = (members.front() - side_faces) % 2;
      EXPECT_EQ(members.size(), static_cast<size_t>(segments)) << "chart " << c;
      for (int f : members) EXPECT_EQ((f - side_faces) % 2, parity) << "chart " << c;
      EXPECT_EQ(p.directions[s.charts.cls[c]], parity ? Vec3(0, 0, 1) : Vec3(0, 0, -1));
    } else {
      ++side_charts;
      EXPECT_EQ(members.size(), static_cast<size_t>(side_faces / 8)) << "chart " << c;
      EXPECT_EQ(p.directions[s.charts.cls[c]].z(), 0.0) << "chart " << c;
    }
  }
  EXPECT_EQ(cap_charts, 2);
  EXPECT_EQ(side_charts, 8);
}

TEST(UvCharts, ClosedCylindersCapsAndSideSeparate) {
  expectCapsAndSideApart(makeCylinder(64, false), 64);
  // Caps on their own copies of the rim: welded, the mesh is closed (every face has 3
  // neighbours), and the charts are the same.
  const TexturedMesh duplicated = makeCylinder(64, true);
  const Prepared p = prepare(duplicated);
  EXPECT_EQ(p.representative.size(), 2u * 64u + 2u);
  EXPECT_EQ(p.adjacency.offset.back(), 3 * static_cast<int>(duplicated.triangles().size()));
  expectCapsAndSideApart(duplicated, 64);
}

// ---------------------------------------------------------------------------------------------
// Pieces

// Twice the signed area of a 2-D triangle.
double signedArea2(const Vec2& a, const Vec2& b, const Vec2& c) { return cross2(b - a, c - a); }

TEST(UvPieces, AlignPieceMovesAnAxisAlignedRectangleToTheOrigin) {
  Piece piece;
  piece.local = {{5, 7}, {7, 7}, {7, 8}, {5, 8}, {6, 7.5}};
  alignPiece(piece);
  EXPECT_EQ(piece.size, Vec2(2, 1));
  EXPECT_EQ(piece.local, (std::vector<Vec2>{{0, 0}, {2, 0}, {2, 1}, {0, 1}, {1, 0.5}}));
}

TEST(UvPieces, AlignPieceTurnsToTheMinimumRectangleWithoutMirroring) {
  // A 5 x 10 rectangle with sides along (3, 4) and (-8, 6). Every hull edge gives the minimum;
  // the first one, from the leftmost corner (-8, 6) to (0, 0), becomes the x axis.
  Piece piece;
  piece.local = {{0, 0}, {3, 4}, {-5, 10}, {-8, 6}};
  alignPiece(piece);
  EXPECT_NEAR(piece.size.x(), 10.0, 1e-12);
  EXPECT_NEAR(piece.size.y(), 5.0, 1e-12);
  const std::vector<Vec2> expected = {{10, 0}, {10, 5}, {0, 5}, {0, 0}};
  for (size_t i = 0; i < expected.size(); ++i) {
    EXPECT_NEAR((piece.local[i] - expected[i]).norm(), 0.0, 1e-12) << "corner " << i;
    // Inside [0, size] exactly: moved by the same minimum its size was measured from.
    EXPECT_GE(piece.local[i].minCoeff(), 0.0);
    EXPECT_LE(piece.local[i].x(), piece.size.x());
    EXPECT_LE(piece.local[i].y(), piece.size.y());
  }
  EXPECT_GT(signedArea2(piece.local[0], piece.local[1], piece.local[2]), 0.0);
}

TEST(UvPieces, ARampThatWouldOverlapItselfIsSplitIntoPiecesThatDoNot) {
  // One chart (every face looks up) whose projection covers itself.
  const TexturedMesh ramp = test::makeHelicoidRamp();
  Prepared p = prepare(ramp);
  const Segmentation s = segmentCharts(p.faces, p.adjacency, p.directions, p.total_area);
  ASSERT_EQ(s.charts.faces.size(), 1u);
  const std::vector<Piece> pieces =
      makePieces(s.charts, p.faces, p.adjacency, s.units, p.positions, p.directions);
  ASSERT_EQ(pieces.size(), 2u);
  std::vector<int> all;
  for (const Piece& piece : pieces) {
    all.insert(all.end(), piece.faces.begin(), piece.faces.end());
    // Every corner of the piece's faces is one of its vertices; no two faces overlap.
    std::vector<std::array<Vec2, 3>> flat;
    for (int f : piece.faces) {
      std::array<Vec2, 3> t;
      for (int k = 0; k < 3; ++k) {
        const auto it = std::find(piece.vertices.begin(), piece.vertices.end(), p.faces[f].v[k]);
        ASSERT_NE(it, piece.vertices.end());
        t[k] = piece.local[it - piece.vertices.begin()];
        EXPECT_GE(t[k].minCoeff(), 0.0);
        EXPECT_LE(t[k].x(), piece.size.x());
        EXPECT_LE(t[k].y(), piece.size.y());
      }
      EXPECT_GT(signedArea2(t[0], t[1], t[2]), 0.0) << "face " << f << " mirrored";
      flat.push_back(t);
    }
    const double eps = 1e-9 * piece.size.norm();
    for (size_t i = 0; i < flat.size(); ++i) {
      for (size_t j = i + 1; j < flat.size(); ++j) {
        EXPECT_FALSE(interiorsOverlap(flat[i], flat[j], eps))
            << "faces " << piece.faces[i] << " and " << piece.faces[j];
      }
    }
  }
  std::sort(all.begin(), all.end());
  std::vector<int> every(ramp.triangles().size());
  std::iota(every.begin(), every.end(), 0);
  EXPECT_EQ(all, every);
}

// ---------------------------------------------------------------------------------------------
// Packing

TEST(UvPacking, SkylinePlacesEachBoxLowestThenLeftmost) {
  // 10 x 10: a 6 x 4 box at the origin, a 4 x 4 beside it (lower than on top of it), a 10 x 2
  // under both.
  std::vector<Placement> placements;
  ASSERT_TRUE(packSkyline({{6, 4}, {4, 4}, {10, 2}}, {0, 1, 2}, 10, 10, placements));
  ASSERT_EQ(placements.size(), 3u);
  EXPECT_EQ(placements[0].x, 0.0);
  EXPECT_EQ(placements[0].y, 0.0);
  EXPECT_EQ(placements[1].x, 6.0);
  EXPECT_EQ(placements[1].y, 0.0);
  EXPECT_EQ(placements[2].x, 0.0);
  EXPECT_EQ(placements[2].y, 4.0);
  for (const Placement& placement : placements) EXPECT_FALSE(placement.rotated);

  // The order given is the order placed: the 10 x 2 first goes to the origin.
  ASSERT_TRUE(packSkyline({{6, 4}, {4, 4}, {10, 2}}, {2, 0, 1}, 10, 10, placements));
  EXPECT_EQ(placements[2].y, 0.0);
  EXPECT_EQ(placements[0].y, 2.0);
  EXPECT_EQ(placements[1].x, 6.0);
  EXPECT_EQ(placements[1].y, 2.0);

  // A box on the left, lower than its neighbour, rests on the neighbour where it spans both:
  // 3 x 1 at the origin, 7 x 5 beside it, then a 4 x 4 at the left on the 7 x 5's height (as
  // low as at x = 3, further left).
  ASSERT_TRUE(packSkyline({{3, 1}, {7, 5}, {4, 4}}, {0, 1, 2}, 10, 10, placements));
  EXPECT_EQ(placements[1].x, 3.0);
  EXPECT_EQ(placements[1].y, 0.0);
  EXPECT_EQ(placements[2].x, 0.0);
  EXPECT_EQ(placements[2].y, 5.0);
  EXPECT_FALSE(placements[1].rotated);

  // A 2 x 8 box only fits an 8 x 3 container turned; a second one does not fit at all.
  ASSERT_TRUE(packSkyline({{2, 8}}, {0}, 8, 3, placements));
  EXPECT_TRUE(placements[0].rotated);
  EXPECT_EQ(placements[0].x, 0.0);
  EXPECT_EQ(placements[0].y, 0.0);
  EXPECT_FALSE(packSkyline({{2, 8}, {2, 8}}, {0, 1}, 8, 3, placements));
}

Piece pieceOfSize(double width, double height) {
  Piece piece;
  piece.size = Vec2(width, height);
  return piece;
}

TEST(UvPacking, OrderIsLargestFirstByLongerThenShorterSideTiesInOrder) {
  const std::vector<Piece> pieces = {pieceOfSize(1, 1), pieceOfSize(3, 1), pieceOfSize(1, 3),
                                     pieceOfSize(2, 2), pieceOfSize(3, 2), pieceOfSize(1, 1)};
  EXPECT_EQ(packingOrder(pieces), (std::vector<int>{4, 1, 2, 3, 0, 5}));
}

// The gap packPieces keeps between pieces and the container it packs their boxes (each with its
// trailing gap) into, as uv_packing.hpp states them.
struct Room {
  double gap, border, container;
};

Room roomOf(const UnwrapOptions& options) {
  const double padding = options.padding_texels;
  Room room;
  room.gap = padding + 1.0 + kMarginTexels;
  room.border = padding + kMarginTexels;
  room.container = options.texture_size + 1.0 - room.border;
  return room;
}

TEST(UvPacking, SinglePieceFillsTheTextureAlongItsLongerSide) {
  const UnwrapOptions options{1024, 4};
  const Room room = roomOf(options);
  // 2 x 1 m: the longer side spans the texture less the border on both sides.
  const Packing wide = packPieces({pieceOfSize(2, 1)}, options);
  EXPECT_EQ(wide.border, 4 + kMarginTexels);
  EXPECT_EQ(wide.scale, (room.container - room.gap) / 2);
  EXPECT_EQ(wide.scale, scaleUpperBound({pieceOfSize(2, 1)}, room.container, room.gap));
  ASSERT_EQ(wide.placements.size(), 1u);
  EXPECT_EQ(wide.placements[0].x, 0.0);
  EXPECT_EQ(wide.placements[0].y, 0.0);
  EXPECT_FALSE(wide.placements[0].rotated);
  // 1 x 2 m: the same scale, turned so its far edge is nearer.
  const Packing tall = packPieces({pieceOfSize(1, 2)}, options);
  EXPECT_EQ(tall.scale, wide.scale);
  EXPECT_TRUE(tall.placements[0].rotated);

  // Through unwrapUvs: a 2 x 1 m rectangle in the z = 0 plane, seen from +z.
  const TexturedMesh rectangle({{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0}},
                               {{0, 1, 2}, {0, 2, 3}});
  const UnwrapResult result = unwrapUvs(rectangle, options);
  EXPECT_EQ(result.chart_count, 1);
  EXPECT_EQ(result.metres_per_uv, 1024 / wide.scale);
  // Texel columns border .. border + 2 scale, rows border .. border + scale (v up, rows down).
  const double border = wide.border;
  const float u0 = static_cast<float>(border / 1024);
  const float u1 = static_cast<float>((border + 2 * wide.scale) / 1024);
  const float v0 = static_cast<float>(1.0 - (border + 1 * wide.scale) / 1024);
  const float v1 = static_cast<float>(1.0 - border / 1024);
  const std::vector<Eigen::Vector2f> expected = {{u0, v0}, {u1, v0}, {u1, v1}, {u0, v1}};
  ASSERT_EQ(result.mesh.uvs().size(), 4u);
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(result.mesh.vertices()[k], rectangle.vertices()[k]) << "vertex " << k;
    EXPECT_EQ(result.mesh.uvs()[k], expected[k]) << "vertex " << k;
  }
}

// Checks packPieces' promises: every piece inside the texture less its padding, every two
// pieces at least padding + 1 texels apart (padding texel centres between them empty), the
// scale positive and within the upper bound. Exact comparisons: the skyline's tolerance
// (1e-9 of the container) is far inside kMarginTexels.
void expectPackedApart(const std::vector<Piece>& pieces, const UnwrapOptions& options) {
  const Packing packing = packPieces(pieces, options);
  const Room room = roomOf(options);
  const double texture = options.texture_size, padding = options.padding_texels;
  EXPECT_GT(packing.scale, 0.0);
  EXPECT_LE(packing.scale, scaleUpperBound(pieces, room.container, room.gap));
  ASSERT_EQ(packing.placements.size(), pieces.size());
  struct Box {
    double left, top, right, bottom;
  };
  std::vector<Box> boxes;
  for (size_t i = 0; i < pieces.size(); ++i) {
    const Placement& placement = packing.placements[i];
    const Vec2 size =
        placement.rotated ? Vec2(pieces[i].size.y(), pieces[i].size.x()) : pieces[i].size;
    Box box;
    box.left = packing.border + placement.x;
    box.top = packing.border + placement.y;
    box.right = box.left + size.x() * packing.scale;
    box.bottom = box.top + size.y() * packing.scale;
    EXPECT_GE(box.left, padding) << "piece " << i;
    EXPECT_GE(box.top, padding) << "piece " << i;
    EXPECT_LE(box.right, texture - padding) << "piece " << i;
    EXPECT_LE(box.bottom, texture - padding) << "piece " << i;
    boxes.push_back(box);
  }
  for (size_t i = 0; i < boxes.size(); ++i) {
    for (size_t j = i + 1; j < boxes.size(); ++j) {
      const Box& a = boxes[i];
      const Box& b = boxes[j];
      const bool apart = a.right + padding + 1 <= b.left || b.right + padding + 1 <= a.left ||
                         a.bottom + padding + 1 <= b.top || b.bottom + padding + 1 <= a.top;
      EXPECT_TRUE(apart) << "pieces " << i << " and " << j;
    }
  }
  // The same pieces give the same packing, bit for bit.
  const Packing again = packPieces(pieces, options);
  EXPECT_EQ(again.scale, packing.scale);
  for (size_t i = 0; i < pieces.size(); ++i) {
    EXPECT_EQ(again.placements[i].x, packing.placements[i].x);
    EXPECT_EQ(again.placements[i].y, packing.placements[i].y);
    EXPECT_EQ(again.placements[i].rotated, packing.placements[i].rotated);
  }
}

TEST(UvPacking, RandomPiecesNeverOverlapAndKeepTheirPadding) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> side(0.001, 0.05);
  std::vector<Piece> pieces;
  for (int i = 0; i < 150; ++i) pieces.push_back(pieceOfSize(side(random), side(random)));
  pieces.push_back(pieceOfSize(0.0, 0.02));  // a segment: no area, still padded
  for (const UnwrapOptions& options :
       {UnwrapOptions{1024, 4}, UnwrapOptions{256, 2}, UnwrapOptions{512, 0}}) {
    SCOPED_TRACE(options.texture_size);
    expectPackedApart(pieces, options);
  }
}

TEST(UvPacking, PiecesOfAMeshNeverOverlapAndKeepTheirPadding) {
  Prepared p = prepare(makeUvSphere(0.005, 24, 48));
  const Segmentation s = segmentCharts(p.faces, p.adjacency, p.directions, p.total_area);
  const std::vector<Piece> pieces =
      makePieces(s.charts, p.faces, p.adjacency, s.units, p.positions, p.directions);
  ASSERT_GE(pieces.size(), 26u);
  expectPackedApart(pieces, UnwrapOptions{1024, 4});
  expectPackedApart(pieces, UnwrapOptions{128, 1});
}

TEST(UvPacking, PaddingThatCannotFitThrows) {
  // 64 texels, padding 16: every piece's box is at least 17.01 texels square (its trailing
  // gap) and the container 48.99 (64 + 1 - 16.01): 2 x 2 boxes fit, 16 do not.
  const std::vector<Piece> four(4, pieceOfSize(0.01, 0.01));
  EXPECT_GT(packPieces(four, UnwrapOptions{64, 16}).scale, 0.0);
  const std::vector<Piece> many(16, pieceOfSize(0.01, 0.01));
  expectError(
      [&] {
        packPieces(many, UnwrapOptions{64, 16});
      },
      {"unwrapUvs", "16 charts", "padding_texels = 16", "larger texture_size"});
}

}  // namespace
}  // namespace norm2tex
