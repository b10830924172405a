#include "norm2tex/render/object_texture_cache.hpp"

#include <algorithm>
#include <chrono>
#include <exception>

#include "norm2tex/common/error.hpp"

namespace norm2tex {
namespace {

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

ObjectTextureCache::ObjectTextureCache(std::size_t capacity) : capacity_(capacity) {
  if (capacity_ < 1) throw Error("ObjectTextureCache: capacity must be at least 1");
}

ObjectTextureCache::~ObjectTextureCache() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;  // the background still runs a job it was given, then returns
  }
  job_ready_.notify_all();
  if (background_.joinable()) background_.join();
}

void ObjectTextureCache::runBackground() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    job_ready_.wait(lock, [this] { return stopping_ || job_; });
    if (!job_) return;  // stopping, nothing left to run
    std::function<void()> job = std::move(job_);
    job_ = nullptr;
    lock.unlock();
    job();  // never throws: the job hands its result or error to a promise
    lock.lock();
  }
}

void ObjectTextureCache::keep(const std::string& key,
                              std::shared_ptr<const ObjectTexture> texture) {
  // Caller holds mutex_.
  kept_.remove_if([&](const auto& entry) { return entry.first == key; });
  kept_.emplace_front(key, std::move(texture));
  while (kept_.size() > capacity_) kept_.pop_back();
}

ObjectTextureCache::Lookup ObjectTextureCache::get(const std::string& key, const Prepare& prepare) {
  const auto start = std::chrono::steady_clock::now();
  Lookup lookup;
  std::shared_future<std::shared_ptr<const ObjectTexture>> pending;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto kept = std::find_if(kept_.begin(), kept_.end(),
                                   [&](const auto& entry) { return entry.first == key; });
    if (kept != kept_.end()) {
      kept_.splice(kept_.begin(), kept_, kept);
      lookup.texture = kept_.front().second;
      lookup.origin = Origin::kCached;
      return lookup;
    }
    if (in_flight_ && in_flight_->key == key) pending = in_flight_->result;
  }
  if (pending.valid()) {
    lookup.origin = Origin::kPrefetched;
    try {
      lookup.texture = pending.get();  // waits if the background is not done yet
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (in_flight_ && in_flight_->key == key) in_flight_.reset();
      throw;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    if (in_flight_ && in_flight_->key == key) in_flight_.reset();
    keep(key, lookup.texture);
    lookup.waited_s = secondsSince(start);
    return lookup;
  }
  lookup.origin = Origin::kPrepared;
  lookup.texture = std::make_shared<const ObjectTexture>(prepare());
  std::lock_guard<std::mutex> lock(mutex_);
  keep(key, lookup.texture);
  lookup.waited_s = secondsSince(start);
  return lookup;
}

bool ObjectTextureCache::prefetch(const std::string& key, Prepare prepare) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (in_flight_) {
    // The finished one is taken in (or dropped, when it failed: get() will prepare it again
    // and report the error) before another starts.
    if (in_flight_->result.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
      return false;
    }
    try {
      keep(in_flight_->key, in_flight_->result.get());
    } catch (...) {
    }
    in_flight_.reset();
  }
  if (std::any_of(kept_.begin(), kept_.end(),
                  [&](const auto& entry) { return entry.first == key; })) {
    return false;
  }
  auto promise = std::make_shared<std::promise<std::shared_ptr<const ObjectTexture>>>();
  in_flight_ = std::make_unique<InFlight>(InFlight{key, promise->get_future().share()});
  job_ = [promise, prepare = std::move(prepare)]() {
    try {
      promise->set_value(std::make_shared<const ObjectTexture>(prepare()));
    } catch (...) {
      promise->set_exception(std::current_exception());
    }
  };
  if (!background_.joinable()) background_ = std::thread([this] { runBackground(); });
  job_ready_.notify_one();
  return true;
}

bool ObjectTextureCache::contains(const std::string& key) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return std::any_of(kept_.begin(), kept_.end(),
                     [&](const auto& entry) { return entry.first == key; });
}

bool ObjectTextureCache::preparing() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return in_flight_ &&
         in_flight_->result.wait_for(std::chrono::seconds(0)) != std::future_status::ready;
}

}  // namespace norm2tex
