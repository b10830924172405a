#pragma once

#include "norm2tex/mesh/textured_mesh.hpp"
#include "norm2tex/texture/height_atlas_baker.hpp"

namespace norm2tex {

/// How the islands of a mesh bake were made to agree across the mesh's seams.
struct SeamReport {
  int seam_edges = 0;  ///< mesh edges whose two sides lie in different islands of the atlas
  int samples = 0;     ///< sample pairs along those edges that landed on valid texels
  /// Height step across the seams (RMS over the samples) before and after the island offsets,
  /// relative to the relief amplitude (the percentile_low..percentile_high range of H).
  double step_before = 0.0;
  double step_after = 0.0;
};

struct MeshBakeReport {
  BakeReport bake;
  int chart_count = 0;        ///< UV charts of the mesh (computeUvLayout's islands)
  double mm_per_texel = 0.0;  ///< of the surface, area-weighted over the charts (or given)
  SeamReport seams;
};

/// H_global of a mesh's own normal texture, with the mesh's UV charts as the islands.
///
/// Islands: the mesh's UV charts rasterised into the atlas (computeUvLayout): texels outside
/// every chart are invalid whatever the alpha says, and charts that touch in the texture are
/// still integrated apart; a chart's texels split into 4-connected parts where invalid texels
/// cut it. Scale: the surface's mm per texel (sqrt(3-D area / UV area), area-weighted over the
/// charts) is used for the relief cutoff and the physical scale unless options.mm_per_texel is
/// given. Seams: every island is integrated with zero mean on its own; islands that meet on the
/// mesh get constant offsets so that heights sampled at both UVs of every seam edge agree (least
/// squares over the island constants; islands without a seam keep zero mean). Then the usual
/// normalisation. Throws Error when the mesh has no UVs or no chart covers a valid texel.
HeightAtlas bakeHeightAtlasForMesh(const NormalMap& normal_map, const TexturedMesh& mesh,
                                   BakeOptions options = {}, const BakeProgress& progress = {},
                                   MeshBakeReport* report = nullptr);

}  // namespace norm2tex
