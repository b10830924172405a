#include "norm2tex/common/huge_pages.hpp"

#include <sys/mman.h>

#include <cstdint>
#include <map>
#include <mutex>
#include <new>

namespace norm2tex {
namespace {

constexpr size_t kHugePage = size_t(2) << 20;

/// Length of the mapping behind a matrix of `bytes`: whole huge pages plus one for alignment.
size_t mappingLength(size_t bytes) {
  return (bytes + kHugePage - 1) / kHugePage * kHugePage + kHugePage;
}

/// Freed mappings kept for the next matrix of the same mapping length: a texture preparation
/// allocates the same buffers for every variant (~250 MB at 2048^2), and zeroing them as fresh
/// huge pages took ~7 % of a print3d recording's CPU. Up to kLimit bytes are kept.
class MappingPool {
 public:
  static constexpr size_t kLimit = size_t(512) << 20;

  /// A kept mapping of exactly `length` bytes (contents are what its last matrix left), or null.
  void* take(size_t length) {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto kept = free_.find(length);
    if (kept == free_.end()) return nullptr;
    void* base = kept->second;
    free_.erase(kept);
    bytes_ -= length;
    return base;
  }

  /// Keeps the mapping if the pool has room; false means the caller unmaps it.
  bool give(void* base, size_t length) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (bytes_ + length > kLimit) return false;
    free_.emplace(length, base);
    bytes_ += length;
    return true;
  }

 private:
  std::mutex mutex_;
  std::multimap<size_t, void*> free_;
  size_t bytes_ = 0;
};

MappingPool& mappingPool() {
  static MappingPool* pool = new MappingPool;  // never destroyed: matrices may outlive statics
  return *pool;
}

class HugePageAllocator final : public cv::MatAllocator {
 public:
  cv::UMatData* allocate(int dims, const int* sizes, int type, void* user_data, size_t* step,
                         cv::AccessFlag, cv::UMatUsageFlags) const override {
    // Same layout rules as OpenCV's StdMatAllocator.
    size_t total = CV_ELEM_SIZE(type);
    for (int i = dims - 1; i >= 0; --i) {
      if (step != nullptr) {
        if (user_data != nullptr && step[i] != cv::Mat::AUTO_STEP) {
          CV_Assert(total <= step[i]);
          total = step[i];
        } else {
          step[i] = total;
        }
      }
      total *= sizes[i];
    }
    auto* u = new cv::UMatData(this);
    u->size = total;
    if (user_data != nullptr) {
      u->data = u->origdata = static_cast<uchar*>(user_data);
      u->flags |= cv::UMatData::USER_ALLOCATED;
      return u;
    }
    if (total < kHugePage) {
      u->data = u->origdata = static_cast<uchar*>(cv::fastMalloc(total));
      return u;
    }
    const size_t length = mappingLength(total);
    void* base = mappingPool().take(length);
    const bool fresh = base == nullptr;
    if (fresh) {
      base = mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    }
    if (base == MAP_FAILED) {
      delete u;
      throw std::bad_alloc();
    }
    const auto address = reinterpret_cast<std::uintptr_t>(base);
    uchar* aligned = reinterpret_cast<uchar*>((address + kHugePage - 1) / kHugePage * kHugePage);
    if (fresh) {
      madvise(aligned, length - static_cast<size_t>(aligned - static_cast<uchar*>(base)),
              MADV_HUGEPAGE);  // advice only: without huge pages this is an ordinary mapping
    }
    u->origdata = static_cast<uchar*>(base);
    u->data = aligned;
    return u;
  }

  bool allocate(cv::UMatData* u, cv::AccessFlag, cv::UMatUsageFlags) const override {
    return u != nullptr;
  }

  void deallocate(cv::UMatData* u) const override {
    if (u == nullptr) return;
    if (!(u->flags & cv::UMatData::USER_ALLOCATED)) {
      if (u->size < kHugePage) {
        cv::fastFree(u->origdata);
      } else if (!mappingPool().give(u->origdata, mappingLength(u->size))) {
        munmap(u->origdata, mappingLength(u->size));
      }
    }
    delete u;
  }
};

}  // namespace

cv::MatAllocator* hugePageAllocator() {
  static HugePageAllocator allocator;
  return &allocator;
}

void createWithHugePages(cv::Mat& matrix, int rows, int cols, int type) {
  matrix.release();
  matrix.allocator = hugePageAllocator();
  matrix.create(rows, cols, type);
}

}  // namespace norm2tex
