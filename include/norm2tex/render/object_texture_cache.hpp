#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <future>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <utility>

#include "norm2tex/render/object_texture.hpp"

namespace norm2tex {

/// The few latest object textures, keyed by name ("wood/3"), and the next one prepared on a
/// background thread while frames still render with the current one.
///
/// Why: a procedural material variant takes ~0.5 s to generate and bake; a probe dataset walks
/// through 24 variants per material, and preparing each on the render thread stalled the whole
/// lock-step pipeline for that long. The source of the frames knows which texture comes next
/// (SimFrame.next_material), so the renderer asks for it early and finds it ready.
///
/// Thread safety: every member may be called from any thread. At most one preparation runs in
/// the background at a time (a prefetch while another is under way is ignored; call it again
/// later). The destructor waits for it.
///
/// The background is one thread for the cache's life, not one per texture: a fresh thread
/// starts with empty thread-local scratch buffers and malloc arena, so each of its textures
/// paid for faulting in and zeroing fresh pages again (~20 % of a 2048^2 variant's time in a
/// recording).
class ObjectTextureCache {
 public:
  using Prepare = std::function<ObjectTexture()>;

  /// Where get() found its texture.
  enum class Origin {
    kCached,      ///< prepared earlier and kept
    kPrefetched,  ///< prepared in the background (ready, or awaited for the rest)
    kPrepared,    ///< prepared by get() itself, on the calling thread
  };

  struct Lookup {
    std::shared_ptr<const ObjectTexture> texture;
    Origin origin = Origin::kPrepared;
    double waited_s = 0.0;  ///< time get() spent preparing or waiting for the background
  };

  /// Keeps at most `capacity` (>= 1) textures; each holds an atlas of megabytes.
  explicit ObjectTextureCache(std::size_t capacity);
  ~ObjectTextureCache();
  ObjectTextureCache(const ObjectTextureCache&) = delete;
  ObjectTextureCache& operator=(const ObjectTextureCache&) = delete;

  /// The texture under `key`: kept, or being prepared in the background (waits for it), or
  /// prepared now by `prepare`. The Error of a failed preparation (background or not) is
  /// thrown here, and nothing is kept for the key, so a later get() tries again.
  Lookup get(const std::string& key, const Prepare& prepare);

  /// Starts preparing `key` in the background, unless it is kept, being prepared, or another
  /// preparation is under way. Returns whether it started one.
  bool prefetch(const std::string& key, Prepare prepare);

  bool contains(const std::string& key) const;
  /// Whether a background preparation is under way.
  bool preparing() const;

 private:
  struct InFlight {
    std::string key;
    std::shared_future<std::shared_ptr<const ObjectTexture>> result;
  };
  void keep(const std::string& key, std::shared_ptr<const ObjectTexture> texture);
  void runBackground();

  const std::size_t capacity_;
  mutable std::mutex mutex_;
  /// Most recent first.
  std::list<std::pair<std::string, std::shared_ptr<const ObjectTexture>>> kept_;
  std::unique_ptr<InFlight> in_flight_;
  /// The background thread (started by the first prefetch) and its next job.
  std::thread background_;
  std::condition_variable job_ready_;
  std::function<void()> job_;
  bool stopping_ = false;
};

}  // namespace norm2tex
