#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace norm2tex {

/// What norm2tex_export writes (docs/datasets.md, "Export and PyTorch").
struct ExportOptions {
  std::string out_dir;
  bool force = false;                ///< write into a non-empty out_dir (files are replaced)
  std::string depth_format = "png16";  ///< png16: uint16 micrometres; tiff: float32 metres
  /// Backgrounds to subtract per sensor, when the bags hold none (the renderer's latched
  /// <sensor>/background): sensor name -> PNG.
  std::map<std::string, std::string> background_files;
};

struct ExportSummary {
  std::uint64_t frames = 0;
  std::uint64_t frames_with_markers = 0;
  std::uint64_t frames_with_shear = 0;  ///< recorded with the recorder's ~record_shear
  std::map<std::string, std::uint64_t> frames_per_material;
  /// What the bags held that could not be read (TactileBagReader::warnings).
  std::vector<std::string> warnings;
};

/// Exports dataset_recorder bags for training, in one pass over the bags (TactileBagReader):
///   OUT/raw/<material>/<name>.png    the tactile image (BGR PNG)
///   OUT/diff/<material>/<name>.png   image - background + 128 per channel (clamped to 0..255),
///                                    the paper's classifier input: 128 where nothing touches
///   OUT/depth/<material>/<name>.png  gel indentation, uint16 micrometres (or .tiff, float metres)
///   OUT/markers/<material>/<name>.csv  the frame's markers (sensors with markers): one row per
///                                    marker, its grid row and column, rest and current position
///                                    (pixels) and displacement (mm, gel frame)
///   OUT/labels.csv                   one row per frame: paths relative to OUT and every label
///   OUT/export.yaml                  counts per material, the sources, the encodings
/// <name> = <sensor>_s<shard>_<stamp in ns>, unique within a recording and across its shards.
/// raw/ and diff/ are ImageFolder layouts (class = material). Throws Error: out_dir not empty
/// without force, unwritable, a bag that is not a bag, a frame without a background to
/// subtract, two frames with one name (bags of different recordings mixed), a failed write.
/// `progress(done)` is called after every frame.
ExportSummary exportDataset(const std::vector<std::string>& bags, const ExportOptions& options,
                            const std::function<void(std::uint64_t)>& progress = {});

}  // namespace norm2tex
