#pragma once
// unwrapUvs' segmentation: every face labelled with one of 26 directions, the labels smoothed
// over planar units, charts as edge-connected faces of one label, small fragments merged into
// their neighbours. Private to the core (src/core/mesh/).

#include <array>
#include <vector>

#include "mesh/uv_adjacency.hpp"
#include "mesh/uv_geometry.hpp"

namespace norm2tex {
namespace uv_unwrap_detail {

/// Faces may be given any direction within this angle (1/cos(40 deg) = 1.31 stretch at worst)
/// when that shortens the borders between charts: noisy normals (scans) would otherwise cut the
/// surface into thousands of single-triangle charts.
constexpr double kMaxAngleDeg = 40.0;

/// The 26 directions of a cube's faces, edges and corners: every unit normal is within
/// 27.6 deg of one of them (the spherical Voronoi cells' covering radius). Order: x, then y,
/// then z from -1 to 1 (index 12 is -z, 13 is +z).
std::array<Vec3, 26> chartDirections();

/// Coplanar, edge-connected faces: the units the labelling moves as a whole.
struct PlanarUnits {
  std::vector<int> unit_of;  ///< per face
  std::vector<int> offset;   ///< faces of unit u: faces[offset[u] .. offset[u + 1])
  std::vector<int> faces;
  std::vector<double> area;      ///< per unit
  std::vector<Vec3> normal_sum;  ///< per unit: sum of area * normal
};

/// Groups edge-connected faces within kPlanarAngleDeg (0.1 deg) of their unit's first face into
/// planar units, in the order of each unit's first face; a degenerate face is a unit of its own.
PlanarUnits findPlanarUnits(const std::vector<Face>& faces, const Adjacency& adjacency);

/// Degenerate faces take a neighbour's class, so they join its chart (their own projection is
/// a segment and claims no texel); isolated ones form their own tiny charts.
void classifyDegenerateFaces(std::vector<Face>& faces, const Adjacency& adjacency);

/// Weight lambda of the border length in smoothLabels: kSmoothness times the root of the mean
/// area of the non-degenerate faces, so the smoothing does not depend on the mesh's resolution.
double borderWeight(const std::vector<Face>& faces, double total_area);

/// Smooths the faces' labels (cls): iterated conditional modes over planar units minimising
///   sum over faces of area (1 - n . d_label) + lambda * length of borders between labels,
/// each unit restricted to directions within kMaxAngleDeg of all its faces. Starts from the
/// nearest direction, so clean meshes keep their nearest-direction charts except along jagged
/// borders.
void smoothLabels(std::vector<Face>& faces, const Adjacency& adjacency, const PlanarUnits& units,
                  const std::array<Vec3, 26>& directions, double lambda);

/// Charts: edge-connected components of faces with one label.
struct Charts {
  std::vector<int> chart_of;            ///< per face
  std::vector<std::vector<int>> faces;  ///< per chart; emptied when merged into another
  std::vector<double> area;             ///< per chart
  std::vector<int> cls;                 ///< per chart: index into chartDirections()
};

/// Splits the labelled faces into edge-connected components of one label, in the order of
/// their first face.
Charts findCharts(const std::vector<Face>& faces, const Adjacency& adjacency);

/// Fragments (smallest first) join the neighbour they share the longest border with, when they
/// are small enough next to it and all their faces are within kMergeAngleDeg of its direction.
void mergeFragments(Charts& charts, const std::vector<Face>& faces, const Adjacency& adjacency,
                    const std::array<Vec3, 26>& directions, double total_area);

/// The segmentation's result: the planar units (the projection prefers their planes) and the
/// charts.
struct Segmentation {
  PlanarUnits units;
  Charts charts;
};

/// The whole segmentation of unwrapUvs on faces from makeFaces: degenerate faces classified,
/// labels smoothed over planar units, charts found and fragments merged. Sets every face's cls
/// to its final label (before the merge: merged fragments keep theirs, their chart has its own).
Segmentation segmentCharts(std::vector<Face>& faces, const Adjacency& adjacency,
                           const std::array<Vec3, 26>& directions, double total_area);

}  // namespace uv_unwrap_detail
}  // namespace norm2tex
